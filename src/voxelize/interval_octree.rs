//! Implicit surfaces by interval octree (Stolte & Kaufman): the bounding cube is subdivided
//! recursively; a cell is dropped when the interval of F over it excludes 0, and the cells left
//! at the finest level are the voxels. Every level envelops the surface (a cell holding a
//! surface point is never dropped, since the interval encloses every value), so the cells kept
//! at each level form the paper's hierarchical voxel model, each cell's parent kept above it.
//!
//! Cells on the axis of spherical or cylindrical coordinates (θ undefined) cannot be bounded
//! usefully; they are subdivided on, and at the finest level split `AXIS_DEPTH` times more
//! before being bounded with θ in [-π, π]. Normals are the normalized Cartesian gradient of F at
//! voxel centres (forward-mode through the coordinate conversion).

use super::Progress;
use crate::error::{Error, Result};
use crate::grid::{Channels, Coord, Leaf, SparseGrid, Transform};
use crate::implicit::{BoxTest, Dual, Formula, Interval, Split, test_box};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Extra halvings of a finest-level cell that contains the axis.
const AXIS_DEPTH: u32 = 4;

#[derive(Clone, Copy, Debug)]
pub struct OctreeOptions {
    /// Voxels along the longest side of the bounds.
    pub resolution: u32,
    /// Also look for the surface at negative r (spherical and cylindrical): r is a distance,
    /// r >= 0, unless asked (the paper: "points with r < 0" are significant for some surfaces).
    pub both_signs: bool,
    /// Keep every level of the octree, not only the finest.
    pub levels: bool,
    /// Stop with `Error::TooLarge` once the surface holds more 8^3 leaves than this: how much
    /// of its box a formula's surface fills is only known while it is voxelized (`0*x` is zero
    /// everywhere).
    pub max_leaves: Option<u64>,
}

impl Default for OctreeOptions {
    fn default() -> Self {
        OctreeOptions {
            resolution: 256,
            both_signs: false,
            levels: false,
            max_leaves: None,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OctreeStats {
    /// Cells whose interval was computed.
    pub cells_tested: u64,
    pub voxels: u64,
    /// Finest-level cells on the axis that needed the extra split.
    pub axis_cells: u64,
    pub depth: u32,
}

pub struct OctreeOutput {
    /// The finest level, with unit normals.
    pub surface: SparseGrid,
    /// With `levels`: level 0 (one cell, the root) to the finest, each with its own voxel
    /// size; empty otherwise.
    pub levels: Vec<SparseGrid>,
    pub stats: OctreeStats,
}

/// Voxelizes F = 0 inside `[min, max]`.
pub fn voxelize_implicit(
    formula: &Formula,
    min: DVec3,
    max: DVec3,
    options: &OctreeOptions,
    progress: &Progress,
) -> Result<OctreeOutput> {
    let extent = (max - min).max_element();
    if !(extent.is_finite() && extent > 0.0 && (max - min).min_element() > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "the bounds {min} .. {max} must be a box with positive size on every axis"
        )));
    }
    if options.resolution == 0 || options.resolution > 1 << 16 {
        return Err(Error::InvalidArgument(format!(
            "resolution {} must be between 1 and 65536",
            options.resolution
        )));
    }
    let h = extent / options.resolution as f64;
    let cells = ((max - min) / h).ceil().as_i64vec3().to_array();
    let depth = depth_of(options.resolution);
    let run = Run {
        formula,
        min,
        h,
        cells,
        depth,
        options: *options,
        divides: formula.tape.divides(),
    };
    // Expand the top levels serially; the subtrees below run in parallel.
    let top_level = depth.min(TOP_LEVEL);
    let mut frontier = vec![(0u32, [0i64; 3])];
    let mut top = Partial::new(&run);
    // At resolution 1 the root cell is the finest: it has no parent to test it.
    if depth == 0 {
        run.keep(0, [0; 3], &mut top);
    }
    while frontier.first().is_some_and(|f| f.0 < top_level) {
        let mut next = Vec::new();
        for (level, c) in frontier {
            next.extend(run.children(level, c, &mut top));
        }
        frontier = next;
    }
    progress.advance(8u64.pow(top_level) - frontier.len() as u64);
    let leaves = AtomicU64::new(top.surface.leaf_count() as u64);
    let budget = options.max_leaves.unwrap_or(u64::MAX);
    let parts = frontier
        .par_iter()
        .fold(
            || Partial::new(&run),
            |mut part, &(level, c)| {
                // Once cancelled or over the budget, the remaining subtrees are skipped.
                if !progress.stopped() && leaves.load(Ordering::Relaxed) <= budget {
                    let before = part.surface.leaf_count() as u64;
                    run.descend(level, c, &mut part);
                    let added = part.surface.leaf_count() as u64 - before;
                    leaves.fetch_add(added, Ordering::Relaxed);
                    progress.advance(1);
                }
                part
            },
        )
        .reduce(|| Partial::new(&run), Partial::merge);
    progress.check()?;
    let leaves = leaves.into_inner();
    if leaves > budget {
        // The budget is what the memory allows: the surface so far needs that in proportion.
        let available_mib = crate::system::available_memory_bytes().unwrap_or(0) >> 20;
        return Err(Error::TooLarge {
            estimated_mib: (available_mib as f64 * leaves as f64 / budget.max(1) as f64) as u64,
            available_mib,
            detail: format!(
                "the surface filled {leaves} leaves of 8^3 voxels before it was stopped, more \
                 than the memory allows ({budget}); the formula is zero on much of the box: \
                 lower the resolution or raise the memory limit"
            ),
        });
    }
    let mut all = top.merge(parts);
    all.stats.depth = depth;
    all.stats.voxels = all.surface.voxel_count();
    Ok(OctreeOutput {
        surface: all.surface,
        levels: all.levels,
        stats: all.stats,
    })
}

