//! `voxelkit solid`, `measure`, `csg` and `intersect` end to end on generated meshes.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;

use cli_support::{json_field, text, voxelkit};
use glam::DVec3;
use voxelkit::io::vdb::{read_vdb_grid, read_vdb_info};
use voxelkit::mesh::generate;

#[test]
fn solid_measure_csg_and_intersect() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32)
        .write_obj(dir.path().join("torus.obj").as_path())
        .unwrap();
    generate::icosphere(DVec3::new(1.0, 0.0, 0.0), 0.5, 4)
        .write_obj(dir.path().join("ball.obj").as_path())
        .unwrap();

    // A solid torus: volume bracketed, genus 1, the density grid on the whole solid.
    let o = voxelkit(&[
        "--json",
        "solid",
        &p("torus.obj"),
        "-r",
        "96",
        "--inside",
        "parity",
        "--flood",
        "xyz",
        "--graystack",
        "256",
        "--topology",
        "-o",
        &p("torus.vdb"),
    ]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    let exact = generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32).signed_volume();
    assert!(
        json_field(&out, "volume_inside") < exact
            && exact < json_field(&out, "volume_with_surface"),
        "{out}"
    );
    assert_eq!(json_field(&out, "genus"), 1.0);
    assert!(json_field(&out, "sweeps") >= 1.0);
    let grids = read_vdb_info(dir.path().join("torus.vdb").as_path()).unwrap();
    let count = |name: &str| grids.iter().find(|g| g.name == name).unwrap().active_voxels;
    assert_eq!(count("density"), count("shell") + count("interior"));

    // measure reads the solid back and agrees; on the mesh it voxelizes first.
    let o = voxelkit(&["--json", "measure", &p("torus.vdb")]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        json_field(&text(&o), "inside_voxels"),
        count("interior") as f64
    );
    let o = voxelkit(&["--json", "measure", &p("torus.obj"), "-r", "96"]);
    assert!((json_field(&text(&o), "mesh_signed_volume") - exact).abs() < 1e-9);

    // Surfaces on one grid each; Booleans need --resample across grids.
    for name in ["torus", "ball"] {
        let o = voxelkit(&[
            "mesh",
            &p(&format!("{name}.obj")),
            "-r",
            "96",
            "-o",
            &p(&format!("{name}-s.vdb")),
        ]);
        assert!(o.status.success(), "{}", text(&o));
    }
    let o = voxelkit(&[
        "intersect",
        &p("torus-s.vdb"),
        &p("ball-s.vdb"),
        "-o",
        &p("curve.vdb"),
    ]);
    assert!(
        !o.status.success() && text(&o).contains("transforms differ"),
        "{}",
        text(&o)
    );
    assert!(!dir.path().join("curve.vdb").exists());
    let o = voxelkit(&[
        "intersect",
        &p("torus-s.vdb"),
        &p("ball-s.vdb"),
        "--resample",
        "-o",
        &p("curve.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let curve = read_vdb_grid(dir.path().join("curve.vdb").as_path(), Some("density")).unwrap();
    assert!(curve.voxel_count() > 100);
    // Any number of surfaces: a third operand equal to the first changes nothing.
    let o = voxelkit(&[
        "intersect",
        &p("torus-s.vdb"),
        &p("ball-s.vdb"),
        &p("torus-s.vdb"),
        "--resample",
        "-o",
        &p("curve3.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let curve3 = read_vdb_grid(dir.path().join("curve3.vdb").as_path(), Some("density")).unwrap();
    assert_eq!(curve3.voxel_count(), curve.voxel_count());
    assert!(curve3.voxels().all(|c| curve.contains(c)));
    // Meshes voxelized by intersect itself: on the first grid's placement they give the
    // surfaces `mesh` gives there; on their own, one grid fitted to both, as `mesh
    // --shared-grid` fits it.
    let o = voxelkit(&[
        "intersect",
        &p("torus-s.vdb"),
        &p("ball.obj"),
        "-o",
        &p("curve-mesh.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let on_torus = read_vdb_grid(dir.path().join("curve-mesh.vdb").as_path(), None).unwrap();
    assert!(on_torus.voxel_count() > 100);
    let o = voxelkit(&[
        "mesh",
        &p("torus.obj"),
        &p("ball.obj"),
        "--shared-grid",
        "-r",
        "96",
        "--out-dir",
        &p("shared"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let (shared_curve, meshes_curve) = (p("shared-curve.vdb"), p("meshes-curve.vdb"));
    let o = voxelkit(&[
        "intersect",
        &p("shared/torus.vdb"),
        &p("shared/ball.vdb"),
        "-o",
        &shared_curve,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let o = voxelkit(&[
        "intersect",
        &p("torus.obj"),
        &p("ball.obj"),
        "-r",
        "96",
        "-o",
        &meshes_curve,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let read = |f: &str| read_vdb_grid(std::path::Path::new(f), None).unwrap();
    let (a, b) = (read(&shared_curve), read(&meshes_curve));
    assert!(a.voxel_count() > 100);
    assert_eq!(a.transform, b.transform);
    assert!(a.voxel_count() == b.voxel_count() && a.voxels().all(|c| b.contains(c)));
    let o = voxelkit(&[
        "csg",
        "union",
        &p("torus-s.vdb"),
        &p("ball-s.vdb"),
        "--resample",
        "-o",
        &p("union.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let union = read_vdb_grid(dir.path().join("union.vdb").as_path(), Some("density")).unwrap();
    let torus = read_vdb_grid(dir.path().join("torus-s.vdb").as_path(), Some("density")).unwrap();
    assert!(union.voxel_count() > torus.voxel_count());
    let o = voxelkit(&[
        "csg",
        "xor",
        &p("torus-s.vdb"),
        &p("ball-s.vdb"),
        "-o",
        &p("x.vdb"),
    ]);
    assert!(!o.status.success() && text(&o).contains("union, intersection or difference"));
}

#[test]
fn depth_layer_solids_report_what_they_cannot_classify() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    generate::g_between_plates()
        .write_obj(dir.path().join("g.obj").as_path())
        .unwrap();
    generate::spheres_in_box()
        .write_obj(dir.path().join("boxed.obj").as_path())
        .unwrap();
    let mut open = generate::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    open.face_starts.pop(); // drop the last face: a box without a side
    open.write_obj(dir.path().join("open.obj").as_path())
        .unwrap();

    // The G: single layers fill its hollow, double layers do not; both agree with the flood
    // on a closed mesh up to the surface voxels.
    let run = |input: &str, extra: &[&str], out: &str| {
        let mut args = vec!["--json", "solid", input, "-r", "70", "-o", out];
        args.extend_from_slice(extra);
        let o = voxelkit(&args);
        assert!(o.status.success(), "{}", text(&o));
        text(&o)
    };
    let double = run(&p("g.obj"), &["--method", "depth-layers"], &p("g2.vdb"));
    let single = run(
        &p("g.obj"),
        &[
            "--method",
            "depth-layers",
            "--layers",
            "single",
            "--directions",
            "3",
        ],
        &p("g1.vdb"),
    );
    let exact = generate::g_between_plates().signed_volume();
    let (v2, v1) = (json_field(&double, "volume"), json_field(&single, "volume"));
    assert!((v2 - exact).abs() < 0.02 * exact, "{v2} vs {exact}");
    // The part of the hollow no axis sees: 12 of the G's cells of (1/7)^3.
    let unseen = 12.0 / 343.0;
    assert!(
        v1 - exact > 0.8 * unseen,
        "single layers should fill the hollow: {v1} vs {exact}"
    );
    assert_eq!(json_field(&double, "unclassified_voxels"), 0.0);
    let grids = read_vdb_info(dir.path().join("g2.vdb").as_path()).unwrap();
    let count = |name: &str| grids.iter().find(|g| g.name == name).unwrap().active_voxels;
    assert_eq!(count("density"), count("shell") + count("interior"));
    assert_eq!(count("unclassified"), 0);

    // Spheres in a hollow box: unclassifiable voxels, written as their own grid.
    let boxed = run(
        &p("boxed.obj"),
        &["--method", "depth-layers"],
        &p("boxed.vdb"),
    );
    assert!(
        json_field(&boxed, "unclassified_voxels") > 1000.0,
        "{boxed}"
    );
    assert_eq!(json_field(&boxed, "odd_rays"), 0.0);
    let u = read_vdb_grid(dir.path().join("boxed.vdb").as_path(), Some("unclassified")).unwrap();
    assert_eq!(
        u.voxel_count() as f64,
        json_field(&boxed, "unclassified_voxels")
    );

    // An open box: the flood by parity refuses it, naming the file and an edge; depth layers
    // report it.
    let o = voxelkit(&[
        "solid",
        &p("open.obj"),
        "--inside",
        "parity",
        "-r",
        "32",
        "-o",
        &p("o.vdb"),
    ]);
    let msg = text(&o);
    assert!(!o.status.success() && msg.contains("open.obj") && msg.contains("boundary edge"));
    assert!(!dir.path().join("o.vdb").exists());
    let open = run(&p("open.obj"), &["--method", "depth-layers"], &p("o.vdb"));
    assert!(json_field(&open, "odd_rays") > 0.0);
    assert!(json_field(&open, "unclassified_on_odd_rays") > 0.0);
    assert_eq!(json_field(&open, "boundary_edges"), 4.0);

    // The paper's unclassified rule marks more of the boxed spheres; the user's own directions
    // are taken, and a direction without a component of ±1 is refused before any work.
    let paper = run(
        &p("boxed.obj"),
        &["--method", "depth-layers", "--unclassified", "paper"],
        &p("boxed-paper.vdb"),
    );
    assert!(
        json_field(&paper, "unclassified_voxels") > json_field(&boxed, "unclassified_voxels"),
        "{paper}"
    );
    let own = run(
        &p("g.obj"),
        &[
            "--method",
            "depth-layers",
            "--directions",
            "0,0,1;1,-1,0;2,1,1",
        ],
        &p("g3.vdb"),
    );
    assert!(
        (json_field(&own, "volume") - exact).abs() < 0.02 * exact,
        "{own}"
    );
    let o = voxelkit(&[
        "solid",
        &p("g.obj"),
        "--method",
        "depth-layers",
        "--directions",
        "2,3,5",
        "-o",
        &p("g4.vdb"),
    ]);
    assert!(
        !o.status.success() && text(&o).contains("component of 1 or -1"),
        "{}",
        text(&o)
    );
    assert!(!dir.path().join("g4.vdb").exists());
}

/// `solid --method beam --fill paper`: Jegathese et al.'s fill from the face voxels, named in
/// the metadata; on a torus the same solid as the parity fill.
#[test]
fn the_papers_beam_fill_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32)
        .write_obj(&obj)
        .unwrap();
    let mut counts = Vec::new();
    for fill in ["parity", "paper"] {
        let out = dir.path().join(format!("{fill}.vdb"));
        let o = voxelkit(&[
            "--json",
            "solid",
            obj.to_str().unwrap(),
            "--method",
            "beam",
            "--fill",
            fill,
            "-r",
            "96",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        counts.push(json_field(
            &String::from_utf8_lossy(&o.stdout),
            "inside_voxels",
        ));
        let info = read_vdb_info(&out).unwrap();
        let method = info[0].metadata.iter().find(|m| m.key == "method").unwrap();
        let expected = if fill == "paper" {
            "projective-beam-paper"
        } else {
            "projective-beam"
        };
        assert_eq!(method.value, expected);
    }
    assert_eq!(counts[0], counts[1]);
    assert!(counts[0] > 10_000.0);
}
