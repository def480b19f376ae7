//! Projective voxelization (Jegathese, Painkras & Prakash, "Fundamental Algorithms for
//! Projective Voxelization"): lines by marching their dominant axis (`line`), triangles by
//! scan-lines in the plane of their dominant normal component (`triangle`), polyhedra as the
//! beam of voxels between front and back faces (`beam`), each carrying an attribute (a
//! colour, or a vertex attribute of the mesh: `interpolate_attribute`) by the same increments
//! as the coordinates.
//!
//! Every primitive is scanned on its own, in parallel chunks into thread-local grids; where
//! several primitives reach a voxel, its colour is the one of the sample nearest to the voxel
//! centre. What the paper leaves open is decided, and documented, in each file. The surface is
//! the union of the triangles' voxels: each triangle is a naive digital plane (one voxel thick
//! along its dominant axis), which blocks face-connected paths across its interior, but the
//! method guarantees no separability where triangles meet; `voxelkit bench projective` measures
//! the leaks against the separating voxelizer.

pub mod attribute;
pub mod line;
pub mod triangle;

use super::Progress;
use super::sink::{Sink, voxelize_indexed, voxelize_parallel};
use crate::error::{Error, Result};
use crate::grid::{Channels, SparseGrid, Transform};
use crate::mesh::Mesh;
use crate::mesh::attributes::{AttributeGrid, VertexAttribute};
use attribute::Attribute;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Where the colours of the voxels come from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Coloring {
    /// No colour grid.
    #[default]
    None,
    /// The mesh's per-vertex colours (OBJ `v x y z r g b`), interpolated.
    Vertex,
    /// One colour for everything.
    Constant(Vec3),
}

impl Coloring {
    /// The mesh's own colours when it has them, else none.
    pub fn of(mesh: &Mesh) -> Coloring {
        if mesh.colors.is_empty() {
            Coloring::None
        } else {
            Coloring::Vertex
        }
    }
}

/// Which lines `voxelize_lines` scans.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LineSource {
    /// The polylines (OBJ `l`).
    pub polylines: bool,
    /// The edges of the faces (the wireframe), each once.
    pub edges: bool,
}

/// What a projective voxelization did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProjectiveStats {
    pub triangles: u64,
    /// Triangles without area, voxelized as their longest edge.
    pub degenerate_triangles: u64,
    pub segments: u64,
}

/// How a scanned voxel reaches the sink: with its colour, or as a bare voxel.
trait Deposit: Attribute {
    fn channels() -> Channels;
    fn deposit(self, sink: &mut Sink, voxel: [i64; 3], distance: f64);
}

impl Deposit for () {
    fn channels() -> Channels {
        Channels::NONE
    }
    #[inline]
    fn deposit(self, sink: &mut Sink, voxel: [i64; 3], distance: f64) {
        sink.add(voxel, distance, DVec3::ZERO);
    }
}

impl Deposit for DVec3 {
    fn channels() -> Channels {
        Channels {
            value: true,
            color: true,
            ..Channels::NONE
        }
    }
    #[inline]
    fn deposit(self, sink: &mut Sink, voxel: [i64; 3], distance: f64) {
        sink.add_color(voxel, distance, self.as_vec3());
    }
}

/// The per-vertex colours `coloring` asks for, or an error naming the mesh.
fn vertex_colors(mesh: &Mesh, coloring: Coloring) -> Result<Option<Vec<DVec3>>> {
    match coloring {
        Coloring::None => Ok(None),
        Coloring::Constant(c) => Ok(Some(vec![c.as_dvec3(); mesh.positions.len()])),
        Coloring::Vertex if mesh.colors.len() == mesh.positions.len() => {
            Ok(Some(mesh.colors.iter().map(|c| c.as_dvec3()).collect()))
        }
        Coloring::Vertex => Err(Error::InvalidArgument(format!(
            "{}: the vertices carry no colours (OBJ `v x y z r g b`); give a constant colour instead",
            mesh.source.display()
        ))),
    }
}

fn index_positions(mesh: &Mesh, transform: &Transform) -> Vec<DVec3> {
    mesh.positions
        .par_iter()
        .map(|&p| transform.world_to_index(p))
        .collect()
}

/// Voxelizes every face of `mesh` (fan-triangulated) by projective scan-lines.
/// `progress` counts faces.
pub fn voxelize_triangles(
    mesh: &Mesh,
    transform: Transform,
    coloring: Coloring,
    progress: &Progress,
) -> Result<(SparseGrid, ProjectiveStats)> {
    let pos = index_positions(mesh, &transform);
    let degenerate = AtomicU64::new(0);
    let grid = match vertex_colors(mesh, coloring)? {
        None => scan_faces(mesh, &pos, |_| [(); 3], transform, &degenerate, progress),
        Some(colors) => {
            let corner = |s: usize| colors[mesh.indices[s] as usize];
            let values = |slots: [usize; 3]| slots.map(corner);
            scan_faces(mesh, &pos, values, transform, &degenerate, progress)
        }
    };
    progress.check()?;
    let stats = ProjectiveStats {
        triangles: mesh.triangle_count() as u64,
        degenerate_triangles: degenerate.into_inner(),
        segments: 0,
    };
    Ok((grid, stats))
}

