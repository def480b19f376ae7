//! The options of `voxelkit solid --method depth-layers` (Passalis et al.'s depth buffers).

use clap::Args;
use voxelkit::solids::depth_layers::{DepthLayerOptions, DirectionSet, Layers, Unclassified};

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

/// `--directions`: a count of the built-in directions, or `x,y,z;x,y,z;...`.
fn parse_directions(s: &str) -> Result<DirectionSet, String> {
    if let Ok(n) = s.trim().parse::<usize>() {
        return DirectionSet::first(n).map_err(|e| e.to_string());
    }
    let list = s
        .split(';')
        .map(|d| {
            let v: Vec<i64> = d
                .split(',')
                .map(|c| c.trim().parse::<i64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("`{d}` is not an integer vector x,y,z"))?;
            <[i64; 3]>::try_from(v).map_err(|_| format!("`{d}` is not an integer vector x,y,z"))
        })
        .collect::<Result<Vec<_>, String>>()?;
    DirectionSet::given(&list).map_err(|e| e.to_string())
}

/// Options of --method depth-layers.
#[derive(Args, Clone, Copy)]
pub struct DepthArgs {
    /// Depth-layer view directions: a count N takes the first N of 16 (3 are the axes,
    /// Karabassi's six z-buffers; more add face and body diagonals, deciding more voxels of
    /// closed meshes but, on open meshes, meeting holes more often); or your own, `x,y,z`
    /// integer vectors separated by `;` (each with a component of 1 or -1, none parallel),
    /// e.g. `0,0,1;1,1,0;2,1,1`.
    #[arg(long, default_value = "16", value_parser = parse_directions, allow_hyphen_values = true)]
    directions: DirectionSet,
    #[arg(long, value_enum, default_value = "double")]
    layers: LayersKind,
    /// Which voxels double layers leave unclassified.
    #[arg(long, value_enum, default_value = "no-direction")]
    unclassified: UnclassifiedKind,
}

impl DepthArgs {
    pub fn options(&self) -> DepthLayerOptions {
        DepthLayerOptions {
            directions: self.directions,
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
