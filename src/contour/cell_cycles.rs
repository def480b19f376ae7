//! The surface pieces inside one cell of the sample lattice, for each of the 256 sign cases:
//! closed, oriented cycles of the cell's crossing edges.
//!
//! A cell is the cube between eight voxel centres; corner `k` sits at offset
//! `(k & 1, k >> 1 & 1, k >> 2 & 1)`. On each of the cube's faces the crossing edges are joined
//! in pairs by segments: a face with two crossings has one segment; a face with four (inside
//! corners on a diagonal, the ambiguous face) has two, each cutting off one inside corner.
//! That rule reads only the face's own four corners, so the two cells that share a face join
//! its crossings alike, which is what makes the whole surface a closed 2-manifold: every
//! segment lies on exactly two cells' cycles, and the cycles around a crossing edge close up.
//! Each crossing edge lies on two faces, so the segments chain into disjoint cycles.
//!
//! Segments are oriented so that every cycle turns counter-clockwise seen from the outside
//! (the side of positive values): on a face with outward normal `N`, with `n` pointing from
//! the face's inside corners to its outside ones, a segment runs along `n × N`.

use std::sync::OnceLock;

/// The cube's twelve edges as (corner, corner + one axis step), axis by axis.
pub const EDGES: [(u8, u8); 12] = edges();

/// Edge `e` runs along axis `e / 4`.
pub fn edge_axis(e: usize) -> usize {
    e / 4
}

/// Whether edges `a` and `b` lie on a common face of the cube.
pub fn edges_share_face(a: usize, b: usize) -> bool {
    let corners = [EDGES[a].0, EDGES[a].1, EDGES[b].0, EDGES[b].1];
    (0..3).any(|axis| {
        let side = corners[0] >> axis & 1;
        corners.iter().all(|k| k >> axis & 1 == side)
    })
}

const fn edges() -> [(u8, u8); 12] {
    let mut out = [(0u8, 0u8); 12];
    let mut n = 0;
    let mut axis = 0;
    while axis < 3 {
        let mut a = 0u8;
        while a < 8 {
            if a & (1 << axis) == 0 {
                out[n] = (a, a | (1 << axis));
                n += 1;
            }
            a += 1;
        }
        axis += 1;
    }
    out
}

/// The cycles of one sign case: edge indices, cycle after cycle, `starts` marking where each
/// begins (a cell has at most four cycles of at most twelve edges in all).
#[derive(Clone, Copy, Debug, Default)]
pub struct CaseCycles {
    pub edges: [u8; 12],
    pub len: u8,
    pub starts: [u8; 5],
    pub count: u8,
}

impl CaseCycles {
    /// The edges of each cycle in order.
    pub fn cycles(&self) -> impl Iterator<Item = &[u8]> {
        (0..self.count as usize)
            .map(|c| &self.edges[self.starts[c] as usize..self.starts[c + 1] as usize])
    }
}

/// The table, indexed by the case: bit `k` set when corner `k` is inside.
pub fn case_cycles() -> &'static [CaseCycles; 256] {
    static TABLE: OnceLock<[CaseCycles; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|case| cycles_of(case as u8)))
}

fn corner_position(k: u8) -> [i32; 3] {
    [(k & 1) as i32, (k >> 1 & 1) as i32, (k >> 2 & 1) as i32]
}

fn cross(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [i32; 3], b: [i32; 3]) -> i32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// An edge's midpoint, doubled to stay in integers.
fn midpoint2(e: usize) -> [i32; 3] {
    let (a, b) = EDGES[e];
    let (pa, pb) = (corner_position(a), corner_position(b));
    [pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]
}