/// Interpolates each of `attributes` of `mesh` across every triangle by the scan that
/// voxelizes it (the triangle's affine interpolant at each voxel's projection along its
/// dominant axis); where several triangles reach a voxel, the value of the sample nearest its
/// centre. `progress` counts faces, once per attribute.
pub fn interpolate_attributes(
    mesh: &Mesh,
    transform: Transform,
    attributes: &[&VertexAttribute],
    progress: &Progress,
) -> Result<Vec<AttributeGrid>> {
    let pos = index_positions(mesh, &transform);
    let degenerate = AtomicU64::new(0);
    attributes
        .iter()
        .map(|&attribute| {
            let values = |slots: [usize; 3]| mesh.attribute_corners(attribute, slots);
            let grid = scan_faces(mesh, &pos, values, transform, &degenerate, progress);
            progress.check()?;
            Ok(AttributeGrid::finished(attribute, grid))
        })
        .collect()
}

/// Scans the fan triangles of every face, each with the values `corner_values` gives its
/// corners (by their positions in `Mesh::indices`), counting triangles without area in
/// `degenerate`; `progress` counts faces.
fn scan_faces<A: Deposit>(
    mesh: &Mesh,
    pos: &[DVec3],
    corner_values: impl Fn([usize; 3]) -> [A; 3] + Sync,
    transform: Transform,
    degenerate: &AtomicU64,
    progress: &Progress,
) -> SparseGrid {
    voxelize_indexed(
        mesh.face_count(),
        transform,
        A::channels(),
        progress,
        |f, sink| {
            for slots in mesh.fan_corners(f) {
                let flat = triangle::voxelize_triangle(
                    slots.map(|s| pos[mesh.indices[s] as usize]),
                    corner_values(slots),
                    |v, d, a: A| a.deposit(sink, v, d),
                );
                if flat {
                    degenerate.fetch_add(1, Ordering::Relaxed);
                }
            }
        },
    )
}

/// The segments `source` selects: consecutive vertices of every polyline, and every edge of
/// the faces once.
pub fn line_segments(mesh: &Mesh, source: LineSource) -> Vec<[u32; 2]> {
    let mut segments = Vec::new();
    if source.polylines {
        for l in &mesh.polylines {
            segments.extend(l.windows(2).map(|w| [w[0], w[1]]));
        }
    }
    if source.edges {
        // Each edge as one sortable key, lower vertex in the high half.
        let mut keys: Vec<u64> = (0..mesh.face_count())
            .into_par_iter()
            .flat_map_iter(|f| {
                let face = mesh.face(f);
                (0..face.len()).map(move |k| {
                    let (a, b) = (face[k], face[(k + 1) % face.len()]);
                    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
                })
            })
            .collect();
        keys.par_sort_unstable();
        keys.dedup();
        segments.extend(keys.iter().map(|&k| [(k >> 32) as u32, k as u32]));
    }
    segments
}

/// Voxelizes the segments `source` selects by marching their dominant axes.
/// `progress` counts segments.
pub fn voxelize_lines(
    mesh: &Mesh,
    transform: Transform,
    source: LineSource,
    coloring: Coloring,
    progress: &Progress,
) -> Result<(SparseGrid, ProjectiveStats)> {
    let segments = line_segments(mesh, source);
    if segments.is_empty() {
        return Err(Error::EmptyMesh {
            path: mesh.source.clone(),
            message: format!(
                "no lines to voxelize: {} polylines, {} faces",
                mesh.polylines.len(),
                mesh.face_count()
            ),
        });
    }
    let pos = index_positions(mesh, &transform);
    let stats = ProjectiveStats {
        segments: segments.len() as u64,
        ..Default::default()
    };
    let grid = match vertex_colors(mesh, coloring)? {
        None => scan_segments(&segments, &pos, &vec![(); pos.len()], transform, progress),
        Some(colors) => scan_segments(&segments, &pos, &colors, transform, progress),
    };
    progress.check()?;
    Ok((grid, stats))
}

fn scan_segments<A: Deposit>(
    segments: &[[u32; 2]],
    pos: &[DVec3],
    attrs: &[A],
    transform: Transform,
    progress: &Progress,
) -> SparseGrid {
    voxelize_parallel(
        segments,
        transform,
        A::channels(),
        progress,
        |&[a, b], sink| {
            let (a, b) = (a as usize, b as usize);
            line::voxelize_segment(pos[a], pos[b], attrs[a], attrs[b], |v, d, c: A| {
                c.deposit(sink, v, d)
            })
        },
    )
}
