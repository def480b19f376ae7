//! Adaptive simplification of a closed, 2-manifold mesh: edges collapsed where the surface is
//! flat, within a stated bound. Every vertex carries the quadric of the planes of the original
//! triangles it stands for (Garland and Heckbert): its value at a point is the sum of the
//! squared distances to those planes, so a collapse whose vertex costs at most `tolerance`
//! squared leaves that vertex within `tolerance` of every one of them. A collapse is made only
//! where it keeps the mesh closed and 2-manifold (the link condition: the two ends share no
//! neighbour but the two opposite corners), turns no triangle by more than `MAX_TURN` and makes
//! none thinner than `MIN_QUALITY` (or than it was).
//!
//! The mesh is held as half-edges: half-edge `3t + i` runs from corner `i` of triangle `t` to
//! corner `i + 1`, and `twin` names the half-edge running the other way.

use super::extract::TriangleMesh;
use crate::mesh::triangle_distance::triangle_distance_squared;
use glam::{DMat3, DVec3};
use rayon::prelude::*;

/// The cosine of the largest turn a collapse may give a triangle's normal (about 37 degrees).
const MAX_TURN: f64 = 0.8;
/// The thinnest triangle a collapse may make (4 sqrt 3 area over the squared edges: 1 for an
/// equilateral one), unless the triangle was thinner before.
const MIN_QUALITY: f64 = 0.15;
/// The least cosine between a merged vertex's triangles and their mean direction: a fan seen
/// from one side has no triangles folded over each other.
const FAN_SIDE: f64 = 0.2;
/// The most triangles a vertex may gather, which keeps every check local.
const MAX_VALENCE: usize = 16;
/// Sweeps over the mesh at most: each takes about a third of what is left where all is flat.
const MAX_SWEEPS: u32 = 40;
/// A triangle removed by a collapse.
const GONE: u32 = u32::MAX;

/// What a simplification did.
#[derive(Clone, Copy, Debug, Default)]
pub struct Simplified {
    pub triangles_before: usize,
    pub collapses: usize,
}

/// Merges the flat regions of `mesh` (closed and 2-manifold) within `adaptivity` voxels of
/// `voxel_size`: collapses the edges whose merged vertex lies within half of it of the plane of
/// every original triangle it stands for, and whose collapses, summed along its making, moved
/// the surface around it by at most as much (each the farthest of the old ends from the new fan
/// and of the new vertex from the old). These bounds hold at the vertices; the other half
/// leaves room for the triangles between them, so that the mesh stays within `adaptivity` of
/// the one it was (measured, not proven: `tests/to_mesh.rs`).
pub fn simplify(mesh: &mut TriangleMesh, adaptivity: f64, voxel_size: f64) -> Simplified {
    let before = mesh.triangles.len();
    let tolerance = 0.5 * adaptivity * voxel_size;
    if tolerance <= 0.0 || before == 0 {
        return Simplified {
            triangles_before: before,
            collapses: 0,
        };
    }
    let mut state = Collapser::new(std::mem::take(mesh), tolerance);
    let mut collapses = 0;
    // Each sweep collapses edges whose neighbourhoods do not overlap, so the mesh coarsens
    // evenly instead of around whichever vertex the scan meets first.
    for sweep in 1..=MAX_SWEEPS {
        let made = state.sweep(sweep);
        collapses += made;
        if made == 0 {
            break;
        }
    }
    *mesh = state.into_mesh();
    Simplified {
        triangles_before: before,
        collapses,
    }
}

/// A symmetric 4x4 quadric over (x, y, z, 1): `a` the 3x3 part, `b` the last column, `c` the
/// corner.
#[derive(Clone, Copy, Default)]
struct Quadric {
    a: [f64; 6],
    b: DVec3,
    c: f64,
}

impl Quadric {
    /// The squared distance to the plane through `p` with unit normal `n`.
    fn plane(n: DVec3, p: DVec3) -> Quadric {
        let d = -n.dot(p);
        Quadric {
            a: [
                n.x * n.x,
                n.x * n.y,
                n.x * n.z,
                n.y * n.y,
                n.y * n.z,
                n.z * n.z,
            ],
            b: n * d,
            c: d * d,
        }
    }

