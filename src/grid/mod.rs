//! Sparse voxel grids: 8^3 leaves keyed by origin, optional per-voxel channels,
//! a cached write accessor, Boolean operations leaf by leaf, and the index-to-world transform.

mod bits;
mod coord;
mod leaf;
mod sparse;
mod transform;

pub use coord::{Coord, CoordBox, LEAF_VOXELS, leaf_offset, leaf_origin, offset_coord};
pub use leaf::{Channels, Leaf};
pub use sparse::{Accessor, SparseGrid};
pub use transform::Transform;

mod adjacency;
mod dense;
pub use adjacency::Adjacency;
pub use dense::DenseMask;
