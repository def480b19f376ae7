//! OpenSubdiv's crease and corner tags on a cube the tests write: infinitely sharp edges give
//! back the control cube exactly (volume 8, area 24, flat faces), semi-sharp ones enclose more
//! the sharper they are, tags read from the OBJ equal those of a sidecar, and the CLI names
//! the tags it applied and refuses bad ones by file and line, writing nothing.
#![cfg(feature = "vdb")]

mod cli_support;
mod common;

use cli_support::{text, voxelkit};
use common::CUBE_OBJ;
use std::path::{Path, PathBuf};
use voxelkit::subd::{ControlMesh, LimitSurface, limit_area, limit_volume};

/// The cube's twelve edges (vertex indices from 0, as tags count them).
const EDGES: [(u32, u32); 12] = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

fn every_edge(sharpness: f64) -> String {
    let pairs: Vec<String> = EDGES.iter().map(|(a, b)| format!("{a} {b}")).collect();
    format!("t crease 24/1/0 {} {sharpness}\n", pairs.join(" "))
}

/// Writes `cube.obj` and, when given, its `cube.tags` into `dir`.
fn cube_with_tags(dir: &Path, tags: Option<&str>) -> PathBuf {
    let obj = dir.join("cube.obj");
    std::fs::write(&obj, CUBE_OBJ).unwrap();
    if let Some(tags) = tags {
        std::fs::write(dir.join("cube.tags"), tags).unwrap();
    }
    obj
}

#[test]
fn infinitely_sharp_edges_give_back_the_control_cube() {
    let dir = tempfile::tempdir().unwrap();
    let control = ControlMesh::load(&cube_with_tags(dir.path(), Some(&every_edge(10.0)))).unwrap();
    assert_eq!(control.tags.creases.len(), 12);
    let surface = LimitSurface::new(control);
    let volume = limit_volume(&surface);
    let area = limit_area(&surface);
    assert!((volume - 8.0).abs() < 1e-12, "{volume}");
    assert!((area - 24.0).abs() < 1e-12, "{area}");
    // Face 0 lies in z = -1 and spans the whole square, corners included.
    for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.5, 0.5)] {
        let p = surface.evaluate(0, u, v).unwrap();
        assert!(
            (p.position.z + 1.0).abs() < 1e-14,
            "{u} {v}: {:?}",
            p.position
        );
        assert!((p.normal.z + 1.0).abs() < 1e-12, "{u} {v}: {:?}", p.normal);
    }
    let corner = surface.evaluate(0, 0.0, 0.0).unwrap().position;
    assert!(
        (corner - glam::DVec3::splat(-1.0)).length() < 1e-14,
        "{corner:?}"
    );
}

#[test]
fn sharper_creases_enclose_more() {
    let dir = tempfile::tempdir().unwrap();
    let volume_at = |sharpness: f64| {
        let obj = cube_with_tags(dir.path(), Some(&every_edge(sharpness)));
        limit_volume(&LimitSurface::new(ControlMesh::load(&obj).unwrap()))
    };
    let smooth = {
        std::fs::remove_file(dir.path().join("cube.tags")).ok();
        let obj = cube_with_tags(dir.path(), None);
        limit_volume(&LimitSurface::new(ControlMesh::load(&obj).unwrap()))
    };
    // A sharpness of 0 is no crease at all.
    assert_eq!(volume_at(0.0), smooth);
    let volumes: Vec<f64> = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0]
        .iter()
        .map(|&s| volume_at(s))
        .collect();
    eprintln!("volumes by sharpness: {volumes:?}");
    for pair in volumes.windows(2) {
        assert!(pair[1] > pair[0] + 1e-6, "{volumes:?}");
    }
    assert!(*volumes.last().unwrap() < 8.0);
    // Each level of sharpness leaves about a quarter of what is left to the control cube:
    // the smooth band along an edge halves in width and in depth per subdivision step.
    let left: Vec<f64> = volumes[3..].iter().map(|v| 8.0 - v).collect();
    let (one_level, two_levels) = (left[2] / left[3], left[3] / left[4]);
    assert!((3.0..5.0).contains(&one_level), "{left:?}");
    assert!((9.0..25.0).contains(&two_levels), "{left:?}");
}

#[test]
fn tags_in_the_obj_equal_those_of_a_sidecar() {
    let tags = "t crease 4/2/0 0 1 1 2 2.5 10\nt corner 1/1/0 6 1.5\n";
    let inline_dir = tempfile::tempdir().unwrap();
    let inline = inline_dir.path().join("cube.obj");
    std::fs::write(&inline, format!("{CUBE_OBJ}{tags}")).unwrap();
    let sidecar_dir = tempfile::tempdir().unwrap();
    let sidecar = cube_with_tags(sidecar_dir.path(), Some(tags));
    let a = ControlMesh::load(&inline).unwrap();
    let b = ControlMesh::load(&sidecar).unwrap();
    assert_eq!(a.tags.creases, vec![(0, 1, 2.5), (1, 2, 10.0)]);
    assert_eq!(a.tags.corners, vec![(6, 1.5)]);
    assert_eq!(
        (&a.tags.creases, &a.tags.corners),
        (&b.tags.creases, &b.tags.corners)
    );
    let (a, b) = (LimitSurface::new(a), LimitSurface::new(b));
    for face in 0..6 {
        for (u, v) in [(0.0, 0.0), (0.2, 0.9), (0.5, 0.5)] {
            assert_eq!(
                a.evaluate(face, u, v).unwrap(),
                b.evaluate(face, u, v).unwrap()
            );
        }
    }
}

