//! Closed-form Catmull-Clark limit position and tangent plane at a vertex whose faces are all
//! quads (after at most one subdivision step every vertex is such a vertex).
//!
//! Interior vertex of valence n, edge neighbours e_i and diagonal neighbours f_i in
//! counter-clockwise order:
//!   position = (n² v + 4 Σ e_i + Σ f_i) / (n (n + 5)),
//!   tangents t1 = Σ A cos(2πi/n) e_i + (cos(2πi/n) + cos(2π(i+1)/n)) f_i and t2 the same with
//!   i shifted by one quarter turn (sines), A = 1 + cos(2π/n) + cos(π/n) √(2 (9 + cos(2π/n))),
//!   so t1 x t2 points to the side from which the faces are counter-clockwise.
//! Crease vertex (two sharp edges, to a and b; a boundary is a crease): position =
//! (a + 4 v + b) / 6; on each side the tangent plane comes from the eigenvectors of that
//! side's subdivision matrix (`local_eigen.rs`: the sector of k faces between the sharp
//! edges, e_0..e_k counter-clockwise), as no closed-form mask fits the standard crease rule
//! there. Corner vertex (a sharp vertex, more than two sharp edges, a boundary vertex with one
//! face): position = v. Dart (one sharp edge ending at the vertex): position and tangent
//! plane from the eigenvectors of its subdivision matrix (`local_eigen.rs`).

use super::crease::{self, Rule, is_sharp};
use super::local_eigen::{crease_limit, dart_limit};
use super::poly_mesh::PolyMesh;
use super::subdivide::{crease_ends, edges_at, vertex_sharpness};
use glam::DVec3;
use std::f64::consts::PI;

/// Limit position at vertex `v` (ring from `start`) by its rule, and the unit normal on the
/// side of the face of outgoing half-edge `side` where the masks give one (not at interior
/// vertices of valence 2, corners with several faces or creases with a single face on that
/// side); `None`
/// asks the caller for another way. Semi-sharp edges count as sharp, as in OpenSubdiv's
/// `Limit()`: exact once no sharpness is left to run out.
pub(crate) fn vertex_limit(
    mesh: &PolyMesh,
    v: u32,
    start: u32,
    side: u32,
) -> (DVec3, Option<DVec3>) {
    let p = mesh.points[v as usize];
    let (ring, closed) = mesh.ring(start);
    let edges = edges_at(mesh, &ring, closed);
    let rule = crease::vertex_rule(
        vertex_sharpness(mesh, v as usize, &ring, closed),
        edges.iter().map(|e| e.0),
    );
    match rule {
        Rule::Smooth => return smooth_limit(mesh, p, &ring),
        Rule::Dart => return dart(mesh, p, &ring),
        Rule::Crease | Rule::Corner => {}
    }
    let sector = sector(mesh, &ring, closed, side);
    let (first, last) = (
        sector.edges[0],
        *sector.edges.last().expect("a sector has edges"),
    );
    let position = match rule {
        Rule::Crease => {
            let (a, b) = crease_ends(&edges, &is_sharp);
            (a + 4.0 * p + b) / 6.0
        }
        _ => p,
    };
    let faces = sector.diagonals.len();
    let normal = match (rule, faces) {
        (Rule::Corner, 1) => (first - p).cross(last - p).try_normalize(),
        (Rule::Crease, 2..) => {
            let (a, b) = crease_limit(p, &sector.edges, &sector.diagonals).tangents;
            // Orient like the faces: along the crease from e_k to e_0, then into the sector.
            let inner = sector.edges[1..sector.edges.len() - 1]
                .iter()
                .chain(&sector.diagonals)
                .sum::<DVec3>()
                / (sector.edges.len() - 2 + faces) as f64;
            let reference = (first - last).cross(inner - p);
            let normal = a.cross(b);
            let normal = if normal.dot(reference) < 0.0 {
                -normal
            } else {
                normal
            };
            normal.try_normalize()
        }
        _ => None,
    };
    (position, normal)
}

