//! Whether a mesh is closed: every edge shared by exactly two faces. The exterior flood and
//! every inside test need it; an open mesh is refused with the first offending edge named.

use super::Mesh;
use super::key_groups::group_by_key;
use crate::error::{Error, Result};

/// Edges used by one face (holes) and by more than two (non-manifold), with one example of
/// each as 1-based vertex numbers of the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EdgeCounts {
    pub boundary: u64,
    pub non_manifold: u64,
    pub first_boundary: Option<[u64; 2]>,
    pub first_non_manifold: Option<[u64; 2]>,
}

impl EdgeCounts {
    pub fn is_closed(&self) -> bool {
        self.boundary == 0 && self.non_manifold == 0
    }
}

impl Mesh {
    pub fn edge_counts(&self) -> EdgeCounts {
        // Each side's upper vertex, grouped by its lower one: edges then come in (lower,
        // upper) order without hashing.
        let (start, mut uppers) = group_by_key(self.positions.len(), |visit| {
            for f in 0..self.face_count() {
                let face = self.face(f);
                for k in 0..face.len() {
                    let (a, b) = (face[k], face[(k + 1) % face.len()]);
                    visit(a.min(b), a.max(b));
                }
            }
        });
        let mut counts = EdgeCounts::default();
        for lo in 0..self.positions.len() {
            let bucket = &mut uppers[start[lo]..start[lo + 1]];
            bucket.sort_unstable();
            for uses in bucket.chunk_by(|a, b| a == b) {
                let edge = || Some([lo as u32, uses[0]].map(|v| self.vertex_number(v)));
                if uses.len() == 1 {
                    counts.boundary += 1;
                    counts.first_boundary = counts.first_boundary.or_else(edge);
                } else if uses.len() > 2 {
                    counts.non_manifold += 1;
                    counts.first_non_manifold = counts.first_non_manifold.or_else(edge);
                }
            }
        }
        counts
    }

    /// An error naming the file and the first hole or non-manifold edge, unless closed;
    /// `why` says what needs it closed.
    pub fn require_closed(&self, why: &str) -> Result<()> {
        let c = self.edge_counts();
        let edge = |e: Option<[u64; 2]>| e.map_or(String::new(), |[a, b]| format!("{a}-{b}"));
        if c.boundary > 0 {
            return Err(Error::BadMesh(format!(
                "{}: the mesh is open: {} boundary edge(s), the first between vertices {}; {why}",
                self.source.display(),
                c.boundary,
                edge(c.first_boundary)
            )));
        }
        if c.non_manifold > 0 {
            return Err(Error::BadMesh(format!(
                "{}: {} edge(s) are shared by more than two faces, the first between vertices {}; {why}",
                self.source.display(),
                c.non_manifold,
                edge(c.first_non_manifold)
            )));
        }
        Ok(())
    }
}
