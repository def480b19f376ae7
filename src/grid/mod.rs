//! Sparse voxel grids: 8^3 leaves keyed by origin, optional per-voxel channels, tiles for
//! whole 8^3 and 128^3 blocks, a cached write accessor, Boolean operations block by block,
//! and the index-to-world transform.

pub mod attribute_grid;
pub(crate) mod bits;
mod channel_pool;
mod coord;
mod leaf;
mod sparse;
mod tiles;
mod transform;
mod up_axis;

pub use channel_pool::{ChannelBox, release_before_exit};
pub use coord::{
    Coord, CoordBox, LEAF_VOXELS, ceil_int, floor_int, leaf_offset, leaf_origin, offset_coord,
};
pub use leaf::{Channels, Leaf, mask_box};
pub use sparse::{Accessor, Block, SparseGrid};
pub use tiles::{NODE_DIM, NODE_LEAVES, NodeMask, Tiles, node_origin, tile_bytes};
pub use transform::Transform;
pub use up_axis::UpAxis;

mod adjacency;
mod dense;
pub use adjacency::Adjacency;
pub use dense::{DenseMask, MAX_DENSE_VOXELS};
