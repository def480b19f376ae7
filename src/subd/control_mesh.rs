//! A Catmull-Clark control mesh: polygons of any size from an OBJ file, with the topology
//! checks the limit surface needs (manifold edges and vertices, consistent orientation, no
//! isolated vertices), each failure named by vertex or face.

use super::poly_mesh::PolyMesh;
use super::tags::Tags;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use glam::DVec3;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct ControlMesh {
    pub(crate) mesh: PolyMesh,
    /// One outgoing half-edge per vertex, the start of its counter-clockwise ring.
    pub(crate) outgoing: Vec<u32>,
    pub source: PathBuf,
    /// The crease and corner tags applied (empty for a smooth surface).
    pub tags: Tags,
}

/// What a control mesh is made of, for summaries.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ControlStats {
    pub vertices: usize,
    pub faces: usize,
    pub quads: usize,
    pub triangles: usize,
    pub other: usize,
    /// Interior vertices of valence other than 4.
    pub extraordinary: usize,
    pub boundary_vertices: usize,
    pub max_valence: usize,
}

/// Most corners of a face, and most faces at a vertex, of a control mesh.
pub const MAX_CORNERS: usize = 256;

impl ControlMesh {
    /// Loads a control mesh with its crease and corner tags (`tags.rs`).
    pub fn load(path: &Path) -> Result<ControlMesh> {
        let mesh = Mesh::load(path)?;
        ControlMesh::from_mesh(&mesh)?.with_tags(Tags::read(path)?)
    }

    /// Makes the tagged edges and vertices sharp. Every tagged edge must be an edge of the
    /// mesh, and a boundary rule other than OpenSubdiv's default is refused on an open mesh
    /// (on a closed one it changes nothing).
    pub fn with_tags(mut self, tags: Tags) -> Result<ControlMesh> {
        let source = tags.sources.first().cloned().unwrap_or(self.source.clone());
        let vertices = self.vertex_count() as u32;
        let out_of_range = |v: u32| Error::Parse {
            path: source.clone(),
            line: 0,
            message: format!(
                "a tag names vertex {v}, but the control mesh has {vertices} vertices                      (tags count vertices from 0)"
            ),
        };
        if let Some((rule, place)) = &tags.boundary_rule
            && !self.is_closed()
        {
            return Err(super::tags::parse_error(
                place,
                format!(
                    "boundary interpolation {rule} is not evaluated on this open mesh;                      voxelkit follows OpenSubdiv's default (1: edges and corners)"
                ),
            ));
        }
        let mut sharp_edges = rustc_hash::FxHashMap::default();
        for &(a, b, s) in &tags.creases {
            if a >= vertices || b >= vertices {
                return Err(out_of_range(a.max(b)));
            }
            let key = (a.min(b), a.max(b));
            sharp_edges.insert(key, s);
        }
        let mut found = rustc_hash::FxHashSet::default();
        let mesh = &mut self.mesh;
        for h in 0..mesh.verts.len() as u32 {
            let (a, b) = (mesh.from(h), mesh.to(h));
            if sharp_edges.contains_key(&(a.min(b), a.max(b))) {
                found.insert((a.min(b), a.max(b)));
            }
        }
        if let Some(&(a, b)) = sharp_edges.keys().find(|k| !found.contains(k)) {
            return Err(Error::Parse {
                path: source.clone(),
                line: 0,
                message: format!(
                    "a crease tag names vertices {a} and {b}, which share no edge of the                      control mesh"
                ),
            });
        }
        mesh.set_edge_sharpness(|a, b| {
            sharp_edges
                .get(&(a.min(b), a.max(b)))
                .copied()
                .unwrap_or(0.0)
        });
        for &(v, s) in &tags.corners {
            if v >= vertices {
                return Err(out_of_range(v));
            }
            mesh.vertex_sharpness[v as usize] = s;
        }
        self.tags = tags;
        Ok(self)
    }