fn cycles_of(case: u8) -> CaseCycles {
    let inside = |k: u8| case >> k & 1 == 1;
    let crossing = |e: usize| inside(EDGES[e].0) != inside(EDGES[e].1);
    let mut next = [u8::MAX; 12];
    for axis in 0..3 {
        for side in 0..2u8 {
            let corners: Vec<u8> = (0..8u8).filter(|k| (k >> axis & 1) == side).collect();
            let on_face: Vec<usize> = (0..12)
                .filter(|&e| corners.contains(&EDGES[e].0) && corners.contains(&EDGES[e].1))
                .filter(|&e| crossing(e))
                .collect();
            let mut normal = [0; 3];
            normal[axis] = if side == 1 { 1 } else { -1 };
            // Doubled positions relative to the face centre keep `n` in integers.
            let centre2 = {
                let mut c = [1, 1, 1];
                c[axis] = 2 * side as i32;
                c
            };
            let rel2 = |k: u8| {
                let p = corner_position(k);
                [
                    2 * p[0] - centre2[0],
                    2 * p[1] - centre2[1],
                    2 * p[2] - centre2[2],
                ]
            };
            let pairs: Vec<(usize, usize, [i32; 3])> = match on_face.len() {
                0 => Vec::new(),
                2 => {
                    // n: from the inside corners' mean to the outside corners' mean.
                    let mut n = [0; 3];
                    for &k in &corners {
                        let r = rel2(k);
                        let s = if inside(k) { -1 } else { 1 };
                        for i in 0..3 {
                            n[i] += s * r[i];
                        }
                    }
                    vec![(on_face[0], on_face[1], n)]
                }
                _ => corners
                    .iter()
                    .filter(|&&k| inside(k))
                    .map(|&k| {
                        let mut around = on_face
                            .iter()
                            .filter(|&&e| EDGES[e].0 == k || EDGES[e].1 == k);
                        let (a, b) = (*around.next().unwrap(), *around.next().unwrap());
                        let r = rel2(k);
                        (a, b, [-r[0], -r[1], -r[2]])
                    })
                    .collect(),
            };
            for (a, b, n) in pairs {
                let d = cross(n, normal);
                let (ma, mb) = (midpoint2(a), midpoint2(b));
                let along = dot([mb[0] - ma[0], mb[1] - ma[1], mb[2] - ma[2]], d);
                let (from, to) = if along > 0 { (a, b) } else { (b, a) };
                next[from] = to as u8;
            }
        }
    }
    let mut out = CaseCycles::default();
    let mut seen = [false; 12];
    for start in 0..12 {
        if !crossing(start) || seen[start] {
            continue;
        }
        out.starts[out.count as usize] = out.len;
        let mut e = start;
        while !seen[e] {
            seen[e] = true;
            out.edges[out.len as usize] = e as u8;
            out.len += 1;
            e = next[e] as usize;
        }
        out.count += 1;
    }
    out.starts[out.count as usize] = out.len;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every crossing edge lies on exactly one cycle; consecutive edges share a face; the
    /// cycles of complementary cases are the same edge sets in the other direction except
    /// where the ambiguous faces' rule differs.
    #[test]
    fn cycles_cover_each_crossing_edge_once_and_close() {
        for (case, cc) in case_cycles().iter().enumerate() {
            let inside = |k: u8| case >> k & 1 == 1;
            let crossings = (0..12)
                .filter(|&e| inside(EDGES[e].0) != inside(EDGES[e].1))
                .count();
            assert_eq!(cc.len as usize, crossings, "case {case}");
            for cycle in cc.cycles() {
                assert!(cycle.len() >= 3, "case {case}: {cycle:?}");
                for i in 0..cycle.len() {
                    let (a, b) = (cycle[i] as usize, cycle[(i + 1) % cycle.len()] as usize);
                    let corners = |e: usize| [EDGES[e].0, EDGES[e].1];
                    let shared_face = (0..3).any(|axis| {
                        (0..2u8).any(|side| {
                            corners(a)
                                .iter()
                                .chain(corners(b).iter())
                                .all(|k| (k >> axis & 1) == side)
                        })
                    });
                    assert!(shared_face, "case {case}: edges {a} and {b}");
                }
            }
        }
    }

    /// One inside corner: a triangle whose winding faces away from the corner.
    #[test]
    fn a_cut_corner_faces_outward() {
        for k in 0..8u8 {
            let cc = case_cycles()[1 << k];
            assert_eq!(cc.count, 1);
            let cycle: Vec<[i32; 3]> = cc
                .cycles()
                .next()
                .unwrap()
                .iter()
                .map(|&e| midpoint2(e as usize))
                .collect();
            let sub = |a: [i32; 3], b: [i32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let n = cross(sub(cycle[1], cycle[0]), sub(cycle[2], cycle[0]));
            let corner = corner_position(k);
            let away = sub(cycle[0], [2 * corner[0], 2 * corner[1], 2 * corner[2]]);
            assert!(dot(n, away) > 0, "corner {k}");
        }
    }
}
