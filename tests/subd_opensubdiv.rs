//! The limit-surface evaluator against OpenSubdiv live (feature `osd`), on every control mesh
//! of the data folder, closed and open, with its crease tags on both sides.
#![cfg(feature = "osd")]

mod common;

use voxelkit::subd::opensubdiv::check_against_opensubdiv;
use voxelkit::subd::{ControlMesh, LimitSurface};

#[test]
fn every_control_mesh_matches_opensubdiv() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let mut checked = 0;
    let mut creased = Vec::new();
    let mut names: Vec<_> = std::fs::read_dir(data.join("subd"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    names.sort();
    for path in names {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let control = match ControlMesh::load(&path) {
            Ok(c) => c,
            Err(e) => {
                // catmark_fan has non-manifold edges, catmark_square_hedit0 hierarchical
                // edits: each must be refused, by name.
                let why = match name.as_str() {
                    "catmark_fan" => "non-manifold",
                    "catmark_square_hedit0" => "hierarchical edits",
                    _ => panic!("{name}: {e}"),
                };
                assert!(e.to_string().contains(why), "{e}");
                continue;
            }
        };
        if !control.tags.creases.is_empty() {
            creased.push(name.clone());
        }
        let closed = control.is_closed();
        let surface = LimitSurface::new(control);
        let per_patch = if surface.patch_count() > 5000 { 1 } else { 8 };
        let check = check_against_opensubdiv(&surface, per_patch, 7).unwrap();
        let dyadic = check.dyadic.map_or("dyadic: too deep".into(), |c| {
            format!(
                "dyadic {} points {:.1e} / {:.1e} rad",
                c.points, c.max_relative_position_error, c.max_normal_angle
            )
        });
        eprintln!(
            "{name} ({}, {} creases): {dyadic}, random {} points {:.1e} / {:.1e} rad",
            if closed { "closed" } else { "open" },
            surface.control().tags.creases.len(),
            check.random.points,
            check.random.max_relative_position_error,
            check.random.max_normal_angle
        );
        if let Some(dyadic) = &check.dyadic {
            common::assert_limit_match(&format!("{name} dyadic"), dyadic);
        }
        common::assert_limit_match(&format!("{name} random"), &check.random);
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} control meshes checked");
    for name in [
        "catmark_bishop",
        "catmark_car",
        "catmark_cube_creases1",
        "catmark_helmet",
        "catmark_pawn",
        "catmark_rook",
    ] {
        assert!(
            creased.iter().any(|c| c == name),
            "{name} was checked without its creases"
        );
    }
}

/// Tags of every kind OpenSubdiv evaluates, on a torus (all regular) and on Spot (triangles,
/// pentagons, extraordinary vertices): an infinitely sharp chain around three sides of a face
/// (darts at its ends, creases turning at its middle vertices), a lone semi-sharp edge with
/// a fractional sharpness (darts that soften), a semi-sharp chain that turns, and a
/// semi-sharp and an infinitely sharp corner.
#[test]
fn every_kind_of_tag_matches_opensubdiv() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in ["catmark_torus", "spot_control_mesh"] {
        let control = ControlMesh::load(&data.join(format!("subd/{name}.obj"))).unwrap();
        let mesh = control.polygon_mesh();
        let edge = |f: usize, k: usize| {
            let face = mesh.face(f);
            (face[k], face[(k + 1) % face.len()])
        };
        // Faces spread over the mesh, apart from one another.
        let at = |eighths: usize| mesh.face_count() * eighths / 8;
        let mut tags = voxelkit::subd::Tags::default();
        for k in 0..3 {
            let (a, b) = edge(0, k);
            tags.creases.push((a, b, 10.0));
        }
        let (a, b) = edge(at(2), 0);
        tags.creases.push((a, b, 0.3));
        for k in 0..2 {
            let (a, b) = edge(at(4), k);
            tags.creases.push((a, b, 2.5));
        }
        tags.corners.push((mesh.face(at(5) + 1)[0], 1.5));
        tags.corners.push((mesh.face(at(7))[2], 10.0));
        let surface = LimitSurface::new(control.with_tags(tags).unwrap());
        let check = check_against_opensubdiv(&surface, 16, 11).unwrap();
        let dyadic = check
            .dyadic
            .expect("sharpness 2.5 is refined away at level 3");
        eprintln!(
            "{name} tagged: dyadic {} points {:.1e} / {:.1e} rad, random {} points {:.1e} / {:.1e} rad",
            dyadic.points,
            dyadic.max_relative_position_error,
            dyadic.max_normal_angle,
            check.random.points,
            check.random.max_relative_position_error,
            check.random.max_normal_angle
        );
        common::assert_limit_match(&format!("{name} tagged dyadic"), &dyadic);
        common::assert_limit_match(&format!("{name} tagged random"), &check.random);
    }
}