    fn add(&mut self, o: &Quadric) {
        for (x, y) in self.a.iter_mut().zip(&o.a) {
            *x += y;
        }
        self.b += o.b;
        self.c += o.c;
    }

    fn sum(&self, o: &Quadric) -> Quadric {
        let mut q = *self;
        q.add(o);
        q
    }

    fn matrix(&self) -> DMat3 {
        let a = &self.a;
        DMat3::from_cols_array(&[a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]])
    }

    fn at(&self, p: DVec3) -> f64 {
        (p.dot(self.matrix() * p) + 2.0 * self.b.dot(p) + self.c).max(0.0)
    }

    /// The point of least value, where the planes pin one down (three well apart).
    fn minimum(&self) -> Option<DVec3> {
        let m = self.matrix();
        let scale = self.a[0] + self.a[3] + self.a[5];
        let det = m.determinant();
        // The determinant is the product of the eigenvalues: a flat or creased region has a
        // tiny one and no single best point.
        if det.is_nan() || det <= 1e-3 * scale * scale * scale {
            return None;
        }
        Some(m.inverse() * -self.b)
    }
}

struct Collapser {
    positions: Vec<DVec3>,
    corners: Vec<[u32; 3]>,
    twin: Vec<u32>,
    /// A half-edge leaving each vertex.
    leaving: Vec<u32>,
    quadrics: Vec<Quadric>,
    /// The last sweep whose collapse moved a vertex or one of its neighbours.
    touched: Vec<u32>,
    /// How far the collapses that made each vertex moved the surface around it, summed.
    moved: Vec<f64>,
    /// The most a vertex may move, by its planes and by its collapses.
    tolerance: f64,
}

fn next(h: u32) -> u32 {
    if h % 3 == 2 { h - 2 } else { h + 1 }
}

fn prev(h: u32) -> u32 {
    if h.is_multiple_of(3) { h + 2 } else { h - 1 }
}

fn normal(p: [DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0])
}

/// 4 sqrt 3 times the area over the sum of the squared edges: 1 for an equilateral triangle,
/// 0 for a flat one.
fn quality(p: [DVec3; 3]) -> f64 {
    let edges = (p[1] - p[0]).length_squared()
        + (p[2] - p[1]).length_squared()
        + (p[0] - p[2]).length_squared();
    if edges == 0.0 {
        return 0.0;
    }
    2.0 * 3f64.sqrt() * normal(p).length() / edges
}

