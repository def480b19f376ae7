//! The caps that close any mesh. A mesh's oriented boundary is what its triangles' edges leave
//! over once each directed edge cancels its reverse (the chain boundary: a hole's rim, or an
//! edge two faces use in the same direction, twice). Walked into loops and each loop fanned from
//! its centroid, facing against the rim, it closes the mesh: mesh and caps together have no
//! boundary, so their winding number is an integer everywhere, counted exactly by ray
//! crossings, and the mesh's own winding number is that integer less the caps' (Jacobson et al.
//! 2013 split it the same way around a hole). Caps are small: one triangle per rim edge.
//!
//! Edges cancel by position, not by vertex number: a seam whose two sides repeat their vertices
//! (a mesh exported in parts, as the Utah teapot is) is no hole, and capping each side would lay
//! two opposite caps on top of each other, whose numbers cancel but whose jumps every query near
//! them must resolve. Where welding would make orientations disagree, the vertices stay apart.

use super::Mesh;
use super::key_groups::group_by_key;
use glam::DVec3;
use std::collections::HashMap;

pub struct BoundaryCaps {
    /// The loops' centroids, numbered after the mesh's vertices.
    pub points: Vec<DVec3>,
    /// The cap triangles, over the mesh's vertices and `points`.
    pub triangles: Vec<[u32; 3]>,
    /// Rim loops.
    pub loops: usize,
    /// Edges two faces use in the same direction: where the orientation is inconsistent.
    pub inconsistent_edges: u64,
    /// Each mesh vertex's first vertex at the same position, where vertices were welded so.
    pub welded: Option<Vec<u32>>,
}

impl BoundaryCaps {
    /// Whether the mesh needs no caps: closed as an oriented surface.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The mesh's triangles over the vertices the caps were made for (welded ones by their
    /// first vertex at the same place): with the caps, a surface without boundary whose shared
    /// edges are numbered alike, so that ray crossings see both sides of every edge the same way.
    pub fn mesh_triangles(&self, mesh: &Mesh) -> Vec<[u32; 3]> {
        match &self.welded {
            Some(first) => mesh
                .triangles()
                .map(|(_, t)| t.map(|v| first[v as usize]))
                .collect(),
            None => mesh.triangles().map(|(_, t)| t).collect(),
        }
    }
}

/// The caps of `mesh`'s fan triangles, its vertices welded by position unless that makes
/// orientations disagree that agreed apart.
pub fn boundary_caps(mesh: &Mesh) -> BoundaryCaps {
    let apart = caps_over(mesh, None);
    // Closed as numbered: nothing to weld.
    if apart.is_empty() {
        return apart;
    }
    let Some(first) = first_at_same_position(mesh) else {
        return apart;
    };
    let welded = caps_over(mesh, Some(first));
    if welded.inconsistent_edges > apart.inconsistent_edges {
        apart
    } else {
        welded
    }
}

/// Each vertex's first vertex at the same position, if any two share one.
fn first_at_same_position(mesh: &Mesh) -> Option<Vec<u32>> {
    let mut seen: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let mut shared = false;
    let first: Vec<u32> = (0..mesh.positions.len() as u32)
        .map(|v| {
            // 0.0 and -0.0 are one place.
            let key = mesh.p(v).to_array().map(|c| (c + 0.0).to_bits());
            let f = *seen.entry(key).or_insert(v);
            shared |= f != v;
            f
        })
        .collect();
    shared.then_some(first)
}

