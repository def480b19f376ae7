//! Voxel-set outputs besides `.vdb`. `.binvox` read back by the format's reference semantics
//! (header `dim`, `translate`, `scale`; run-length bytes, x slowest, then z, y fastest; voxel
//! centres at `translate + (index + 0.5) * scale / dim`) and `.vox` read back by `dot_vox`:
//! the same voxels as the `.vdb` of the same run (colours from `Cd` in `.vox`); distances and
//! models past 256^3 refused without a file.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use glam::DVec3;
use std::collections::HashSet;
use std::path::Path;
use std::process::Command;
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::generate;

/// The world centres of the voxels of a binvox file.
fn binvox_centres(path: &Path) -> Vec<DVec3> {
    let bytes = std::fs::read(path).unwrap();
    let data = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    let header = std::str::from_utf8(&bytes[..data]).unwrap();
    let numbers = |key: &str| -> Vec<f64> {
        let line = header.lines().find(|l| l.starts_with(key)).unwrap();
        line.split_whitespace()
            .skip(1)
            .map(|w| w.parse().unwrap())
            .collect()
    };
    assert!(header.starts_with("#binvox 1\n"));
    let dim = numbers("dim");
    assert!(dim[0] == dim[1] && dim[1] == dim[2]);
    let d = dim[0] as usize;
    let t = numbers("translate");
    let scale = numbers("scale")[0];
    let mut centres = Vec::new();
    let mut n = 0usize;
    for pair in bytes[data..].chunks_exact(2) {
        let (value, count) = (pair[0], pair[1] as usize);
        assert!(value <= 1 && count >= 1);
        if value == 1 {
            for i in n..n + count {
                let (x, z, y) = (i / (d * d), i / d % d, i % d);
                let index = DVec3::new(x as f64, y as f64, z as f64) + 0.5;
                centres.push(DVec3::new(t[0], t[1], t[2]) + index * scale / d as f64);
            }
        }
        n += count;
    }
    assert_eq!(n, d * d * d, "the runs cover the cube");
    centres
}

