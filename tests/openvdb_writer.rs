//! The two ways a result becomes a `.vdb`, voxelkit's native writer and OpenVDB's own
//! (`voxelkit_openvdb::write_with_openvdb`: the result built as OpenVDB grids in memory, then
//! written by OpenVDB's `io::File`), give files that OpenVDB reads as the same grids: every leaf,
//! value (inactive ones included), tile, class, transform and metadata item, on the shared
//! meshes for a surface with normals, a solid and a level set; and the grids in memory measure
//! as the file does.

mod common;

use std::path::Path;
use voxelkit::io::vdb::{Compression, WriteOptions};
use voxelkit::mesh::GridFit;
use voxelkit::mesh::attributes::AttributeChoice;
use voxelkit::pipeline::{Job, MeshSource, Outcome, SurfaceMethod, Task};
use voxelkit::progress::Unobserved;
use voxelkit::solids::exterior_flood::FloodMethod;
use voxelkit::solids::inside_rule::InsideRule;
use voxelkit::voxelize::separating::SeparatingOptions;
use voxelkit_openvdb::{OpenVdbGrids, read_grid, write_with_openvdb};

fn run(task: Task, resolution: u32) -> Outcome {
    Job::new(task, GridFit::Resolution(resolution))
        .run(&Unobserved)
        .unwrap()
}

/// Both files hold the same grids, as OpenVDB reads them.
fn assert_same_files(native: &Path, openvdb: &Path) {
    let (a, b) = (
        voxelkit_openvdb::grid_infos(native.to_str().unwrap()).unwrap(),
        voxelkit_openvdb::grid_infos(openvdb.to_str().unwrap()).unwrap(),
    );
    let names = |infos: &[voxelkit_openvdb::GridInfo]| -> Vec<String> {
        infos.iter().map(|i| i.name.clone()).collect()
    };
    assert_eq!(names(&a), names(&b));
    for (x, y) in a.iter().zip(&b) {
        let what = format!("{}: grid {}", native.display(), x.name);
        assert_eq!(x.value_type, y.value_type, "{what}");
        assert_eq!(x.grid_class, y.grid_class, "{what}");
        assert_eq!((x.voxel_size, x.origin), (y.voxel_size, y.origin), "{what}");
        assert_eq!(
            (x.active_voxels, x.leaf_count, x.tile_count),
            (y.active_voxels, y.leaf_count, y.tile_count),
            "{what}"
        );
        assert_eq!((x.bbox_min, x.bbox_max), (y.bbox_min, y.bbox_max), "{what}");
        let meta = |i: &voxelkit_openvdb::GridInfo| -> Vec<(String, String)> {
            i.metadata
                .iter()
                .map(|m| (m.key.clone(), m.value.clone()))
                .collect()
        };
        assert_eq!(meta(x), meta(y), "{what}");
        let (p, q) = (
            read_grid(native.to_str().unwrap(), &x.name).unwrap(),
            read_grid(openvdb.to_str().unwrap(), &x.name).unwrap(),
        );
        assert_eq!(p.origins, q.origins, "{what}");
        assert_eq!(p.masks, q.masks, "{what}");
        assert_eq!(p.tiles, q.tiles, "{what}");
        assert_eq!(p.values.len(), q.values.len(), "{what}");
        // A file at half precision holds halves: OpenVDB's writer also rounds the inactive
        // values it stores, where the native one stores none and OpenVDB reads the background.
        let half = x
            .metadata
            .iter()
            .any(|m| m.key == "is_saved_as_half_float" && m.value == "true");
        let stored = |v: f32| {
            if half {
                half::f16::from_f32(v).to_f32().to_bits()
            } else {
                v.to_bits()
            }
        };
        let differ = p
            .values
            .iter()
            .zip(&q.values)
            .position(|(u, v)| stored(*u) != stored(*v));
        assert_eq!(
            differ.map(|i| (i, p.values[i], q.values[i])),
            None,
            "{what}: the first differing value (index, native, OpenVDB's)"
        );
    }
}

#[test]
fn openvdbs_writer_and_the_native_one_write_the_same_grids() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let mesh = |m: &str| MeshSource::File(data.join("meshes").join(format!("{m}.obj")));
    let surface = run(
        Task::MeshSurface {
            mesh: mesh("armadillo"),
            method: SurfaceMethod::Separating(SeparatingOptions {
                normals: true,
                ..Default::default()
            }),
            attributes: AttributeChoice::None,
        },
        160,
    );
    let solid = run(
        Task::Solid {
            mesh: mesh("bunny-closed"),
            fill: voxelkit::pipeline::Fill::Flood(FloodMethod::Blocks),
            density: 1.0,
            topology: false,
            inside: InsideRule::Parity,
        },
        300,
    );
    // Whole 128^3 blocks inside: active tiles in `density`, inactive ones in `surface`.
    let level_set = run(
        Task::DistanceBand {
            mesh: mesh("sphere"),
            band: 3.0,
            signed: true,
            inside: InsideRule::Winding,
            attributes: AttributeChoice::None,
        },
        400,
    );
    let dir = tempfile::tempdir().unwrap();
    let all = WriteOptions {
        grids: ["density", "voxels", "normal"].map(String::from).to_vec(),
        ..Default::default()
    };
    let zip_half = WriteOptions {
        compression: Compression::Zip,
        half: true,
        ..Default::default()
    };
    let cases = [
        ("surface", &surface, all),
        ("solid", &solid, WriteOptions::default()),
        ("level-set", &level_set, WriteOptions::default()),
        ("level-set-zip-half", &level_set, zip_half),
    ];
    for (name, outcome, options) in cases {
        let native = dir.path().join(format!("{name}.vdb"));
        let openvdb = dir.path().join(format!("{name}-openvdb.vdb"));
        outcome.write_files(&native, &[], &options).unwrap();
        write_with_openvdb(outcome, &openvdb, &options).unwrap();
        assert_same_files(&native, &openvdb);
    }
    let tiles =
        voxelkit_openvdb::grid_infos(dir.path().join("level-set-openvdb.vdb").to_str().unwrap())
            .unwrap();
    assert!(
        tiles
            .iter()
            .any(|g| g.name == "density" && g.tile_count > 0)
    );

    // In memory, OpenVDB measures the level set as it does the file.
    let grids = OpenVdbGrids::from_outcome(&level_set, &WriteOptions::default()).unwrap();
    let in_memory = grids.level_set_volume("surface").unwrap();
    let from_file = voxelkit_openvdb::level_set_volume(
        dir.path().join("level-set.vdb").to_str().unwrap(),
        "surface",
    )
    .unwrap();
    assert_eq!(in_memory, from_file);
    let exact = 4.0 / 3.0 * std::f64::consts::PI;
    assert!((in_memory - exact).abs() < 0.01 * exact, "{in_memory}");

    // OpenVDB writes .vdb only, and nothing is left of a refused write.
    let refused = dir.path().join("x.nvdb");
    assert!(write_with_openvdb(&surface, &refused, &WriteOptions::default()).is_err());
    assert!(!refused.exists());
}
