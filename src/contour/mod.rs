//! Meshes out of grids: the closed, 2-manifold, outward-oriented triangle mesh of a level
//! set's zero set, a fog volume's iso surface or a voxel set's boundary (`extract`), over the
//! per-cell surface cycles (`cell_cycles`) with vertices placed on the tangent planes the
//! values give (`vertex_placement`), or where the source is known exactly, on its own
//! (`hermite`). `mesh::simplify` merges their flat regions.

mod cell_cycles;
mod extract;
mod field;
mod hermite;
mod vertex_placement;

pub use extract::{TriangleMesh, contour};
pub use field::{BlockSign, Meaning, ScalarField};
pub use hermite::{ExactSurface, SegmentCrossings, crossing_of_values};
