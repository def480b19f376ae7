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
//!
//! Or, as Passalis et al. offer for parametric surfaces, by depth layers: double layers along
//! z, x and y run on a tessellation certified within `TESSELLATION_TOLERANCE` voxel of the
//! limit surface (`subd::certified_tessellation`), so every centre they decide wrongly lies
//! within that distance of the limit surface, inside its voxel's half-voxel ball: a voxel the
//! surface touches, which the enclosing surface holds. The solid is the centres the layers put
//! inside, united with the enclosing surface: no seeds, no flood, every pocket filled. The
//! rare centre off the surface that all three directions cross more than four times is settled
//! by the closed tessellation's winding number.

use crate::error::{Error, Result};
use crate::grid::{Coord, CoordBox, DenseMask, Transform};
use crate::mesh::winding::WindingTree;
use crate::ops::flood::padded;
use crate::ops::flood_xyz::{FloodXyzStats, flood_xyz};
use crate::ops::measure::SolidMeasures;
use crate::ops::seed::seeds_from_normals;
use crate::progress::Progress;
use crate::solids::depth_layers::{DepthLayerOptions, DepthLayerStats, depth_layer_solid};
use crate::solids::exterior_flood::Solid;
use crate::subd::{
    ControlMesh, LimitSurface, TESSELLATION_TRIANGLE_BYTES, certified_tessellation,
    limit_volume_and_area,
};
use crate::voxelize::parametric::{ParametricOptions, ParametricOutput, voxelize_subdivision};
use rayon::prelude::*;

/// How far (voxels) the tessellation depth layers run on may stray from the limit surface:
/// below half a voxel, with room for rounding.
pub const TESSELLATION_TOLERANCE: f64 = 0.45;

/// A Catmull-Clark solid and what made it.
pub struct SubdivisionSolid {
    /// The voxelized limit surface (with normals) and its opposite-normal voxels.
    pub surface: ParametricOutput,
    pub solid: Solid,
    pub filled: Filled,
    /// The exact volume the limit surface encloses (Gauss quadrature), in world units: its
    /// sign tells which way the normals face.
    pub limit_volume: f64,
    /// The limit surface's exact area, from the same quadrature.
    pub limit_area: f64,
}

/// How the inside was found.
pub enum Filled {
    /// Seeds the rule gave, and those whose flood reached the border (dropped).
    Seeds { seeds: u64, outside_seeds: u64 },
    /// Depth layers on a certified tessellation: its triangles, the deepest quadtree level a
    /// patch took, the layers' ray counts, and the voxels off the surface no direction decided
    /// (settled by the tessellation's winding number).
    DepthLayers {
        triangles: u64,
        deepest: u32,
        stats: DepthLayerStats,
        by_winding_number: u64,
    },
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
    let Enclosed {
        surface,
        bbox,
        limit_volume,
        limit_area,
        ..
    } = enclosed(control, transform, options, progress)?;
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
        filled: Filled::Seeds {
            seeds: seeds.len() as u64,
            outside_seeds,
        },
        limit_volume: limit_volume.abs(),
        limit_area,
    })
}

/// The enclosing voxelization of a closed limit surface, the surface itself, the voxelization's
/// box grown by a voxel, and the limit volume (signed: its sign says which way the normals
/// face) and area.
struct Enclosed {
    surface: ParametricOutput,
    limit: LimitSurface,
    bbox: CoordBox,
    limit_volume: f64,
    limit_area: f64,
}

fn enclosed(
    control: &ControlMesh,
    transform: Transform,
    options: &ParametricOptions,
    progress: &Progress,
) -> Result<Enclosed> {
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
    let Some(bbox) = surface.surface.bbox() else {
        return Err(Error::InvalidArgument(format!(
            "{}: the limit surface has no voxels",
            control.source.display()
        )));
    };
    let limit = LimitSurface::new(control.clone());
    let (limit_volume, limit_area) = limit_volume_and_area(&limit);
    Ok(Enclosed {
        surface,
        limit,
        bbox: padded(bbox, 1),
        limit_volume,
        limit_area,
    })
}

/// The solid of the closed limit surface of `control` by double depth layers along z, x and
/// y on a tessellation within `TESSELLATION_TOLERANCE` voxel of it, united with the
/// enclosing surface; the tessellation may take `memory` bytes at most.
pub fn subdivision_depth_layer_solid(
    control: &ControlMesh,
    transform: Transform,
    options: &ParametricOptions,
    memory: u64,
    progress: &Progress,
) -> Result<SubdivisionSolid> {
    let Enclosed {
        surface,
        limit,
        bbox,
        limit_volume,
        limit_area,
    } = enclosed(control, transform, options, progress)?;
    let tessellation = certified_tessellation(
        &limit,
        TESSELLATION_TOLERANCE * transform.voxel_size,
        memory / TESSELLATION_TRIANGLE_BYTES,
        progress,
    )?;
    let layers = depth_layer_solid(
        &tessellation.mesh,
        &transform,
        bbox,
        &DepthLayerOptions::default(),
        progress,
    )?;
    let on_surface = DenseMask::from_grid(&surface.surface, bbox)?;
    let mut inside = layers.inside.minus(&on_surface);
    // The tessellation is closed: its winding number settles the few centres that every
    // direction's rays cross more than four times.
    let undecided: Vec<usize> = layers.unclassified.minus(&on_surface).ones().collect();
    if !undecided.is_empty() {
        let tree = WindingTree::new(&tessellation.mesh);
        let settled: Vec<usize> = undecided
            .par_iter()
            .copied()
            .filter(|&i| {
                let centre = transform.index_to_world(inside.coord(i));
                tree.winding_number(centre).abs() >= 0.5
            })
            .collect();
        for i in settled {
            inside.set_index(i);
        }
    }
    let measures = SolidMeasures::of(inside.count(), on_surface.count(), transform.voxel_size);
    Ok(SubdivisionSolid {
        surface,
        solid: Solid {
            inside: inside.to_grid(transform),
            measures,
            xyz_stats: None,
        },
        filled: Filled::DepthLayers {
            triangles: tessellation.mesh.triangle_count() as u64,
            deepest: tessellation.deepest,
            stats: layers.stats,
            by_winding_number: undecided.len() as u64,
        },
        limit_volume: limit_volume.abs(),
        limit_area,
    })
}