/// What `progress` counts up to: the cells of the level where the parallel subtrees start.
pub fn progress_total(options: &OctreeOptions) -> u64 {
    8u64.pow(depth_of(options.resolution).min(TOP_LEVEL))
}

fn depth_of(resolution: u32) -> u32 {
    (resolution.max(1) as f64).log2().ceil() as u32
}

/// Subtrees start at this level (512 of them, for the threads to share).
const TOP_LEVEL: u32 = 3;

struct Run<'a> {
    formula: &'a Formula,
    min: DVec3,
    h: f64,
    /// Voxels per axis inside the bounds.
    cells: [i64; 3],
    depth: u32,
    options: OctreeOptions,
    /// Whether the formula divides: then boxes are evaluated as split intervals, which
    /// keep a pole out of the enclosure (plain intervals are faster otherwise).
    divides: bool,
}

struct Partial {
    surface: SparseGrid,
    levels: Vec<SparseGrid>,
    stats: OctreeStats,
    slots: Vec<Interval>,
    split_slots: Vec<Split>,
    dual_slots: Vec<Dual>,
}

impl Partial {
    fn new(run: &Run) -> Partial {
        let channels = Channels {
            normal: true,
            ..Channels::NONE
        };
        let levels = if run.options.levels {
            (0..=run.depth)
                .map(|l| SparseGrid::new(run.level_transform(l), channels))
                .collect()
        } else {
            Vec::new()
        };
        Partial {
            surface: SparseGrid::new(run.level_transform(run.depth), channels),
            levels,
            stats: OctreeStats::default(),
            slots: Vec::new(),
            split_slots: Vec::new(),
            dual_slots: Vec::new(),
        }
    }

    fn merge(mut self, other: Partial) -> Partial {
        let with_normals = |dst: &mut Leaf, src: &Leaf| {
            let (dn, sn) = (dst.normal.as_mut().unwrap(), src.normal.as_ref().unwrap());
            for n in src.offsets() {
                dn[n] = sn[n];
            }
            for w in 0..8 {
                dst.mask[w] |= src.mask[w];
            }
        };
        self.surface.merge_with(other.surface, with_normals);
        for (mine, theirs) in self.levels.iter_mut().zip(other.levels) {
            mine.merge_with(theirs, with_normals);
        }
        self.stats.cells_tested += other.stats.cells_tested;
        self.stats.axis_cells += other.stats.axis_cells;
        self
    }
}

