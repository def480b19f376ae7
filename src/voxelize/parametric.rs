//! Catmull-Clark surfaces voxelized in parameter space (Lai & Cheng §4): every patch is
//! pre-split k x k, and each sub-patch is halved in u and v until the voxels (eq. 2,
//! `floor(p + 1/2)`) of its four corners pass the 6-, 18- or 26-adjacency test, or its side
//! falls below the depth guard `1 / max(M)`. The voxels of all corners evaluated are the
//! output, each with the unit normal of the first point that landed in it; a voxel that also
//! receives a point whose normal disagrees (dot <= 0) is marked as crossed by two sheets
//! (§6.1). Surface area is the sum of the final sub-patch quads (§7.2).
//!
//! The paper proves (§5) that the output is 6-separating for every N, from eq. (3): "every
//! surface point lies in an output voxel". Eq. (3) does not hold for its output, though:
//! adjacent corner voxels do not keep a sub-patch inside them — a small curved or tilted piece
//! whose corners fall in voxels A and B can pass through a third voxel C that no sample lands
//! in (with 26-adjacency it cannot hold at all: the voxels a plane touches form a thicker set
//! than any 26-adjacent one). Flooding finds the output 6-separating all the same, but not
//! 26-separating even for N = 6: a sheet can clip the corner of a voxel that holds no sample,
//! leaving two corner-sharing empty voxels on either side.
//!
//! Correction (option `enclose`): a sub-patch is accepted only when a bound of it (the box of
//! its Bezier control points, or of its control ring near an extraordinary vertex) touches no
//! voxel but its corner voxels; otherwise it is halved until the bound is smaller than
//! `ENCLOSE_TOLERANCE` voxels, and then every voxel the bound touches is added (counted in
//! `guard_voxels`; this is where the surface crosses a voxel edge or corner in a sliver no
//! corner sample lands in; each such voxel counted once). The output is then every voxel the surface touches (eq. 3),
//! whatever N; every output voxel holds an evaluated surface point (eq. 4) or lies within
//! `ENCLOSE_TOLERANCE` of one. The result blocks 26-paths.

use super::Progress;
use crate::error::Result;
use crate::grid::{Adjacency, Channels, Coord, Leaf, SparseGrid, Transform};
use crate::subd::{ControlMesh, LimitSample, LimitSurface};
use glam::DVec3;
use rayon::prelude::*;

#[derive(Clone, Copy, Debug)]
pub struct ParametricOptions {
    /// The adjacency the corner voxels of a final sub-patch must satisfy.
    pub adjacency: Adjacency,
    /// Each patch is first split into `presplit x presplit` sub-patches (the paper: 8).
    pub presplit: u32,
    /// Refine until each sub-patch's bound lies in its corner voxels, so that every voxel the
    /// surface touches is output (see the module docs).
    pub enclose: bool,
}

impl Default for ParametricOptions {
    fn default() -> Self {
        ParametricOptions {
            adjacency: Adjacency::TwentySix,
            presplit: 8,
            enclose: false,
        }
    }
}

/// What the voxelizer did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ParametricStats {
    pub patches: u64,
    /// Limit-surface evaluations.
    pub evaluations: u64,
    /// Final sub-patches (the quads of the area sum).
    pub subpatches: u64,
    /// Evaluations a uniform grid on every patch would need at that patch's finest spacing.
    pub uniform_evaluations: u64,
    /// Sub-patches stopped by the depth guard while the test still failed.
    pub depth_guard_stops: u64,
    /// Sub-patches halved because their bound left their corner voxels (`enclose`).
    pub enclose_splits: u64,
    /// Voxels a bound smaller than `ENCLOSE_TOLERANCE` touched (`enclose`), each once; many
    /// also hold a sample.
    pub guard_voxels: u64,
    /// Surface area from the final sub-patch quads, in world units.
    pub area: f64,
    pub voxels: u64,
    /// Voxels crossed by sheets with opposite normals.
    pub opposite_voxels: u64,
}

pub struct ParametricOutput {
    /// Surface voxels with a unit normal each.
    pub surface: SparseGrid,
    /// Voxels crossed by sheets whose normals disagree (§6.1).
    pub opposite: SparseGrid,
    pub stats: ParametricStats,
}

