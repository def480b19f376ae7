//! Where a CSG leaf is placed (Lai & Cheng's Fig. 4: positioned copies of one solid): an
//! optional `"place"` object on every leaf, `{"translate": [x, y, z], "rotate": {"axis": [x,
//! y, z], "degrees": d} or {"euler": [x, y, z]}, "scale": s}` (scaled, then rotated about the
//! origin, then moved; Euler angles in degrees about x, then y, then z) or `{"matrix": [[..4],
//! [..4], [..4], [0, 0, 0, 1]]}` (any invertible affine map, rows). Meshes and control meshes
//! are moved point by point (their surfaces are affine images of the points); boxes,
//! cylinders, spheres, formulas and grids are asked about each voxel centre mapped back into
//! their own frame, so their placed solids are as exact as the unplaced ones.

use crate::mesh::Aabb;
use glam::{DAffine3, DMat3, DQuat, DVec3, EulerRot};
use serde::Deserialize;

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct PlaceSpec {
    translate: Option<[f64; 3]>,
    rotate: Option<RotateSpec>,
    scale: Option<f64>,
    matrix: Option<[[f64; 4]; 4]>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(
    untagged,
    expecting = "{\"axis\": [x, y, z], \"degrees\": d} or {\"euler\": [x, y, z]} (degrees)"
)]
enum RotateSpec {
    AxisAngle(AxisAngle),
    Euler(Euler),
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct AxisAngle {
    axis: [f64; 3],
    degrees: f64,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct Euler {
    euler: [f64; 3],
}

/// The map from a leaf's own frame to the world that `spec` gives, or what is wrong with it
/// (the field's name first).
pub fn to_world(spec: &PlaceSpec) -> Result<DAffine3, String> {
    let finite = |v: &[f64], name: &str| {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(format!("{name}: must be finite numbers"))
        }
    };
    if let Some(m) = spec.matrix {
        if spec.translate.is_some() || spec.rotate.is_some() || spec.scale.is_some() {
            return Err("matrix: give a matrix or translate, rotate and scale, not both".into());
        }
        finite(m.as_flattened(), "matrix")?;
        if m[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err("matrix: the last row must be [0, 0, 0, 1] (an affine map)".into());
        }
        let linear = DMat3::from_cols_array_2d(&[0, 1, 2].map(|c| [m[0][c], m[1][c], m[2][c]]));
        if linear.determinant() == 0.0 || !linear.inverse().is_finite() {
            return Err("matrix: must be invertible".into());
        }
        return Ok(DAffine3::from_mat3_translation(
            linear,
            DVec3::new(m[0][3], m[1][3], m[2][3]),
        ));
    }
    let scale = spec.scale.unwrap_or(1.0);
    if !(scale > 0.0 && scale.is_finite()) {
        return Err("scale: must be positive".into());
    }
    let rotation = match spec.rotate {
        None => DQuat::IDENTITY,
        Some(RotateSpec::AxisAngle(r)) => {
            finite(&r.axis, "rotate.axis")?;
            finite(&[r.degrees], "rotate.degrees")?;
            let axis = DVec3::from_array(r.axis)
                .try_normalize()
                .ok_or("rotate.axis: must not be zero")?;
            DQuat::from_axis_angle(axis, r.degrees.to_radians())
        }
        Some(RotateSpec::Euler(e)) => {
            finite(&e.euler, "rotate.euler")?;
            let [x, y, z] = e.euler.map(f64::to_radians);
            // Extrinsic x, then y, then z: the same as intrinsic z, y, x.
            DQuat::from_euler(EulerRot::ZYX, z, y, x)
        }
    };
    let translate = spec.translate.unwrap_or([0.0; 3]);
    finite(&translate, "translate")?;
    Ok(DAffine3::from_scale_rotation_translation(
        DVec3::splat(scale),
        rotation,
        DVec3::from_array(translate),
    ))
}

/// The world box of box `b` placed by `to_world`: the box of its eight corners' images.
pub fn placed_box(b: &Aabb, to_world: &DAffine3) -> Aabb {
    let mut out = Aabb {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };
    for corner in 0..8 {
        let p = DVec3::select(
            glam::BVec3::new(corner & 1 == 1, corner & 2 == 2, corner & 4 == 4),
            b.max,
            b.min,
        );
        let q = to_world.transform_point3(p);
        out.min = out.min.min(q);
        out.max = out.max.max(q);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn place(json: &str) -> Result<DAffine3, String> {
        to_world(&serde_json::from_str::<PlaceSpec>(json).unwrap())
    }

    #[test]
    fn scale_then_rotate_then_translate() {
        let m = place(
            r#"{"translate": [1, 2, 3], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "scale": 2}"#,
        )
        .unwrap();
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 4.0, 3.0)).length() < 1e-12, "{p}");
        let e = place(r#"{"rotate": {"euler": [90, 0, 90]}}"#).unwrap();
        // About x by 90 (y to z), then about z by 90 (x to y): y ends on z, x on y.
        assert!((e.transform_point3(DVec3::Y) - DVec3::Z).length() < 1e-12);
        assert!((e.transform_point3(DVec3::X) - DVec3::Y).length() < 1e-12);
        let m = place(r#"{"matrix": [[0, -1, 0, 5], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}"#)
            .unwrap();
        assert!((m.transform_point3(DVec3::X) - DVec3::new(5.0, 1.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn bad_placements_are_named() {
        for (json, field) in [
            (r#"{"scale": 0}"#, "scale"),
            (
                r#"{"rotate": {"axis": [0, 0, 0], "degrees": 5}}"#,
                "rotate.axis",
            ),
            (
                r#"{"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]}"#,
                "invertible",
            ),
            (
                r#"{"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1]]}"#,
                "last row",
            ),
            (
                r#"{"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "scale": 2}"#,
                "not both",
            ),
        ] {
            let e = place(json).unwrap_err();
            assert!(e.contains(field), "{json}: {e}");
        }
    }
}
