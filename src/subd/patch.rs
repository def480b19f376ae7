//! One quad patch of the limit surface, evaluated exactly: a bicubic B-spline when the quad is
//! regular; otherwise its 1-ring is subdivided locally, lazily and once, into four child
//! patches (a quadtree that stays irregular only towards extraordinary vertices), and exactly
//! at an extraordinary vertex the closed-form limit masks apply.
//!
//! A patch's parameter square has corner k of its quad at (0,0), (1,0), (1,1), (0,1). The
//! children are ordered by quadrant, each with its corners listed so that its own parameters
//! are `(2u - i, 2v - j)` in quadrant `(i, j)`.

use super::bicubic::Bicubic;
use super::crease::{self, Rule, is_infinite, is_sharp};
use super::limit_masks::{sector_range, vertex_limit};
use super::poly_mesh::PolyMesh;
use super::subdivide::{edges_at, subdivide, vertex_sharpness};
use glam::DVec3;
use std::sync::OnceLock;

/// A point of the limit surface with its parametric derivatives and unit normal. At an
/// extraordinary vertex the parametric derivatives degenerate; there `du`, `dv` are zero and
/// the normal comes from the limit masks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitSample {
    pub position: DVec3,
    pub du: DVec3,
    pub dv: DVec3,
    pub normal: DVec3,
}

// Regular patches are the vast majority and are evaluated millions of times: kept inline.
#[allow(clippy::large_enum_variant)]
pub(crate) enum PatchNode {
    Regular(Bicubic),
    Irregular(Box<IrregularPatch>),
}

pub(crate) struct IrregularPatch {
    /// Face 0 and every face sharing a vertex with it.
    net: PolyMesh,
    /// How each corner of face 0 behaves (the quadtree never ends at an extraordinary one).
    corners: [CornerKind; 4],
    children: OnceLock<Box<[PatchNode; 4]>>,
}

/// Rotation that lists the child at corner k starting with its quadrant's (0,0) corner.
const CHILD_ROTATION: [usize; 4] = [0, 3, 2, 1];
/// Quadrant (i, j) of the corner k of a quad.
const CORNER_QUADRANT: [(usize, usize); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];

/// Parameter square of a corner: a point exactly there is that corner.
fn corner_at(u: f64, v: f64) -> Option<usize> {
    match (u, v) {
        (0.0, 0.0) => Some(0),
        (1.0, 0.0) => Some(1),
        (1.0, 1.0) => Some(2),
        (0.0, 1.0) => Some(3),
        _ => None,
    }
}

impl PatchNode {
    /// The patch of face 0 of `net`, a quad whose corners are complete in `net`: a bicubic
    /// B-spline when every corner is regular (infinitely sharp edges of face 0 act as
    /// boundaries), otherwise a node of the quadtree.
    pub fn new(net: PolyMesh) -> PatchNode {
        let outgoing = net.outgoing();
        let corners: [CornerKind; 4] = std::array::from_fn(|k| {
            let start = outgoing[net.from(k as u32) as usize];
            corner_kind(&net, start, k as u32)
        });
        if corners.iter().all(|&c| c == CornerKind::Regular) {
            PatchNode::Regular(gather_bicubic(&net))
        } else {
            PatchNode::Irregular(Box::new(IrregularPatch {
                net,
                corners,
                children: OnceLock::new(),
            }))
        }
    }

    /// Position, derivatives and unit normal at `(u, v)` in `[0,1]²`.
    pub fn eval(&self, u: f64, v: f64) -> LimitSample {
        let mut node = self;
        let (mut u, mut v, mut scale) = (u, v, 1.0);
        loop {
            match node {
                PatchNode::Regular(b) => {
                    let (position, du, dv) = b.eval(u, v);
                    let normal = du.cross(dv).normalize_or_zero();
                    return LimitSample {
                        position,
                        du: du * scale,
                        dv: dv * scale,
                        normal,
                    };
                }
                PatchNode::Irregular(p) => {
                    if let Some(k) =
                        corner_at(u, v).filter(|&k| p.corners[k] == CornerKind::Extraordinary)
                        && let Some(sample) = p.corner_limit(k)
                    {
                        return sample;
                    }
                    let i = usize::from(u >= 0.5);
                    let j = usize::from(v >= 0.5);
                    node = &p.children()[quadrant_index(i, j)];
                    u = 2.0 * u - i as f64;
                    v = 2.0 * v - j as f64;
                    scale *= 2.0;
                }
            }
        }
    }

