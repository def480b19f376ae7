//! voxelkit writes and reads `.vdb` files itself (`io::vdb_writer`, `io::vdb_reader`): whatever
//! the compression and precision, OpenVDB reads back every grid it writes with the same
//! voxels, tiles, values and normals, leaves at negative coordinates and past a root node's
//! 4096 voxels included, and voxelkit's reader reads them as OpenVDB does.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use glam::DVec3;
use voxelkit::grid::SparseGrid;
use voxelkit::io::vdb::{Compression, WriteOptions, read_vdb_grid, write_vdb_as};
use voxelkit::mesh::generate;
use voxelkit::voxelize::separating::SeparatingOptions;

mod common;

fn sorted_voxels(g: &SparseGrid) -> Vec<[i64; 3]> {
    let mut v: Vec<_> = g.voxels().collect();
    v.sort();
    v
}

/// A torus surface with normals, placed across the origin.
fn surface_with_normals() -> SparseGrid {
    let mut mesh = generate::torus(DVec3::ZERO, 1.0, 0.35, 48, 24);
    for p in &mut mesh.positions {
        *p += DVec3::new(-0.6, 0.3, -0.2);
    }
    let opts = SeparatingOptions {
        normals: true,
        ..Default::default()
    };
    common::voxelize_at(&mesh, 80, opts).0
}

/// The torus's voxels without channels, plus whole 8^3 and 128^3 blocks far from it, on both
/// sides of the origin and in other root nodes.
fn set_with_tiles(surface: &SparseGrid) -> SparseGrid {
    let mut grid = SparseGrid::new(surface.transform, Default::default());
    for c in surface.voxels() {
        grid.insert(c);
    }
    for origin in [
        [-8, -8, -8],
        [512, 0, 8],
        [-4104, 16, 0],
        [8000, -4096, 4096],
    ] {
        grid.fill_leaf_block(origin);
    }
    for origin in [[256, 256, -256], [-4096, 0, 4096]] {
        grid.fill_node_block(origin);
    }
    grid
}

#[test]
fn openvdb_reads_back_every_grid_in_every_compression_and_precision() {
    let dir = tempfile::tempdir().unwrap();
    let surface = surface_with_normals();
    let set = set_with_tiles(&surface);
    for compression in [Compression::Blosc, Compression::Zip, Compression::None] {
        for half in [false, true] {
            let what = format!("{compression:?}, half {half}");
            let options = WriteOptions {
                grids: vec![],
                compression,
                half,
            };
            // A set with tiles as `density` (and `voxels`), the surface with its normals.
            let tiled = dir.path().join("tiled.vdb");
            let with_normals = dir.path().join("normals.vdb");
            let all = WriteOptions {
                grids: vec!["density".into(), "voxels".into()],
                ..options.clone()
            };
            write_vdb_as(&tiled, &set, &[], &[], &all).unwrap();
            write_vdb_as(&with_normals, &surface, &[], &[], &options).unwrap();

            for name in ["density", "voxels"] {
                common::assert_read_as_openvdb_reads(&tiled, name);
                let back = read_vdb_grid(&tiled, Some(name)).unwrap();
                assert_eq!(sorted_voxels(&back), sorted_voxels(&set), "{what}: {name}");
                assert_eq!(
                    back.tiles().with_edges().count(),
                    set.tiles().with_edges().count(),
                    "{what}: {name}'s tiles"
                );
            }
            let density = read_vdb_grid(&tiled, Some("density")).unwrap();
            for leaf in density.leaves() {
                let values = leaf.value.as_ref().unwrap();
                assert!(leaf.offsets().all(|n| values[n] == 1.0), "{what}: density");
            }

            common::assert_read_as_openvdb_reads(&with_normals, "density");
            common::assert_read_as_openvdb_reads(&with_normals, "normal");
            let normals = read_vdb_grid(&with_normals, Some("normal")).unwrap();
            assert_eq!(sorted_voxels(&normals), sorted_voxels(&surface), "{what}");
            let tolerance = if half { 1e-3 } else { 0.0 };
            for leaf in normals.leaves() {
                let written = surface.leaf(leaf.origin).unwrap();
                let (a, b) = (
                    leaf.normal.as_ref().unwrap(),
                    written.normal.as_ref().unwrap(),
                );
                for n in leaf.offsets() {
                    for k in 0..3 {
                        assert!(
                            (a[n][k] - b[n][k]).abs() <= tolerance,
                            "{what}: normal {:?} read as {:?}",
                            b[n],
                            a[n]
                        );
                    }
                }
            }
        }
    }
}
