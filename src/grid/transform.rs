//! The index-to-world transform (DESIGN §3): `world = origin + voxel_size * index`.
//! Voxel `(i,j,k)` is the cube centred on the integer point, so a point maps to
//! voxel `floor(p + 1/2)` (Lai & Cheng eq. 2).

use super::coord::Coord;
use glam::DVec3;

/// Uniform-scale map between voxel index space and world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// World position of the centre of voxel (0,0,0).
    pub origin: DVec3,
    /// Edge length of one voxel in world units.
    pub voxel_size: f64,
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            origin: DVec3::ZERO,
            voxel_size: 1.0,
        }
    }
}

impl Transform {
    pub fn new(origin: DVec3, voxel_size: f64) -> Self {
        Transform { origin, voxel_size }
    }

    /// World position of the centre of voxel `c`.
    pub fn index_to_world(&self, c: Coord) -> DVec3 {
        self.origin + self.voxel_size * DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
    }

    /// Continuous index-space position of world point `p` (voxel centres are integers).
    pub fn world_to_index(&self, p: DVec3) -> DVec3 {
        (p - self.origin) / self.voxel_size
    }

    /// The voxel containing world point `p`: `floor(index + 1/2)`.
    pub fn world_to_voxel(&self, p: DVec3) -> Coord {
        let q = (self.world_to_index(p) + 0.5).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxel_of_a_point_is_the_cube_centred_on_it() {
        let t = Transform::new(DVec3::new(1.0, 2.0, 3.0), 0.5);
        assert_eq!(t.world_to_voxel(DVec3::new(1.0, 2.0, 3.0)), [0, 0, 0]);
        // 0.24 voxel-size units left of centre stays, 0.26 right of the face goes to the next.
        assert_eq!(
            t.world_to_voxel(DVec3::new(1.0 + 0.24, 2.0, 3.0)),
            [0, 0, 0]
        );
        assert_eq!(
            t.world_to_voxel(DVec3::new(1.0 + 0.26, 2.0, 3.0)),
            [1, 0, 0]
        );
        assert_eq!(
            t.world_to_voxel(DVec3::new(1.0 - 0.26, 2.0, 3.0)),
            [-1, 0, 0]
        );
        let w = t.index_to_world([4, -2, 0]);
        assert_eq!(w, DVec3::new(3.0, 1.0, 3.0));
    }
}