impl Run<'_> {
    /// Cells of level `l` are `2^(depth - l)` voxels wide; voxel (0,0,0) starts at `min`.
    fn level_transform(&self, l: u32) -> Transform {
        let size = self.h * (1u64 << (self.depth - l)) as f64;
        Transform::new(self.min + DVec3::splat(size / 2.0), size)
    }

    /// The world box of cell `c` at level `l`, moved out to cover rounding of its corners.
    fn cell_box(&self, l: u32, c: Coord) -> [Interval; 3] {
        let size = self.h * (1u64 << (self.depth - l)) as f64;
        std::array::from_fn(|a| {
            let lo = self.min[a] + c[a] as f64 * size;
            Interval::new(lo, lo + size).widened()
        })
    }

    /// Whether any voxel of cell `c` at level `l` lies inside the bounds.
    fn inside(&self, l: u32, c: Coord) -> bool {
        let shift = self.depth - l;
        (0..3).all(|a| (c[a] << shift) < self.cells[a])
    }

    fn test(&self, b: [Interval; 3], whole_axis: bool, part: &mut Partial) -> BoxTest {
        part.stats.cells_tested += 1;
        let f = self.formula;
        let both = self.options.both_signs;
        if self.divides {
            test_box(f, b, both, whole_axis, &mut part.split_slots)
        } else {
            test_box(f, b, both, whole_axis, &mut part.slots)
        }
    }

    /// The kept children of a kept cell (recording them per level).
    fn children(&self, level: u32, c: Coord, part: &mut Partial) -> Vec<(u32, Coord)> {
        if level == 0 && self.options.levels {
            self.record(0, c, part);
        }
        let mut kept = Vec::new();
        for k in 0..8 {
            let child = [
                2 * c[0] + (k & 1),
                2 * c[1] + (k >> 1 & 1),
                2 * c[2] + (k >> 2 & 1),
            ];
            if self.keep(level + 1, child, part) {
                kept.push((level + 1, child));
            }
        }
        kept
    }

    /// Tests a cell, and records it when kept (finest-level cells become voxels).
    fn keep(&self, level: u32, c: Coord, part: &mut Partial) -> bool {
        if !self.inside(level, c) {
            return false;
        }
        let kept = match self.test(self.cell_box(level, c), false, part) {
            BoxTest::Empty => false,
            BoxTest::MayContain => true,
            BoxTest::Undecided if level < self.depth => true,
            BoxTest::Undecided => {
                part.stats.axis_cells += 1;
                let corner =
                    DVec3::from_array(std::array::from_fn(|a| self.min[a] + c[a] as f64 * self.h));
                self.axis_cell(corner, self.h, 1, part)
            }
        };
        if kept {
            if self.options.levels {
                self.record(level, c, part);
            }
            if level == self.depth {
                let normal = self.normal(level, c, &mut part.dual_slots);
                set_with_normal(&mut part.surface, c, normal);
            }
        }
        kept
    }

    /// Records a kept cell in its level's grid, with the normal at its centre (each voxel of
    /// every level stores the normal vector, as the paper's octree does).
    fn record(&self, level: u32, c: Coord, part: &mut Partial) {
        let normal = self.normal(level, c, &mut part.dual_slots);
        set_with_normal(&mut part.levels[level as usize], c, normal);
    }

    /// Whether some sub-cell of the axis cell with corner `lo` and side `size`, split
    /// `extra` times so far, may hold surface.
    fn axis_cell(&self, lo: DVec3, size: f64, extra: u32, part: &mut Partial) -> bool {
        let half = size / 2.0;
        for k in 0..8 {
            let offset = DVec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64);
            let sub = lo + offset * half;
            let b: [Interval; 3] =
                std::array::from_fn(|a| Interval::new(sub[a], sub[a] + half).widened());
            let found = match self.test(b, extra == AXIS_DEPTH, part) {
                BoxTest::Empty => false,
                BoxTest::MayContain => true,
                BoxTest::Undecided => self.axis_cell(sub, half, extra + 1, part),
            };
            if found {
                return true;
            }
        }
        false
    }

    fn descend(&self, level: u32, c: Coord, part: &mut Partial) {
        if level == self.depth {
            return;
        }
        for (l, child) in self.children(level, c, part) {
            self.descend(l, child, part);
        }
    }

    /// Unit Cartesian gradient of F at the centre of cell `c` of `level` (zero where
    /// undefined).
    fn normal(&self, level: u32, c: Coord, slots: &mut Vec<Dual>) -> [f32; 3] {
        let size = self.h * f64::from(1u32 << (self.depth - level));
        let p = std::array::from_fn(|a| self.min[a] + (c[a] as f64 + 0.5) * size);
        match self.formula.gradient_at(p, slots).try_normalize() {
            Some(n) => n.as_vec3().into(),
            None => [0.0; 3],
        }
    }
}

/// Turns voxel `c` of `grid` (which has normals) on, with `normal`.
fn set_with_normal(grid: &mut SparseGrid, c: Coord, normal: [f32; 3]) {
    let mut acc = grid.accessor();
    let (leaf, n) = acc.leaf_mut(c);
    leaf.set_on(n);
    leaf.normal.as_mut().expect("the grid has normals")[n] = normal;
}
