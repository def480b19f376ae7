//! One Catmull-Clark subdivision step of a (local) polygon mesh, with OpenSubdiv's default
//! boundary rule VTX_BOUNDARY_EDGE_AND_CORNER: boundary edges are infinitely sharp creases and
//! a boundary vertex with a single face is a sharp corner.
//!
//! Only vertices whose every face is present (`complete`) get a vertex point, so a local
//! neighbourhood can be refined without the rest of the mesh: the child faces kept are those at
//! complete corners, which is all that the 1-ring of any child of a complete face needs.

use super::poly_mesh::{NONE, PolyMesh};
use glam::DVec3;
use rustc_hash::FxHashSet;

/// The refined mesh; child face `k` is the child of parent face 0 at its corner `k`
/// (`[vertex point, edge point of edge k, face point, edge point of edge k-1]`), which
/// requires all corners of face 0 to be complete.
pub(crate) fn subdivide(mesh: &PolyMesh, complete: &[bool]) -> PolyMesh {
    let face_points: Vec<DVec3> = (0..mesh.face_count())
        .map(|f| {
            let face = mesh.face(f);
            face.iter().map(|&v| mesh.points[v as usize]).sum::<DVec3>() / face.len() as f64
        })
        .collect();

    let mut points = Vec::with_capacity(mesh.points.len() + mesh.verts.len());
    let mut vertex_point = vec![NONE; mesh.points.len()];
    let outgoing = mesh.outgoing();
    for (v, &start) in outgoing.iter().enumerate() {
        if complete[v] && start != NONE {
            vertex_point[v] = points.len() as u32;
            points.push(vertex_rule(mesh, v, start, &face_points));
        }
    }

    let mut edge_point = vec![NONE; mesh.verts.len()];
    for h in 0..mesh.verts.len() as u32 {
        let (a, b) = (mesh.from(h), mesh.to(h));
        if edge_point[h as usize] != NONE || !(complete[a as usize] || complete[b as usize]) {
            continue;
        }
        let (pa, pb) = (mesh.points[a as usize], mesh.points[b as usize]);
        let id = points.len() as u32;
        match mesh.twin(h) {
            Some(t) => {
                let (fa, fb) = (mesh.face_of[h as usize], mesh.face_of[t as usize]);
                points.push((pa + pb + face_points[fa as usize] + face_points[fb as usize]) / 4.0);
                edge_point[t as usize] = id;
            }
            None => points.push((pa + pb) / 2.0),
        }
        edge_point[h as usize] = id;
    }

    let face_base = points.len() as u32;
    points.extend_from_slice(&face_points);

    let mut faces: Vec<[u32; 4]> = Vec::new();
    let mut boundary_edges = FxHashSet::default();
    for f in 0..mesh.face_count() {
        let start = mesh.face_starts[f];
        let end = mesh.face_starts[f + 1];
        for h in start..end {
            let v = mesh.from(h) as usize;
            if vertex_point[v] == NONE {
                continue;
            }
            let before = mesh.prev(h);
            let child = [
                vertex_point[v],
                edge_point[h as usize],
                face_base + f as u32,
                edge_point[before as usize],
            ];
            if mesh.boundary[h as usize] {
                boundary_edges.insert((child[0], child[1]));
            }
            if mesh.boundary[before as usize] {
                boundary_edges.insert((child[3], child[0]));
            }
            faces.push(child);
        }
    }
    let refs: Vec<&[u32]> = faces.iter().map(|f| f.as_slice()).collect();
    PolyMesh::build(points, &refs, |a, b| boundary_edges.contains(&(a, b)))
        .expect("refining a valid mesh gives a valid mesh")
}

/// The new position of a complete vertex.
fn vertex_rule(mesh: &PolyMesh, v: usize, start: u32, face_points: &[DVec3]) -> DVec3 {
    let p = mesh.points[v];
    let (ring, closed) = mesh.ring(start);
    if closed {
        let n = ring.len() as f64;
        let mut sum = DVec3::ZERO;
        for &h in &ring {
            sum +=
                mesh.points[mesh.to(h) as usize] + face_points[mesh.face_of[h as usize] as usize];
        }
        (n - 2.0) / n * p + sum / (n * n)
    } else if ring.len() == 1 {
        p
    } else {
        let (first, last) = boundary_neighbours(mesh, &ring);
        (first + 6.0 * p + last) / 8.0
    }
}

/// The two neighbours of a boundary vertex along the boundary, given its ring.
pub(crate) fn boundary_neighbours(mesh: &PolyMesh, ring: &[u32]) -> (DVec3, DVec3) {
    let first = mesh.points[mesh.to(ring[0]) as usize];
    let last_h = *ring.last().expect("a vertex has a face");
    let last = mesh.points[mesh.from(mesh.prev(last_h)) as usize];
    (first, last)
}
