//! The leaves of a CSG tree as solids over one dense volume, each voxel classified by its
//! centre: boxes, cylinders and spheres exactly; formulas by the sign of F (inside where
//! F < 0); meshes by their inside rule (`inside_rule`: the winding number, or for
//! inconsistently oriented closed meshes depth layers, exact ray parity at the centres); voxel
//! grids from .vdb files as they are, resampled when their transform differs.

use super::csg_placement::placed_box;
use crate::error::{Error, Result};
use crate::grid::{CoordBox, DenseMask, SparseGrid, Transform};
use crate::implicit::Formula;
use crate::mesh::{Aabb, Mesh, index_box};
use crate::ops::csg::{resample, same_transform};
use crate::ops::flood_xyz::DEFAULT_GRAYSTACK;
use crate::progress::Progress;
use crate::shapes::{Cuboid, Cylinder, Sphere};
use crate::solids::depth_layers::{DepthLayerOptions, depth_layer_solid};
use crate::solids::inside_rule::{Inside, InsideRule, choose_inside};
use crate::solids::winding_inside::winding_inside;
use glam::{DAffine3, DVec3};
use rayon::prelude::*;

/// A solid leaf given by its shape, in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    Cuboid(Cuboid),
    Cylinder(Cylinder),
    Sphere(Sphere),
}

impl Primitive {
    pub fn contains(&self, p: DVec3) -> bool {
        match self {
            Primitive::Cuboid(b) => b.contains(p),
            Primitive::Cylinder(c) => c.contains(p),
            Primitive::Sphere(s) => s.contains(p),
        }
    }

    /// A short description for summaries, its numbers as typed: to 15 significant digits,
    /// so that a cylinder's base found back from its centre reads -0.1, not -0.09999999999999998.
    pub fn describe(&self) -> String {
        let n = |x: f64| {
            let typed: f64 = format!("{x:.14e}").parse().unwrap_or(x);
            format!("{typed}")
        };
        let v = |p: DVec3| format!("({}, {}, {})", n(p.x), n(p.y), n(p.z));
        match self {
            Primitive::Cuboid(b) => format!("box {} .. {}", v(b.min), v(b.max)),
            Primitive::Cylinder(c) => format!(
                "cylinder from {} along {} radius {} height {}",
                v(c.ends()[0]),
                v(c.axis),
                n(c.radius),
                n(c.height)
            ),
            Primitive::Sphere(s) => format!("sphere {} radius {}", v(s.center), n(s.radius)),
        }
    }

    pub fn bounds(&self) -> Aabb {
        match self {
            Primitive::Cuboid(b) => b.bounds(),
            Primitive::Cylinder(c) => c.bounds(),
            Primitive::Sphere(s) => s.bounds(),
        }
    }
}

/// The voxels of `bbox` whose centres, within `bounds`, satisfy `inside`; `scratch` makes
/// per-thread state.
fn fill_centres<S>(
    bbox: CoordBox,
    transform: &Transform,
    bounds: &Aabb,
    scratch: impl Fn() -> S + Sync,
    inside: impl Fn(&mut S, DVec3) -> bool + Sync,
) -> Result<DenseMask> {
    let mut mask = DenseMask::new(bbox)?;
    let near = index_box(bounds, transform);
    let lo: [i64; 3] = std::array::from_fn(|a| near.min[a].max(bbox.min[a]));
    let hi: [i64; 3] = std::array::from_fn(|a| near.max[a].min(bbox.max[a]));
    if (0..3).any(|a| lo[a] > hi[a]) {
        return Ok(mask);
    }
    let runs: Vec<Vec<(usize, usize)>> = (lo[0]..=hi[0])
        .into_par_iter()
        .map_init(&scratch, |state, x| {
            let mut runs: Vec<(usize, usize)> = Vec::new();
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if inside(state, transform.index_to_world([x, y, z])) {
                        let i = mask.index([x, y, z]);
                        match runs.last_mut() {
                            Some(r) if r.1 + 1 == i => r.1 = i,
                            _ => runs.push((i, i)),
                        }
                    }
                }
            }
            runs
        })
        .collect();
    for (a, b) in runs.into_iter().flatten() {
        mask.set_index_range(a, b);
    }
    Ok(mask)
}

pub fn primitive_solid(
    p: &Primitive,
    to_local: &DAffine3,
    transform: &Transform,
    bbox: CoordBox,
) -> Result<DenseMask> {
    let bounds = placed_box(&p.bounds(), &to_local.inverse());
    fill_centres(
        bbox,
        transform,
        &bounds,
        || (),
        |_, c| p.contains(to_local.transform_point3(c)),
    )
}

