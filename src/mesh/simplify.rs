//! Adaptive simplification of a closed, 2-manifold triangle mesh (a contoured surface's): edges collapsed where the surface is
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
//!
//! Each sweep hands every vertex to the cube of space (`CELL` voxels) it started in, and the
//! cubes run on all threads at once: a collapse is made only where every vertex around both
//! ends belongs to the cube making it, so no two threads ever touch one triangle or vertex.
//! Alternate sweeps shift the cubes by half, so that the edges along one sweep's cube faces
//! lie inside the next sweep's cubes. The result does not depend on the number of threads.

use super::triangle_distance::triangle_distance_squared;
use crate::contour::TriangleMesh;
use crate::error::Result;
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::cell::UnsafeCell;

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
/// The edge of the cubes of space that sweeps hand out to threads, in voxels.
const CELL: f64 = 32.0;
/// The memory the merge takes besides the mesh, per triangle: the twins (12 bytes), each
/// vertex's (about half a vertex per triangle) quadric, ring start, marks, cubes and place in
/// the sweep list (about 130 bytes), and while the twins are found, the half-edges by vertex
/// (12 bytes); measured on igea's level set at 1024, 9.2 M triangles: 670 MiB, 76 bytes each.
const BYTES_PER_TRIANGLE: u64 = 90;
/// A triangle removed by a collapse.
const GONE: u32 = u32::MAX;

/// What a simplification did.
#[derive(Clone, Copy, Debug, Default)]
pub struct Simplified {
    pub triangles_before: usize,
}

/// Merges the flat regions of `mesh` (closed and 2-manifold) within `adaptivity` voxels of
/// `voxel_size`: collapses the edges whose merged vertex lies within half of it of the plane of
/// every original triangle it stands for, and whose collapses, summed along its making, moved
/// the surface around it by at most as much (each the farthest of the old ends from the new fan
/// and of the new vertex from the old). These bounds hold at the vertices; the other half
/// leaves room for the triangles between them, so that the mesh stays within `adaptivity` of
/// the one it was (measured, not proven: `tests/to_mesh.rs`).
pub fn simplify(mesh: &mut TriangleMesh, adaptivity: f64, voxel_size: f64) -> Result<Simplified> {
    let before = mesh.triangles.len();
    let tolerance = 0.5 * adaptivity * voxel_size;
    if tolerance <= 0.0 || before == 0 {
        return Ok(Simplified {
            triangles_before: before,
        });
    }
    crate::system::check_fits(
        before as u64 * BYTES_PER_TRIANGLE,
        None,
        &format!("merging the flat regions of a mesh of {before} triangles"),
    )?;
    let cubes = [0.0, 0.5].map(|shift| Cubes::of(&mesh.positions, CELL * voxel_size, shift));
    let state = Collapser::new(std::mem::take(mesh), tolerance);
    // The vertices whose surroundings changed since they last found no edge to collapse.
    let mut pending: Vec<u32> = (0..state.leaving.0.len() as u32).collect();
    let mut idle = 0;
    for sweep in 1..=MAX_SWEEPS {
        if pending.is_empty() {
            break;
        }
        let cubes = &cubes[sweep as usize % 2];
        // Each vertex once, keyed by its cube in the high half, grouped by cube.
        let mut keyed: Vec<u64> = pending
            .par_iter()
            .map(|&v| (cubes.owner[v as usize] as u64) << 32 | v as u64)
            .collect();
        keyed.par_sort_unstable();
        keyed.dedup();
        let runs: Vec<&[u64]> = keyed.chunk_by(|a, b| a >> 32 == b >> 32).collect();
        let swept: Vec<(usize, Vec<u32>)> = runs
            .into_par_iter()
            .map_init(Rings::default, |rings, run| {
                state.sweep_cube(run, cubes, sweep, rings)
            })
            .collect();
        let made: usize = swept.iter().map(|s| s.0).sum();
        pending = swept.into_iter().flat_map(|s| s.1).collect();
        // Both placements of the cubes found nothing more.
        idle = if made == 0 { idle + 1 } else { 0 };
        if idle == 2 {
            break;
        }
    }
    *mesh = state.into_mesh();
    Ok(Simplified {
        triangles_before: before,
    })
}

/// The cube of space each vertex lies in.
struct Cubes {
    owner: Vec<u32>,
}

