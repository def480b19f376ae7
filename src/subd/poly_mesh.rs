//! A small half-edge polygon mesh, used both for a whole control mesh and for the local
//! neighbourhood (1-ring) of one face during local subdivision.
//!
//! Half-edge `h` of face `f` is slot `h` of the flat corner list: it runs from corner `h` to the
//! next corner of the same face. A half-edge without a twin is either a true boundary of the
//! surface (`boundary[h]`) or, in a local neighbourhood, the rim where the copy stops.

use super::crease::INFINITE;
use glam::DVec3;

pub(crate) const NONE: u32 = u32::MAX;

#[derive(Clone, Debug, Default)]
pub(crate) struct PolyMesh {
    pub points: Vec<DVec3>,
    /// Corner vertex of every half-edge (its origin), faces back to back.
    pub verts: Vec<u32>,
    /// `face_starts[f]..face_starts[f + 1]` are the half-edges of face `f`.
    pub face_starts: Vec<u32>,
    /// Face of every half-edge.
    pub face_of: Vec<u32>,
    /// Opposite half-edge, or `NONE`.
    pub twin: Vec<u32>,
    /// True where the half-edge lies on the boundary of the surface itself.
    pub boundary: Vec<bool>,
    /// Crease sharpness of every half-edge's edge (equal on both halves; 0 is smooth).
    pub sharpness: Vec<f32>,
    /// Corner sharpness of every vertex (0 is smooth).
    pub vertex_sharpness: Vec<f32>,
}

impl PolyMesh {
    /// Builds the half-edge structure; `is_boundary(a, b)` says whether an unmatched edge
    /// from `a` to `b` is a true boundary (always true for a whole control mesh).
    /// Returns the first edge used twice in the same direction, if any, as an error value.
    pub fn build(
        points: Vec<DVec3>,
        faces: &[&[u32]],
        is_boundary: impl Fn(u32, u32) -> bool,
    ) -> Result<PolyMesh, (u32, u32)> {
        let mut m = PolyMesh {
            points,
            face_starts: vec![0],
            ..Default::default()
        };
        for (f, face) in faces.iter().enumerate() {
            m.verts.extend_from_slice(face);
            m.face_of.extend(std::iter::repeat_n(f as u32, face.len()));
            m.face_starts.push(m.verts.len() as u32);
        }
        let count = m.verts.len();
        m.twin = vec![NONE; count];
        m.boundary = vec![false; count];
        m.sharpness = vec![0.0; count];
        m.vertex_sharpness = vec![0.0; m.points.len()];
        let mut by_edge = rustc_hash::FxHashMap::default();
        by_edge.reserve(count);
        for h in 0..count as u32 {
            let key = (m.verts[h as usize], m.to(h));
            if by_edge.insert(key, h).is_some() {
                return Err(key);
            }
        }
        for h in 0..count as u32 {
            let (a, b) = (m.verts[h as usize], m.to(h));
            match by_edge.get(&(b, a)) {
                Some(&t) => m.twin[h as usize] = t,
                None => m.boundary[h as usize] = is_boundary(a, b),
            }
        }
        Ok(m)
    }

    pub fn face_count(&self) -> usize {
        self.face_starts.len() - 1
    }

    pub fn face(&self, f: usize) -> &[u32] {
        &self.verts[self.face_starts[f] as usize..self.face_starts[f + 1] as usize]
    }

    pub fn face_len(&self, f: usize) -> usize {
        (self.face_starts[f + 1] - self.face_starts[f]) as usize
    }

    #[inline]
    pub fn from(&self, h: u32) -> u32 {
        self.verts[h as usize]
    }

    #[inline]
    pub fn next(&self, h: u32) -> u32 {
        let f = self.face_of[h as usize] as usize;
        if h + 1 == self.face_starts[f + 1] {
            self.face_starts[f]
        } else {
            h + 1
        }
    }

    #[inline]
    pub fn prev(&self, h: u32) -> u32 {
        let f = self.face_of[h as usize] as usize;
        if h == self.face_starts[f] {
            self.face_starts[f + 1] - 1
        } else {
            h - 1
        }
    }

    #[inline]
    pub fn to(&self, h: u32) -> u32 {
        self.from(self.next(h))
    }

    /// Sharpness of the edge of `h`; a boundary of the surface is an infinitely sharp crease.
    #[inline]
    pub fn edge_sharpness(&self, h: u32) -> f32 {
        if self.boundary[h as usize] {
            INFINITE
        } else {
            self.sharpness[h as usize]
        }
    }

