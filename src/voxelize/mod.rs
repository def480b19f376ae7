//! Voxelization methods, one file each, named for what they do.

mod brick_bins;
pub mod distance_band;
pub mod interval_octree;
pub mod parametric;
pub mod projective;
pub mod separating;
pub mod separating_analytic;
pub mod separating_formula;
mod separating_kernel;
pub mod sign_change;
mod sink;
pub mod step_certificate;
mod vertex_cone;

pub use crate::progress::Progress;

use glam::DVec3;

/// Which paths of empty voxels a surface must block (Huang et al. §4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Separability {
    /// Blocks paths through voxel faces: the thin surface, `t6 = (L/2) max|n_i|`.
    Six,
    /// Blocks paths through faces, edges and corners: `t26 = (L/2) sum|n_i|`.
    #[default]
    TwentySix,
}

impl Separability {
    /// The adjacency number N of an N-separating surface.
    pub fn adjacency(self) -> u32 {
        match self {
            Separability::Six => 6,
            Separability::TwentySix => 26,
        }
    }

    /// The connectivity of the empty voxels this surface blocks (what a flood check uses).
    pub fn flood_adjacency(self) -> crate::grid::Adjacency {
        match self {
            Separability::Six => crate::grid::Adjacency::Six,
            Separability::TwentySix => crate::grid::Adjacency::TwentySix,
        }
    }

    /// Half thickness `t` of the slab around a plane with unit normal `n`, in voxels.
    pub fn slab_half_thickness(self, n: DVec3) -> f64 {
        let a = n.abs();
        match self {
            Separability::Six => 0.5 * a.max_element(),
            Separability::TwentySix => 0.5 * (a.x + a.y + a.z),
        }
    }

    /// Radius `Rc` of the vertex spheres and edge cylinders, in voxels.
    pub fn vertex_edge_radius(self) -> f64 {
        match self {
            Separability::Six => 0.5,
            Separability::TwentySix => 0.5 * 3f64.sqrt(),
        }
    }
}

crate::named_choices! {
    Separability, "separability":
    "6" => Six,
    "26" => TwentySix,
}
