//! A level set read as a Boolean operand stands for its inside: its negative values, active or
//! not, and its negative tiles (OpenVDB keeps a level set's interior as inactive tiles at minus
//! the background). A level-set sphere written by OpenVDB itself (pyopenvdb's
//! createLevelSetSphere) subtracted from a solid box removes every voxel OpenVDB holds negative,
//! through `csg` and through a CSG tree's `vdb` leaf.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;
mod common;

use cli_support::{OPENVDB_SPHERE, json_field, run_pyopenvdb, text, voxelkit};
use glam::DVec3;
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::generate;

#[test]
fn an_openvdb_level_set_subtracted_from_a_solid_removes_its_whole_inside() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name);
    let p = |name: &str| path(name).to_str().unwrap().to_string();
    let Some(out) = run_pyopenvdb(OPENVDB_SPHERE, &path("sphere.vdb"), "an OpenVDB level set")
    else {
        return;
    };
    let mut words = out.split_whitespace();
    let inside: u64 = words.next().unwrap().parse().unwrap();
    let h: f64 = words.next().unwrap().parse().unwrap();
    assert!(
        inside > 60_000,
        "OpenVDB's sphere holds {inside} negative voxels"
    );
    // A box whose voxel centres lie on the sphere's lattice (multiples of h), around it.
    let half = 50.5 * h;
    generate::cuboid(DVec3::splat(-half), DVec3::splat(half))
        .write_obj(&path("box.obj"))
        .unwrap();
    let hs = format!("{h:?}");
    let o = voxelkit(&[
        "solid",
        &p("box.obj"),
        "--voxel-size",
        &hs,
        "-o",
        &p("box.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let solid = read_vdb_grid(&path("box.vdb"), Some("density"))
        .unwrap()
        .voxel_count();

    let o = voxelkit(&[
        "--json",
        "csg",
        "difference",
        &p("box.vdb"),
        &p("sphere.vdb"),
        "--resample",
        "-o",
        &p("cut.vdb"),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert_eq!(json_field(&t, "voxels") as u64, solid - inside, "{t}");

    // The same through a tree's `vdb` leaves, on the box's own grid.
    let tree = format!(
        r#"{{ "voxel_size": {h:?},
              "bounds": {{ "min": [{lo:?}, {lo:?}, {lo:?}], "max": [{hi:?}, {hi:?}, {hi:?}] }},
              "tree": {{ "difference": [ {{ "vdb": "box.vdb" }}, {{ "vdb": "sphere.vdb" }} ] }} }}"#,
        lo = -half - h,
        hi = half + h
    );
    std::fs::write(path("cut.json"), tree).unwrap();
    let o = voxelkit(&[
        "--json",
        "csg",
        "--tree",
        &p("cut.json"),
        "-o",
        &p("tree.vdb"),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert_eq!(json_field(&t, "voxels") as u64, solid - inside, "{t}");
}
