//! How far apart two triangle meshes lie: the two-sided (Hausdorff) distance, each side the
//! largest exact distance from points of one mesh to the other's nearest triangle. The points
//! are three of each triangle (its first corner, the middle of its first edge, its centroid):
//! over a mesh's triangles, nearly every vertex and half the edge midpoints, where a surface
//! strays farthest from a nearby one.

use super::winding::WindingTree;
use glam::DVec3;
use rayon::prelude::*;

/// The distance from `a` to `b` and from `b` to `a`, in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoSided {
    pub a_to_b: f64,
    pub b_to_a: f64,
}

impl TwoSided {
    pub fn max(&self) -> f64 {
        self.a_to_b.max(self.b_to_a)
    }
}

/// The two-sided distance between the triangles `a` and `b` (corners in world units).
pub fn two_sided_distance(a: &[[DVec3; 3]], b: &[[DVec3; 3]]) -> TwoSided {
    let (tree_a, tree_b) = rayon::join(
        || WindingTree::of_triangles(a.to_vec()),
        || WindingTree::of_triangles(b.to_vec()),
    );
    TwoSided {
        a_to_b: farthest(a, &tree_b),
        b_to_a: farthest(b, &tree_a),
    }
}

fn farthest(from: &[[DVec3; 3]], to: &WindingTree) -> f64 {
    from.par_iter()
        .map(|&[p, q, r]| {
            [p, 0.5 * (p + q), (p + q + r) / 3.0]
                .into_iter()
                .map(|x| to.distance(x))
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}