/// The faces around a vertex between the sharp edges on either side of one face: the edge
/// neighbours e_0..e_k counter-clockwise from the leading sharp edge, and the k diagonals.
struct Sector {
    edges: Vec<DVec3>,
    diagonals: Vec<DVec3>,
}

fn sector(mesh: &PolyMesh, ring: &[u32], closed: bool, side: u32) -> Sector {
    let n = ring.len();
    let (first, end) = sector_range(mesh, ring, closed, side);
    let mut edges: Vec<DVec3> = (first..end)
        .map(|i| mesh.points[mesh.to(ring[i % n]) as usize])
        .collect();
    edges.push(if end == n && !closed {
        mesh.points[mesh.from(mesh.prev(ring[n - 1])) as usize]
    } else {
        mesh.points[mesh.to(ring[end % n]) as usize]
    });
    let diagonals = (first..end)
        .map(|i| mesh.points[mesh.to(mesh.next(ring[i % n])) as usize])
        .collect();
    Sector { edges, diagonals }
}

/// The faces of a vertex's `ring` between the sharp edges on either side of the face of
/// outgoing half-edge `side`, as ring positions `first..end` (taken modulo the ring's length
/// for a closed ring; all of it when no edge is sharp).
pub(crate) fn sector_range(
    mesh: &PolyMesh,
    ring: &[u32],
    closed: bool,
    side: u32,
) -> (usize, usize) {
    let n = ring.len();
    let sharp = |i: usize| is_sharp(mesh.edge_sharpness(ring[i % n]));
    let at = ring.iter().position(|&h| h == side).unwrap_or(0);
    // An open ring starts and ends at its boundary edges, which are sharp.
    let before = (0..n).find(|&d| sharp(at + n - d)).unwrap_or(n);
    let after = (1..=n)
        .find(|&d| (!closed && at + d == n) || sharp(at + d))
        .unwrap_or(n);
    let first = (at + n - before) % n;
    (first, first + (before + after).min(n))
}

/// The limit at a dart (all faces quads) from its local subdivision matrix, oriented like
/// the faces.
fn dart(mesh: &PolyMesh, p: DVec3, ring: &[u32]) -> (DVec3, Option<DVec3>) {
    let n = ring.len();
    let sharp = (0..n)
        .find(|&i| is_sharp(mesh.edge_sharpness(ring[i])))
        .expect("a dart has a sharp edge");
    let turn: Vec<u32> = (0..n).map(|i| ring[(sharp + i) % n]).collect();
    let edges: Vec<DVec3> = turn
        .iter()
        .map(|&h| mesh.points[mesh.to(h) as usize])
        .collect();
    let diagonals: Vec<DVec3> = turn
        .iter()
        .map(|&h| mesh.points[mesh.to(mesh.next(h)) as usize])
        .collect();
    let limit = dart_limit(p, &edges, &diagonals);
    // The faces run counter-clockwise around the ring's fan of edges.
    let reference: DVec3 = (0..n)
        .map(|i| (edges[i] - p).cross(edges[(i + 1) % n] - p))
        .sum();
    let normal = limit.tangents.0.cross(limit.tangents.1);
    let normal = if normal.dot(reference) < 0.0 {
        -normal
    } else {
        normal
    };
    (limit.position, normal.try_normalize())
}

/// The closed-form masks of an interior vertex under the smooth rule.
fn smooth_limit(mesh: &PolyMesh, p: DVec3, ring: &[u32]) -> (DVec3, Option<DVec3>) {
    let edge = |h: u32| mesh.points[mesh.to(h) as usize];
    let diagonal = |h: u32| mesh.points[mesh.to(mesh.next(h)) as usize];
    let n = ring.len();
    let nf = n as f64;
    let mut sum = nf * nf * p;
    for &h in ring {
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