/// Voxels whose centres lie in `bounds` (world) with F < 0 at the centre mapped by
/// `to_local` into the formula's frame.
pub fn formula_solid(
    f: &Formula,
    bounds: &Aabb,
    to_local: &DAffine3,
    transform: &Transform,
    bbox: CoordBox,
) -> Result<DenseMask> {
    fill_centres(
        bbox,
        transform,
        bounds,
        || Vec::with_capacity(f.tape.len()),
        |slots, c| {
            let vars = f.coordinates_of(to_local.transform_point3(c).to_array());
            f.tape.eval_with(vars, slots) < 0.0
        },
    )
}

/// A mesh's centres inside it by the automatic inside rule: its winding number, or where its
/// orientation is inconsistent, depth layers (voxels they cannot decide are an error naming
/// the mesh).
pub fn mesh_solid(
    mesh: &Mesh,
    transform: &Transform,
    bbox: CoordBox,
    options: &DepthLayerOptions,
) -> Result<DenseMask> {
    let choice = choose_inside(InsideRule::Auto, mesh, "a CSG mesh leaf needs an inside")?;
    if let Inside::Winding(caps) = &choice.inside {
        return match index_box(&mesh.bbox(), transform).intersection(&bbox) {
            Some(region) => {
                let (grid, _) = winding_inside(mesh, caps, *transform, region, &Progress::none())?
                    .into_grids(*transform);
                DenseMask::from_grid(&grid, bbox)
            }
            None => DenseMask::new(bbox),
        };
    }
    let s = depth_layer_solid(mesh, transform, bbox, options, &Progress::none())?;
    if s.stats.unclassified_voxels > 0 {
        return Err(Error::InvalidArgument(format!(
            "{}: {} voxels cannot be classified by depth layers (crossed more than four times \
             along all {} directions)",
            mesh.source.display(),
            s.stats.unclassified_voxels,
            options.directions.len()
        )));
    }
    Ok(s.inside)
}

/// A closed Catmull-Clark control mesh's solid: its voxelized limit surface and the inside
/// flooded from seeds (Lai & Cheng), surface voxels included.
pub fn subdivision_leaf(
    control: &crate::subd::ControlMesh,
    transform: &Transform,
    bbox: CoordBox,
) -> Result<DenseMask> {
    let made = crate::solids::subdivision::subdivision_solid(
        control,
        *transform,
        &Default::default(),
        DEFAULT_GRAYSTACK,
        &Progress::none(),
    )?;
    let whole = super::flooded_mesh::SurfaceAndInside::of(made.surface.surface, made.solid).whole;
    DenseMask::from_grid(&whole, bbox)
}

/// The active voxels of `grid` on `transform` (resampled when the transforms differ) that
/// lie in `bbox`; placed elsewhere (`to_local` not the identity), the centres whose image in
/// the grid's frame lies in an active voxel.
pub fn grid_solid(
    grid: &SparseGrid,
    to_local: &DAffine3,
    transform: &Transform,
    bbox: CoordBox,
) -> Result<DenseMask> {
    if *to_local != DAffine3::IDENTITY {
        let Some(local) = grid_bounds(grid) else {
            return DenseMask::new(bbox);
        };
        let bounds = placed_box(&local, &to_local.inverse());
        return fill_centres(
            bbox,
            transform,
            &bounds,
            || (),
            |_, c| {
                let i = grid.transform.world_to_index(to_local.transform_point3(c));
                grid.contains(i.round().as_i64vec3().to_array())
            },
        );
    }
    let resampled;
    let grid = if same_transform(&grid.transform, transform) {
        grid
    } else {
        resampled = resample(grid, *transform);
        &resampled
    };
    DenseMask::from_grid(grid, bbox)
}

/// The world box a grid's active voxels cover.
pub fn grid_bounds(grid: &SparseGrid) -> Option<Aabb> {
    let b = grid.bbox()?;
    let h = grid.transform.voxel_size / 2.0;
    Some(Aabb {
        min: grid.transform.index_to_world(b.min) - h,
        max: grid.transform.index_to_world(b.max) + h,
    })
}

/// Volume (voxel centres where F < 0) and face-weighted area (normals from the gradient of F)
/// of a formula's solid at `resolution` voxels along the longest side of `bounds`.
pub fn measure_formula_solid(
    formula: &crate::implicit::Formula,
    bounds: &crate::mesh::Aabb,
    resolution: u32,
) -> crate::error::Result<(f64, f64)> {
    use crate::mesh::{GridFit, fit_transform, index_box};
    let transform = fit_transform(bounds, GridFit::Resolution(resolution))?;
    let bbox = index_box(bounds, &transform);
    let solid = formula_solid(formula, bounds, &DAffine3::IDENTITY, &transform, bbox)?;
    let volume = solid.count() as f64 * transform.voxel_size.powi(3);
    let (area, _) = crate::ops::surface_area::face_weighted_area(&solid, &transform, |p| {
        formula.gradient_at(p.to_array(), &mut Vec::new())
    });
    Ok((volume, area))
}
