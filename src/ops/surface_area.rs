//! Surface area from a voxel solid: every voxel face between the solid and the outside adds
//! `h² |n_i|`, where `i` is the face's axis and `n` the unit surface normal at the face. A
//! plane piece of area A with normal n shows `A |n_i| / h²` faces along axis i, so the sum
//! tends to `A Σ n_i² = A` as h shrinks (the bare face count tends to `A ‖n‖₁`, up to √3 A).

use crate::grid::{DenseMask, Transform};
use glam::DVec3;
use rayon::prelude::*;

/// The area estimate and the number of boundary faces of `solid`; `normal_at` gives the
/// surface normal (any length) at a world point.
pub fn face_weighted_area(
    solid: &DenseMask,
    transform: &Transform,
    normal_at: impl Fn(DVec3) -> DVec3 + Sync,
) -> (f64, u64) {
    let [nx, ny, nz] = solid.dims();
    let h = transform.voxel_size;
    let corner = transform.index_to_world(solid.bbox.min);
    // Each face at index-space offset q (from the box's first voxel) along axis `axis`.
    let weight = |q: DVec3, axis: usize| {
        let n = normal_at(corner + q * h);
        let len = n.length();
        if len > 0.0 { n[axis].abs() / len } else { 0.0 }
    };
    let chunks = nz.div_ceil(64);
    let (area, faces) = (0..=nx as i64)
        .into_par_iter()
        .map(|x| {
            let (mut area, mut faces) = (0.0, 0u64);
            let mut add = |diff: u64, z0: usize, at: &dyn Fn(usize) -> DVec3, axis: usize| {
                let mut d = diff;
                while d != 0 {
                    let k = d.trailing_zeros() as usize;
                    d &= d - 1;
                    area += weight(at(z0 + k), axis);
                    faces += 1;
                }
            };
            for y in 0..=ny as i64 {
                let mut carry = 0u64; // the last voxel of the previous chunk of this row
                for c in 0..chunks {
                    let z0 = c * 64;
                    let n = (nz - z0).min(64);
                    let here = solid.row_bits(x, y, z0, n);
                    // Faces between rows x-1 and x, and y-1 and y.
                    let fx = here ^ solid.row_bits(x - 1, y, z0, n);
                    add(
                        fx,
                        z0,
                        &|z| DVec3::new(x as f64 - 0.5, y as f64, z as f64),
                        0,
                    );
                    let fy = here ^ solid.row_bits(x, y - 1, z0, n);
                    add(
                        fy,
                        z0,
                        &|z| DVec3::new(x as f64, y as f64 - 0.5, z as f64),
                        1,
                    );
                    // Faces below each voxel of the chunk, and above the row's last one.
                    let mask = if n < 64 { (1u64 << n) - 1 } else { u64::MAX };
                    let fz = (here ^ ((here << 1) | carry)) & mask;
                    add(
                        fz,
                        z0,
                        &|z| DVec3::new(x as f64, y as f64, z as f64 - 0.5),
                        2,
                    );
                    carry = here >> (n - 1) & 1;
                }
                if carry == 1 {
                    add(
                        1,
                        nz,
                        &|z| DVec3::new(x as f64, y as f64, z as f64 - 0.5),
                        2,
                    );
                }
            }
            (area, faces)
        })
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    (area * h * h, faces)
}