/// The caps of `mesh`'s triangles with each vertex taken as `first` names it.
fn caps_over(mesh: &Mesh, first: Option<Vec<u32>>) -> BoundaryCaps {
    let id = |v: u32| first.as_ref().map_or(v, |f| f[v as usize]);
    // Each undirected edge's uses from its lower to its upper vertex, less the reverse uses:
    // the uses grouped by lower vertex (a counting sort), each group sorted by upper vertex.
    let (start, mut uses) = group_by_key(mesh.positions.len(), |visit| {
        for (_, t) in mesh.triangles() {
            let t = t.map(id);
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a != b {
                    visit(a.min(b), (a.max(b), if a < b { 1 } else { -1 }));
                }
            }
        }
    });
    let mut inconsistent_edges = 0;
    let mut out: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut rims: Vec<(u32, u32)> = Vec::new();
    for lo in 0..mesh.positions.len() {
        let group = &mut uses[start[lo]..start[lo + 1]];
        group.sort_unstable_by_key(|u| u.0);
        for edge in group.chunk_by(|x, y| x.0 == y.0) {
            let (hi, n) = (edge[0].0, edge.iter().map(|u| u.1).sum::<i32>());
            if n == 0 {
                continue;
            }
            inconsistent_edges += u64::from(n.unsigned_abs() > 1);
            let directed = if n > 0 {
                (lo as u32, hi)
            } else {
                (hi, lo as u32)
            };
            rims.extend(std::iter::repeat_n(directed, n.unsigned_abs() as usize));
        }
    }
    // Sorted, so that the same mesh gets the same loops and caps on every run.
    rims.sort_unstable();
    for &(a, b) in &rims {
        out.entry(a).or_default().push(b);
    }
    let mut caps = BoundaryCaps {
        points: Vec::new(),
        triangles: Vec::new(),
        loops: 0,
        inconsistent_edges,
        welded: None,
    };
    let base = mesh.positions.len() as u32;
    for &(start, _) in &rims {
        // Every vertex has as many rim edges in as out, so a walk from one returns to it.
        let mut rim = vec![start];
        let mut at = start;
        while let Some(next) = out.get_mut(&at).and_then(Vec::pop) {
            rim.push(next);
            at = next;
            if at == start {
                break;
            }
        }
        if rim.len() < 2 {
            continue;
        }
        let centre = rim[1..].iter().map(|&v| mesh.p(v)).sum::<DVec3>() / (rim.len() - 1) as f64;
        let c = base + caps.points.len() as u32;
        caps.points.push(centre);
        caps.triangles
            .extend(rim.windows(2).map(|edge| [c, edge[1], edge[0]]));
        caps.loops += 1;
    }
    caps.welded = first;
    caps
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    fn without_faces(mesh: &Mesh, drop: impl Fn(usize) -> bool) -> Mesh {
        let keep: Vec<Vec<u32>> = (0..mesh.face_count())
            .filter(|&f| !drop(f))
            .map(|f| mesh.face(f).to_vec())
            .collect();
        Mesh::from_polygons("open", mesh.positions.clone(), &keep)
    }

    #[test]
    fn a_closed_mesh_needs_no_caps_and_a_holed_one_is_closed_by_them() {
        let torus = generate::torus(DVec3::ZERO, 1.0, 0.35, 24, 12);
        let closed = boundary_caps(&torus);
        assert!(closed.is_empty());
        assert_eq!(closed.inconsistent_edges, 0);
        let open = without_faces(&torus, |f| f % 17 == 3);
        let caps = boundary_caps(&open);
        assert_eq!(caps.inconsistent_edges, 0);
        assert!(caps.loops > 0);
        // Mesh and caps together: every directed edge cancelled by its reverse.
        let mut net: HashMap<(u32, u32), i32> = HashMap::new();
        let mesh_triangles = open.triangles().map(|(_, t)| t);
        for t in mesh_triangles.chain(caps.triangles.iter().copied()) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *net.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(net.values().all(|&n| n == 0));
    }

    /// A cube whose first face has vertices of its own at the same places: a seam all round
    /// it, closed once welded; with the face also flipped, welding would make its edges
    /// inconsistent, so the vertices stay apart and the seam is capped.
    #[test]
    fn a_seam_of_repeated_vertices_is_welded_unless_orientations_then_disagree() {
        let cube = generate::cuboid(DVec3::ZERO, DVec3::ONE);
        let mut positions = cube.positions.clone();
        let copies: Vec<u32> = cube
            .face(0)
            .iter()
            .map(|&v| {
                positions.push(cube.p(v));
                (positions.len() - 1) as u32
            })
            .collect();
        let seamed = |flip: bool| {
            let mut faces: Vec<Vec<u32>> = (0..cube.face_count())
                .map(|f| cube.face(f).to_vec())
                .collect();
            faces[0] = copies.clone();
            if flip {
                faces[0].reverse();
            }
            Mesh::from_polygons("seamed", positions.clone(), &faces)
        };
        let welded = boundary_caps(&seamed(false));
        assert!(welded.is_empty() && welded.welded.is_some());
        assert_eq!(welded.inconsistent_edges, 0);
        let apart = boundary_caps(&seamed(true));
        assert!(apart.welded.is_none());
        assert_eq!((apart.loops, apart.inconsistent_edges), (2, 0));
    }

    #[test]
    fn a_flipped_face_is_inconsistent() {
        let cube = generate::cuboid(DVec3::ZERO, DVec3::ONE);
        let faces: Vec<Vec<u32>> = (0..cube.face_count())
            .map(|f| {
                let mut face = cube.face(f).to_vec();
                if f == 0 {
                    face.reverse();
                }
                face
            })
            .collect();
        let flipped = Mesh::from_polygons("flipped", cube.positions.clone(), &faces);
        assert!(boundary_caps(&flipped).inconsistent_edges > 0);
    }
}