    /// Checks the topology of a polygon mesh and builds the control mesh.
    pub fn from_mesh(mesh: &Mesh) -> Result<ControlMesh> {
        mesh.validate()?;
        let source = mesh.source.clone();
        let bad_face = |face: usize, message: String| Error::BadFace {
            path: source.clone(),
            face,
            message,
        };
        let faces: Vec<&[u32]> = (0..mesh.face_count()).map(|f| mesh.face(f)).collect();
        let mut valence = vec![0usize; mesh.positions.len()];
        for (f, face) in faces.iter().enumerate() {
            if face.len() > MAX_CORNERS {
                return Err(bad_face(
                    f,
                    format!(
                        "has {} corners; faces of at most {MAX_CORNERS} are subdivided (each of \
                         a face's patches keeps the whole face around it, so memory grows with \
                         the square of its size)",
                        face.len()
                    ),
                ));
            }
            let mut sorted = face.to_vec();
            sorted.sort_unstable();
            if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
                return Err(bad_face(
                    f,
                    format!(
                        "uses vertex {} twice (degenerate face)",
                        mesh.vertex_number(w[0])
                    ),
                ));
            }
            for &v in face.iter() {
                valence[v as usize] += 1;
                if valence[v as usize] > MAX_CORNERS {
                    return Err(bad_face(
                        f,
                        format!(
                            "makes vertex {} shared by more than {MAX_CORNERS} faces; the \
                             patches around a vertex keep all its neighbours, so memory grows \
                             with the square of its valence",
                            mesh.vertex_number(v)
                        ),
                    ));
                }
            }
        }
        let poly =
            PolyMesh::build(mesh.positions.clone(), &faces, |_, _| true).map_err(|(a, b)| {
                let users: Vec<String> = (0..faces.len())
                    .filter(|&f| {
                        let face = faces[f];
                        (0..face.len()).any(|k| {
                            let (p, q) = (face[k], face[(k + 1) % face.len()]);
                            (p, q) == (a, b) || (p, q) == (b, a)
                        })
                    })
                    .map(|f| f.to_string())
                    .collect();
                Error::Unsupported(format!(
                    "{}: edge between vertices {} and {} is non-manifold or inconsistently \
                     oriented: it is used by faces {} (a Catmull-Clark surface needs every \
                     edge shared by at most two faces, traversed in opposite directions)",
                    source.display(),
                    mesh.vertex_number(a),
                    mesh.vertex_number(b),
                    users.join(", ")
                ))
            })?;
        let outgoing = poly.outgoing();
        let mut incidences = vec![0usize; poly.points.len()];
        for &v in &poly.verts {
            incidences[v as usize] += 1;
        }
        for (v, &count) in incidences.iter().enumerate() {
            let vertex_error = |what: &str| {
                Error::Unsupported(format!(
                    "{}: vertex {} (at {:?}) {what}",
                    source.display(),
                    mesh.vertex_number(v as u32),
                    poly.points[v]
                ))
            };
            if count == 0 {
                return Err(vertex_error(
                    "is used by no face (isolated vertex); remove it from the control mesh",
                ));
            }
            let (ring, _) = poly.ring(outgoing[v]);
            if ring.len() != count {
                return Err(vertex_error(&format!(
                    "is non-manifold: its {count} faces form more than one fan"
                )));
            }
        }
        Ok(ControlMesh {
            mesh: poly,
            outgoing,
            source,
            tags: Tags::default(),
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.mesh.points.len()
    }

    pub fn face_count(&self) -> usize {
        self.mesh.face_count()
    }

    pub fn face_len(&self, f: usize) -> usize {
        self.mesh.face_len(f)
    }

    /// The vertices of face `f`, counter-clockwise.
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        self.mesh.face(f)
    }

    /// Patches of the limit surface: one per quad, n per n-gon.
    pub fn patch_count(&self) -> usize {
        (0..self.face_count())
            .map(|f| match self.face_len(f) {
                4 => 1,
                n => n,
            })
            .sum()
    }

    pub fn positions(&self) -> &[DVec3] {
        &self.mesh.points
    }

    /// Applies `map` to every control point. Catmull-Clark rules are affine combinations,
    /// so the limit surface moves with any affine map (used to go to voxel index space).
    pub fn map_points(&mut self, map: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.mesh.points {
            *p = map(*p);
        }
    }

