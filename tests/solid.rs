//! Solids by exterior flooding against an exact inside test (ray parity at voxel centres) on
//! every voxel off the surface, on the closed meshes of the data folder, with either flood. The
//! only disagreements allowed are outside voxels sealed in by the surface where two sheets
//! pass within a voxel or two (the flood cannot reach them); an inside voxel reached from
//! outside would be a leak and fails.

mod common;

use voxelkit::mesh::Mesh;
use voxelkit::mesh::inside::inside_centres;
use voxelkit::ops::flood::padded;
use voxelkit::solids::exterior_flood::{FloodMethod, solid_from_surface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::SeparatingOptions;

#[test]
fn flooded_solids_match_ray_parity_off_the_surface() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap();
        for resolution in [64, 128, 256] {
            let options = SeparatingOptions {
                separability: Separability::TwentySix,
                ..Default::default()
            };
            let (surface, _) = common::voxelize_at(&mesh, resolution, options);
            // FloodingXYZ with a small stack at 64, the span flood above.
            let method = if resolution == 64 {
                FloodMethod::Xyz { capacity: 4096 }
            } else {
                FloodMethod::Spans
            };
            let solid = solid_from_surface(&surface, method, &voxelkit::progress::Progress::none())
                .unwrap();
            let bbox = padded(surface.bbox().unwrap(), 2);
            let exact = inside_centres(&mesh, &surface.transform, bbox).unwrap();
            let mut wrong = 0u64;
            for i in 0..exact.len() {
                let c = exact.coord(i);
                if !surface.contains(c) && solid.inside.contains(c) != exact.get_index(i) {
                    assert!(
                        solid.inside.contains(c),
                        "{name} {resolution}: inside voxel {c:?} reached from outside"
                    );
                    wrong += 1;
                }
            }
            eprintln!(
                "{name} {resolution}: {} inside, {} surface voxels; {wrong} sealed outside voxels called inside",
                solid.measures.inside_voxels, solid.measures.surface_voxels
            );
            assert!(
                wrong * 1000 <= solid.measures.inside_voxels,
                "{name} {resolution}: {wrong} disagree"
            );
            let v = mesh.signed_volume().abs();
            let m = solid.measures;
            assert!(
                m.volume_inside <= v && v <= m.volume_with_surface,
                "{name} {resolution}: {v} not in [{}, {}]",
                m.volume_inside,
                m.volume_with_surface
            );
        }
    }
}

/// The block flood (the default) fills exactly the voxels the voxel-by-voxel span flood fills,
/// on every closed mesh of the data folder, and holds the whole blocks of the inside as tiles.
#[test]
fn the_block_flood_fills_what_the_voxel_flood_fills_on_every_closed_mesh() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let names = common::shared_meshes(&data);
    let mut closed = 0;
    for path in names {
        let mesh = Mesh::load(&path).unwrap();
        if !mesh.edge_counts().is_closed() {
            continue;
        }
        closed += 1;
        for resolution in [128, 256] {
            let options = SeparatingOptions {
                separability: Separability::TwentySix,
                ..Default::default()
            };
            let (surface, _) = common::voxelize_at(&mesh, resolution, options);
            let none = voxelkit::progress::Progress::none();
            let blocks = solid_from_surface(&surface, FloodMethod::Blocks, &none).unwrap();
            let spans = solid_from_surface(&surface, FloodMethod::Spans, &none).unwrap();
            let what = format!("{} at {resolution}", path.display());
            assert_eq!(blocks.measures, spans.measures, "{what}");
            assert!(
                spans.inside.voxels().all(|c| blocks.inside.contains(c)),
                "{what}"
            );
            let tiles = blocks.inside.tiles();
            assert!(tiles.voxel_count() > 0, "{what}: no whole block inside");
            eprintln!(
                "{what}: {} inside voxels, {} in {} tiles of 8^3 and {} of 128^3",
                blocks.measures.inside_voxels,
                tiles.voxel_count(),
                tiles.leaf_tiles().count(),
                tiles.node_tiles().count()
            );
        }
    }
    assert!(closed >= 10, "only {closed} closed meshes found");
}
