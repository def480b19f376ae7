//! Closed-form Catmull-Clark limit position and tangent plane at a vertex whose faces are all
//! quads (after at most one subdivision step every vertex is such a vertex).
//!
//! Interior vertex of valence n, edge neighbours e_i and diagonal neighbours f_i in
//! counter-clockwise order:
//!   position = (n² v + 4 Σ e_i + Σ f_i) / (n (n + 5)),
//!   tangents t1 = Σ A cos(2πi/n) e_i + (cos(2πi/n) + cos(2π(i+1)/n)) f_i and t2 the same with
//!   i shifted by one quarter turn (sines), A = 1 + cos(2π/n) + cos(π/n) √(2 (9 + cos(2π/n))),
//!   so t1 x t2 points to the side from which the faces are counter-clockwise.
//! Boundary (crease) vertex with k faces, edges e_0..e_k counter-clockwise from the leading
//! boundary edge: position = (e_0 + 4 v + e_k) / 6; the tangent plane comes from the
//! eigenvectors of the local subdivision matrix (`boundary_tangent.rs`), as no closed-form
//! mask fits the standard crease rule there.

use super::boundary_tangent::boundary_tangent_plane;
use super::poly_mesh::PolyMesh;
use super::subdivide::boundary_neighbours;
use glam::DVec3;
use std::f64::consts::PI;

/// Limit position at vertex `v` (ring from `start`), and its unit normal where the masks
/// give one (all but interior vertices of valence 2); `None` asks the caller for another way.
pub(crate) fn vertex_limit(mesh: &PolyMesh, v: u32, start: u32) -> (DVec3, Option<DVec3>) {
    let p = mesh.points[v as usize];
    let (ring, closed) = mesh.ring(start);
    let edge = |h: u32| mesh.points[mesh.to(h) as usize];
    let diagonal = |h: u32| mesh.points[mesh.to(mesh.next(h)) as usize];
    if !closed {
        let (first, last) = boundary_neighbours(mesh, &ring);
        if ring.len() == 1 {
            let normal = (first - p).cross(last - p).try_normalize();
            return (p, normal);
        }
        let mut edges: Vec<DVec3> = ring.iter().map(|&h| edge(h)).collect();
        edges.push(last);
        let diagonals: Vec<DVec3> = ring.iter().map(|&h| diagonal(h)).collect();
        let (a, b) = boundary_tangent_plane(p, &edges, &diagonals);
        // Orient like the faces: along the boundary from e_k to e_0, then into the surface.
        let inner = edges[1..edges.len() - 1]
            .iter()
            .chain(&diagonals)
            .sum::<DVec3>()
            / (edges.len() - 2 + diagonals.len()) as f64;
        let reference = (first - last).cross(inner - p);
        let normal = a.cross(b);
        let normal = if normal.dot(reference) < 0.0 {
            -normal
        } else {
            normal
        };
        return ((first + 4.0 * p + last) / 6.0, normal.try_normalize());
    }
    let n = ring.len();
    let nf = n as f64;
    let mut sum = nf * nf * p;
    for &h in &ring {
        sum += 4.0 * edge(h) + diagonal(h);
    }
    let position = sum / (nf * (nf + 5.0));
    if n < 3 {
        return (position, None);
    }
    let a = 1.0
        + (2.0 * PI / nf).cos()
        + (PI / nf).cos() * (2.0 * (9.0 + (2.0 * PI / nf).cos())).sqrt();
    let mut t1 = DVec3::ZERO;
    let mut t2 = DVec3::ZERO;
    for (i, &h) in ring.iter().enumerate() {
        let angle = 2.0 * PI * i as f64 / nf;
        let next = 2.0 * PI * (i + 1) as f64 / nf;
        t1 += a * angle.cos() * edge(h) + (angle.cos() + next.cos()) * diagonal(h);
        t2 += a * angle.sin() * edge(h) + (angle.sin() + next.sin()) * diagonal(h);
    }
    let normal = t1.cross(t2);
    let len = normal.length();
    (position, (len > 0.0).then(|| normal / len))
}