    /// The polygons of one Catmull-Clark step with every vertex at its limit position (exact
    /// masks: after a step every vertex has only quads around it): their area and box are
    /// within a few percent of the limit surface's, which the control hull can far exceed (a
    /// cube's limit surface has about a third of its area).
    pub fn limit_polygons(&self) -> Mesh {
        let every = vec![true; self.mesh.points.len()];
        let child = super::subdivide::subdivide(&self.mesh, &every);
        let points = child
            .outgoing()
            .iter()
            .enumerate()
            .map(|(v, &h)| super::limit_masks::vertex_limit(&child, v as u32, h, h).0)
            .collect();
        let faces: Vec<Vec<u32>> = (0..child.face_count())
            .map(|f| child.face(f).to_vec())
            .collect();
        Mesh::from_polygons(self.source.clone(), points, &faces)
    }

    /// The control polygons as a plain mesh (for areas, bounding boxes, fitting).
    pub fn polygon_mesh(&self) -> Mesh {
        let faces: Vec<Vec<u32>> = (0..self.face_count())
            .map(|f| self.mesh.face(f).to_vec())
            .collect();
        Mesh::from_polygons(self.source.clone(), self.mesh.points.clone(), &faces)
    }

    pub fn is_closed(&self) -> bool {
        self.mesh.boundary.iter().all(|&b| !b)
    }

    pub fn bbox(&self) -> crate::mesh::Aabb {
        self.mesh
            .points
            .iter()
            .fold(crate::mesh::Aabb::empty(), |b, &p| b.with(p))
    }

    /// Quadtree nodes that semi-sharp tags add to the patches, for a voxel of `voxel_size`:
    /// each side of an edge of sharpness s is subdivided ceil(s) levels deep along it (2^level
    /// nodes per side at the last level, as many again above), but only where the voxelizer
    /// samples it: about two paths per voxel of the edge's length, each ceil(s) nodes deep. A
    /// corner of sharpness s adds about 4 nodes per level in each of its faces.
    pub fn crease_nodes(&self, voxel_size: f64) -> f64 {
        let levels =
            |s: f32| (s > 0.0 && !super::crease::is_infinite(s)).then(|| f64::from(s.ceil()));
        let mesh = &self.mesh;
        let edges: f64 = (0..mesh.verts.len() as u32)
            .filter(|&h| mesh.twin(h).is_some_and(|t| t > h))
            .filter_map(|h| {
                let l = levels(mesh.sharpness[h as usize])?;
                let length =
                    mesh.points[mesh.from(h) as usize].distance(mesh.points[mesh.to(h) as usize]);
                let sampled = 2.0 * l * (length / voxel_size).max(1.0);
                Some(2.0 * 2f64.powf(l + 1.0).min(sampled))
            })
            .sum();
        let corners: f64 = self
            .outgoing
            .iter()
            .zip(&mesh.vertex_sharpness)
            .filter_map(|(&h, &s)| Some(mesh.ring(h).0.len() as f64 * 4.0 * levels(s)?))
            .sum();
        edges + corners
    }

    /// Patch corners at extraordinary points: each interior vertex of valence n != 4 is a
    /// corner of n patches, and each n-gon (n != 4) splits into n patches meeting at its centre.
    pub fn irregular_corner_count(&self) -> usize {
        let at_vertices: usize = self
            .outgoing
            .iter()
            .map(|&h| self.mesh.ring(h))
            .filter(|(ring, closed)| *closed && ring.len() != 4)
            .map(|(ring, _)| ring.len())
            .sum();
        let at_centres: usize = (0..self.face_count())
            .map(|f| self.face_len(f))
            .filter(|&n| n != 4)
            .sum();
        at_vertices + at_centres
    }

    pub fn stats(&self) -> ControlStats {
        let mut s = ControlStats {
            vertices: self.vertex_count(),
            faces: self.face_count(),
            ..Default::default()
        };
        for f in 0..self.face_count() {
            match self.face_len(f) {
                4 => s.quads += 1,
                3 => s.triangles += 1,
                _ => s.other += 1,
            }
        }
        for &h in &self.outgoing {
            let (ring, closed) = self.mesh.ring(h);
            let valence = if closed { ring.len() } else { ring.len() + 1 };
            s.max_valence = s.max_valence.max(valence);
            if !closed {
                s.boundary_vertices += 1;
            } else if valence != 4 {
                s.extraordinary += 1;
            }
        }
        s
    }
}
