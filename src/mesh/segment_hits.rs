//! Where a lattice edge meets a mesh, for the Hermite data of its level set's mesh
//! (`contour::ExactSurface`): the triangles near a block of edges, found once through the
//! clusters of a tree, each met by Möller and Trumbore's test where its box meets the edge's,
//! and the hit nearest the grid's own crossing with its triangle's normal, turned to point
//! from the inside end to the outside one. A segment that meets no triangle crosses the level
//! set's zero elsewhere than on the mesh (the sheet the winding number spans over a hole):
//! the grid's crossing stands there.

use super::Mesh;
use super::winding::WindingTree;
use crate::contour::{ExactSurface, SegmentCrossings};
use glam::DVec3;
use std::sync::{Arc, OnceLock};

/// A mesh made ready for segment queries; its tree is built on the first one.
pub struct MeshHits {
    mesh: Arc<Mesh>,
    tree: OnceLock<WindingTree>,
}

impl MeshHits {
    pub fn new(mesh: Arc<Mesh>) -> MeshHits {
        MeshHits {
            mesh,
            tree: OnceLock::new(),
        }
    }
}

/// The fraction along `a + t d`, t in [0, 1], where it meets triangle `[p, q, r]`; none
/// where it misses or runs parallel to it.
fn segment_hit(a: DVec3, d: DVec3, [p, q, r]: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (q - p, r - p);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() <= 1e-15 * e1.length_squared().max(e2.length_squared()) * d.length() {
        return None;
    }
    let s = a - p;
    let u = s.dot(h) / det;
    let k = s.cross(e1);
    let v = d.dot(k) / det;
    let t = e2.dot(k) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&t)).then_some(t)
}

impl ExactSurface for MeshHits {
    fn near(&self, lo: DVec3, hi: DVec3) -> Box<dyn SegmentCrossings + '_> {
        let tree = self.tree.get_or_init(|| WindingTree::new(&self.mesh));
        let mut triangles = Vec::new();
        tree.visit(
            |centre, radius| centre.distance(centre.clamp(lo, hi)) <= radius,
            |leaf| {
                triangles.extend(leaf.iter().filter_map(|t| {
                    let (a, b) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                    (a.cmple(hi).all() && b.cmpge(lo).all()).then_some((*t, a, b))
                }))
            },
        );
        Box::new(NearTriangles { triangles })
    }
}

/// The triangles that meet a box, with their own boxes.
struct NearTriangles {
    triangles: Vec<([DVec3; 3], DVec3, DVec3)>,
}

impl SegmentCrossings for NearTriangles {
    fn crossing(&self, a: DVec3, b: DVec3, a_inside: bool, guess: f64) -> Option<(f64, DVec3)> {
        let d = b - a;
        let (lo, hi) = (a.min(b), a.max(b));
        let mut best: Option<(f64, DVec3)> = None;
        for (t, t_lo, t_hi) in &self.triangles {
            if t_lo.cmpgt(hi).any() || t_hi.cmplt(lo).any() {
                continue;
            }
            let Some(at) = segment_hit(a, d, *t) else {
                continue;
            };
            if best.is_none_or(|(b, _)| (at - guess).abs() < (b - guess).abs()) {
                best = Some((at, (t[1] - t[0]).cross(t[2] - t[0])));
            }
        }
        let (t, n) = best?;
        let outward = if a_inside { d } else { -d };
        let n = n.try_normalize()?;
        Some((t, if n.dot(outward) < 0.0 { -n } else { n }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn segments_meet_a_cube_on_its_faces_with_their_normals() {
        let mesh = MeshHits::new(Arc::new(generate::cuboid(DVec3::ZERO, DVec3::ONE)));
        let hits = mesh.near(DVec3::splat(-1.0), DVec3::splat(4.0));
        let (a, b) = (DVec3::new(0.5, 0.3, 0.2), DVec3::new(1.5, 0.4, 0.3));
        let (t, n) = hits.crossing(a, b, true, 0.5).unwrap();
        assert!((a.x + t * (b.x - a.x) - 1.0).abs() < 1e-12);
        assert!((n - DVec3::X).length() < 1e-12);
        // From outside in, the normal still points out of the solid.
        let (t, n) = hits.crossing(b, a, false, 0.5).unwrap();
        assert!((b.x + t * (a.x - b.x) - 1.0).abs() < 1e-12);
        assert!((n - DVec3::X).length() < 1e-12);
        // Through two faces: the hit nearest the guess.
        let (a, b) = (DVec3::new(-0.5, 0.5, 0.5), DVec3::new(1.5, 0.5, 0.5));
        assert!((hits.crossing(a, b, false, 0.2).unwrap().0 - 0.25).abs() < 1e-12);
        assert!((hits.crossing(a, b, false, 0.9).unwrap().0 - 0.75).abs() < 1e-12);
        // Missing the cube: none.
        assert!(
            hits.crossing(DVec3::splat(2.0), DVec3::splat(3.0), true, 0.5)
                .is_none()
        );
    }
}
