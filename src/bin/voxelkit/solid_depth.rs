//! The options of `voxelkit solid --method depth-layers` (Passalis et al.'s depth buffers).

use clap::Args;
use voxelkit::solids::depth_layers::{DepthLayerOptions, Layers};

#[derive(clap::ValueEnum, Clone, Copy)]
enum LayersKind {
    /// Two layers per side and a stencil count of crossings (Passalis et al.).
    Double,
    /// One layer per side (Karabassi et al.): fills concavities no direction sees.
    Single,
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
}

impl DepthArgs {
    pub fn options(&self) -> DepthLayerOptions {
        DepthLayerOptions {
            directions: self.directions as usize,
            layers: match self.layers {
                LayersKind::Double => Layers::Double,
                LayersKind::Single => Layers::Single,
            },
        }
    }
}
