//! One Catmull-Clark subdivision step of a (local) polygon mesh, with OpenSubdiv's creases and
//! corners (`crease.rs`) and its default boundary rule VTX_BOUNDARY_EDGE_AND_CORNER: boundary
//! edges are infinitely sharp creases and a boundary vertex with a single face is a sharp
//! corner.
//!
//! Only vertices whose every face is present (`complete`) get a vertex point, so a local
//! neighbourhood can be refined without the rest of the mesh: the child faces kept are those at
//! complete corners, which is all that the 1-ring of any child of a complete face needs.

use super::crease::{self, Rule, child_sharpness, fractional_weight, is_sharp};
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
                let smooth = (pa + pb + face_points[fa as usize] + face_points[fb as usize]) / 4.0;
                points.push(edge_rule(mesh.sharpness[h as usize], pa, pb, smooth));
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
    let mut child = PolyMesh::build(points, &refs, |a, b| boundary_edges.contains(&(a, b)))
        .expect("refining a valid mesh gives a valid mesh");
    if mesh.has_creases() {
        // Each half of a parent edge keeps its sharpness less one step; edges from an edge
        // point to a face point are new and smooth.
        let mut sharp_children = rustc_hash::FxHashMap::default();
        for (h, (&sharpness, &middle)) in mesh.sharpness.iter().zip(&edge_point).enumerate() {
            let s = child_sharpness(sharpness);
            if s > 0.0 && middle != NONE {
                let (a, b) = (mesh.from(h as u32) as usize, mesh.to(h as u32) as usize);
                sharp_children.insert((vertex_point[a], middle), s);
                sharp_children.insert((middle, vertex_point[b]), s);
            }
        }
        child.set_edge_sharpness(|a, b| sharp_children.get(&(a, b)).copied().unwrap_or(0.0));
        for (v, &point) in vertex_point.iter().enumerate() {
            if point != NONE {
                child.vertex_sharpness[point as usize] = child_sharpness(mesh.vertex_sharpness[v]);
            }
        }
    }
    child
}

/// The new position of an edge with a twin, from its smooth position: the midpoint while
/// the edge is sharp, a blend of the two in the step where its sharpness runs out.
fn edge_rule(sharpness: f32, pa: DVec3, pb: DVec3, smooth: DVec3) -> DVec3 {
    if !is_sharp(sharpness) {
        return smooth;
    }
    let midpoint = (pa + pb) / 2.0;
    if is_sharp(child_sharpness(sharpness)) {
        return midpoint;
    }
    let w = f64::from(sharpness);
    w * midpoint + (1.0 - w) * smooth
}

/// The new position of a complete vertex, by its rule; where the rule changes in this step
/// (sharpness running out), the blend of the old rule's and the new one's positions.
fn vertex_rule(mesh: &PolyMesh, v: usize, start: u32, face_points: &[DVec3]) -> DVec3 {
    let p = mesh.points[v];
    let (ring, closed) = mesh.ring(start);
    let edges = edges_at(mesh, &ring, closed);
    let sharpness = vertex_sharpness(mesh, v, &ring, closed);
    let parent = crease::vertex_rule(sharpness, edges.iter().map(|e| e.0));
    let smooth = || {
        let n = ring.len() as f64;
        let mut sum = DVec3::ZERO;
        for &h in &ring {
            sum +=
                mesh.points[mesh.to(h) as usize] + face_points[mesh.face_of[h as usize] as usize];
        }
        (n - 2.0) / n * p + sum / (n * n)
    };
    if matches!(parent, Rule::Smooth | Rule::Dart) {
        return smooth();
    }
    let by_rule = |rule: Rule, sharp: &dyn Fn(f32) -> bool| match rule {
        Rule::Smooth | Rule::Dart => smooth(),
        Rule::Corner => p,
        Rule::Crease => {
            let (a, b) = crease_ends(&edges, sharp);
            (a + 6.0 * p + b) / 8.0
        }
    };
    let parent_point = by_rule(parent, &is_sharp);
    let child = crease::vertex_rule(
        child_sharpness(sharpness),
        edges.iter().map(|e| child_sharpness(e.0)),
    );
    if child == parent {
        return parent_point;
    }
    let child_point = by_rule(child, &|s| is_sharp(child_sharpness(s)));
    let w = f64::from(fractional_weight(sharpness, edges.iter().map(|e| e.0)));
    w * parent_point + (1.0 - w) * child_point
}

/// The far ends of a crease vertex's two sharp edges (by `sharp`), in ring order.
pub(crate) fn crease_ends(edges: &[(f32, DVec3)], sharp: &dyn Fn(f32) -> bool) -> (DVec3, DVec3) {
    let mut ends = edges.iter().filter(|e| sharp(e.0)).map(|e| e.1);
    match (ends.next(), ends.next()) {
        (Some(a), Some(b)) => (a, b),
        _ => unreachable!("a crease has two sharp edges"),
    }
}

/// Every edge at a vertex as (sharpness, other end), counter-clockwise from `ring[0]`; an
/// open ring ends with its incoming boundary edge.
pub(crate) fn edges_at(mesh: &PolyMesh, ring: &[u32], closed: bool) -> Vec<(f32, DVec3)> {
    let mut edges: Vec<(f32, DVec3)> = ring
        .iter()
        .map(|&h| (mesh.edge_sharpness(h), mesh.points[mesh.to(h) as usize]))
        .collect();
    if !closed {
        let incoming = mesh.prev(*ring.last().expect("a vertex has a face"));
        edges.push((
            mesh.edge_sharpness(incoming),
            mesh.points[mesh.from(incoming) as usize],
        ));
    }
    edges
}

/// A vertex's corner sharpness; a boundary vertex with a single face is an infinitely sharp
/// corner (OpenSubdiv's default boundary rule, `VTX_BOUNDARY_EDGE_AND_CORNER`).
pub(crate) fn vertex_sharpness(mesh: &PolyMesh, v: usize, ring: &[u32], closed: bool) -> f32 {
    if !closed && ring.len() == 1 {
        crease::INFINITE
    } else {
        mesh.vertex_sharpness[v]
    }
}