/// Voxelizes the limit surface of `control` on the grid of `transform`; `progress` receives
/// the number of patches finished (`control.patch_count()` in all).
pub fn voxelize_subdivision(
    control: &ControlMesh,
    transform: Transform,
    options: &ParametricOptions,
    progress: &Progress,
) -> Result<ParametricOutput> {
    if options.presplit == 0 {
        return Err(crate::Error::InvalidArgument(
            "the pre-split count k must be at least 1".into(),
        ));
    }
    // Catmull-Clark is affine invariant: evaluate directly in voxel index space.
    let mut index_space = control.clone();
    index_space.map_points(|p| transform.world_to_index(p));
    let b = index_space.bbox();
    let extent = (b.max - b.min).max_element().ceil().max(1.0);
    let surface = LimitSurface::new(index_space);
    let run = Run {
        surface: &surface,
        options: *options,
        guard: 1.0 / extent,
    };
    let channels = Channels {
        normal: true,
        ..Channels::NONE
    };
    let Partial {
        grid,
        opposite,
        grazed,
        mut stats,
    } = (0..surface.patch_count())
        .into_par_iter()
        .with_min_len(16)
        .fold(
            || Partial::new(transform, channels),
            |mut part, pid| {
                // Once cancelled, the remaining patches are skipped.
                if !progress.stopped() {
                    run.patch(pid, &mut part);
                    progress.advance(1);
                }
                part
            },
        )
        .reduce(|| Partial::new(transform, channels), merge_partials);
    progress.check()?;
    stats.area *= transform.voxel_size * transform.voxel_size;
    stats.patches = surface.patch_count() as u64;
    stats.voxels = grid.voxel_count();
    stats.opposite_voxels = opposite.voxel_count();
    stats.guard_voxels = grazed.voxel_count();
    Ok(ParametricOutput {
        surface: grid,
        opposite,
        stats,
    })
}

/// One thread's share of the output.
struct Partial {
    grid: SparseGrid,
    opposite: SparseGrid,
    /// The voxels bounds smaller than `ENCLOSE_TOLERANCE` touched.
    grazed: SparseGrid,
    stats: ParametricStats,
}

impl Partial {
    fn new(transform: Transform, channels: Channels) -> Self {
        Partial {
            grid: SparseGrid::new(transform, channels),
            opposite: SparseGrid::new(transform, Channels::NONE),
            grazed: SparseGrid::new(transform, Channels::NONE),
            stats: ParametricStats::default(),
        }
    }

    /// Adds the voxel of a surface point, keeping the first normal and marking disagreement.
    fn add(&mut self, voxel: Coord, normal: DVec3) {
        let mut acc = self.grid.accessor();
        let (leaf, n) = acc.leaf_mut(voxel);
        let was_on = leaf.is_on(n);
        leaf.set_on(n);
        let normals = leaf.normal.as_mut().expect("surface grid has normals");
        if !was_on {
            normals[n] = normal.as_vec3().into();
        } else if disagree(normals[n], normal.as_vec3().into()) {
            self.opposite.insert(voxel);
        }
    }
}

/// Normals of two sheets through one voxel disagree when their dot product is <= 0.
fn disagree(a: [f32; 3], b: [f32; 3]) -> bool {
    let known = |v: [f32; 3]| v != [0.0; 3];
    known(a) && known(b) && a[0] * b[0] + a[1] * b[1] + a[2] * b[2] <= 0.0
}

fn merge_partials(a: Partial, b: Partial) -> Partial {
    let Partial {
        mut grid,
        mut opposite,
        mut grazed,
        mut stats,
    } = a;
    let Partial {
        grid: other_grid,
        opposite: other_opposite,
        grazed: other_grazed,
        stats: s,
    } = b;
    let mut crossed = Vec::new();
    grid.merge_with(other_grid, |dst: &mut Leaf, src: &Leaf| {
        let before = dst.mask;
        let (dn, sn) = (dst.normal.as_mut().unwrap(), src.normal.as_ref().unwrap());
        for n in src.offsets() {
            if before[n / 64] >> (n % 64) & 1 == 0 {
                dn[n] = sn[n];
            } else if disagree(dn[n], sn[n]) {
                crossed.push(crate::grid::offset_coord(dst.origin, n));
            }
        }
        for w in 0..8 {
            dst.mask[w] |= src.mask[w];
        }
    });
    opposite.union(&other_opposite);
    grazed.union(&other_grazed);
    for c in crossed {
        opposite.insert(c);
    }
    stats.evaluations += s.evaluations;
    stats.subpatches += s.subpatches;
    stats.uniform_evaluations += s.uniform_evaluations;
    stats.depth_guard_stops += s.depth_guard_stops;
    stats.enclose_splits += s.enclose_splits;
    stats.area += s.area;
    Partial {
        grid,
        opposite,
        grazed,
        stats,
    }
}

#[derive(Clone, Copy)]
struct Corner {
    sample: LimitSample,
    voxel: Coord,
}

struct Run<'a> {
    surface: &'a LimitSurface,
    options: ParametricOptions,
    /// The paper's depth guard: stop when a sub-patch side is below 1 / max(M).
    guard: f64,
}

/// The enclosure refinement stops once a sub-patch's bound is this small (in voxels), and
/// outputs the voxels the bound touches: they lie within this distance of the surface.
pub const ENCLOSE_TOLERANCE: f64 = 0.01;

