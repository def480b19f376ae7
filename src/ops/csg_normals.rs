//! Normals carried through a Boolean (Lai & Cheng's Fig. 4 lights its results by the
//! operands' normals): a voxel of the result takes the normal its first operand gives it,
//! else the second's; what a difference cuts out of the first operand shows the subtracted
//! solid's surface from the other side, so a voxel of the result that has none and touches a
//! voxel of the second operand with a normal takes that normal turned.

use super::csg::BooleanOp;
use crate::grid::{
    Adjacency, Channels, Coord, Leaf, SparseGrid, leaf_offset, leaf_origin, offset_coord,
};
use glam::Vec3;
use rayon::prelude::*;

/// The normal `grid` holds at `c`, if any.
fn normal_at(grid: &SparseGrid, c: Coord) -> Option<Vec3> {
    let leaf = grid.leaf(leaf_origin(c))?;
    let n = leaf_offset(c);
    leaf.is_on(n)
        .then(|| leaf.normal.as_ref().map(|normals| Vec3::from(normals[n])))
        .flatten()
}

/// The normals of `result` (= `a op b`, on one transform) from those of `a` and `b` (grids with
/// a normal channel, or none); none when neither has any.
pub fn boolean_normals(
    result: &SparseGrid,
    a: Option<&SparseGrid>,
    b: Option<&SparseGrid>,
    op: BooleanOp,
) -> Option<SparseGrid> {
    if a.is_none() && b.is_none() {
        return None;
    }
    let channels = Channels {
        normal: true,
        ..Channels::NONE
    };
    let neighbours = Adjacency::TwentySix.offsets();
    let leaves: Vec<Leaf> = result
        .leaves()
        .par_iter()
        .filter_map(|leaf| {
            let mut out = Leaf::new(leaf.origin, channels);
            for n in leaf.offsets() {
                let c = offset_coord(leaf.origin, n);
                let from_b = || match op {
                    BooleanOp::Difference => neighbours.iter().find_map(|d| {
                        let q = [0, 1, 2].map(|k| c[k] + d[k]);
                        b.and_then(|b| normal_at(b, q)).map(|v| -v)
                    }),
                    _ => b.and_then(|b| normal_at(b, c)),
                };
                if let Some(v) = a.and_then(|a| normal_at(a, c)).or_else(from_b) {
                    out.set_on(n);
                    out.normal.as_mut().expect("a normal leaf")[n] = v.into();
                }
            }
            (!out.is_empty()).then_some(out)
        })
        .collect();
    Some(SparseGrid::from_distinct_leaves(
        result.transform,
        channels,
        leaves,
    ))
}
