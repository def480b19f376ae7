//! Questions about single points, exactly: a mesh's distance from each (the nearest triangle,
//! found through a tree of triangle clusters), and whether each lies inside it by the mesh's
//! inside rule. By the winding number (at least 1/2, read reversed for a mesh facing inward as
//! a whole, as `winding_inside` reads it), split as `winding_inside` splits it: the integer
//! winding of mesh and caps, counted by signed crossings of the ray up +z, less the caps' own
//! winding number (exact wherever its tree's bound cannot tell). By ray parity, the crossings
//! of that ray counted. A ray through an edge or a corner exactly counts neither side. A
//! signed distance is negative inside.

use super::inside_rule::Inside;
use super::winding_inside::{closed_by_caps, winds_reversed};
use crate::mesh::Mesh;
use crate::mesh::winding::{WindingTree, winding_number_of};
use glam::DVec3;

/// A mesh made ready for point queries.
pub struct PointQueries {
    /// The mesh's triangles.
    surface: WindingTree,
    rule: Rule,
}

enum Rule {
    Winding {
        /// -1 where the mesh is read reversed.
        orientation: f64,
        /// The caps' triangles: crossed by rays, and their own winding number.
        caps: WindingTree,
        cap_corners: Vec<[DVec3; 3]>,
    },
    Parity,
}

impl PointQueries {
    pub fn new(mesh: &Mesh, inside: &Inside) -> PointQueries {
        let rule = match inside {
            Inside::Winding(caps) => {
                let (points, triangles) = closed_by_caps(mesh, caps);
                let cap_corners: Vec<[DVec3; 3]> = caps
                    .triangles
                    .iter()
                    .map(|t| t.map(|v| points[v as usize]))
                    .collect();
                Rule::Winding {
                    orientation: if winds_reversed(&points, &triangles) {
                        -1.0
                    } else {
                        1.0
                    },
                    caps: WindingTree::of_triangles(cap_corners.clone()),
                    cap_corners,
                }
            }
            Inside::Parity => Rule::Parity,
        };
        let corners = mesh
            .triangles()
            .map(|(_, t)| t.map(|v| mesh.p(v)))
            .collect();
        PointQueries {
            surface: WindingTree::of_triangles(corners),
            rule,
        }
    }

    /// The distance from `p` to the mesh.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.surface.distance(p)
    }

    pub fn contains(&self, p: DVec3) -> bool {
        match &self.rule {
            Rule::Winding {
                orientation,
                caps,
                cap_corners,
            } => {
                let k = (crossings_above(&self.surface, p).winding
                    + crossings_above(caps, p).winding) as f64;
                let b = caps.bounds(p);
                let w = orientation * (k - b.value);
                if (w - 0.5).abs() > b.spread {
                    w >= 0.5
                } else {
                    orientation * (k - winding_number_of(cap_corners, p)) >= 0.5
                }
            }
            Rule::Parity => crossings_above(&self.surface, p).count % 2 == 1,
        }
    }

    /// The distance from `p` to the mesh, negative inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        let d = self.distance(p);
        if self.contains(p) { -d } else { d }
    }
}

/// The triangles of `tree` the ray from `p` up +z passes through: how many, and their sum
/// signed by the way each faces (+1 up, -1 down), the winding number of a closed surface at p.
struct Crossings {
    count: usize,
    winding: i64,
}

fn crossings_above(tree: &WindingTree, p: DVec3) -> Crossings {
    let mut crossings = Crossings {
        count: 0,
        winding: 0,
    };
    tree.visit(
        |centre, radius| centre.z + radius >= p.z && (centre - p).truncate().length() <= radius,
        |triangles| {
            for t in triangles {
                if let Some(up) = crosses_above(p, t) {
                    crossings.count += 1;
                    crossings.winding += if up { 1 } else { -1 };
                }
            }
        },
    );
    crossings
}

/// Whether the ray from `p` up +z passes through the inside of triangle `t`, and if so
/// whether `t` faces up.
fn crosses_above(p: DVec3, t: &[DVec3; 3]) -> Option<bool> {
    let edge = |a: DVec3, b: DVec3| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    let e = [edge(t[0], t[1]), edge(t[1], t[2]), edge(t[2], t[0])];
    let area = e[0] + e[1] + e[2];
    let inside = e.iter().all(|&x| x > 0.0) || e.iter().all(|&x| x < 0.0);
    if !inside {
        return None;
    }
    // e[i] / area weighs the corner opposite edge i; a counter-clockwise triangle seen from
    // above (positive area) faces up.
    let z = (e[1] * t[0].z + e[2] * t[1].z + e[0] * t[2].z) / area;
    (z > p.z).then_some(area > 0.0)
}