impl Collapser {
    fn new(mesh: TriangleMesh, tolerance: f64) -> Collapser {
        let TriangleMesh {
            positions,
            triangles: corners,
        } = mesh;
        let n = positions.len();
        // The half-edges leaving each vertex, grouped by vertex, to find each one's twin.
        let mut start = vec![0u32; n + 1];
        for t in &corners {
            for &v in t {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut leaving_all = vec![0u32; corners.len() * 3];
        for (t, c) in corners.iter().enumerate() {
            for (i, &v) in c.iter().enumerate() {
                leaving_all[fill[v as usize] as usize] = (3 * t + i) as u32;
                fill[v as usize] += 1;
            }
        }
        let head = |h: u32| corners[h as usize / 3][(h as usize % 3 + 1) % 3];
        let tail = |h: u32| corners[h as usize / 3][h as usize % 3];
        let twin: Vec<u32> = (0..corners.len() as u32 * 3)
            .into_par_iter()
            .map(|h| {
                let (from, to) = (tail(h), head(h));
                let around =
                    &leaving_all[start[to as usize] as usize..start[to as usize + 1] as usize];
                *around
                    .iter()
                    .find(|&&o| head(o) == from)
                    .expect("a closed mesh: every edge has its reverse")
            })
            .collect();
        let leaving: Vec<u32> = (0..n).map(|v| leaving_all[start[v] as usize]).collect();
        drop(leaving_all);
        let mut quadrics = vec![Quadric::default(); n];
        for c in &corners {
            let p = c.map(|v| positions[v as usize]);
            let q = Quadric::plane(normal(p).normalize_or_zero(), p[0]);
            for &v in c {
                quadrics[v as usize].add(&q);
            }
        }
        Collapser {
            positions,
            corners,
            twin,
            leaving,
            quadrics,
            touched: vec![0; n],
            moved: vec![0.0; n],
            tolerance,
        }
    }

    fn tail(&self, h: u32) -> u32 {
        self.corners[h as usize / 3][h as usize % 3]
    }

    fn head(&self, h: u32) -> u32 {
        self.tail(next(h))
    }

    /// The half-edges leaving `v`, in turn around it.
    fn ring(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let first = self.leaving[v as usize];
        let mut h = first;
        loop {
            out.push(h);
            h = self.twin[prev(h) as usize];
            // A ring this long can merge with no other: it need not be walked further.
            if h == first || out.len() > MAX_VALENCE + 1 {
                break;
            }
        }
    }

    /// One sweep over every edge, collapsing those within the tolerance whose ends no other
    /// collapse of this sweep has touched; returns how many.
    fn sweep(&mut self, sweep: u32) -> usize {
        let (mut ring_u, mut ring_v) = (Vec::new(), Vec::new());
        let mut made = 0;
        for h in 0..self.corners.len() as u32 * 3 {
            if self.corners[h as usize / 3][0] == GONE || self.twin[h as usize] < h {
                continue;
            }
            let (u, v) = (self.tail(h), self.head(h));
            if self.touched[u as usize] == sweep || self.touched[v as usize] == sweep {
                continue;
            }
            if self.try_collapse(h, &mut ring_u, &mut ring_v) {
                for &o in ring_u.iter().chain(&ring_v) {
                    if self.corners[o as usize / 3][0] != GONE {
                        let w = self.head(o);
                        self.touched[w as usize] = sweep;
                    }
                }
                self.touched[u as usize] = sweep;
                made += 1;
            }
        }
        made
    }

    /// Collapses half-edge `h`'s head into its tail if the merged vertex can stand somewhere
    /// within the tolerance of its planes and of the surface it replaces that keeps the mesh
    /// sound.
    fn try_collapse(&mut self, h: u32, ring_u: &mut Vec<u32>, ring_v: &mut Vec<u32>) -> bool {
        let tolerance = self.tolerance;
        let bound = tolerance * tolerance;
        let (u, v) = (self.tail(h), self.head(h));
        let q = self.quadrics[u as usize].sum(&self.quadrics[v as usize]);
        let (pu, pv) = (self.positions[u as usize], self.positions[v as usize]);
        let mut candidates: Vec<(f64, DVec3)> =
            [Some(pu), Some(pv), Some(0.5 * (pu + pv)), q.minimum()]
                .into_iter()
                .flatten()
                .map(|p| (q.at(p), p))
                .filter(|(cost, _)| *cost <= bound)
                .collect();
        if candidates.is_empty() {
            return false;
        }
        self.ring(u, ring_u);
        self.ring(v, ring_v);
        if ring_u.len() + ring_v.len() - 4 > MAX_VALENCE || !self.link_holds(h, ring_u, ring_v) {
            return false;
        }
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let moved = self.moved[u as usize].max(self.moved[v as usize]);
        let Some((p, moved)) = candidates.iter().find_map(|&(_, p)| {
            let moved = moved + self.movement(h, p, ring_u, ring_v)?;
            (moved <= tolerance).then_some((p, moved))
        }) else {
            return false;
        };
        self.collapse(h, p, ring_v);
        self.quadrics[u as usize] = q;
        self.moved[u as usize] = moved;
        true
    }

    /// The link condition: the ends of `h` share only the two corners opposite it.
    fn link_holds(&self, h: u32, ring_u: &[u32], ring_v: &[u32]) -> bool {
        let a = self.head(next(h));
        let b = self.head(next(self.twin[h as usize]));
        if a == b {
            return false;
        }
        let shared = ring_u
            .iter()
            .map(|&o| self.head(o))
            .filter(|w| ring_v.iter().any(|&o| self.head(o) == *w))
            .count();
        shared == 2
    }

    /// How far the surface around the ends of `h` moves with both ends at `p` (the farthest of
    /// the old ends from the new fan and of `p` from the old one), if the triangles it keeps
    /// stay turned by at most `MAX_TURN`, no thinner than `MIN_QUALITY` (or than before) and
    /// form a fan that a plane sees from one side (so that no two of them overlap).
    fn movement(&self, h: u32, p: DVec3, ring_u: &[u32], ring_v: &[u32]) -> Option<f64> {
        let (t1, t2) = (h / 3, self.twin[h as usize] / 3);
        let (u, v) = (self.tail(h), self.head(h));
        let mut normals = [DVec3::ZERO; 2 * MAX_VALENCE];
        let mut new_fan = [[DVec3::ZERO; 3]; 2 * MAX_VALENCE];
        let (mut count, mut to_old) = (0, f64::INFINITY);
        for &o in ring_u.iter().chain(ring_v) {
            let t = o / 3;
            let c = self.corners[t as usize];
            let old = c.map(|w| self.positions[w as usize]);
            to_old = to_old.min(triangle_distance_squared(p, old));
            if t == t1 || t == t2 {
                continue;
            }
            let new = c.map(|w| {
                if w == u || w == v {
                    p
                } else {
                    self.positions[w as usize]
                }
            });
            let n_new = normal(new).normalize_or_zero();
            if n_new.dot(normal(old).normalize_or_zero()) < MAX_TURN
                || quality(new) < MIN_QUALITY.min(quality(old))
            {
                return None;
            }
            normals[count] = n_new;
            new_fan[count] = new;
            count += 1;
        }
        let axis = normals[..count].iter().sum::<DVec3>().normalize_or_zero();
        if normals[..count].iter().any(|n| n.dot(axis) < FAN_SIDE) {
            return None;
        }
        let from_new = |q: DVec3| {
            new_fan[..count]
                .iter()
                .map(|t| triangle_distance_squared(q, *t))
                .fold(f64::INFINITY, f64::min)
        };
        let farthest = to_old
            .max(from_new(self.positions[u as usize]))
            .max(from_new(self.positions[v as usize]));
        Some(farthest.sqrt())
    }

    /// Removes `h`'s two triangles and its head `v`, whose half-edges (`ring_v`) now leave its
    /// tail `u`, moved to `p`.
    fn collapse(&mut self, h: u32, p: DVec3, ring_v: &[u32]) {
        let g = self.twin[h as usize];
        let (u, v) = (self.tail(h), self.head(h));
        let (a, b) = (self.head(next(h)), self.head(next(g)));
        // The outer edges of each removed triangle become twins of each other.
        let join = |s: &mut Collapser, x: u32, y: u32| {
            let (tx, ty) = (s.twin[x as usize], s.twin[y as usize]);
            s.twin[tx as usize] = ty;
            s.twin[ty as usize] = tx;
        };
        let (u_to_a, a_to_v) = (self.twin[prev(h) as usize], self.twin[next(h) as usize]);
        let b_to_u = self.twin[next(g) as usize];
        join(self, next(h), prev(h));
        join(self, next(g), prev(g));
        for &o in ring_v {
            let t = o as usize / 3;
            if t as u32 != h / 3 && t as u32 != g / 3 {
                self.corners[t][o as usize % 3] = u;
            }
        }
        self.corners[h as usize / 3] = [GONE; 3];
        self.corners[g as usize / 3] = [GONE; 3];
        self.positions[u as usize] = p;
        self.leaving[u as usize] = u_to_a;
        self.leaving[a as usize] = a_to_v;
        self.leaving[b as usize] = b_to_u;
        self.leaving[v as usize] = GONE;
    }

    /// The remaining vertices and triangles, in their first order.
    fn into_mesh(self) -> TriangleMesh {
        let mut number = vec![GONE; self.positions.len()];
        let mut positions = Vec::new();
        for (v, p) in self.positions.iter().enumerate() {
            if self.leaving[v] != GONE {
                number[v] = positions.len() as u32;
                positions.push(*p);
            }
        }
        let triangles = self
            .corners
            .iter()
            .filter(|c| c[0] != GONE)
            .map(|c| c.map(|v| number[v as usize]))
            .collect();
        TriangleMesh {
            positions,
            triangles,
        }
    }
}