impl Run<'_> {
    fn corner(&self, pid: usize, s: f64, t: f64, part: &mut Partial) -> Corner {
        part.stats.evaluations += 1;
        let sample = self.surface.eval_patch(pid, s, t);
        let p = sample.position;
        Corner {
            sample,
            voxel: [
                (p.x + 0.5).floor() as i64,
                (p.y + 0.5).floor() as i64,
                (p.z + 0.5).floor() as i64,
            ],
        }
    }

    fn patch(&self, pid: usize, part: &mut Partial) {
        let k = self.options.presplit as usize;
        let step = 1.0 / k as f64;
        // The pre-split grid's corners are shared by neighbouring sub-patches: evaluate once.
        let grid: Vec<Corner> = (0..=k)
            .flat_map(|j| (0..=k).map(move |i| (i, j)))
            .map(|(i, j)| self.corner(pid, i as f64 * step, j as f64 * step, part))
            .collect();
        let at = |i: usize, j: usize| grid[j * (k + 1) + i];
        let mut finest = step;
        for j in 0..k {
            for i in 0..k {
                let rect = [
                    i as f64 * step,
                    (i + 1) as f64 * step,
                    j as f64 * step,
                    (j + 1) as f64 * step,
                ];
                let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                self.subpatch(pid, rect, corners, part, &mut finest);
            }
        }
        let per_side = (1.0 / finest).round() as u64 + 1;
        part.stats.uniform_evaluations += per_side * per_side;
    }

    /// VoxelizeSubPatch: corners in the order (u1,v1), (u2,v1), (u2,v2), (u1,v2).
    fn subpatch(
        &self,
        pid: usize,
        rect: [f64; 4],
        c: [Corner; 4],
        part: &mut Partial,
        finest: &mut f64,
    ) {
        let [u1, u2, v1, v2] = rect;
        let size = u2 - u1;
        let done = if self.options.enclose {
            let (lo_exact, hi_exact) = self.surface.bound_patch(pid, u1, u2, v1, v2);
            let (lo, hi) = ((lo_exact + 0.5).floor(), (hi_exact + 0.5).floor());
            if enclosed(lo, hi, &c) {
                true
            } else if (hi_exact - lo_exact).max_element() < ENCLOSE_TOLERANCE {
                for voxel in box_voxels(lo, hi) {
                    part.grazed.insert(voxel);
                    part.add(voxel, c[0].sample.normal);
                }
                true
            } else {
                part.stats.enclose_splits += 1;
                false
            }
        } else if adjacent(self.options.adjacency, &c) {
            true
        } else if size < self.guard {
            part.stats.depth_guard_stops += 1;
            true
        } else {
            false
        };
        if done {
            *finest = finest.min(size);
            part.stats.subpatches += 1;
            let p = c.map(|x| x.sample.position);
            part.stats.area += 0.5 * (p[2] - p[0]).cross(p[3] - p[1]).length();
            for x in &c {
                part.add(x.voxel, x.sample.normal);
            }
            return;
        }
        let (um, vm) = (0.5 * (u1 + u2), 0.5 * (v1 + v2));
        let bottom = self.corner(pid, um, v1, part);
        let right = self.corner(pid, u2, vm, part);
        let top = self.corner(pid, um, v2, part);
        let left = self.corner(pid, u1, vm, part);
        let centre = self.corner(pid, um, vm, part);
        self.subpatch(
            pid,
            [u1, um, v1, vm],
            [c[0], bottom, centre, left],
            part,
            finest,
        );
        self.subpatch(
            pid,
            [um, u2, v1, vm],
            [bottom, c[1], right, centre],
            part,
            finest,
        );
        self.subpatch(
            pid,
            [um, u2, vm, v2],
            [centre, right, c[2], top],
            part,
            finest,
        );
        self.subpatch(
            pid,
            [u1, um, vm, v2],
            [left, centre, top, c[3]],
            part,
            finest,
        );
    }
}

/// Whether every voxel of the box `lo..=hi` (voxel indices) is one of the corner voxels.
fn enclosed(lo: DVec3, hi: DVec3, c: &[Corner; 4]) -> bool {
    // At most four distinct corner voxels: a larger box cannot be covered.
    (hi - lo + DVec3::ONE).element_product() <= 4.0
        && box_voxels(lo, hi).all(|v| c.iter().any(|k| k.voxel == v))
}

fn box_voxels(lo: DVec3, hi: DVec3) -> impl Iterator<Item = Coord> {
    let (lo, hi) = (lo.as_i64vec3(), hi.as_i64vec3());
    (lo.x..=hi.x)
        .flat_map(move |x| (lo.y..=hi.y).flat_map(move |y| (lo.z..=hi.z).map(move |z| [x, y, z])))
}

/// The paper's lines 6-11: the spread of the corner voxels along each axis.
fn adjacent(adjacency: Adjacency, c: &[Corner; 4]) -> bool {
    let mut spread = [0i64; 3];
    for (a, s) in spread.iter_mut().enumerate() {
        let lo = c.iter().map(|k| k.voxel[a]).min().unwrap();
        let hi = c.iter().map(|k| k.voxel[a]).max().unwrap();
        *s = hi - lo;
    }
    let sum: i64 = spread.iter().sum();
    let each_one = spread.iter().all(|&d| d <= 1);
    match adjacency {
        Adjacency::Six => sum <= 1,
        Adjacency::Eighteen => each_one && sum <= 2,
        Adjacency::TwentySix => each_one,
    }
}
