//! The area and the enclosed volume of the limit surface by Gauss-Legendre quadrature over
//! every patch: the area of |P_s x P_t|, an independent reference for the area the voxelizer
//! sums from its sub-patch quads; the volume, by the divergence theorem, of
//! (P - o) . (P_s x P_t) / 3 about a reference point o (the centre of the control points'
//! box, so that a surface far from the origin loses no precision), signed by the surface's
//! orientation (positive when its normals face outward).

use super::patch::LimitSample;
use super::surface::LimitSurface;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::iter::Sum;
use std::ops::{Add, Mul};

/// 5-point Gauss-Legendre nodes and weights on [0, 1].
const NODES: [f64; 5] = [
    0.046_910_077_030_668_004,
    0.230_765_344_947_158_45,
    0.5,
    0.769_234_655_052_841_6,
    0.953_089_922_969_332,
];
const WEIGHTS: [f64; 5] = [
    0.118_463_442_528_094_54,
    0.239_314_335_249_683_23,
    0.284_444_444_444_444_45,
    0.239_314_335_249_683_23,
    0.118_463_442_528_094_54,
];

/// Cells per patch side to start from.
const CELLS: usize = 8;
/// A cell is halved until it lies within one bicubic piece of its patch, at most this many
/// times: towards an extraordinary corner the surface is piecewise polynomial on ever smaller
/// rings; along a semi-sharp crease down to 2^-sharpness.
const CORNER_DEPTH: u32 = 30;

pub fn limit_area(surface: &LimitSurface) -> f64 {
    integrate(surface, area_element)
}

/// The signed volume the closed limit surface encloses (see the module docs).
pub fn limit_volume(surface: &LimitSurface) -> f64 {
    let o = reference_point(surface);
    integrate(surface, |s| volume_element(s, o))
}

/// The signed volume and the area in one pass over the same samples (the refinements
/// towards extraordinary corners are the costly part, and they serve both).
pub fn limit_volume_and_area(surface: &LimitSurface) -> (f64, f64) {
    let o = reference_point(surface);
    let both = integrate(surface, |s| {
        DVec2::new(volume_element(s, o), area_element(s))
    });
    (both.x, both.y)
}

fn area_element(s: &LimitSample) -> f64 {
    s.du.cross(s.dv).length()
}

fn volume_element(s: &LimitSample, o: DVec3) -> f64 {
    (s.position - o).dot(s.du.cross(s.dv)) / 3.0
}

/// The centre of the control points' box.
fn reference_point(surface: &LimitSurface) -> DVec3 {
    let b = surface.control().bbox();
    0.5 * (b.min + b.max)
}

/// The integral of `f` over every patch's parameter square.
fn integrate<T>(surface: &LimitSurface, f: impl Fn(&LimitSample) -> T + Sync) -> T
where
    T: Copy + Default + Send + Sum + Add<Output = T> + Mul<f64, Output = T>,
{
    (0..surface.patch_count())
        .into_par_iter()
        .map(|pid| {
            let h = 1.0 / CELLS as f64;
            let mut sum = T::default();
            for j in 0..CELLS {
                for i in 0..CELLS {
                    let at = [i as f64 * h, j as f64 * h];
                    sum = sum + cell(surface, pid, at, h, 0, &f);
                }
            }
            sum
        })
        .sum()
}

fn cell<T>(
    surface: &LimitSurface,
    pid: usize,
    at: [f64; 2],
    h: f64,
    depth: u32,
    f: &impl Fn(&LimitSample) -> T,
) -> T
where
    T: Copy + Default + Sum + Add<Output = T> + Mul<f64, Output = T>,
{
    let polynomial = surface.polynomial_on(pid, at[0], at[0] + h, at[1], at[1] + h);
    if !polynomial && depth < CORNER_DEPTH {
        let g = h / 2.0;
        return [(0.0, 0.0), (g, 0.0), (0.0, g), (g, g)]
            .iter()
            .map(|&(du, dv)| cell(surface, pid, [at[0] + du, at[1] + dv], g, depth + 1, f))
            .sum();
    }
    let mut sum = T::default();
    for (a, wa) in NODES.iter().zip(WEIGHTS) {
        for (b, wb) in NODES.iter().zip(WEIGHTS) {
            sum = sum + f(&surface.eval_patch(pid, at[0] + a * h, at[1] + b * h)) * (wa * wb);
        }
    }
    sum * h * h
}
