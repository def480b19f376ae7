//! Operations on voxel sets: flooding, inside classification, topology checks.

pub mod crossings;
pub mod csg;
pub mod csg_tree;
pub mod flood;
pub mod flood_linear;
pub mod flood_spans;
pub mod flood_xyz;
pub mod inside;
pub mod measure;
pub mod minimality;
pub mod seed;
pub mod separability;
pub mod solid;
pub mod solid_leaves;
pub mod surface_area;
pub mod topology;
