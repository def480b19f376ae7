//! Questions about single points, exactly: a mesh's distance from each (the nearest triangle,
//! found through a tree of triangle clusters), and whether each lies inside it by the mesh's
//! inside rule — its winding number (at least 1/2, read reversed for a mesh facing inward as
//! a whole, as `winding_inside` reads it; evaluated exactly wherever the tree's bound cannot
//! tell) or ray parity (crossings of the ray up +z). A signed distance is negative inside.

use super::inside_rule::Inside;
use super::winding_inside::{closed_by_caps, winds_reversed};
use crate::mesh::Mesh;
use crate::mesh::winding::WindingTree;
use glam::DVec3;

/// A mesh made ready for point queries.
pub struct PointQueries {
    tree: WindingTree,
    rule: Rule,
}

enum Rule {
    /// Inside where the winding number, times this orientation, is at least 1/2.
    Winding(f64),
    Parity,
}

impl PointQueries {
    pub fn new(mesh: &Mesh, inside: &Inside) -> PointQueries {
        let rule = match inside {
            Inside::Winding(caps) => {
                let (points, triangles) = closed_by_caps(mesh, caps);
                Rule::Winding(if winds_reversed(&points, &triangles) {
                    -1.0
                } else {
                    1.0
                })
            }
            Inside::Parity => Rule::Parity,
        };
        let corners = mesh
            .triangles()
            .map(|(_, t)| t.map(|v| mesh.p(v)))
            .collect();
        PointQueries {
            tree: WindingTree::of_triangles(corners),
            rule,
        }
    }

    /// The distance from `p` to the mesh.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.tree.distance(p)
    }

    pub fn contains(&self, p: DVec3) -> bool {
        match self.rule {
            Rule::Winding(orientation) => {
                let b = self.tree.bounds(p);
                let w = orientation * b.value;
                if (w - 0.5).abs() > b.spread {
                    w >= 0.5
                } else {
                    orientation * self.tree.exact_winding_number(p) >= 0.5
                }
            }
            Rule::Parity => self.crossings_above(p) % 2 == 1,
        }
    }

    /// The distance from `p` to the mesh, negative inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        let d = self.distance(p);
        if self.contains(p) { -d } else { d }
    }

    /// The triangles the ray from `p` up +z passes through (a ray through an edge or corner
    /// exactly counts neither side).
    fn crossings_above(&self, p: DVec3) -> usize {
        let mut count = 0;
        self.tree.visit(
            |centre, radius| centre.z + radius >= p.z && (centre - p).truncate().length() <= radius,
            |triangles| {
                count += triangles.iter().filter(|t| crosses_above(p, t)).count();
            },
        );
        count
    }
}

/// Whether the ray from `p` up +z passes through the inside of triangle `t`.
fn crosses_above(p: DVec3, t: &[DVec3; 3]) -> bool {
    let edge = |a: DVec3, b: DVec3| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    let e = [edge(t[0], t[1]), edge(t[1], t[2]), edge(t[2], t[0])];
    let area = e[0] + e[1] + e[2];
    let inside = e.iter().all(|&x| x > 0.0) || e.iter().all(|&x| x < 0.0);
    if !inside {
        return false;
    }
    // e[i] / area weighs the corner opposite edge i.
    let z = (e[1] * t[0].z + e[2] * t[1].z + e[0] * t[2].z) / area;
    z > p.z
}
