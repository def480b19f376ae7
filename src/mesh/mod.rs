//! Polygon meshes: loading (OBJ with n-gons kept, binary and ASCII STL, PLY, OFF, glTF),
//! validation, measurement, fitting to a grid, merging a contoured mesh's flat regions
//! (`simplify`), and the project's own generated fixtures.

pub mod attributes;
pub mod boundary_caps;
mod closed;
pub mod crossings;
mod fit;
#[cfg(feature = "fixtures")]
pub mod generate;
mod gltf_scene;
pub mod inside;
pub mod key_groups;
pub mod nearest_attributes;
mod obj;
mod off;
mod ply;
pub mod segment_hits;
pub mod shells;
pub mod simplify;
mod stl;
pub mod surface_distance;
pub mod triangle_distance;
mod up_axis;
pub mod winding;
pub mod winding_split;
pub use gltf_scene::GltfLayout;
pub use up_axis::UpAxis;

pub use closed::EdgeCounts;
pub use fit::{DEFAULT_RESOLUTION, GridFit, fit_transform, index_box};

use crate::error::{Error, Result};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// A polygon mesh: shared positions and faces of any size (kept as in the file).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    /// Vertex indices of all faces, back to back.
    pub indices: Vec<u32>,
    /// `face_starts[f]..face_starts[f+1]` is face `f` in `indices`; `len = faces + 1`.
    pub face_starts: Vec<u32>,
    /// Where the mesh came from (a file, or a generator name), for error messages and metadata.
    pub source: PathBuf,
    /// One RGB colour per position (OBJ `v x y z r g b`), or empty.
    pub colors: Vec<Vec3>,
    /// Polylines (OBJ `l`), as vertex indices.
    pub polylines: Vec<Vec<u32>>,
    /// Vertices are numbered from 0 in messages (arrays from C or Python) instead of from 1
    /// (files, as OBJ numbers them).
    pub numbered_from_zero: bool,
    /// Texture coordinates, normals and named scalars of the vertices or face corners.
    pub attributes: Vec<attributes::VertexAttribute>,
    /// Per-vertex attributes the file holds that voxelkit reads past (glTF attributes, PLY
    /// list properties, OBJ texture coordinates on some faces only), named as the file names
    /// them, so that a job can say what it does not write.
    pub unread: Vec<String>,
}

/// Axis-aligned bounding box in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    /// The box around nothing (the empty box's min above its max).
    pub fn empty() -> Aabb {
        Aabb {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        }
    }

    /// The box around `self` and `p`.
    pub fn with(self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The box around `self` and `other` (either may be empty).
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }
}

impl Mesh {
    /// Builds a mesh from positions and polygons; `source` names it in errors.
    pub fn from_polygons(
        source: impl Into<PathBuf>,
        positions: Vec<DVec3>,
        polygons: &[Vec<u32>],
    ) -> Self {
        let mut face_starts = vec![0u32];
        let mut indices = Vec::new();
        for p in polygons {
            indices.extend_from_slice(p);
            face_starts.push(indices.len() as u32);
        }
        Mesh {
            positions,
            indices,
            face_starts,
            source: source.into(),
            ..Default::default()
        }
    }

    /// Loads an `.obj`, `.stl`, `.off`, `.ply`, `.gltf` or `.glb` file (chosen by extension) and checks it has faces, as every
    /// surface and solid method needs.
    pub fn load(path: &Path) -> Result<Mesh> {
        let mesh = Self::read(path)?;
        mesh.validate()?;
        Ok(mesh)
    }

    /// Loads an `.obj` or `.stl` file for line voxelization: polylines, faces or both.
    pub fn load_lines(path: &Path) -> Result<Mesh> {
        let mesh = Self::read(path)?;
        if mesh.polylines.is_empty() {
            mesh.validate()?;
        } else {
            mesh.validate_positions()?;
            if mesh.face_count() > 0 {
                mesh.validate_faces()?;
            }
        }
        Ok(mesh)
    }

