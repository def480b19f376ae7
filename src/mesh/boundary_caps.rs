//! The caps that close any mesh. A mesh's oriented boundary is what its triangles' edges leave
//! over once each directed edge cancels its reverse (the chain boundary: a hole's rim, or an
//! edge two faces use in the same direction, twice). Walked into loops and each loop fanned from
//! its centroid, facing against the rim, it closes the mesh: mesh and caps together have no
//! boundary, so their winding number is an integer everywhere, counted exactly by ray
//! crossings, and the mesh's own winding number is that integer less the caps' (Jacobson et al.
//! 2013 split it the same way around a hole). Caps are small: one triangle per rim edge.

use super::Mesh;
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
}

impl BoundaryCaps {
    /// Whether the mesh needs no caps: closed as an oriented surface.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
}

/// The caps of `mesh`'s fan triangles.
pub fn boundary_caps(mesh: &Mesh) -> BoundaryCaps {
    // Each undirected edge's uses from its lower to its upper vertex, less the reverse uses.
    let mut net: HashMap<(u32, u32), i32> = HashMap::new();
    for (_, t) in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                *net.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
    }
    let mut inconsistent_edges = 0;
    let mut out: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut rims: Vec<(u32, u32)> = net
        .into_iter()
        .filter(|&(_, n)| n != 0)
        .map(|((lo, hi), n)| (if n > 0 { (lo, hi) } else { (hi, lo) }, n.unsigned_abs()))
        .flat_map(|(edge, uses)| {
            if uses > 1 {
                inconsistent_edges += 1;
            }
            std::iter::repeat_n(edge, uses as usize)
        })
        .collect();
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
