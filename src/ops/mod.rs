//! Operations on voxel sets: flooding, Booleans, measures, topology, separability and minimality checks.

pub mod csg;
pub mod csg_normals;
pub mod flood;
pub mod flood_blocks;
pub mod flood_linear;
pub mod flood_spans;
pub mod flood_xyz;
pub mod labels;
pub mod measure;
pub mod minimality;
pub mod seed;
pub mod separability;
pub mod surface_area;
pub mod topology;