impl Cubes {
    /// Cubes of `edge` world units, their corners shifted by `shift` of an edge.
    fn of(positions: &[DVec3], edge: f64, shift: f64) -> Cubes {
        let lo = positions.iter().fold(DVec3::INFINITY, |a, p| a.min(*p)) - shift * edge;
        let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
        let dims = ((hi - lo) / edge).floor().as_uvec3() + 1;
        let owner = positions
            .par_iter()
            .map(|p| {
                let c = ((*p - lo) / edge).floor().as_uvec3().min(dims - 1);
                (c.x * dims.y + c.y) * dims.z + c.z
            })
            .collect();
        Cubes { owner }
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

/// Values that several threads read and write at once, each only the elements it owns.
///
/// Safety: during a sweep, the thread sweeping cube `k` reads and writes the vertices `k`
/// owns and the triangles (corners, twins) around them; it writes a triangle only when all its
/// corners are `k`'s, and reads a vertex's values only once it has seen that `k` owns it. A
/// triangle around a vertex of `k` has a corner of `k`, so no other thread writes it; no two
/// threads ever touch one element but to read it.
struct Shared<T>(Vec<UnsafeCell<T>>);

unsafe impl<T: Send> Sync for Shared<T> {}

impl<T: Copy> Shared<T> {
    fn new(values: Vec<T>) -> Shared<T> {
        Shared(values.into_iter().map(UnsafeCell::new).collect())
    }

    fn get(&self, i: usize) -> T {
        // SAFETY: see the type's note: no other thread writes element `i` meanwhile.
        unsafe { *self.0[i].get() }
    }

    fn set(&self, i: usize, value: T) {
        // SAFETY: see the type's note: this thread alone touches element `i` meanwhile.
        unsafe { *self.0[i].get() = value }
    }

    fn into_inner(self) -> Vec<T> {
        self.0.into_iter().map(UnsafeCell::into_inner).collect()
    }
}

struct Collapser {
    positions: Shared<DVec3>,
    corners: Shared<[u32; 3]>,
    twin: Shared<u32>,
    /// A half-edge leaving each vertex (`GONE` once the vertex is merged away).
    leaving: Shared<u32>,
    quadrics: Shared<Quadric>,
    /// The last sweep whose collapse moved a vertex or one of its neighbours.
    touched: Shared<u32>,
    /// How far the collapses that made each vertex moved the surface around it, summed.
    moved: Shared<f64>,
    /// The most a vertex may move, by its planes and by its collapses.
    tolerance: f64,
}

/// What came of trying an edge.
enum Collapse {
    Made,
    /// It would break a bound or the mesh.
    Refused,
    /// Vertices around it belong to another cube this sweep.
    Untried,
}

/// The half-edges leaving the two ends of an edge, reused from vertex to vertex.
#[derive(Default)]
struct Rings {
    u: Vec<u32>,
    v: Vec<u32>,
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
        drop(fill);
        let head = |h: u32| corners[h as usize / 3][(h as usize % 3 + 1) % 3];
        let tail = |h: u32| corners[h as usize / 3][h as usize % 3];
        let around =
            |v: u32| &leaving_all[start[v as usize] as usize..start[v as usize + 1] as usize];
        let twin: Vec<u32> = (0..corners.len() as u32 * 3)
            .into_par_iter()
            .map(|h| {
                let (from, to) = (tail(h), head(h));
                *around(to)
                    .iter()
                    .find(|&&o| head(o) == from)
                    .expect("a closed mesh: every edge has its reverse")
            })
            .collect();
        let plane = |t: u32| {
            let p = corners[t as usize].map(|v| positions[v as usize]);
            Quadric::plane(normal(p).normalize_or_zero(), p[0])
        };
        let (leaving, quadrics): (Vec<u32>, Vec<Quadric>) = (0..n as u32)
            .into_par_iter()
            .map(|v| {
                let mut q = Quadric::default();
                for &h in around(v) {
                    q.add(&plane(h / 3));
                }
                (around(v)[0], q)
            })
            .unzip();
        drop(leaving_all);
        Collapser {
            positions: Shared::new(positions),
            corners: Shared::new(corners),
            twin: Shared::new(twin),
            leaving: Shared::new(leaving),
            quadrics: Shared::new(quadrics),
            touched: Shared::new(vec![0; n]),
            moved: Shared::new(vec![0.0; n]),
            tolerance,
        }
    }

    fn tail(&self, h: u32) -> u32 {
        self.corners.get(h as usize / 3)[h as usize % 3]
    }

    fn head(&self, h: u32) -> u32 {
        self.tail(next(h))
    }

    fn position(&self, v: u32) -> DVec3 {
        self.positions.get(v as usize)
    }

    /// The half-edges leaving `v`, in turn around it.
    fn ring(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let first = self.leaving.get(v as usize);
        let mut h = first;
        loop {
            out.push(h);
            h = self.twin.get(prev(h) as usize);
            // A ring this long can merge with no other: it need not be walked further.
            if h == first || out.len() > MAX_VALENCE + 1 {
                break;
            }
        }
    }

    /// Sweeps `vertices` (keyed by their cube, all one): collapses into each the first edge around it that
    /// stays within the tolerance, where no other collapse of this sweep has touched either
    /// end. Returns how many it made, and the vertices to sweep again: those around each
    /// collapse and those with an edge this sweep could not try.
    fn sweep_cube(
        &self,
        vertices: &[u64],
        cubes: &Cubes,
        sweep: u32,
        rings: &mut Rings,
    ) -> (usize, Vec<u32>) {
        let k = (vertices[0] >> 32) as u32;
        let mut made = 0;
        let mut again = Vec::new();
        for u in vertices.iter().map(|&key| key as u32) {
            if self.leaving.get(u as usize) == GONE {
                continue;
            }
            if self.touched.get(u as usize) == sweep {
                again.push(u);
                continue;
            }
            self.ring(u, &mut rings.u);
            let mut untried = false;
            for i in 0..rings.u.len() {
                let h = rings.u[i];
                let v = self.head(h);
                if cubes.owner[v as usize] != k || self.touched.get(v as usize) == sweep {
                    untried = true;
                    continue;
                }
                match self.try_collapse(h, cubes, k, rings) {
                    Collapse::Made => {
                        for &o in rings.u.iter().chain(&rings.v) {
                            if self.corners.get(o as usize / 3)[0] != GONE {
                                again.push(self.head(o));
                            }
                        }
                        self.touched.set(u as usize, sweep);
                        again.push(u);
                        made += 1;
                        untried = false;
                        break;
                    }
                    Collapse::Untried => untried = true,
                    Collapse::Refused => {}
                }
            }
            if untried {
                again.push(u);
            }
        }
        (made, again)
    }

    /// Collapses half-edge `h`'s head into its tail (both of cube `k`; `rings.u` the tail's
    /// ring) if the merged vertex
    /// can stand somewhere within the tolerance of its planes and of the surface it replaces
    /// that keeps the mesh sound; leaves it untried unless every vertex around both ends is
    /// `k`'s.
    fn try_collapse(&self, h: u32, cubes: &Cubes, k: u32, rings: &mut Rings) -> Collapse {
        let tolerance = self.tolerance;
        let bound = tolerance * tolerance;
        let (u, v) = (self.tail(h), self.head(h));
        let q = self
            .quadrics
            .get(u as usize)
            .sum(&self.quadrics.get(v as usize));
        let (pu, pv) = (self.position(u), self.position(v));
        // The places within the bound, on the stack: this runs for every edge tried.
        let mut within = [(0.0, DVec3::ZERO); 4];
        let mut count = 0;
        for p in [Some(pu), Some(pv), Some(0.5 * (pu + pv)), q.minimum()]
            .into_iter()
            .flatten()
        {
            let cost = q.at(p);
            if cost <= bound {
                within[count] = (cost, p);
                count += 1;
            }
        }
        let candidates = &mut within[..count];
        if candidates.is_empty() {
            return Collapse::Refused;
        }
        self.ring(v, &mut rings.v);
        let (ring_u, ring_v) = (&rings.u, &rings.v);
        if ring_u.len() + ring_v.len() - 4 > MAX_VALENCE {
            return Collapse::Refused;
        }
        if ring_u
            .iter()
            .chain(ring_v)
            .any(|&o| cubes.owner[self.head(o) as usize] != k)
        {
            return Collapse::Untried;
        }
        if !self.link_holds(h, ring_u, ring_v) {
            return Collapse::Refused;
        }
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let moved = self.moved.get(u as usize).max(self.moved.get(v as usize));
        let Some((p, moved)) = candidates.iter().find_map(|&(_, p)| {
            let moved = moved + self.movement(h, p, ring_u, ring_v)?;
            (moved <= tolerance).then_some((p, moved))
        }) else {
            return Collapse::Refused;
        };
        self.collapse(h, p, ring_v);
        self.quadrics.set(u as usize, q);
        self.moved.set(u as usize, moved);
        Collapse::Made
    }

    /// The link condition: the ends of `h` share only the two corners opposite it.
    fn link_holds(&self, h: u32, ring_u: &[u32], ring_v: &[u32]) -> bool {
        let a = self.head(next(h));
        let b = self.head(next(self.twin.get(h as usize)));
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
        let (t1, t2) = (h / 3, self.twin.get(h as usize) / 3);
        let (u, v) = (self.tail(h), self.head(h));
        let mut normals = [DVec3::ZERO; 2 * MAX_VALENCE];
        let mut new_fan = [[DVec3::ZERO; 3]; 2 * MAX_VALENCE];
        let mut count = 0;
        for &o in ring_u.iter().chain(ring_v) {
            let t = o / 3;
            if t == t1 || t == t2 {
                continue;
            }
            let c = self.corners.get(t as usize);
            let old = c.map(|w| self.position(w));
            let new = c.map(|w| {
                if w == u || w == v {
                    p
                } else {
                    self.position(w)
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
        // An end left where it was is a corner of both fans: it moves nothing.
        let (pu, pv) = (self.position(u), self.position(v));
        let to_old = if p == pu || p == pv {
            0.0
        } else {
            ring_u
                .iter()
                .chain(ring_v)
                .map(|&o| {
                    let c = self.corners.get(o as usize / 3);
                    triangle_distance_squared(p, c.map(|w| self.position(w)))
                })
                .fold(f64::INFINITY, f64::min)
        };
        let from_new = |q: DVec3| {
            new_fan[..count]
                .iter()
                .map(|t| triangle_distance_squared(q, *t))
                .fold(f64::INFINITY, f64::min)
        };
        let from_u = if p == pu { 0.0 } else { from_new(pu) };
        let from_v = if p == pv { 0.0 } else { from_new(pv) };
        let farthest = to_old.max(from_u).max(from_v);
        Some(farthest.sqrt())
    }

    /// Removes `h`'s two triangles and its head `v`, whose half-edges (`ring_v`) now leave its
    /// tail `u`, moved to `p`.
    fn collapse(&self, h: u32, p: DVec3, ring_v: &[u32]) {
        let g = self.twin.get(h as usize);
        let (u, v) = (self.tail(h), self.head(h));
        let (a, b) = (self.head(next(h)), self.head(next(g)));
        // The outer edges of each removed triangle become twins of each other.
        let join = |x: u32, y: u32| {
            let (tx, ty) = (self.twin.get(x as usize), self.twin.get(y as usize));
            self.twin.set(tx as usize, ty);
            self.twin.set(ty as usize, tx);
        };
        let (u_to_a, a_to_v) = (
            self.twin.get(prev(h) as usize),
            self.twin.get(next(h) as usize),
        );
        let b_to_u = self.twin.get(next(g) as usize);
        join(next(h), prev(h));
        join(next(g), prev(g));
        for &o in ring_v {
            let t = o as usize / 3;
            if t as u32 != h / 3 && t as u32 != g / 3 {
                let mut c = self.corners.get(t);
                c[o as usize % 3] = u;
                self.corners.set(t, c);
            }
        }
        self.corners.set(h as usize / 3, [GONE; 3]);
        self.corners.set(g as usize / 3, [GONE; 3]);
        self.positions.set(u as usize, p);
        self.leaving.set(u as usize, u_to_a);
        self.leaving.set(a as usize, a_to_v);
        self.leaving.set(b as usize, b_to_u);
        self.leaving.set(v as usize, GONE);
    }

    /// The remaining vertices and triangles, in their first order.
    fn into_mesh(self) -> TriangleMesh {
        let leaving = self.leaving.into_inner();
        let mut number = vec![GONE; leaving.len()];
        let mut positions = Vec::new();
        for (v, p) in self.positions.into_inner().into_iter().enumerate() {
            if leaving[v] != GONE {
                number[v] = positions.len() as u32;
                positions.push(p);
            }
        }
        let triangles = self
            .corners
            .into_inner()
            .into_iter()
            .filter(|c| c[0] != GONE)
            .map(|c| c.map(|v| number[v as usize]))
            .collect();
        TriangleMesh {
            positions,
            triangles,
        }
    }
}