    /// Whether the patch is one polynomial over `[u0,u1] x [v0,v1]`: the square lies within
    /// one bicubic leaf of the quadtree (never where it touches an extraordinary corner, nor
    /// across the finer pieces along a semi-sharp crease).
    pub fn polynomial_on(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> bool {
        match self {
            PatchNode::Regular(_) => true,
            PatchNode::Irregular(p) => {
                let i = usize::from(u0 >= 0.5);
                let j = usize::from(v0 >= 0.5);
                let within =
                    |lo: f64, hi: f64, k: usize| if k == 0 { hi <= 0.5 } else { lo >= 0.5 };
                if !(within(u0, u1, i) && within(v0, v1, j)) {
                    return false;
                }
                p.children()[quadrant_index(i, j)].polynomial_on(
                    2.0 * u0 - i as f64,
                    2.0 * u1 - i as f64,
                    2.0 * v0 - j as f64,
                    2.0 * v1 - j as f64,
                )
            }
        }
    }

    /// Whether triangles spanning any points of the piece over the square `[u0,u1] x [v0,v1]`
    /// lie within `tolerance` of the piece at the same parameters. On a bicubic leaf, whose own
    /// parameters give the square a side `h`, linear interpolation is within
    /// `h^2/2 (|S_uu| + 2 |S_uv| + |S_vv|)` (Taylor's remainder; the linear terms cancel in a
    /// convex combination); a square spanning several leaves of the quadtree (towards an
    /// extraordinary corner) passes when its box, which holds the piece and so the triangles,
    /// has a diagonal below `tolerance`.
    pub fn within_tolerance(&self, u0: f64, u1: f64, v0: f64, v1: f64, tolerance: f64) -> bool {
        match self {
            PatchNode::Regular(b) => {
                let side = (u1 - u0).max(v1 - v0);
                0.5 * side * side * b.second_derivative_bound() < tolerance
            }
            PatchNode::Irregular(p) => {
                let i = usize::from(u0 >= 0.5);
                let j = usize::from(v0 >= 0.5);
                let within =
                    |lo: f64, hi: f64, k: usize| if k == 0 { hi <= 0.5 } else { lo >= 0.5 };
                if within(u0, u1, i) && within(v0, v1, j) {
                    return p.children()[quadrant_index(i, j)].within_tolerance(
                        2.0 * u0 - i as f64,
                        2.0 * u1 - i as f64,
                        2.0 * v0 - j as f64,
                        2.0 * v1 - j as f64,
                        tolerance,
                    );
                }
                let (lo, hi) = self.bound(u0, u1, v0, v1);
                (hi - lo).length() < tolerance
            }
        }
    }

    /// A box containing the piece of the patch over `[u0,u1] x [v0,v1]`.
    pub fn bound(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> (DVec3, DVec3) {
        match self {
            PatchNode::Regular(b) => b.bound(u0, u1, v0, v1),
            PatchNode::Irregular(p) => {
                if u0 <= 0.0 && v0 <= 0.0 && u1 >= 1.0 && v1 >= 1.0 {
                    // The piece is a convex combination of its 1-ring (all weights >= 0).
                    return p.net.points.iter().fold(
                        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                        |(lo, hi), &q| (lo.min(q), hi.max(q)),
                    );
                }
                let mut lo = DVec3::splat(f64::INFINITY);
                let mut hi = DVec3::splat(f64::NEG_INFINITY);
                for (i, j) in CORNER_QUADRANT {
                    let (qu0, qv0) = (i as f64 * 0.5, j as f64 * 0.5);
                    let (a0, a1) = (u0.max(qu0), u1.min(qu0 + 0.5));
                    let (b0, b1) = (v0.max(qv0), v1.min(qv0 + 0.5));
                    if a0 >= a1 || b0 >= b1 {
                        continue;
                    }
                    let child = &p.children()[quadrant_index(i, j)];
                    let (l, h) = child.bound(
                        2.0 * a0 - i as f64,
                        2.0 * a1 - i as f64,
                        2.0 * b0 - j as f64,
                        2.0 * b1 - j as f64,
                    );
                    lo = lo.min(l);
                    hi = hi.max(h);
                }
                (lo, hi)
            }
        }
    }
}

#[inline]
fn quadrant_index(i: usize, j: usize) -> usize {
    match (i, j) {
        (0, 0) => 0,
        (1, 0) => 1,
        (1, 1) => 2,
        _ => 3,
    }
}

impl IrregularPatch {
    fn children(&self) -> &[PatchNode; 4] {
        self.children.get_or_init(|| {
            let complete: Vec<bool> = (0..self.net.points.len() as u32)
                .map(|v| self.net.face(0).contains(&v))
                .collect();
            let child = subdivide(&self.net, &complete);
            let outgoing = child.outgoing();
            Box::new(std::array::from_fn(|q| {
                // Quadrant q holds the child at corner q of face 0 (CORNER_QUADRANT order).
                let faces = child.one_ring_faces(q, &outgoing);
                PatchNode::new(child.extract_rotated(&faces, CHILD_ROTATION[q]))
            }))
        })
    }

    /// The exact limit at extraordinary corner k, when its faces are all quads and the masks
    /// give the tangent plane; `None` sends the caller one level down.
    fn corner_limit(&self, k: usize) -> Option<LimitSample> {
        let outgoing = self.net.outgoing();
        let v = self.net.from(k as u32);
        let start = outgoing[v as usize];
        let (ring, _) = self.net.ring(start);
        if !ring
            .iter()
            .all(|&h| self.net.face_len(self.net.face_of[h as usize] as usize) == 4)
        {
            return None;
        }
        let (position, normal) = vertex_limit(&self.net, v, start, k as u32);
        let normal = normal.unwrap_or_else(|| self.normal_near_corner(k));
        Some(LimitSample {
            position,
            du: DVec3::ZERO,
            dv: DVec3::ZERO,
            normal,
        })
    }

    /// Where no mask gives the tangent plane (boundary vertices, interior valence 2): the
    /// normal of the limit surface 2^-40 away from the corner along the diagonal, which the
    /// normal approaches continuously.
    fn normal_near_corner(&self, k: usize) -> DVec3 {
        const EPS: f64 = 1.0 / (1u64 << 40) as f64;
        let (i, j) = CORNER_QUADRANT[k];
        let u = if i == 0 { EPS } else { 1.0 - EPS };
        let v = if j == 0 { EPS } else { 1.0 - EPS };
        let (ci, cj) = (usize::from(u >= 0.5), usize::from(v >= 0.5));
        self.children()[quadrant_index(ci, cj)]
            .eval(2.0 * u - ci as f64, 2.0 * v - cj as f64)
            .normal
    }
}

/// How the limit surface behaves at a corner of face 0, seen from face 0's side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CornerKind {
    /// As a bicubic B-spline: an interior vertex of 4 quads without sharp edges, a crease
    /// with two quads on this side, or a corner with face 0 alone on this side.
    Regular,
    /// Semi-sharp edges or a semi-sharp vertex: regular or extraordinary once subdivision has
    /// used up their sharpness, after finitely many levels.
    Softening,
    /// Irregular at every level (valence, darts, creases that turn): the quadtree never ends
    /// there and the limit masks give the exact corner.
    Extraordinary,
}

/// The corner whose ring starts at `start`, for the face of outgoing half-edge `side`.
fn corner_kind(net: &PolyMesh, start: u32, side: u32) -> CornerKind {
    let (ring, closed) = net.ring(start);
    let v = net.from(start) as usize;
    let edges = edges_at(net, &ring, closed);
    let sharpness = vertex_sharpness(net, v, &ring, closed);
    let softening = |s: f32| is_sharp(s) && !is_infinite(s);
    if softening(sharpness) || edges.iter().any(|e| softening(e.0)) {
        return CornerKind::Softening;
    }
    let quads = ring
        .iter()
        .all(|&h| net.face_len(net.face_of[h as usize] as usize) == 4);
    let (first, end) = sector_range(net, &ring, closed, side);
    let sector = end - first;
    let rule = crease::vertex_rule(sharpness, edges.iter().map(|e| e.0));
    let regular = quads
        && match rule {
            Rule::Smooth => closed && ring.len() == 4,
            Rule::Dart => false,
            Rule::Crease => sector == 2,
            Rule::Corner => sector == 1,
        };
    if regular {
        CornerKind::Regular
    } else {
        CornerKind::Extraordinary
    }
}

/// The 16 control points of a regular quad (face 0 of `net`), with the phantom points of
/// boundary patches extrapolated so the limit interpolates the boundary curve (2a - b across a
/// boundary edge or an infinitely sharp crease; the tensor product of that at a corner).
fn gather_bicubic(net: &PolyMesh) -> Bicubic {
    const CORNER: [(i32, i32); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];
    const ALONG: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];
    let mut grid: [[Option<DVec3>; 4]; 4] = [[None; 4]; 4];
    let mut put =
        |(i, j): (i32, i32), v: u32| grid[i as usize][j as usize] = Some(net.points[v as usize]);
    for k in 0..4usize {
        let h = k as u32;
        let c = CORNER[k];
        let a = ALONG[k];
        // Outward across edge k, and backwards along it.
        let out = (a.1, -a.0);
        put(c, net.from(h));
        if let Some(t) = net.twin(h) {
            let x_half = net.next(t);
            put((c.0 + out.0, c.1 + out.1), net.to(x_half));
            if let Some(t2) = net.twin(x_half) {
                let to_y = net.next(t2);
                put((c.0 - a.0, c.1 - a.1), net.to(to_y));
                put(
                    (c.0 + out.0 - a.0, c.1 + out.1 - a.1),
                    net.to(net.next(to_y)),
                );
            }
        }
        if let Some(t) = net.twin(net.prev(h)) {
            put((c.0 - a.0, c.1 - a.1), net.to(net.next(net.next(t))));
        }
    }
    let boundary = |k: usize| net.twin(k as u32).is_none() || is_infinite(net.sharpness[k]);
    let mut p = grid;
    let get =
        |p: &[[Option<DVec3>; 4]; 4], i: usize, j: usize| p[i][j].expect("inner control point");
    // Middle points of boundary sides: reflect the inner row through the face's edge.
    for m in 1..3 {
        if boundary(0) {
            p[m][0] = Some(2.0 * get(&p, m, 1) - get(&p, m, 2));
        }
        if boundary(2) {
            p[m][3] = Some(2.0 * get(&p, m, 2) - get(&p, m, 1));
        }
        if boundary(3) {
            p[0][m] = Some(2.0 * get(&p, 1, m) - get(&p, 2, m));
        }
        if boundary(1) {
            p[3][m] = Some(2.0 * get(&p, 2, m) - get(&p, 1, m));
        }
    }
    // Corners: extrapolate along whichever side is a boundary (both agree at a corner vertex).
    for (i, j, di, dj, side_u, side_v) in [
        (0, 0, 1i32, 1i32, 3, 0),
        (3, 0, -1, 1, 1, 0),
        (3, 3, -1, -1, 1, 2),
        (0, 3, 1, -1, 3, 2),
    ] {
        let step = |a: usize, d: i32| (a as i32 + d) as usize;
        if boundary(side_u) {
            p[i][j] = Some(2.0 * get(&p, step(i, di), j) - get(&p, step(i, 2 * di), j));
        } else if boundary(side_v) {
            p[i][j] = Some(2.0 * get(&p, i, step(j, dj)) - get(&p, i, step(j, 2 * dj)));
        }
    }
    Bicubic {
        p: p.map(|row| row.map(|q| q.expect("a regular quad has all 16 control points"))),
    }
}
