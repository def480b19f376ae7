//! `voxelkit csg --tree`: the bundled mechanical part against its exact volume, trees over
//! meshes and .vdb grids, placed leaves (Lai & Cheng's moved copies), and errors that name the
//! file and the node.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;
mod common;

use cli_support::{json_field, text, voxelkit};
use glam::DVec3;
use std::f64::consts::PI;
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::generate;

/// The flange of examples/csg/flange.json: plate + boss - bore - two holes - half a torus.
fn flange_volume() -> f64 {
    let groove = (PI * 0.01 / 2.0) * 2.0 * PI * (0.8 - 0.4 / (3.0 * PI)); // Pappus
    4.0 + 0.64 * PI - 0.16 * PI * 1.5 - 2.0 * 0.0625 * PI * 0.5 - groove
}

#[test]
fn the_flange_example_matches_its_exact_volume() {
    let dir = tempfile::tempdir().unwrap();
    let example = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/csg/flange.json");
    let text_in = std::fs::read_to_string(example).unwrap();
    let exact = flange_volume();
    for resolution in [128, 256, 512] {
        let tree = dir.path().join(format!("flange{resolution}.json"));
        std::fs::write(
            &tree,
            text_in.replace(
                "\"resolution\": 256",
                &format!("\"resolution\": {resolution}"),
            ),
        )
        .unwrap();
        let out = dir.path().join("flange.vdb");
        let o = voxelkit(&[
            "--json",
            "csg",
            "--tree",
            tree.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let t = text(&o);
        assert!(o.status.success(), "{t}");
        let volume = json_field(&t, "volume");
        let error = (volume - exact).abs() / exact;
        eprintln!(
            "flange at {resolution}: volume {volume:.6}, exact {exact:.6}, error {error:.2e}"
        );
        // Centre sampling: the error shrinks with the voxel size.
        assert!(
            error < 1.0 / resolution as f64,
            "{resolution}: {volume} vs {exact}"
        );
        let grid = read_vdb_grid(&out, Some("density")).unwrap();
        assert_eq!(grid.voxel_count() as f64, json_field(&t, "voxels"));
    }
}

#[test]
fn trees_over_meshes_and_grids_obey_the_boolean_counts() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n);
    let p = |n: &str| path(n).to_str().unwrap().to_string();
    generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32)
        .write_obj(&path("torus.obj"))
        .unwrap();
    // A solid ball as a .vdb, on another grid: the tree resamples it.
    generate::icosphere(DVec3::new(1.0, 0.0, 0.0), 0.5, 4)
        .write_obj(&path("ball.obj"))
        .unwrap();
    let o = voxelkit(&[
        "solid",
        &p("ball.obj"),
        "-r",
        "50",
        "--method",
        "depth-layers",
        "-o",
        &p("ball.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let bounds =
        r#""bounds": {"min": [-1.5, -1.5, -1.5], "max": [1.5, 1.5, 1.5]}, "resolution": 96"#;
    let (mesh, vdb) = (r#"{ "mesh": "torus.obj" }"#, r#"{ "vdb": "ball.vdb" }"#);
    let run = |name: &str, op: &str, first: &str, second: &str| {
        let tree = format!(r#"{{ {bounds}, "tree": {{ "{op}": [ {first}, {second} ] }} }}"#);
        std::fs::write(path(name), tree).unwrap();
        let o = voxelkit(&[
            "--json",
            "csg",
            "--tree",
            &p(name),
            "-o",
            &p(&format!("{name}.vdb")),
        ]);
        let t = text(&o);
        assert!(o.status.success(), "{t}");
        json_field(&t, "voxels")
    };
    let union = run("u.json", "union", mesh, vdb);
    let inter = run("i.json", "intersection", mesh, vdb);
    let diff = run("d.json", "difference", mesh, vdb);
    let a = run("a.json", "union", mesh, mesh);
    let b = run("b.json", "union", vdb, vdb);
    assert_eq!(run("u2.json", "union", vdb, mesh), union);
    let written = read_vdb_grid(&path("d.json.vdb"), Some("density")).unwrap();
    assert_eq!(written.voxel_count() as f64, diff);
    eprintln!("|A| {a} |B| {b} union {union} intersection {inter} difference {diff}");
    // |A| = |A - B| + |A ∩ B| and |A ∪ B| = |A| + |B| - |A ∩ B|.
    assert!(inter > 0.0 && diff > 0.0);
    assert_eq!(a, diff + inter);
    assert_eq!(union, a + b - inter);
    let exact = generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32).signed_volume();
    let h: f64 = 3.0 / 96.0;
    assert!((a * h.powi(3) - exact).abs() < 0.02 * exact, "{a}");
}

#[test]
fn bad_trees_are_refused_naming_the_file_and_the_node() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n);
    // Open, and one face turned against the rest: neither inside rule applies.
    let mut open = generate::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    open.face_starts.pop();
    open.indices[0..4].reverse();
    open.write_obj(&path("open.obj")).unwrap();
    let cases = [
        ("syntax.json", "{ \"tree\": \n { \"box\": ", "syntax.json:2"),
        (
            "kind.json",
            r#"{ "tree": { "union": [ { "torus": 1 } ] } }"#,
            "tree.union[0]: unknown variant `torus`",
        ),
        (
            "radius.json",
            r#"{ "tree": { "sphere": { "center": [0, 0, 0], "radius": -1 } } }"#,
            "tree.sphere.radius: must be positive",
        ),
        (
            "formula.json",
            r#"{ "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}, "tree": { "formula": "x^2 + * y" } }"#,
            "tree.formula: formula, column",
        ),
        (
            "cylinder.json",
            r#"{ "tree": { "difference": [ { "box": { "min": [0, 0, 0], "max": [1, 1, 1] } },
                 { "cylinder": { "base": [0, 0, 0], "axis": [0, 0, 1], "radius": "wide", "height": 1 } } ] } }"#,
            "tree.difference[1].cylinder.radius",
        ),
        (
            "place.json",
            r#"{ "tree": { "union": [ { "sphere": { "center": [0, 0, 0], "radius": 1 } },
                 { "sphere": { "center": [0, 0, 0], "radius": 1, "place": { "scale": -2 } } } ] } }"#,
            "tree.union[1].sphere.place.scale: must be positive",
        ),
        (
            "nobounds.json",
            r#"{ "tree": { "formula": "x^2 + y^2 + z^2 - 1" } }"#,
            "no leaf has bounds",
        ),
        (
            "open.json",
            r#"{ "tree": { "mesh": "open.obj" } }"#,
            "open.obj: the mesh is open",
        ),
        (
            "missing.json",
            r#"{ "tree": { "mesh": "nowhere.obj" } }"#,
            "nowhere.obj",
        ),
    ];
    for (name, body, expected) in cases {
        std::fs::write(path(name), body).unwrap();
        let out = path("out.vdb");
        let o = voxelkit(&[
            "csg",
            "--tree",
            path(name).to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let t = text(&o);
        assert!(!o.status.success(), "{name}: {t}");
        assert!(
            t.contains(expected) && t.contains(name.split('.').next().unwrap()),
            "{name}: {t}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn the_summary_prints_the_leaves_numbers_as_typed() {
    let dir = tempfile::tempdir().unwrap();
    let example = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/csg/flange.json");
    let out = dir.path().join("flange.vdb");
    let o = voxelkit(&["csg", "--tree", example, "-o", out.to_str().unwrap()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("cylinder from (0, 0, -0.1) along (0, 0, 1) radius 0.4 height 1.7"),
        "{t}"
    );
    assert!(!t.contains("99999"), "{t}");
}

/// Runs `csg --tree` on `tree` (JSON text, written into `dir`), giving the voxel count.
fn tree_voxels(dir: &std::path::Path, name: &str, tree: &str) -> f64 {
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, tree).unwrap();
    let out = dir.join(format!("{name}.vdb"));
    let o = voxelkit(&[
        "--json",
        "csg",
        "--tree",
        path.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{name}: {t}");
    json_field(&t, "voxels")
}

#[test]
fn placed_leaves_are_their_shapes_moved_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, tree: &str| {
        let top = r#""bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}, "resolution": 200"#;
        tree_voxels(dir.path(), name, &format!(r#"{{ {top}, "tree": {tree} }}"#))
    };
    // A unit cube and itself turned 45 degrees about z meet in a regular octagonal prism.
    let cube = r#"{"box": {"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}}"#;
    let turned = r#"{"box": {"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5],
        "place": {"rotate": {"axis": [0, 0, 1], "degrees": 45}}}}"#;
    let h: f64 = 2.0 / 200.0;
    let octagon = run(
        "octagon",
        &format!(r#"{{"intersection": [{cube}, {turned}]}}"#),
    ) * h.powi(3);
    let exact = 8.0 * 0.25 * (PI / 8.0).tan();
    assert!(
        (octagon - exact).abs() < 0.01 * exact,
        "{octagon} against {exact}"
    );
    // The same by Euler angles and by a matrix.
    for (name, place) in [
        ("euler", r#"{"rotate": {"euler": [0, 0, 45]}}"#),
        (
            "matrix",
            r#"{"matrix": [[0.7071067811865476, -0.7071067811865476, 0, 0],
            [0.7071067811865476, 0.7071067811865476, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}"#,
        ),
    ] {
        let other = format!(
            r#"{{"box": {{"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "place": {place}}}}}"#
        );
        let differ = run(name, &format!(r#"{{"difference": [{turned}, {other}]}}"#));
        assert!(differ <= 4.0, "{name}: {differ} voxels differ");
    }
    // A formula's sphere moved is the sphere at the moved centre, voxel for voxel.
    let formula = r#"{"formula": {"text": "x^2 + y^2 + z^2 - 0.16",
        "bounds": {"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
        "place": {"translate": [0.3, -0.2, 0.1]}}}"#;
    let sphere = r#"{"sphere": {"center": [0.3, -0.2, 0.1], "radius": 0.4}}"#;
    let both = run("sphere", sphere);
    assert!(both > 1000.0);
    assert_eq!(
        run(
            "f-s",
            &format!(r#"{{"difference": [{formula}, {sphere}]}}"#)
        ),
        0.0
    );
    assert_eq!(
        run(
            "s-f",
            &format!(r#"{{"difference": [{sphere}, {formula}]}}"#)
        ),
        0.0
    );
}

/// Fig. 4 (i)-(j) of Lai & Cheng: a cow less a moved copy, united with a turned one. Its
/// voxels obey inclusion-exclusion over its parts' trees on the same grid, and a placed cow
/// keeps its volume.
#[test]
fn moved_cows_differenced_then_united() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let cow = data.join("meshes/cow.obj");
    let cow = cow.to_str().unwrap();
    let a = format!(r#"{{"mesh": "{cow}"}}"#);
    let b = format!(r#"{{"mesh": {{"file": "{cow}", "place": {{"translate": [2.5, 1, 0]}}}}}}"#);
    let c = format!(
        r#"{{"mesh": {{"file": "{cow}", "place": {{"rotate": {{"axis": [0, 0, 1], "degrees": 90}}, "scale": 0.8}}}}}}"#
    );
    // One grid for every tree: the box of all three cows.
    let run = |name: &str, tree: &str| {
        let top =
            r#""bounds": {"min": [-4.5, -4.6, -1.8], "max": [8.6, 4.9, 1.8]}, "resolution": 200"#;
        tree_voxels(dir.path(), name, &format!(r#"{{ {top}, "tree": {tree} }}"#))
    };
    let whole = run(
        "whole",
        &format!(r#"{{"union": [{{"difference": [{a}, {b}]}}, {c}]}}"#),
    );
    let (va, vb, vc) = (run("a", &a), run("b", &b), run("c", &c));
    let ab = run("ab", &format!(r#"{{"intersection": [{a}, {b}]}}"#));
    let ac = run("ac", &format!(r#"{{"intersection": [{a}, {c}]}}"#));
    let abc = run("abc", &format!(r#"{{"intersection": [{a}, {b}, {c}]}}"#));
    eprintln!("cows: whole {whole}, a {va}, b {vb}, c {vc}, ab {ab}, ac {ac}, abc {abc}");
    // |(A - B) ∪ C| = |A| - |A ∩ B| + |C| - |A ∩ C| + |A ∩ B ∩ C|.
    assert_eq!(whole, va - ab + vc - ac + abc);
    assert!(
        ab > 0.0 && ac > 0.0 && va - ab > 0.0,
        "the copies overlap the cow"
    );
    // Moving keeps the volume; scaling by 0.8 scales it by 0.512.
    assert!((vb - va).abs() < 0.01 * va, "{vb} against {va}");
    assert!(
        (vc - 0.512 * va).abs() < 0.02 * va,
        "{vc} against {}",
        0.512 * va
    );
}

/// Catmull-Clark solids and grids placed in a multi-level tree: two tori side by side (one
/// moved, one turned) less a box through both, against their parts on the same grid; a grid
/// leaf turned a quarter about z is the torus turned so, up to nearest sampling.
#[test]
fn placed_catmull_clark_and_grid_leaves_in_a_multi_level_tree() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let torus = data.join("subd/catmark_torus.obj");
    let torus = torus.to_str().unwrap();
    let a = format!(r#"{{"subdiv": "{torus}"}}"#);
    let b = format!(
        r#"{{"subdiv": {{"file": "{torus}", "place": {{"translate": [3, 0, 0], "rotate": {{"axis": [1, 0, 0], "degrees": 90}}}}}}}}"#
    );
    let cut = r#"{"box": {"min": [-0.5, -0.2, -2], "max": [3.5, 0.2, 2]}}"#;
    let run = |name: &str, tree: &str| {
        let top =
            r#""bounds": {"min": [-1.6, -1.6, -1.6], "max": [4.6, 1.6, 1.6]}, "resolution": 240"#;
        tree_voxels(dir.path(), name, &format!(r#"{{ {top}, "tree": {tree} }}"#))
    };
    let (va, vb) = (run("a", &a), run("b", &b));
    let whole = run(
        "whole",
        &format!(r#"{{"difference": [{{"union": [{a}, {b}]}}, {cut}]}}"#),
    );
    let (a_cut, b_cut) = (
        run("acut", &format!(r#"{{"intersection": [{a}, {cut}]}}"#)),
        run("bcut", &format!(r#"{{"intersection": [{b}, {cut}]}}"#)),
    );
    eprintln!("tori: a {va}, b {vb}, whole {whole}, cut {a_cut} and {b_cut}");
    assert!(a_cut > 0.0 && b_cut > 0.0, "the box cuts both tori");
    // Apart, the tori share no voxel: the tree is each less its cut.
    assert_eq!(whole, va - a_cut + vb - b_cut);
    assert!((vb - va).abs() < 0.01 * va, "{vb} against {va}");
    // The grid of the first torus turned a quarter about z is the torus turned so.
    let grid = dir.path().join("a.vdb");
    let quarter = r#"{"rotate": {"axis": [0, 0, 1], "degrees": 90}}"#;
    let turned_grid = format!(
        r#"{{"vdb": {{"file": "{}", "place": {quarter}}}}}"#,
        grid.to_str().unwrap()
    );
    let turned_torus = format!(r#"{{"subdiv": {{"file": "{torus}", "place": {quarter}}}}}"#);
    let vt = run("turned", &turned_grid);
    let apart = run(
        "apart",
        &format!(r#"{{"difference": [{turned_grid}, {turned_torus}]}}"#),
    ) + run(
        "apart2",
        &format!(r#"{{"difference": [{turned_torus}, {turned_grid}]}}"#),
    );
    eprintln!("turned grid {vt}, {apart} voxels apart from the turned torus");
    assert!((vt - va).abs() < 0.01 * va, "{vt} against {va}");
    // Nearest sampling moves the boundary by at most a voxel: a thin shell of the 112,877.
    assert!(apart < 0.02 * va, "{apart} voxels apart");
}

/// Lai & Cheng's Fig. 4 lights Boolean results by their exact normals: a tree of shapes and
/// formulas writes `normal` on its shell voxels, the normal of the leaf surface each centre
/// measures, pointing out of the result: up on a box's top, into the hole on a bore drilled
/// through it (the subtracted cylinder's normal turned), and unit everywhere.
#[test]
fn trees_of_exact_leaves_carry_their_normals() {
    let dir = tempfile::tempdir().unwrap();
    let tree = r#"{ "resolution": 96, "tree": { "difference": [
        { "box": { "min": [-1, -1, 0], "max": [1, 1, 0.5] } },
        { "cylinder": { "base": [0, 0, -0.2], "axis": [0, 0, 1], "radius": 0.4, "height": 1 } }
    ] } }"#;
    tree_voxels(dir.path(), "drilled", tree);
    let path = dir.path().join("drilled.vdb");
    let shell = read_vdb_grid(&path, Some("shell")).unwrap();
    let normals = read_vdb_grid(&path, Some("normal")).unwrap();
    assert_eq!(normals.voxel_count(), shell.voxel_count());
    let h = normals.transform.voxel_size;
    let (mut top, mut bore) = (0, 0);
    for leaf in normals.leaves() {
        let values = leaf.normal.as_ref().unwrap();
        for n in leaf.offsets() {
            let c = voxelkit::grid::offset_coord(leaf.origin, n);
            assert!(shell.contains(c));
            let p = normals.transform.index_to_world(c);
            let v = glam::Vec3::from(values[n]).as_dvec3();
            assert!((v.length() - 1.0).abs() < 1e-5, "{p}: {v}");
            let r = p.truncate().length();
            if p.z > 0.5 - h && r > 0.4 + 2.0 * h && p.x.abs().max(p.y.abs()) < 1.0 - 2.0 * h {
                assert!(v.z > 0.999, "top at {p}: {v}");
                top += 1;
            }
            if r < 0.4 + h && p.z > 2.0 * h && p.z < 0.5 - 2.0 * h {
                let into_hole = -p.truncate().extend(0.0) / r;
                assert!(v.dot(into_hole) > 0.999, "bore at {p}: {v}");
                bore += 1;
            }
        }
    }
    assert!(top > 1000 && bore > 500, "{top} top, {bore} bore voxels");
}

/// Normals through a Boolean of two `.vdb` solids that carry them: the first operand's stay
/// where its voxels do, and the dent a difference cuts shows the subtracted sphere's normals
/// turned (pointing into the dent, out of the result).
#[test]
fn grid_booleans_carry_their_operands_normals() {
    let dir = tempfile::tempdir().unwrap();
    // One grid for both: the same voxel size and bounds.
    let grid =
        r#""voxel_size": 0.03125, "bounds": { "min": [-1.1, -1.1, -0.1], "max": [1.1, 1.1, 1.6] }"#;
    let box_tree =
        format!(r#"{{ {grid}, "tree": {{ "box": {{ "min": [-1, -1, 0], "max": [1, 1, 1] }} }} }}"#);
    let ball_tree = format!(
        r#"{{ {grid}, "tree": {{ "sphere": {{ "center": [0, 0, 1], "radius": 0.5 }} }} }}"#
    );
    tree_voxels(dir.path(), "box", &box_tree);
    tree_voxels(dir.path(), "ball", &ball_tree);
    let out = dir.path().join("dented.vdb");
    let o = voxelkit(&[
        "csg",
        "difference",
        dir.path().join("box.vdb").to_str().unwrap(),
        dir.path().join("ball.vdb").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let result = read_vdb_grid(&out, Some("density")).unwrap();
    let normals = read_vdb_grid(&out, Some("normal")).unwrap();
    let h = normals.transform.voxel_size;
    let centre = DVec3::new(0.0, 0.0, 1.0);
    let (mut dent, mut top) = (0, 0);
    for leaf in normals.leaves() {
        let values = leaf.normal.as_ref().unwrap();
        for n in leaf.offsets() {
            let c = voxelkit::grid::offset_coord(leaf.origin, n);
            assert!(result.contains(c));
            let p = normals.transform.index_to_world(c);
            let v = glam::Vec3::from(values[n]).as_dvec3();
            if p.z < 1.0 - 2.0 * h && (p.distance(centre) - 0.5).abs() < 2.0 * h {
                assert!(v.dot((centre - p).normalize()) > 0.95, "dent at {p}: {v}");
                dent += 1;
            }
            let inner = p.x.abs().max(p.y.abs()) < 1.0 - 2.0 * h;
            if p.z > 1.0 - h && inner && p.truncate().length() > 0.5 + 2.0 * h {
                assert!(v.z > 0.999, "top at {p}: {v}");
                top += 1;
            }
        }
    }
    assert!(dent > 300 && top > 1000, "{dent} dent, {top} top voxels");
}
