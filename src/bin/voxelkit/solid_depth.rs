//! The options of `voxelkit solid --method depth-layers` (Passalis et al.'s depth buffers).

use clap::Args;
use voxelkit::solids::depth_layers::{DepthLayerOptions, Layers, Unclassified};

#[derive(clap::ValueEnum, Clone, Copy)]
enum LayersKind {
    /// Two layers per side and a stencil count of crossings (Passalis et al.).
    Double,
    /// One layer per side (Karabassi et al.): fills concavities no direction sees.
    Single,
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum UnclassifiedKind {
    /// A voxel is unclassified only when no direction decides it (at most four crossings on
    /// one of its rays decide; exact crossings make deciding directions agree).
    NoDirection,
    /// Passalis et al.'s rule: unclassified when a ray of any direction through the voxel
    /// counts more than four crossings.
    Paper,
}

/// Options of --method depth-layers.
#[derive(Args, Clone, Copy)]
pub struct DepthArgs {
    /// Depth-layer view directions: 3 are the axes (Karabassi's six z-buffers); up to 16 add
    /// face and body diagonals, deciding more voxels of closed meshes (but, on open meshes,
    /// meeting holes more often).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(3..=16))]
    directions: u32,
    #[arg(long, value_enum, default_value = "double")]
    layers: LayersKind,
    /// Which voxels double layers leave unclassified.
    #[arg(long, value_enum, default_value = "no-direction")]
    unclassified: UnclassifiedKind,
}

impl DepthArgs {
    pub fn options(&self) -> DepthLayerOptions {
        DepthLayerOptions {
            directions: self.directions as usize,
            layers: match self.layers {
                LayersKind::Double => Layers::Double,
                LayersKind::Single => Layers::Single,
            },
            unclassified: match self.unclassified {
                UnclassifiedKind::NoDirection => Unclassified::NoDirection,
                UnclassifiedKind::Paper => Unclassified::Paper,
            },
        }
    }
}
