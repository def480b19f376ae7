//! A formula's solid, F < 0 within the bounds searched, to mesh (`contour::ExactSurface`):
//! the octree's voxels only envelop F = 0, so the values are the formula's own. Around every
//! block of the envelope (and its neighbours) F over the length of its gradient is sampled at
//! each voxel centre, in voxels; a block beyond them holds no surface, so F's sign at its
//! centre is its sign throughout, and those inside become tiles. The crossings are solved on
//! the max of that distance and the bounds' box, so a solid cut by the bounds is closed by
//! their faces.

use super::Formula;
use crate::contour::{ExactSurface, Meaning, ScalarField, SegmentCrossings, crossing_of_values};
use crate::grid::{Channels, Coord, Leaf, SparseGrid, offset_coord};
use crate::shapes::Cuboid;
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;
use std::borrow::Cow;

/// The band's values reach this many voxels; beyond them a voxel counts as this far.
const BAND: f32 = 3.0;

pub struct FormulaSolid {
    formula: Formula,
    bounds: Cuboid,
}

impl FormulaSolid {
    /// The solid where F < 0 in `bounds`; none for formulas whose sign does not say inside
    /// (Stolte and Kaufman's squared substitution, the surface sought at negative r too).
    pub fn new(formula: &Formula, bounds: Cuboid, negative_r: bool) -> Option<FormulaSolid> {
        (!formula.squared && !negative_r).then(|| FormulaSolid {
            formula: formula.clone(),
            bounds,
        })
    }

    /// The distance to the solid's surface to first order (negative inside) and its normal.
    fn sample(&self, p: DVec3, slots: &mut Vec<super::Dual>) -> (f64, DVec3) {
        let f = self.formula.first_order_distance(p.to_array(), slots);
        let b = self.bounds.signed_distance(p);
        if b.0 > f.0 { b } else { f }
    }
}

impl ExactSurface for FormulaSolid {
    fn near(&self, _lo: DVec3, _hi: DVec3) -> Box<dyn SegmentCrossings + '_> {
        Box::new(self)
    }

    fn field_around(&self, grid: &SparseGrid) -> Option<ScalarField<'static>> {
        let t = grid.transform;
        let mut band: FxHashSet<Coord> = FxHashSet::default();
        for leaf in grid.leaves() {
            for code in 0..27 {
                let step = [code % 3, code / 3 % 3, code / 9].map(|s| 8 * (s - 1));
                band.insert(std::array::from_fn(|a| leaf.origin[a] + step[a]));
            }
        }
        let band: Vec<Coord> = band.into_iter().collect();
        let leaves: Vec<Leaf> = band
            .par_iter()
            .map_init(Vec::new, |slots, &origin| {
                let mut leaf = Leaf::new(origin, Channels::VALUE);
                leaf.mask = [u64::MAX; 8];
                let values = leaf.value.as_mut().expect("a value leaf");
                for (n, v) in values.iter_mut().enumerate() {
                    let d = self
                        .sample(t.index_to_world(offset_coord(origin, n)), slots)
                        .0;
                    *v = ((d / t.voxel_size) as f32).clamp(-BAND, BAND);
                }
                leaf
            })
            .collect();
        let mut field = SparseGrid::from_distinct_leaves(t, Channels::VALUE, leaves);
        // Every other block of the bounds, by the sign at its centre.
        let (lo, hi) = (
            t.world_to_index(self.bounds.min).floor(),
            t.world_to_index(self.bounds.max).ceil(),
        );
        let block = |v: f64| (v as i64).div_euclid(8) * 8;
        let band: FxHashSet<Coord> = band.into_iter().collect();
        let xs: Vec<i64> = (block(lo.x)..=block(hi.x)).step_by(8).collect();
        let inside: Vec<Coord> = xs
            .par_iter()
            .map_init(Vec::new, |slots, &x| {
                let mut found = Vec::new();
                for y in (block(lo.y)..=block(hi.y)).step_by(8) {
                    for z in (block(lo.z)..=block(hi.z)).step_by(8) {
                        let origin = [x, y, z];
                        let centre = t.index_to_world(origin) + 3.5 * t.voxel_size;
                        if !band.contains(&origin) && self.sample(centre, slots).0 < 0.0 {
                            found.push(origin);
                        }
                    }
                }
                found
            })
            .flatten()
            .collect();
        field.fill_leaf_blocks(inside);
        Some(ScalarField {
            grid: Cow::Owned(field),
            meaning: Meaning::LevelSet { outside: BAND },
            iso: 0.0,
        })
    }
}

impl SegmentCrossings for &FormulaSolid {
    fn crossing(&self, a: DVec3, b: DVec3, a_inside: bool, _guess: f64) -> Option<(f64, DVec3)> {
        let mut slots = Vec::new();
        crossing_of_values(|p| self.sample(p, &mut slots), a, b, a_inside)
    }
}
