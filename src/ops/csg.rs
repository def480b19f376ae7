//! Booleans of voxel sets (Lai & Cheng §7.3): union, intersection and difference, leaf by leaf
//! when both grids share a transform; otherwise the second grid is resampled onto the first
//! (the voxels whose centres lie in one of its voxels) when asked, or refused with an error
//! that says the transforms differ. The intersection curve of two surfaces is the voxels they
//! share.

use crate::error::{Error, Result};
use crate::grid::{Channels, SparseGrid, Transform};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BooleanOp {
    Union,
    Intersection,
    Difference,
}

crate::named_choices! {
    BooleanOp, "the operation":
    "union" => Union,
    "intersection" => Intersection,
    "difference" => Difference,
}

/// Whether two transforms place voxels identically (to 1e-9 of a voxel).
pub fn same_transform(a: &Transform, b: &Transform) -> bool {
    let tolerance = 1e-9 * a.voxel_size;
    (a.voxel_size - b.voxel_size).abs() <= 1e-9 * a.voxel_size
        && (a.origin - b.origin).abs().max_element() <= tolerance
}

/// The voxels of the grid of `target` whose centres lie in an active voxel of `grid`.
pub fn resample(grid: &SparseGrid, target: Transform) -> SparseGrid {
    let mut out = SparseGrid::new(target, Channels::NONE);
    let h = grid.transform.voxel_size;
    for c in grid.voxels() {
        let centre = grid.transform.index_to_world(c);
        // Target centres q with centre - h/2 <= q < centre + h/2 (voxels are half-open).
        let lo = target
            .world_to_index(centre - glam::DVec3::splat(h / 2.0))
            .ceil()
            .as_i64vec3();
        let hi = (target
            .world_to_index(centre + glam::DVec3::splat(h / 2.0))
            .ceil()
            - glam::DVec3::ONE)
            .as_i64vec3();
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    out.insert([x, y, z]);
                }
            }
        }
    }
    out
}

/// `a op b` as a plain voxel set on `a`'s transform. Grids on different transforms are
/// resampled when `allow_resample`, and refused otherwise.
pub fn combine(
    a: &SparseGrid,
    b: &SparseGrid,
    op: BooleanOp,
    allow_resample: bool,
) -> Result<SparseGrid> {
    let resampled;
    let b = if same_transform(&a.transform, &b.transform) {
        b
    } else if allow_resample {
        resampled = resample(b, a.transform);
        &resampled
    } else {
        return Err(Error::InvalidArgument(format!(
            "the grids' transforms differ (voxel size {} at {} against {} at {}): resample the second onto the first (option `resample`), or voxelize both on one grid",
            a.transform.voxel_size, a.transform.origin, b.transform.voxel_size, b.transform.origin
        )));
    };
    let mut out = mask_copy(a);
    match op {
        BooleanOp::Union => out.union(b),
        BooleanOp::Intersection => out.intersection(b),
        BooleanOp::Difference => out.difference(b),
    }
    Ok(out)
}

/// The voxels of `grid` without its channels.
fn mask_copy(grid: &SparseGrid) -> SparseGrid {
    let mut out = SparseGrid::new(grid.transform, Channels::NONE);
    out.union(grid);
    out
}
