//! The limit-surface evaluator against OpenSubdiv live (feature `osd`), on every control mesh
//! of the data folder, closed and open (tags such as creases are ignored on both sides).
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
                // catmark_fan has non-manifold edges: it must be refused, by name.
                assert_eq!(name, "catmark_fan", "{name}: {e}");
                assert!(e.to_string().contains("non-manifold"), "{e}");
                continue;
            }
        };
        let closed = control.is_closed();
        let surface = LimitSurface::new(control);
        let per_patch = if surface.patch_count() > 5000 { 1 } else { 8 };
        let check = check_against_opensubdiv(&surface, per_patch, 7).unwrap();
        eprintln!(
            "{name} ({}): dyadic {} points {:.1e} / {:.1e} rad, random {} points {:.1e} / {:.1e} rad",
            if closed { "closed" } else { "open" },
            check.dyadic.points,
            check.dyadic.max_relative_position_error,
            check.dyadic.max_normal_angle,
            check.random.points,
            check.random.max_relative_position_error,
            check.random.max_normal_angle
        );
        common::assert_limit_match(&format!("{name} dyadic"), &check.dyadic);
        common::assert_limit_match(&format!("{name} random"), &check.random);
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} control meshes checked");
}
