//! Lai & Cheng's solids of Catmull-Clark surfaces (§6-7): the limit surface voxelized in
//! parameter space with a normal per voxel, seeds chosen from those normals (§6.1), the inside
//! flooded from the seeds by FloodingXYZ with a bounded GRAYSTACK (§6.2), and the exact limit
//! volume by Gauss quadrature beside the voxel volume (§7.2).
//!
//! Decided here where the paper is silent:
//! - The surface is always the enclosing one (`ParametricOptions::enclose`): the paper's
//!   adjacency test alone can leave a gap a 6-connected flood passes through (it does on
//!   catmark_smoothtris0 at 256), and an inside flood through a gap fills the outside.
//! - Every surface voxel that gives a seed gives one (not only the first): where surface voxels
//!   cut the inside into pockets, each pocket is seeded from its own walls.
//! - "Against the normal" is inward only if the normals face outward; the sign of the exact
//!   limit volume says which way they face, so inward-oriented control meshes fill the same.
//! - The flood runs in a box one voxel larger than the surface, from one seed at a time (seeds
//!   already reached are skipped). A step along an axis only loosely opposed to the normal, or
//!   through a part thinner than a voxel, can land outside: a seed whose flood reaches the
//!   border of the box lay outside, and its flood is dropped and counted (`outside_seeds`);
//!   later seeds in that region are skipped. If no seed stays inside, the solid is refused.

use crate::error::{Error, Result};
use crate::grid::{Coord, DenseMask, Transform};
use crate::ops::flood::padded;
use crate::ops::flood_xyz::{FloodXyzStats, flood_xyz};
use crate::ops::measure::SolidMeasures;
use crate::ops::seed::seeds_from_normals;
use crate::progress::Progress;
use crate::solids::exterior_flood::Solid;
use crate::subd::{ControlMesh, LimitSurface, limit_volume_and_area};
use crate::voxelize::parametric::{ParametricOptions, ParametricOutput, voxelize_subdivision};

/// A Catmull-Clark solid and what made it.
pub struct SubdivisionSolid {
    /// The voxelized limit surface (with normals) and its opposite-normal voxels.
    pub surface: ParametricOutput,
    pub solid: Solid,
    /// Seeds the rule gave, and those whose flood reached the border (dropped).
    pub seeds: u64,
    pub outside_seeds: u64,
    /// The exact volume the limit surface encloses (Gauss quadrature), in world units: its
    /// sign tells which way the normals face.
    pub limit_volume: f64,
    /// The limit surface's exact area, from the same quadrature.
    pub limit_area: f64,
}

/// Why a solid needs a closed control mesh.
const SOLID_NEEDS_CLOSED: &str = "a solid needs a closed limit surface; this control mesh has boundary edges, so the inside flood would leak out";

/// Voxelizes the closed limit surface of `control` and floods its inside from seeds by
/// FloodingXYZ with a GRAYSTACK of `capacity` entries.
pub fn subdivision_solid(
    control: &ControlMesh,
    transform: Transform,
    options: &ParametricOptions,
    capacity: usize,
    progress: &Progress,
) -> Result<SubdivisionSolid> {
    if !control.is_closed() {
        return Err(Error::InvalidArgument(format!(
            "{}: {SOLID_NEEDS_CLOSED}",
            control.source.display()
        )));
    }
    let options = ParametricOptions {
        enclose: true,
        ..*options
    };
    let surface = voxelize_subdivision(control, transform, &options, progress)?;
    let (limit_volume, limit_area) = limit_volume_and_area(&LimitSurface::new(control.clone()));
    let outward = limit_volume < 0.0;
    let seeds: Vec<Coord> = seeds_from_normals(&surface.surface, &surface.opposite, outward)
        .map(|choice| choice.seed)
        .collect();
    if seeds.is_empty() {
        return Err(Error::InvalidArgument(format!(
            "{}: no surface voxel gives a seed (the solid is thinner than a voxel everywhere)",
            control.source.display()
        )));
    }
    let Some(bbox) = surface.surface.bbox() else {
        return Err(Error::InvalidArgument(format!(
            "{}: the limit surface has no voxels",
            control.source.display()
        )));
    };
    let bbox = padded(bbox, 1);
    let blocked = DenseMask::from_grid(&surface.surface, bbox)?;
    let mut inside = DenseMask::new(bbox)?;
    let mut outside = DenseMask::new(bbox)?;
    let mut stats = FloodXyzStats::default();
    let mut outside_seeds = 0u64;
    progress.stage("filling", seeds.len() as u64);
    for &seed in &seeds {
        progress.advance(1);
        if inside.get(seed) || outside.get(seed) {
            continue;
        }
        let (region, s) = flood_xyz(&blocked, &[seed], capacity, progress)?;
        stats.line_floods += s.line_floods;
        stats.sweeps += s.sweeps;
        stats.overflows += s.overflows;
        // The box's outer layer holds no surface voxel and is one 6-connected shell: a flood
        // that reaches the border reaches its corner.
        if region.get(bbox.min) {
            outside_seeds += 1;
            outside.combine_words(&region, |a, b| a | b);
        } else {
            inside.combine_words(&region, |a, b| a | b);
        }
    }
    if inside.count() == 0 {
        return Err(Error::InvalidArgument(format!(
            "{}: every seed's flood reached the border of the box: the surface leaks at this \
             resolution, or the solid is thinner than a voxel everywhere",
            control.source.display()
        )));
    }
    let measures = SolidMeasures::of(inside.count(), blocked.count(), transform.voxel_size);
    Ok(SubdivisionSolid {
        surface,
        solid: Solid {
            inside: inside.to_grid(transform),
            measures,
            xyz_stats: Some(stats),
        },
        seeds: seeds.len() as u64,
        outside_seeds,
        limit_volume: limit_volume.abs(),
        limit_area,
    })
}
