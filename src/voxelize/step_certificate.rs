//! A certificate that a voxel set separates the two sides of a formula's surface F = 0: a path
//! of centres outside the set keeps F's sign when no step of it meets the surface, so the set
//! separates once every step between two adjacent centres outside it (6- or 26-adjacent, as
//! the separation asked) is proven free of F = 0 by interval arithmetic over the step, halved
//! until proven, down to 2^-`MOST_HALVINGS` of its length. A step that is not proven (F changes
//! sign along it, or the halvings run out) gets the end nearer the surface, to first order,
//! added to the set. On a surface whose foot points are found exactly nothing is added; where
//! the paper's plain rule leaves holes (curvature), this closes them.

use super::Separability;
use super::separating_analytic::blocks_of;
use super::separating_formula::FormulaSurface;
use super::sink::Sink;
use crate::error::Result;
use crate::grid::{Coord, CoordBox, SparseGrid};
use crate::implicit::Dual;
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;

/// Halvings of a step before it is taken as meeting the surface.
const MOST_HALVINGS: u32 = 10;

/// Adds to `grid` one end of every step between two centres of `region` outside it that
/// interval arithmetic cannot prove free of `surface`; returns how many voxels were added.
pub fn close_unproven_steps(
    surface: &FormulaSurface,
    grid: &mut SparseGrid,
    region: CoordBox,
    separability: Separability,
    progress: &Progress,
) -> Result<u64> {
    let t = grid.transform;
    let h = t.voxel_size;
    // Each step once: the offsets whose first non-zero component is positive.
    let steps: Vec<Coord> = separability
        .flood_adjacency()
        .offsets()
        .into_iter()
        .filter(|d| d.iter().find(|&&v| v != 0).is_some_and(|&v| v > 0))
        .collect();
    let blocks = blocks_of(region.min, region.max);
    let found: Vec<(Coord, f64, DVec3)> = {
        let grid = &*grid;
        blocks
            .par_iter()
            .map_init(Vec::new, |slots, &origin| {
                let mut added = Vec::new();
                let (lo, hi) = (
                    t.index_to_world(origin) - h,
                    t.index_to_world(origin.map(|v| v + 8)),
                );
                if progress.stopped() || surface.box_is_empty(lo, hi) {
                    return added;
                }
                let last = origin.map(|v| v + 7);
                for x in origin[0].max(region.min[0])..=last[0].min(region.max[0]) {
                    for y in origin[1].max(region.min[1])..=last[1].min(region.max[1]) {
                        for z in origin[2].max(region.min[2])..=last[2].min(region.max[2]) {
                            let a = [x, y, z];
                            let pa = t.index_to_world(a);
                            if grid.contains(a) || surface.box_is_empty(pa - h, pa + h) {
                                continue;
                            }
                            for d in &steps {
                                let b = [0, 1, 2].map(|k| a[k] + d[k]);
                                if !region.contains(b) || grid.contains(b) {
                                    continue;
                                }
                                let pb = t.index_to_world(b);
                                if !step_is_free(surface, pa, pb) {
                                    added.push(nearer_end(surface, (a, pa), (b, pb), h, slots));
                                }
                            }
                        }
                    }
                }
                added
            })
            .flatten()
            .collect()
    };
    progress.check()?;
    let before = grid.voxel_count();
    {
        let mut sink = Sink::new(grid);
        for (c, distance, normal) in found {
            sink.add(c, distance, normal);
        }
    }
    Ok(grid.voxel_count() - before)
}

/// Whether interval arithmetic proves the segment `a`-`b` free of the surface.
fn step_is_free(surface: &FormulaSurface, a: DVec3, b: DVec3) -> bool {
    // F changes sign (or is not a number) along the step: it meets the surface.
    let (fa, fb) = (surface.value(a), surface.value(b));
    if fa.is_nan() || fb.is_nan() || fa * fb <= 0.0 {
        return false;
    }
    let mut pieces = vec![(a, b, 0)];
    while let Some((p, q, depth)) = pieces.pop() {
        if surface.box_is_empty(p.min(q), p.max(q)) {
            continue;
        }
        if depth == MOST_HALVINGS {
            return false;
        }
        let mid = 0.5 * (p + q);
        pieces.push((p, mid, depth + 1));
        pieces.push((mid, q, depth + 1));
    }
    true
}

/// The end of a step nearer the surface to first order, with that distance (voxels) and the
/// unit gradient there.
fn nearer_end(
    surface: &FormulaSurface,
    (a, pa): (Coord, DVec3),
    (b, pb): (Coord, DVec3),
    h: f64,
    slots: &mut Vec<Dual>,
) -> (Coord, f64, DVec3) {
    let at = |p: DVec3, slots: &mut Vec<Dual>| {
        let (d, n) = surface.formula().first_order_distance(p.to_array(), slots);
        (d.abs() / h, n)
    };
    let ((da, na), (db, nb)) = (at(pa, slots), at(pb, slots));
    if db < da { (b, db, nb) } else { (a, da, na) }
}
