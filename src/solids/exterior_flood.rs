//! From a closed voxel surface to a solid: flood the empty voxels from outside (a box two
//! voxels larger than the surface, seeded at its corner, which the empty border shell connects
//! to everything outside), and call inside everything the flood cannot reach. Needing no
//! normals, this works for inward-oriented meshes and for surfaces without normals alike. The
//! flood is 6-connected, which every surface voxelkit makes blocks.

use crate::error::Result;
use crate::grid::{Channels, DenseMask, SparseGrid};
use crate::ops::flood::padded;
use crate::ops::flood_blocks::inside_by_blocks;
use crate::ops::flood_spans::flood_spans;
use crate::ops::flood_xyz::{FloodXyzStats, flood_xyz};
use crate::ops::measure::SolidMeasures;
use crate::progress::Progress;

/// Which flood finds the exterior.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FloodMethod {
    /// Whole empty 8^3 blocks at once, voxels only in blocks with surface voxels (fastest;
    /// the inside comes out as tiles).
    Blocks,
    /// Scanline spans over a dense bit volume.
    Spans,
    /// Lai & Cheng's FloodingXYZ with a GRAYSTACK of this capacity.
    Xyz { capacity: usize },
}

pub struct Solid {
    /// Voxels strictly inside the surface.
    pub inside: SparseGrid,
    pub measures: SolidMeasures,
    /// FloodingXYZ's counters, when it was used.
    pub xyz_stats: Option<FloodXyzStats>,
}

/// The solid enclosed by `surface` (an empty surface encloses nothing).
pub fn solid_from_surface(
    surface: &SparseGrid,
    method: FloodMethod,
    progress: &Progress,
) -> Result<Solid> {
    let Some(bbox) = surface.bbox() else {
        return Ok(Solid {
            inside: SparseGrid::new(surface.transform, Channels::NONE),
            measures: SolidMeasures::default(),
            xyz_stats: None,
        });
    };
    if method == FloodMethod::Blocks {
        let inside = inside_by_blocks(surface, progress)?;
        let measures = SolidMeasures::of(
            inside.voxel_count(),
            surface.voxel_count(),
            surface.transform.voxel_size,
        );
        return Ok(Solid {
            inside,
            measures,
            xyz_stats: None,
        });
    }
    let bbox = padded(bbox, 2);
    let blocked = DenseMask::from_grid(surface, bbox)?;
    let seed = [bbox.min];
    // These floods cannot tell how far they have come: one item, done at the end.
    progress.stage("filling", 1);
    let (exterior, xyz_stats) = match method {
        FloodMethod::Blocks | FloodMethod::Spans => (flood_spans(&blocked, &seed, progress)?, None),
        FloodMethod::Xyz { capacity } => {
            let (reached, stats) = flood_xyz(&blocked, &seed, capacity, progress)?;
            (reached, Some(stats))
        }
    };
    progress.advance(1);
    let inside_mask = DenseMask::neither(&blocked, &exterior);
    let inside = inside_mask.to_grid(surface.transform);
    let measures = SolidMeasures::of(
        inside_mask.count(),
        blocked.count(),
        surface.transform.voxel_size,
    );
    Ok(Solid {
        inside,
        measures,
        xyz_stats,
    })
}
