//! Line voxelization by marching the dominant axis (Jegathese et al. §4.1, Fig. 2): one
//! voxel per unit step along the axis the segment is most inclined to, the other two
//! coordinates and the attribute advanced by constant increments.
//!
//! Decided here where the paper is silent:
//! - Samples lie on the centre planes `axis = k` of the voxels from the first endpoint's to the
//!   last endpoint's, so each step moves exactly one voxel along the axis and at most one along
//!   the others (their increments are at most 1): consecutive voxels are 26-adjacent.
//! - The endpoints' own voxels are always included. The first and last samples extrapolate the
//!   segment by up to half a voxel and may round one voxel away from the endpoint; the endpoint
//!   voxel is 26-adjacent to them and is what joins consecutive segments of a polyline.
//! - The attribute at a sample is the segment's value at that sample, held at the endpoint
//!   values beyond the segment.

use super::attribute::Attribute;
use glam::DVec3;

/// The voxel holding index-space point `p` (voxel `i` covers `[i - 1/2, i + 1/2)`).
#[inline]
pub fn voxel_of(p: DVec3) -> [i64; 3] {
    [round(p.x), round(p.y), round(p.z)]
}

/// `floor(x + 1/2)`: the voxel of coordinate `x`. Written out because `f64::floor` is a
/// library call on baseline x86-64, and this runs once or more per voxel.
#[inline]
pub fn round(x: f64) -> i64 {
    let y = x + 0.5;
    let t = y as i64;
    t - ((t as f64) > y) as i64
}

/// The axis of the largest component of `d`; ties go to x, then y (the paper's order).
#[inline]
pub fn dominant_axis(d: DVec3) -> usize {
    let a = d.abs();
    if a.y > a.x && a.y >= a.z {
        1
    } else if a.z > a.x && a.z > a.y {
        2
    } else {
        0
    }
}

/// Emits the voxel holding `p` with its distance from `p`.
#[inline]
fn emit_point<A>(emit: &mut impl FnMut([i64; 3], f64, A), p: DVec3, c: A) {
    let v = voxel_of(p);
    emit(v, (p - DVec3::from_array(v.map(|x| x as f64))).length(), c);
}

/// Calls `emit(voxel, distance, attribute)` for the voxels of segment `a`-`b` (index space),
/// `distance` being how far the sample lies from the voxel centre. Voxels may repeat.
#[inline]
pub fn voxelize_segment<A: Attribute>(
    a: DVec3,
    b: DVec3,
    ca: A,
    cb: A,
    mut emit: impl FnMut([i64; 3], f64, A),
) {
    emit_point(&mut emit, a, ca);
    let d = b - a;
    let axis = dominant_axis(d);
    if d[axis] != 0.0 {
        let (k0, k1) = (round(a[axis]), round(b[axis]));
        let step = if d[axis] > 0.0 { 1 } else { -1 };
        // Increments per unit step along the axis, in the direction of travel.
        let dp = d / d[axis].abs();
        let dc = cb.sub(ca).scale(1.0 / d[axis].abs());
        let t0 = (k0 as f64 - a[axis]) * step as f64;
        let (mut p, mut c) = (a + dp * t0, ca.add(dc.scale(t0)));
        let mut k = k0;
        loop {
            // The axis coordinate is exact; only the other two accumulate increments.
            p[axis] = k as f64;
            emit_point(&mut emit, p, c.clamp_between(ca, cb));
            if k == k1 {
                break;
            }
            k += step;
            p += dp;
            c = c.add(dc);
        }
    }
    emit_point(&mut emit, b, cb);
}
