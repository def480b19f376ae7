//! Placing a mesh in index space.
//!
//! With `Resolution(R)` the voxel size is `longest bbox axis / R` and the bbox minimum lies
//! on the lower face of voxel 0, so the bbox spans voxels `0..R` along its longest axis (and
//! proportionally fewer on the others). No padding is stored in the sparse grid: surfaces
//! reach at most one voxel beyond the bbox (index -1 and R), and dense consumers such as the
//! flood fill add their own two-voxel border. `VoxelSize(h)` uses `h` with the same placement.

use super::Aabb;
use crate::error::{Error, Result};
use crate::grid::{CoordBox, Transform};
use glam::DVec3;

/// Voxels along the longest bounding-box axis when neither a resolution nor a voxel size is
/// given.
pub const DEFAULT_RESOLUTION: u32 = 256;

/// How to choose the voxel size for a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridFit {
    /// Voxels along the longest bbox axis.
    Resolution(u32),
    /// Voxel edge length in world units.
    VoxelSize(f64),
    /// Voxels along the longest bbox axis, with the centre of voxel (0, 0, 0) at a given
    /// world position.
    ResolutionAt(u32, DVec3),
    /// A placement decided beforehand (one grid shared by several meshes, e.g. the frames of
    /// an animation, or a voxel size and origin given): used as it is, whatever the mesh's
    /// box.
    Placed(Transform),
    /// A world box the grid covers, placed in it as the other fits place a mesh's box:
    /// only the voxels whose centres lie in the box are kept.
    Within(Transform, Aabb),
}

impl GridFit {
    /// The fit the front ends' options ask for: the voxel size when given, else the
    /// resolution, else `DEFAULT_RESOLUTION` voxels along the longest axis.
    pub fn from_options(resolution: Option<u32>, voxel_size: Option<f64>) -> GridFit {
        match (resolution, voxel_size) {
            (_, Some(h)) => GridFit::VoxelSize(h),
            (Some(r), None) => GridFit::Resolution(r),
            (None, None) => GridFit::Resolution(DEFAULT_RESOLUTION),
        }
    }

    /// The fit with the centre of voxel (0, 0, 0) at `origin`, when given: the grid then
    /// lies where the caller's other grids lie (`[0, 0, 0]`: every centre on a multiple of
    /// the voxel size, as trimesh places them; the mesh's low corner: as Open3D does).
    pub fn with_origin(self, origin: Option<DVec3>) -> GridFit {
        match (self, origin) {
            (GridFit::Resolution(r), Some(o)) => GridFit::ResolutionAt(r, o),
            (GridFit::VoxelSize(h), Some(o)) => GridFit::Placed(Transform::new(o, h)),
            (fit, _) => fit,
        }
    }

    /// The fit placed in the world box `bounds`, when given, instead of the mesh's box; the
    /// job then keeps only the voxels whose centres lie in it.
    pub fn within(self, bounds: Option<Aabb>) -> Result<GridFit> {
        let Some(b) = bounds else {
            return Ok(self);
        };
        if !(b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()) {
            return Err(Error::InvalidArgument(format!(
                "bounds must be two finite corners, low then high, got {} and {}",
                b.min, b.max
            )));
        }
        Ok(GridFit::Within(fit_transform(&b, self)?, b))
    }

    /// The voxels whose centres lie in the box the fit keeps (`Within`), on its transform.
    pub fn kept_voxels(&self) -> Option<CoordBox> {
        let GridFit::Within(t, b) = self else {
            return None;
        };
        let (lo, hi) = (t.world_to_index(b.min), t.world_to_index(b.max));
        Some(CoordBox {
            min: lo.to_array().map(|v| v.ceil() as i64),
            max: hi.to_array().map(|v| v.floor() as i64),
        })
    }
}

/// The transform that places `bbox` in index space as described in the module docs. Every
/// fit's voxel size and origin are checked here, whichever front end gave them.
pub fn fit_transform(bbox: &Aabb, fit: GridFit) -> Result<Transform> {
    let h = voxel_size(bbox, fit)?;
    let origin = match fit {
        GridFit::Placed(t) | GridFit::Within(t, _) => t.origin,
        GridFit::ResolutionAt(_, origin) => origin,
        GridFit::Resolution(_) | GridFit::VoxelSize(_) => bbox.min + 0.5 * h,
    };
    if !origin.is_finite() {
        return Err(Error::InvalidArgument(format!(
            "the origin must be three finite numbers, got {origin}"
        )));
    }
    Ok(Transform::new(origin, h))
}

/// The voxel size `fit` gives `bbox`.
fn voxel_size(bbox: &Aabb, fit: GridFit) -> Result<f64> {
    let longest = bbox.extent().max_element();
    match fit {
        GridFit::Placed(t) | GridFit::Within(t, _) => {
            voxel_size(bbox, GridFit::VoxelSize(t.voxel_size))
        }
        GridFit::ResolutionAt(r, _) => voxel_size(bbox, GridFit::Resolution(r)),
        GridFit::Resolution(0) => Err(Error::InvalidArgument(
            "resolution must be at least 1".into(),
        )),
        GridFit::Resolution(r) if longest > 0.0 => Ok(longest / r as f64),
        GridFit::Resolution(_) => Err(Error::InvalidArgument(
            "the mesh has zero extent; give a voxel size (option `voxel_size`) instead of a resolution"
                .into(),
        )),
        // Volumes and masses need h^3: refuse sizes whose cube overflows.
        GridFit::VoxelSize(h) if h > 0.0 && h.powi(3).is_finite() => Ok(h),
        GridFit::VoxelSize(h) => Err(Error::InvalidArgument(format!(
            "voxel size must be a positive number whose cube is finite, got {h:?}"
        ))),
    }
}

/// The voxels covering `bbox` on `transform`, one more on every side: a dense volume in which
/// every voxel centre inside the box has outside neighbours around it.
pub fn index_box(bbox: &Aabb, transform: &Transform) -> CoordBox {
    let (lo, hi) = (
        transform.world_to_index(bbox.min),
        transform.world_to_index(bbox.max),
    );
    CoordBox {
        min: lo.to_array().map(|v| v.floor() as i64 - 1),
        max: hi.to_array().map(|v| v.ceil() as i64 + 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn resolution_spans_the_longest_axis() {
        let b = Aabb {
            min: DVec3::new(-1.0, 0.0, 2.0),
            max: DVec3::new(3.0, 1.0, 2.5),
        };
        let t = fit_transform(&b, GridFit::Resolution(8)).unwrap();
        assert_eq!(t.voxel_size, 0.5);
        assert_eq!(t.world_to_voxel(b.min + 1e-9), [0, 0, 0]);
        assert_eq!(t.world_to_voxel(b.max - 1e-9), [7, 1, 0]);
        assert!(fit_transform(&b, GridFit::Resolution(0)).is_err());
        assert!(fit_transform(&b, GridFit::VoxelSize(f64::NAN)).is_err());
        let elsewhere = Aabb {
            min: DVec3::splat(10.0),
            max: DVec3::splat(11.0),
        };
        assert_eq!(fit_transform(&elsewhere, GridFit::Placed(t)).unwrap(), t);
    }
}
