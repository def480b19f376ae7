//! voxelkit: voxelization with guaranteed topology.
//!
//! Meshes and analytic surfaces become sparse voxel grids whose separability is proven
//! (Huang et al.), checked by flooding, and written as OpenVDB files.

pub mod choice;
pub mod contour;
pub mod error;
pub mod grid;
pub mod huge_pages;
pub mod implicit;
pub mod io;
pub mod mapped_bytes;
pub mod mesh;
pub mod ops;
pub mod parallel_concat;
#[cfg(feature = "vdb")]
pub mod pipeline;
pub mod progress;
/// The Python module `voxelkit._voxelkit` (built by maturin).
#[cfg(feature = "python")]
mod python;
pub mod random;
pub mod shapes;
pub mod solids;
pub mod subd;
pub mod system;
pub mod voxelize;

pub use error::{Error, Result};
/// The C interface of `include/voxelkit.h`: exported symbols only, not Rust API (its
/// functions take raw pointers from C).
#[cfg(feature = "vdb")]
mod capi;
pub mod ffi;
