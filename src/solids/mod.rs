//! Solids: the layer above voxelization that fills, classifies and combines (Lai & Cheng's
//! exterior flood of a separating surface, Passalis et al.'s depth layers, Jegathese et
//! al.'s beams, CSG trees of shapes, formulas, meshes and grids).

pub mod beam;
pub mod cavities;
pub mod column_inside;
#[cfg(feature = "vdb")]
pub mod csg_exact;
pub mod csg_leaves;
pub mod csg_placement;
#[cfg(feature = "vdb")]
pub mod csg_tree;
pub mod depth_layers;
pub mod exterior_flood;
pub mod flooded_mesh;
pub mod formula_rays;
pub mod inside_rule;
pub mod level_set;
pub mod point_queries;
pub mod subdivision;
pub mod winding_inside;
