//! Voxelizing in bricks (the Dask front end's library side) gives the single run's voxels:
//! the surface of each brick's binned faces clipped to the brick, and solids whose outside
//! components are joined across bricks. Generated fixtures with pockets, holes and nested
//! shells, at brick sizes that cut them anywhere.
#![cfg(feature = "fixtures")]

use glam::DVec3;
use std::collections::BTreeMap;
use voxelkit::grid::SparseGrid;
use voxelkit::io::brick_set::fill_box;
use voxelkit::mesh::{GridFit, Mesh, generate};
use voxelkit::pipeline::brick_exterior::exterior_labels;
use voxelkit::pipeline::bricks::{BrickLayout, BrickOutside, FACES, brick_surface, sub_mesh};
use voxelkit::progress::Progress;
use voxelkit::solids::exterior_flood::{FloodMethod, solid_from_surface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

fn options(separability: Separability) -> SeparatingOptions {
    SeparatingOptions {
        separability,
        ..Default::default()
    }
}

/// The surface and the solid, assembled from bricks of `size`.
fn in_bricks(
    mesh: &Mesh,
    resolution: u32,
    size: u32,
    sep: Separability,
) -> (SparseGrid, SparseGrid) {
    let layout = BrickLayout::new(mesh, GridFit::Resolution(resolution), size).unwrap();
    let bins = layout.bin_faces(mesh);
    let none = Progress::none();
    let mut surface = SparseGrid::new(layout.transform, Default::default());
    let mut parts = BTreeMap::new();
    for (b, faces) in &bins {
        let sub = sub_mesh(mesh, faces);
        let brick = brick_surface(
            &sub,
            layout.transform,
            layout.voxels(*b),
            &options(sep),
            &none,
        )
        .unwrap();
        surface.union(&brick);
        let solid_surface = brick_surface(
            &sub,
            layout.transform,
            layout.voxels(*b),
            &options(Separability::TwentySix),
            &none,
        )
        .unwrap();
        let outside = BrickOutside::label(&solid_surface, layout.voxels(*b)).unwrap();
        parts.insert(*b, (solid_surface, outside));
    }
    let faces: BTreeMap<_, Vec<Vec<u32>>> = parts
        .iter()
        .map(|(b, (_, o))| (*b, (0..FACES).map(|f| o.face(f)).collect()))
        .collect();
    let exterior = exterior_labels(&layout, &faces).unwrap();
    let mut solid = SparseGrid::new(layout.transform, Default::default());
    for (b, labels) in &exterior {
        match parts.get(b) {
            Some((s, outside)) => solid.union(&outside.solid(s, labels)),
            None if labels.is_empty() => fill_box(&mut solid, layout.voxels(*b)),
            None => assert_eq!(labels, &[1]),
        }
    }
    (surface, solid)
}

fn same(a: &SparseGrid, b: &SparseGrid) -> bool {
    let mut d = a.clone();
    d.difference(b);
    a.voxel_count() == b.voxel_count() && d.voxel_count() == 0
}

#[test]
fn bricks_give_the_single_runs_surface_and_solid() {
    let fixtures = [
        (
            "torus",
            generate::torus(DVec3::new(0.3, -0.2, 0.1), 1.0, 0.35, 48, 24),
        ),
        ("g shape", generate::g_shape()),
        ("spheres in a box", generate::spheres_in_box()),
        ("random", generate::random_closed(7)),
    ];
    for (name, mesh) in &fixtures {
        for (resolution, size) in [(90, 16), (120, 40), (64, 128)] {
            for sep in [Separability::Six, Separability::TwentySix] {
                let (surface, solid) = in_bricks(mesh, resolution, size, sep);
                let t =
                    voxelkit::mesh::fit_transform(&mesh.bbox(), GridFit::Resolution(resolution))
                        .unwrap();
                let (single, _) = voxelize_mesh(mesh, t, &options(sep), &Progress::none()).unwrap();
                assert!(
                    same(&surface, &single),
                    "{name} {resolution}/{size} {sep:?}: surface"
                );
                let (shell, _) = voxelize_mesh(
                    mesh,
                    t,
                    &options(Separability::TwentySix),
                    &Progress::none(),
                )
                .unwrap();
                let mut whole = solid_from_surface(&shell, FloodMethod::Spans, &Progress::none())
                    .unwrap()
                    .inside;
                whole.union(&shell);
                assert!(same(&solid, &whole), "{name} {resolution}/{size}: solid");
                assert!(
                    whole.voxel_count() > shell.voxel_count(),
                    "{name}: a solid inside"
                );
            }
        }
    }
}

#[test]
fn brick_sizes_must_be_multiples_of_eight() {
    let mesh = generate::torus(DVec3::ZERO, 1.0, 0.3, 16, 8);
    for bad in [0, 4, 12] {
        let e = BrickLayout::new(&mesh, GridFit::Resolution(64), bad).unwrap_err();
        assert!(e.to_string().contains("multiple of 8"), "{e}");
    }
}
