//! The limit-surface evaluator against OpenSubdiv's exact limit points
//! (`subd/reference/*.limit.txt`), without OpenSubdiv installed.

mod common;

use voxelkit::subd::{ControlMesh, LimitSurface, compare_points, read_points};

/// Reference file and the control mesh it was made from (relative to `subd/`).
const REFERENCES: [(&str, &str); 14] = [
    ("cube", "reference/cube.obj"),
    ("cube_fan", "reference/cube_fan.obj"),
    ("catmark_cube", "catmark_cube.obj"),
    ("catmark_torus", "catmark_torus.obj"),
    ("catmark_toroidal_tet", "catmark_toroidal_tet.obj"),
    ("catmark_pyramid", "catmark_pyramid.obj"),
    ("catmark_gregory_test8", "catmark_gregory_test8.obj"),
    ("catmark_righthanded", "catmark_righthanded.obj"),
    ("catmark_smoothtris0", "catmark_smoothtris0.obj"),
    ("spot_control_mesh", "spot_control_mesh.obj"),
    ("fish_control_mesh", "fish_control_mesh.obj"),
    ("penguin_control_mesh", "penguin_control_mesh.obj"),
    ("beast.stride64", "beast.obj"),
    // Its tags (eleven edges of sharpness 5, one of 0.1) come from the sidecar beside it.
    ("catmark_cube_creases1.tags", "catmark_cube_creases1.obj"),
];

#[test]
fn reference_limit_points_are_reproduced() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let subd = data.join("subd");
    let mut checked = 0;
    for (name, mesh) in REFERENCES {
        let control = ControlMesh::load(&subd.join(mesh)).unwrap();
        let surface = LimitSurface::new(control);
        let points = read_points(&subd.join(format!("reference/{name}.limit.txt"))).unwrap();
        let c = compare_points(&surface, &points).unwrap();
        eprintln!(
            "{name}: {} points, position {:.2e} of the diagonal, normal {:.2e} rad",
            c.points, c.max_relative_position_error, c.max_normal_angle
        );
        common::assert_limit_match(name, &c);
        checked += 1;
    }
    assert_eq!(checked, 14);
}

#[test]
fn every_reference_file_is_listed() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for entry in std::fs::read_dir(data.join("subd/reference")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(stem) = name.strip_suffix(".limit.txt") {
            assert!(
                REFERENCES.iter().any(|(r, _)| *r == stem),
                "reference file {name} is not checked by this test"
            );
        }
    }
}

#[test]
fn normals_at_irregular_boundary_vertices_are_the_limit_of_nearby_normals() {
    // catmark_helmet face 36, corner (1, 1): a boundary vertex with 3 faces, where no
    // closed-form mask gives the tangent plane. Normals approaching it along the face's edge
    // and diagonal converge to the one reported there. The helmet's creases are left out: they
    // make the vertex a corner for seven levels, after which the same convergence starts.
    let Some(data) = common::data_dir() else {
        return;
    };
    let mesh = voxelkit::mesh::Mesh::load(&data.join("subd/catmark_helmet.obj")).unwrap();
    let control = ControlMesh::from_mesh(&mesh).unwrap();
    let surface = LimitSurface::new(control);
    let at = surface.evaluate(36, 1.0, 1.0).unwrap().normal;
    let off = |k: i32, diagonal: bool| {
        let e = 0.5f64.powi(k);
        let v = if diagonal { 1.0 - e } else { 1.0 };
        voxelkit::subd::angle_between(surface.evaluate(36, 1.0 - e, v).unwrap().normal, at)
    };
    for diagonal in [false, true] {
        let (near, nearer) = (off(20, diagonal), off(35, diagonal));
        assert!(
            nearer < near / 4.0 && nearer < 2e-4,
            "{near:e} then {nearer:e}"
        );
    }
}