#[test]
fn the_cli_names_the_tags_and_fills_the_sharp_cube() {
    let dir = tempfile::tempdir().unwrap();
    let obj = cube_with_tags(dir.path(), Some(&every_edge(10.0)));
    let surface = dir.path().join("surface.vdb");
    let o = voxelkit(&[
        "subdiv",
        obj.to_str().unwrap(),
        "-r",
        "64",
        "-o",
        surface.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("12 creases and 0 corners from") && text(&o).contains("cube.tags"),
        "{}",
        text(&o)
    );
    let grids = voxelkit::io::vdb::read_vdb_info(&surface).unwrap();
    let creases = grids[0].metadata.iter().find(|m| m.key == "creases");
    assert_eq!(creases.map(|m| m.value.as_str()), Some("12"));

    let solid = dir.path().join("solid.vdb");
    let o = voxelkit(&[
        "--json",
        "subdiv",
        obj.to_str().unwrap(),
        "--solid",
        "-r",
        "64",
        "-o",
        solid.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("one JSON report on stdout");
    let number = |key: &str| report[key].as_f64().unwrap();
    assert!((number("limit_volume") - 8.0).abs() < 1e-9, "{report}");
    assert!(number("volume_inside") <= 8.0 && 8.0 <= number("volume_with_surface"));
    // The grid fits the cube's faces to voxel boundaries within one voxel.
    let h = number("voxel_size");
    assert!(8.0 - number("volume_inside") <= 24.0 * h, "{report}");
}

#[test]
fn bad_tags_are_refused_by_file_and_line_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    for (tags, needles) in [
        (
            "t crease 2/1/0 0 6 3\n",
            &["cube.tags", "0 and 6", "share no edge"][..],
        ),
        (
            "t crease 2/1/0 0 99 3\n",
            &["cube.tags", "vertex 99", "8 vertices"],
        ),
        (
            "# edits\nt vertexedit 1/0/0 3\n",
            &["cube.tags:2", "hierarchical edits"],
        ),
        ("t crease 2/1/0 0 1 -2\n", &["cube.tags:1", "at least 0"]),
        ("v 0 0 0\n", &["cube.tags:1", "not a tag line"]),
    ] {
        let obj = cube_with_tags(dir.path(), Some(tags));
        let out = dir.path().join("out.vdb");
        let o = voxelkit(&[
            "subdiv",
            obj.to_str().unwrap(),
            "-r",
            "32",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{tags:?} was accepted");
        for needle in needles {
            assert!(
                text(&o).contains(needle),
                "{tags:?}: `{needle}` missing: {}",
                text(&o)
            );
        }
        assert!(!out.exists(), "{tags:?} left an output");
    }
}

#[test]
fn boundary_rules_other_than_the_default_are_refused_on_open_meshes_only() {
    let dir = tempfile::tempdir().unwrap();
    // Closed: the rule changes nothing and is accepted.
    let closed = cube_with_tags(dir.path(), Some("t interpolateboundary 1/0/0 2\n"));
    ControlMesh::load(&closed).unwrap();
    // Open (the cube without its top): refused, naming the line.
    let open_obj = dir.path().join("open.obj");
    std::fs::write(&open_obj, CUBE_OBJ.replace("f 5 6 7 8\n", "")).unwrap();
    std::fs::write(
        dir.path().join("open.tags"),
        "t interpolateboundary 1/0/0 2\n",
    )
    .unwrap();
    let e = ControlMesh::load(&open_obj).unwrap_err().to_string();
    assert!(e.contains("open.tags:1") && e.contains("edges only"), "{e}");
}

#[test]
fn a_darts_corner_is_the_limit_of_the_points_around_it() {
    // One infinitely sharp edge of the cube: both its ends are darts (valence 3), where
    // neither the smooth position mask nor its tangent masks give the limit.
    let dir = tempfile::tempdir().unwrap();
    let obj = cube_with_tags(dir.path(), Some("t crease 2/1/0 0 1 10\n"));
    let surface = LimitSurface::new(ControlMesh::load(&obj).unwrap());
    // Face 0 is (0 3 2 1): vertex 0 is its corner (0, 0).
    let at = surface.evaluate(0, 0.0, 0.0).unwrap();
    for (k, position_within) in [(20, 1e-5), (40, 1e-11)] {
        let e = 0.5f64.powi(k);
        for (u, v) in [(e, 0.0), (0.0, e), (e, e)] {
            let near = surface.evaluate(0, u, v).unwrap();
            let d = (near.position - at.position).length();
            assert!(d < position_within, "{k} ({u}, {v}): {d:e}");
        }
    }
    let normal_off = |k: i32| {
        let e = 0.5f64.powi(k);
        voxelkit::subd::angle_between(surface.evaluate(0, e, e / 3.0).unwrap().normal, at.normal)
    };
    // Much closer, the patches' derivatives are lost to rounding.
    let (near, nearer) = (normal_off(10), normal_off(20));
    assert!(
        nearer < near / 16.0 && nearer < 1e-5,
        "{near:e} then {nearer:e}"
    );
}