    fn read(path: &Path) -> Result<Mesh> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        let mesh = match ext.as_deref() {
            Some("obj") => obj::load_obj(path)?,
            Some("stl") => stl::load_stl(path)?,
            Some("off") => off::load_off(path)?,
            Some("ply") => ply::load_ply(path)?,
            Some("gltf" | "glb") => gltf_scene::load_gltf(path)?,
            _ => {
                return Err(Error::UnsupportedFormat {
                    path: path.to_path_buf(),
                });
            }
        };
        Ok(mesh)
    }

    /// Vertex `i` as messages number it: from 1 in files, from 0 in arrays.
    pub fn vertex_number(&self, i: u32) -> u64 {
        u64::from(i) + u64::from(!self.numbered_from_zero)
    }

    pub fn face_count(&self) -> usize {
        self.face_starts.len().saturating_sub(1)
    }

    pub fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.face_starts[f] as usize..self.face_starts[f + 1] as usize]
    }

    /// Checks what every algorithm relies on: a face, finite positions, indices in range,
    /// at least three corners per face, attributes with a value for every corner.
    pub fn validate(&self) -> Result<()> {
        if self.face_count() == 0 {
            return Err(self.empty_error());
        }
        self.validate_positions()?;
        self.validate_faces()?;
        self.validate_attributes()
    }

    fn empty_error(&self) -> Error {
        Error::EmptyMesh {
            path: self.source.clone(),
            message: format!(
                "{} vertices, {} faces, {} lines",
                self.positions.len(),
                self.face_count(),
                self.polylines.len()
            ),
        }
    }

    fn validate_positions(&self) -> Result<()> {
        if self.positions.is_empty() {
            return Err(self.empty_error());
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "{}: vertex {} has a non-finite coordinate {:?}",
                self.source.display(),
                self.vertex_number(v as u32),
                self.positions[v]
            )));
        }
        Ok(())
    }

    fn validate_faces(&self) -> Result<()> {
        let n = self.positions.len() as u32;
        for f in 0..self.face_count() {
            let face = self.face(f);
            if face.len() < 3 {
                return Err(
                    self.bad_face(f, format!("has {} corners; 3 or more needed", face.len()))
                );
            }
            if let Some(&i) = face.iter().find(|&&i| i >= n) {
                return Err(self.bad_face(
                    f,
                    format!(
                        "vertex index {} is out of range (the mesh has {n} vertices)",
                        self.vertex_number(i)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn bad_face(&self, face: usize, message: String) -> Error {
        Error::BadFace {
            path: self.source.clone(),
            face,
            message,
        }
    }

    /// The box around every vertex a face or polyline uses.
    pub fn bbox(&self) -> Aabb {
        // Taken on all threads: a large mesh's box is asked for several times a run, while
        // nothing else runs.
        let faces = self
            .indices
            .par_iter()
            .fold(Aabb::empty, |b, &i| b.with(self.p(i)))
            .reduce(Aabb::empty, Aabb::union);
        self.polylines
            .iter()
            .flatten()
            .fold(faces, |b, &i| b.with(self.p(i)))
    }

    /// Fan triangulation of every face: `(face, [a, b, c])`.
    pub fn triangles(&self) -> impl Iterator<Item = (usize, [u32; 3])> + '_ {
        (0..self.face_count()).flat_map(move |f| self.fan(f).map(move |t| (f, t)))
    }

    /// Fan triangulation of face `f`.
    #[inline]
    pub fn fan(&self, f: usize) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.fan_corners(f)
            .map(move |slots| slots.map(|s| self.indices[s]))
    }

    /// Fan triangulation of face `f` as positions of its corners in `indices`.
    #[inline]
    pub fn fan_corners(&self, f: usize) -> impl Iterator<Item = [usize; 3]> + use<> {
        let (start, end) = (
            self.face_starts[f] as usize,
            self.face_starts[f + 1] as usize,
        );
        (start + 1..end - 1).map(move |k| [start, k, k + 1])
    }

    /// Number of triangles in the fan triangulation.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() - 2 * self.face_count()
    }

    /// Surface area of the fan triangulation.
    pub fn area(&self) -> f64 {
        self.triangles()
            .map(|(_, [a, b, c])| {
                let (a, b, c) = (self.p(a), self.p(b), self.p(c));
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Signed volume by the divergence theorem (positive for outward-facing normals).
    /// The volume the faces enclose, signed by their orientation; taken about the centre of
    /// the bounding box, so that a mesh far from the origin loses no precision.
    pub fn signed_volume(&self) -> f64 {
        self.volume_about(self.bbox(), self.triangles().map(|(_, t)| t))
    }

    /// The signed volume the faces `faces` enclose (a shell of the mesh).
    pub fn signed_volume_of(&self, faces: &[u32]) -> f64 {
        let triangles = faces.iter().flat_map(|&f| self.fan(f as usize));
        self.volume_about(self.bbox_of(faces), triangles)
    }

    /// The box of the corners of the faces `faces`.
    pub fn bbox_of(&self, faces: &[u32]) -> Aabb {
        faces
            .iter()
            .flat_map(|&f| self.face(f as usize))
            .fold(Aabb::empty(), |b, &v| b.with(self.p(v)))
    }

    /// The signed volume of `triangles`' cones from the centre of `b` (near the triangles,
    /// so that far-away meshes keep their digits).
    fn volume_about(&self, b: Aabb, triangles: impl Iterator<Item = [u32; 3]>) -> f64 {
        let o = 0.5 * (b.min + b.max);
        triangles
            .map(|[a, b, c]| (self.p(a) - o).dot((self.p(b) - o).cross(self.p(c) - o)) / 6.0)
            .sum()
    }

    #[inline]
    pub fn p(&self, i: u32) -> DVec3 {
        self.positions[i as usize]
    }

    /// Writes the mesh as OBJ text, with vertex colours and polylines when it has them (used by
    /// `voxelkit demo` to ship the model it voxelizes).
    pub fn write_obj(&self, path: &Path) -> Result<()> {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(s, "# written by voxelkit {}", env!("CARGO_PKG_VERSION"));
        for (i, p) in self.positions.iter().enumerate() {
            let _ = write!(s, "v {} {} {}", p.x, p.y, p.z);
            if let Some(c) = self.colors.get(i) {
                let _ = write!(s, " {} {} {}", c.x, c.y, c.z);
            }
            s.push('\n');
        }
        for f in 0..self.face_count() {
            s.push('f');
            for &i in self.face(f) {
                let _ = write!(s, " {}", i + 1);
            }
            s.push('\n');
        }
        for line in &self.polylines {
            s.push('l');
            for &i in line {
                let _ = write!(s, " {}", i + 1);
            }
            s.push('\n');
        }
        crate::io::atomic::write_atomic(path, |tmp| {
            std::fs::write(tmp, s.as_bytes()).map_err(|e| Error::io(tmp, e))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    /// The box taken on all threads is the box of every used vertex, taken one by one, with
    /// faces alone, polylines alone, both, and neither.
    #[test]
    fn the_box_is_that_of_the_used_vertices() {
        let mut random = SplitMix64(3);
        let positions: Vec<DVec3> = (0..5000)
            .map(|_| {
                DVec3::new(
                    random.range(-9.0, 9.0),
                    random.range(-1.0, 1.0),
                    random.range(0.0, 5.0),
                )
            })
            .collect();
        let faces: Vec<Vec<u32>> = (0..3000)
            .map(|_| (0..3).map(|_| (random.next_u64() % 4000) as u32).collect())
            .collect();
        let lines: Vec<Vec<u32>> = (0..40)
            .map(|_| {
                (0..5)
                    .map(|_| 4000 + (random.next_u64() % 1000) as u32)
                    .collect()
            })
            .collect();
        for (faces, lines) in [
            (&faces[..], &lines[..]),
            (&faces[..], &[][..]),
            (&[][..], &lines[..]),
            (&[][..], &[][..]),
        ] {
            let mut mesh = Mesh::from_polygons("box", positions.clone(), faces);
            mesh.polylines = lines.to_vec();
            let used = faces.iter().chain(lines).flatten();
            let expected = used.fold(Aabb::empty(), |b, &i| Aabb {
                min: b.min.min(positions[i as usize]),
                max: b.max.max(positions[i as usize]),
            });
            let b = mesh.bbox();
            assert_eq!((b.min, b.max), (expected.min, expected.max));
        }
    }
}