fn voxelkit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs `command` on a torus into `.binvox` and `.vdb` (`--grids voxels`) and compares them.
fn same_voxels_as_the_vdb(command: &str) {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    generate::torus(DVec3::new(0.3, -0.2, 0.1), 1.0, 0.3, 64, 16)
        .write_obj(&obj)
        .unwrap();
    let (binvox, vdb) = (dir.path().join("t.binvox"), dir.path().join("t.vdb"));
    for (out, grids) in [(&binvox, "density"), (&vdb, "voxels")] {
        let o = voxelkit(&[
            command,
            "--grids",
            grids,
            obj.to_str().unwrap(),
            "-r",
            "40",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let grid = read_vdb_grid(&vdb, Some("voxels")).unwrap();
    let centres = binvox_centres(&binvox);
    assert_eq!(centres.len() as u64, grid.voxel_count(), "{command}");
    let found: HashSet<[i64; 3]> = centres
        .iter()
        .map(|&c| {
            let i = grid.transform.world_to_index(c);
            assert!(
                (i - i.round()).abs().max_element() < 1e-6,
                "{c} is no voxel centre"
            );
            i.round().as_i64vec3().to_array()
        })
        .collect();
    assert_eq!(found.len(), centres.len());
    assert!(found.iter().all(|&c| grid.contains(c)), "{command}");
}

#[test]
fn a_surface_as_binvox_holds_the_voxels_of_its_vdb() {
    same_voxels_as_the_vdb("mesh");
}

#[test]
fn a_solid_as_binvox_holds_the_voxels_of_its_vdb() {
    same_voxels_as_the_vdb("solid");
}

#[test]
fn distances_are_refused_as_binvox_and_nothing_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    generate::torus(DVec3::ZERO, 1.0, 0.3, 32, 8)
        .write_obj(&obj)
        .unwrap();
    let out = dir.path().join("d.binvox");
    let o = voxelkit(&[
        "mesh",
        obj.to_str().unwrap(),
        "--sdf",
        "-r",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && msg.contains("d.binvox") && msg.contains("distances"),
        "{msg}"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the mesh"
    );
}

/// Projective voxels of a coloured torus as `.vox`: one model with the `.vdb`'s voxels, from
/// its box's minimum, coloured from `Cd` to within the palette's step.
#[test]
fn a_coloured_surface_as_vox_holds_the_voxels_and_colours_of_its_vdb() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    let mut torus = generate::torus(DVec3::ZERO, 1.0, 0.3, 48, 12);
    torus.colors = torus
        .positions
        .iter()
        .map(|p| glam::Vec3::new((p.x as f32 + 1.3) / 2.6, 0.2, 0.9))
        .collect();
    torus.write_obj(&obj).unwrap();
    let (vox, vdb) = (dir.path().join("t.vox"), dir.path().join("t.vdb"));
    for out in [&vox, &vdb] {
        let o = voxelkit(&[
            "mesh",
            "--grids",
            "voxels,Cd",
            obj.to_str().unwrap(),
            "--method",
            "projective",
            "-r",
            "60",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let grid = read_vdb_grid(&vdb, Some("voxels")).unwrap();
    let data = dot_vox::load_bytes(&std::fs::read(&vox).unwrap()).unwrap();
    assert_eq!(data.models.len(), 1);
    let model = &data.models[0];
    assert_eq!(model.voxels.len() as u64, grid.voxel_count());
    let min = grid.bbox().unwrap().min;
    let mut reds = Vec::new();
    for v in &model.voxels {
        let c = [
            min[0] + v.x as i64,
            min[1] + v.y as i64,
            min[2] + v.z as i64,
        ];
        assert!(grid.contains(c), "{c:?}");
        let colour = data.palette[v.i as usize];
        assert!(
            (colour.g as f32 / 255.0 - 0.2).abs() <= 0.1 + 1e-6,
            "{colour:?}"
        );
        reds.push(colour.r);
    }
    reds.sort_unstable();
    reds.dedup();
    assert!(reds.len() >= 5, "red follows x: {reds:?}");
}

/// Past 256 voxels per axis the set is split into 256^3 models placed by the scene graph:
/// read back with `dot_vox`, the models at their translations hold exactly the `.vdb`'s
/// voxels. Past 2048 per axis it is refused, leaving no file.
#[test]
fn a_set_past_256_voxels_is_split_into_models_and_past_2048_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    generate::torus(DVec3::ZERO, 1.0, 0.3, 32, 8)
        .write_obj(&obj)
        .unwrap();
    let (vox, vdb) = (dir.path().join("big.vox"), dir.path().join("big.vdb"));
    for out in [&vox, &vdb] {
        let o = voxelkit(&[
            "mesh",
            "--grids",
            "voxels",
            obj.to_str().unwrap(),
            "-r",
            "600",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let grid = read_vdb_grid(&vdb, Some("voxels")).unwrap();
    let min = grid.bbox().unwrap().min;
    let data = dot_vox::load_bytes(&std::fs::read(&vox).unwrap()).unwrap();
    // 600 x 600 x 138 voxels: 3 x 3 x 1 blocks, less the empty centre.
    assert!(data.models.len() > 4, "{}", data.models.len());
    let mut seen = 0u64;
    for node in &data.scenes {
        let dot_vox::SceneNode::Transform { frames, child, .. } = node else {
            continue;
        };
        let dot_vox::SceneNode::Shape { models, .. } = &data.scenes[*child as usize] else {
            continue;
        };
        let t = frames[0].position().unwrap();
        let model = &data.models[models[0].model_id as usize];
        let corner = [
            t.x as i64 - (model.size.x / 2) as i64,
            t.y as i64 - (model.size.y / 2) as i64,
            t.z as i64 - (model.size.z / 2) as i64,
        ];
        for v in &model.voxels {
            let c = [
                min[0] + corner[0] + v.x as i64,
                min[1] + corner[1] + v.y as i64,
                min[2] + corner[2] + v.z as i64,
            ];
            assert!(grid.contains(c), "{c:?}");
            seen += 1;
        }
    }
    assert_eq!(seen, grid.voxel_count());

    let out = dir.path().join("huge.vox");
    let o = voxelkit(&[
        "mesh",
        obj.to_str().unwrap(),
        "-r",
        "2100",
        "-o",
        out.to_str().unwrap(),
    ]);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && msg.contains("huge.vox") && msg.contains("2048"),
        "{msg}"
    );
    assert!(!out.exists());
}