    /// Whether any edge or vertex carries a crease or corner tag.
    pub fn has_creases(&self) -> bool {
        self.sharpness
            .iter()
            .chain(&self.vertex_sharpness)
            .any(|&s| s > 0.0)
    }

    #[inline]
    pub fn twin(&self, h: u32) -> Option<u32> {
        let t = self.twin[h as usize];
        (t != NONE).then_some(t)
    }

    /// One outgoing half-edge of every vertex; for a vertex with an unmatched incoming
    /// side, the one from which a counter-clockwise walk (`ring`) sees all its faces.
    pub fn outgoing(&self) -> Vec<u32> {
        let mut out = vec![NONE; self.points.len()];
        for h in 0..self.verts.len() as u32 {
            let v = self.from(h) as usize;
            // A walk goes clockwise-backwards through incoming edges: it must start at the face
            // whose outgoing edge is unmatched, or it would miss the faces before it.
            let starts_fan = self.twin(h).is_none();
            if out[v] == NONE || starts_fan {
                out[v] = h;
            }
        }
        out
    }

    /// The outgoing half-edges around the origin of `start`, counter-clockwise, one per face,
    /// and whether the walk closed (an interior vertex) or stopped at an unmatched edge.
    pub fn ring(&self, start: u32) -> (Vec<u32>, bool) {
        let mut ring = vec![start];
        let mut h = start;
        loop {
            match self.twin(self.prev(h)) {
                Some(t) if t == start => return (ring, true),
                Some(t) => {
                    // A vertex with more faces than half-edges can only be a broken input;
                    // the caller checks the count against the incidences.
                    if ring.len() > self.verts.len() {
                        return (ring, false);
                    }
                    ring.push(t);
                    h = t;
                }
                None => return (ring, false),
            }
        }
    }

    /// Faces that share a vertex with face `f`, `f` first, each once.
    pub fn one_ring_faces(&self, f: usize, outgoing: &[u32]) -> Vec<usize> {
        let mut faces = vec![f];
        for &v in self.face(f) {
            for h in self.ring(outgoing[v as usize]).0 {
                let g = self.face_of[h as usize] as usize;
                if !faces.contains(&g) {
                    faces.push(g);
                }
            }
        }
        faces
    }

    /// A copy of `faces` (the first becomes face 0, its corner list rotated left by
    /// `rotation`) with vertices renumbered; unmatched edges keep their boundary flag.
    pub fn extract_rotated(&self, faces: &[usize], rotation: usize) -> PolyMesh {
        let mut map = rustc_hash::FxHashMap::default();
        let mut points = Vec::new();
        let mut local_faces: Vec<Vec<u32>> = Vec::with_capacity(faces.len());
        let mut true_boundary = rustc_hash::FxHashSet::default();
        let mut sharp_edges = rustc_hash::FxHashMap::default();
        for &f in faces {
            let start = self.face_starts[f];
            let local: Vec<u32> = self
                .face(f)
                .iter()
                .map(|&v| {
                    *map.entry(v).or_insert_with(|| {
                        points.push(self.points[v as usize]);
                        points.len() as u32 - 1
                    })
                })
                .collect();
            for (k, _) in local.iter().enumerate() {
                let edge = (local[k], local[(k + 1) % local.len()]);
                if self.boundary[start as usize + k] {
                    true_boundary.insert(edge);
                }
                let s = self.sharpness[start as usize + k];
                if s > 0.0 {
                    sharp_edges.insert(edge, s);
                }
            }
            local_faces.push(local);
        }
        local_faces[0].rotate_left(rotation);
        let refs: Vec<&[u32]> = local_faces.iter().map(|f| f.as_slice()).collect();
        let mut copy = PolyMesh::build(points, &refs, |a, b| true_boundary.contains(&(a, b)))
            .expect("a copy of a valid mesh is valid");
        if !sharp_edges.is_empty() {
            copy.set_edge_sharpness(|a, b| sharp_edges.get(&(a, b)).copied().unwrap_or(0.0));
        }
        for (&v, &local) in &map {
            copy.vertex_sharpness[local as usize] = self.vertex_sharpness[v as usize];
        }
        copy
    }

    /// Sets every edge's sharpness from `sharpness(a, b)` of its half-edges (the sharper of
    /// the two directions, so a caller may name either).
    pub fn set_edge_sharpness(&mut self, sharpness: impl Fn(u32, u32) -> f32) {
        for h in 0..self.verts.len() as u32 {
            let (a, b) = (self.from(h), self.to(h));
            self.sharpness[h as usize] = sharpness(a, b).max(sharpness(b, a));
        }
    }
}
