//! Meshes read Y-up turned Z-up (`grid::UpAxis`): the volume then stands where Blender puts
//! the imported mesh.

use super::Mesh;
use super::attributes::AttributeKind;
pub use crate::grid::UpAxis;

impl Mesh {
    /// The mesh with its `up` axis turned to +z, its normals with it.
    pub fn with_up_axis(mut self, up: UpAxis) -> Mesh {
        for p in &mut self.positions {
            *p = up.turn(*p);
        }
        for a in &mut self.attributes {
            if a.kind == AttributeKind::Normal {
                for n in &mut a.values {
                    *n = up.turn(n.as_dvec3()).as_vec3();
                }
            }
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn y_up_turns_to_z_up_keeping_the_volume() {
        let mesh = crate::mesh::generate::torus(DVec3::new(0.0, 2.0, 0.0), 1.0, 0.3, 16, 8);
        let volume = mesh.signed_volume();
        let turned = mesh.clone().with_up_axis(UpAxis::Y);
        assert!((turned.signed_volume() - volume).abs() < 1e-12);
        // The centre at y = 2 goes to z = 2.
        let b = turned.bbox();
        assert!(((b.min.z + b.max.z) / 2.0 - 2.0).abs() < 1e-9);
        assert_eq!(
            mesh.with_up_axis(UpAxis::Z).positions,
            turned
                .with_up_axis(UpAxis::Z)
                .positions
                .iter()
                .map(|p| DVec3::new(p.x, p.z, -p.y))
                .collect::<Vec<_>>()
        );
    }
}
