//! The voxel centres inside any mesh by its generalized winding number w (Jacobson et al.
//! 2013): inside where w >= 1/2. Open, self-intersecting, nested and hollow meshes all get the
//! answer w gives; a mesh whose whole winding integrates negative (its surface faces inward as
//! a whole) is read reversed, so an inward-facing mesh keeps its inside.
//!
//! w is split as the caps of `mesh::boundary_caps` allow: w = k - c, with k the integer winding
//! of mesh and caps together, counted exactly by signed ray crossings along z (one column of
//! centres a ray, as ray parity does), and c the caps' own winding number, which is smooth away
//! from the caps and small far from them. A centre is inside where k >= c + 1/2. Blocks of
//! centres are decided together from a proven range of c over each (`WindingTree::bounds`,
//! Barill et al.'s hierarchy with its error bounded): where no integer lies within `AMBIGUOUS`
//! of c + 1/2 over a block, one integer threshold decides all its centres from the crossings
//! alone. Blocks a cap's w = 1/2 sheet passes through are resolved with the caps split around
//! them (`mesh::winding_split`: the caps near the block summed exactly, the far ones by a
//! second-order model with a proven error), into cubes: where the mesh does not pass through a
//! cube, w is smooth there, and where no cap does, c is; a second-order Taylor model around the
//! cube's middle (gradient and Hessian exact from the boundaries, the remainder bounded by
//! their third derivatives) then settles every centre it leaves clear of 1/2. The rest, mostly
//! beside a hole's rim, are evaluated centre by centre, where a bound too loose to decide falls
//! back to the exact sum over the caps. A closed,
//! consistently oriented mesh has no caps: every block's threshold is 1 and the answer is ray
//! crossings alone, as fast as parity and equal to it wherever the mesh does not overlap itself.

use crate::error::Result;
use crate::grid::{Channels, Coord, CoordBox, Leaf, SparseGrid, Transform};
use crate::mesh::Mesh;
use crate::mesh::boundary_caps::BoundaryCaps;
use crate::mesh::inside::{ColumnCrossings, ColumnRule, Crossing};
use crate::mesh::winding::{RimBound, WindingBounds, WindingTree};
use crate::mesh::winding_split::{SplitWinding, Splitter};
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Centres whose winding number lies within this of 1/2 are reported ambiguous: the input
/// leaves them undecided (the sheet a hole's rim spans, where two overlapping parts meet).
pub const AMBIGUOUS: f64 = 0.001;

/// The inside of a mesh by its winding number over a box of voxels.
pub struct WindingInside {
    /// Leaves of the inside centres, for blocks partly inside.
    pub leaves: Vec<Leaf>,
    /// The origins of the 8^3 blocks wholly inside.
    pub full_blocks: Vec<Coord>,
    /// The centres whose winding number lies within `AMBIGUOUS` of 1/2.
    pub ambiguous: SparseGrid,
    /// Whether the mesh was read reversed (its winding integrates negative).
    pub reversed: bool,
}

impl WindingInside {
    /// The inside as one grid (leaves, and whole blocks as tiles), and the ambiguous centres.
    pub fn into_grids(self, t: Transform) -> (SparseGrid, SparseGrid) {
        let mut grid = SparseGrid::from_distinct_leaves(t, Channels::NONE, self.leaves);
        grid.fill_free_leaf_blocks(self.full_blocks);
        (grid, self.ambiguous)
    }
}

/// How a block of centres is decided.
#[derive(Clone, Copy, Debug)]
enum Block {
    /// Inside where the integer winding is at least this.
    Threshold(i32),
    /// The caps' winding number lies in [low, high] (oriented): centres whose integer winding
    /// lies within `AMBIGUOUS` of [low, high] + 1/2 are evaluated one by one.
    Near { low: f64, high: f64 },
}

/// The largest ball `settle_by_model` asks about: half an 8^3 block's diagonal.
const MODEL_REACH: f64 = 4.0 * 1.7320508075688772;

/// Blocks decided by threshold 1 are not listed: the default far from any cap, which the
/// columns' own reading of the integer winding applies (`ColumnRule::Winding`).
const DEFAULT_THRESHOLD: i32 = 1;

/// The edge of the coarsest blocks the caps' range is bounded over.
const TOP_BLOCK: i64 = 128;

/// The integer threshold that decides every centre whose caps' winding lies in [low, high],
/// unless an integer lies within `AMBIGUOUS` of [low, high] + 1/2.
fn threshold(low: f64, high: f64) -> Option<i32> {
    let first = (low + 0.5 - AMBIGUOUS).ceil();
    (first > high + 0.5 + AMBIGUOUS).then_some(first as i32)
}

/// The columns of 8^3 blocks `winding_inside` decides over `region`: the items it counts.
pub fn block_columns(region: CoordBox) -> Vec<(i64, i64)> {
    let aligned = |lo: i64| lo & !7;
    (aligned(region.min[0])..=region.max[0])
        .step_by(8)
        .flat_map(|x| {
            (aligned(region.min[1])..=region.max[1])
                .step_by(8)
                .map(move |y| (x, y))
        })
        .collect()
}

/// The inside centres of `mesh` (closed by `caps`) over `region`, with `transform`;
/// `progress` counts the block columns decided.
pub fn winding_inside(
    mesh: &Mesh,
    caps: &BoundaryCaps,
    transform: Transform,
    region: CoordBox,
    progress: &Progress,
) -> Result<WindingInside> {
    let (points, triangles) = closed_by_caps(mesh, caps);
    let orientation = if winds_reversed(&points, &triangles) {
        -1
    } else {
        1
    };
    let index: Vec<DVec3> = points
        .par_iter()
        .map(|&p| transform.world_to_index(p))
        .collect();
    let corners: Vec<[DVec3; 3]> = caps
        .triangles
        .iter()
        .map(|t| t.map(|v| index[v as usize]))
        .collect();
    // Each cap triangle is (centroid, rim vertex, rim vertex).
    let rim = RimBound::new(corners.iter().map(|&[_, a, b]| [a, b]).collect());
    let fans = WindingTree::of_triangles(corners.clone());
    let caps_winding = Caps {
        fans: &fans,
        rim: &rim,
        splitter: Splitter::new(&corners, &rim),
        orientation,
    };
    let (columns, (special, surface)) = rayon::join(
        || {
            ColumnCrossings::of_triangles(&points, &triangles, &transform, region)
                .read_by(ColumnRule::Winding { orientation })
        },
        || {
            if caps.is_empty() {
                (BTreeMap::new(), WindingTree::of_triangles(Vec::new()))
            } else {
                rayon::join(
                    || classify_blocks(&caps_winding, region),
                    || {
                        let mesh_part = &triangles[..triangles.len() - caps.triangles.len()];
                        surface_near_caps(mesh_part, &index, &fans, region)
                    },
                )
            }
        },
    );
    let context = Context {
        columns: &columns,
        caps: caps_winding,
        surface: &surface,
        region,
        special: &special,
    };
    // Once cancelled, the remaining columns are skipped (the call then fails).
    let parts: Vec<Option<BlockColumn>> = block_columns(region)
        .par_iter()
        .map(|&(x, y)| {
            if progress.stopped() {
                return None;
            }
            let column = context.block_column(x, y);
            progress.advance(1);
            Some(column)
        })
        .collect();
    progress.check()?;
    let mut inside = WindingInside {
        leaves: Vec::new(),
        full_blocks: Vec::new(),
        ambiguous: SparseGrid::new(transform, Channels::NONE),
        reversed: orientation < 0,
    };
    let mut ambiguous = Vec::new();
    for part in parts.into_iter().flatten() {
        inside.leaves.extend(part.leaves);
        inside.full_blocks.extend(part.full_blocks);
        ambiguous.extend(part.ambiguous);
    }
    inside.ambiguous = SparseGrid::from_distinct_leaves(transform, Channels::NONE, ambiguous);
    Ok(inside)
}

/// The mesh's own `triangles` (over `index`, its points in index space) that
/// `settle_by_model` may ask about: it asks whether the mesh comes within a ball of radius at
/// most `MODEL_REACH` only where a cap comes within it too, so triangles farther than twice
/// that from every cap (or beyond that of the region) are never found there.
fn surface_near_caps(
    triangles: &[[u32; 3]],
    index: &[DVec3],
    caps: &WindingTree,
    region: CoordBox,
) -> WindingTree {
    let lo = DVec3::from_array(region.min.map(|v| v as f64)) - MODEL_REACH;
    let hi = DVec3::from_array(region.max.map(|v| v as f64)) + MODEL_REACH;
    WindingTree::of_triangles(
        triangles
            .par_iter()
            .map(|t| t.map(|v| index[v as usize]))
            .filter(|t| {
                let (a, b) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                let centre = 0.5 * (a + b);
                a.cmple(hi).all()
                    && b.cmpge(lo).all()
                    && caps.comes_within(centre, centre.distance(b) + 2.0 * MODEL_REACH)
            })
            .collect(),
    )
}

/// The mesh closed by its caps: their points and triangles together.
pub fn closed_by_caps(mesh: &Mesh, caps: &BoundaryCaps) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut points = mesh.positions.clone();
    points.extend_from_slice(&caps.points);
    let mut triangles = caps.mesh_triangles(mesh);
    triangles.extend_from_slice(&caps.triangles);
    (points, triangles)
}

/// Whether mesh and caps together (`points`, `triangles`) enclose a negative volume (the
/// integral of their winding number): then the mesh faces inward as a whole and is read
/// reversed.
pub fn winds_reversed(points: &[DVec3], triangles: &[[u32; 3]]) -> bool {
    let Some(&first) = points.first() else {
        return false;
    };
    let volume: f64 = triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| points[v as usize] - first);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    volume < 0.0
}

/// The caps' winding number, as the blocks are classified by it.
struct Caps<'a> {
    /// The caps as they close the mesh, clustered: where they pass, and their winding number
    /// with its error.
    fans: &'a WindingTree,
    rim: &'a RimBound,
    /// The same, split around each block whose centres are resolved one by one, and summed
    /// exactly where no bound can tell.
    splitter: Splitter<'a>,
    orientation: i32,
}

impl Caps<'_> {
    /// The range of the caps' (oriented) winding number over the ball of radius `reach` around
    /// `centre`: its value there, its error, and the most the rim lets it change in the ball;
    /// none where a cap comes within the ball (the number jumps across a cap).
    fn range(&self, centre: DVec3, reach: f64) -> Option<(f64, f64)> {
        if self.fans.comes_within(centre, reach) {
            return None;
        }
        let b = self.fans.bounds(centre);
        let spread = b.spread + reach * self.rim.gradient(centre, reach);
        spread.is_finite().then(|| {
            self.oriented(WindingBounds {
                value: b.value,
                spread,
            })
        })
    }

    /// The range of `b` as the orientation reads it: [low, high].
    fn oriented(&self, b: WindingBounds) -> (f64, f64) {
        let o = self.orientation as f64;
        let (x, y) = (b.low() * o, b.high() * o);
        (x.min(y), x.max(y))
    }
}

/// The blocks (8^3, by origin) not decided by the default threshold, found from the coarsest
/// blocks down: a block whose caps' range decides it is not split further.
fn classify_blocks(caps: &Caps, region: CoordBox) -> BTreeMap<Coord, Block> {
    let aligned = |lo: i64| lo.div_euclid(TOP_BLOCK) * TOP_BLOCK;
    let mut tops = Vec::new();
    for x in (aligned(region.min[0])..=region.max[0]).step_by(TOP_BLOCK as usize) {
        for y in (aligned(region.min[1])..=region.max[1]).step_by(TOP_BLOCK as usize) {
            for z in (aligned(region.min[2])..=region.max[2]).step_by(TOP_BLOCK as usize) {
                tops.push([x, y, z]);
            }
        }
    }
    tops.par_iter()
        .flat_map_iter(|&origin| {
            let mut found = Vec::new();
            classify(caps, region, origin, TOP_BLOCK, &mut found);
            found
        })
        .collect()
}

fn classify(
    caps: &Caps,
    region: CoordBox,
    origin: Coord,
    size: i64,
    found: &mut Vec<(Coord, Block)>,
) {
    let last = origin.map(|v| v + size - 1);
    if (0..3).any(|a| last[a] < region.min[a] || origin[a] > region.max[a]) {
        return;
    }
    let half = (size - 1) as f64 / 2.0;
    let centre = DVec3::from_array(origin.map(|v| v as f64)) + half;
    let bounds = caps.range(centre, half * 3f64.sqrt());
    if let Some(m) = bounds.and_then(|(low, high)| threshold(low, high)) {
        if m != DEFAULT_THRESHOLD {
            for_each_block(origin, size, |b| found.push((b, Block::Threshold(m))));
        }
        return;
    }
    if size == 8 {
        let (low, high) = bounds.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        found.push((origin, Block::Near { low, high }));
        return;
    }
    for child in eighths(origin, size) {
        classify(caps, region, child, size / 2, found);
    }
}

/// The origins of the eight cubes of half the edge that make the cube at `origin` of edge
/// `size`.
fn eighths(origin: Coord, size: i64) -> impl Iterator<Item = Coord> {
    let h = size / 2;
    (0..8)
        .map(move |corner| [0, 1, 2].map(|a| origin[a] + if corner >> a & 1 == 1 { h } else { 0 }))
}

/// Calls `f` with the origin of every 8^3 block of the block at `origin` of edge `size`.
fn for_each_block(origin: Coord, size: i64, mut f: impl FnMut(Coord)) {
    for x in (0..size).step_by(8) {
        for y in (0..size).step_by(8) {
            for z in (0..size).step_by(8) {
                f([origin[0] + x, origin[1] + y, origin[2] + z]);
            }
        }
    }
}

struct Context<'a> {
    columns: &'a ColumnCrossings,
    caps: Caps<'a>,
    /// The mesh's own triangles (index space): the winding number is continuous off them.
    surface: &'a WindingTree,
    region: CoordBox,
    special: &'a BTreeMap<Coord, Block>,
}

/// What one column of 8^3 blocks contributes.
#[derive(Default)]
struct BlockColumn {
    leaves: Vec<Leaf>,
    full_blocks: Vec<Coord>,
    ambiguous: Vec<Leaf>,
}

/// The stretches of one column between crossings: centres `first ..= last` (a centre on a
/// crossing lies on the side the tie rule puts it) and the integer winding there.
fn stretches(crossings: &[Crossing], orientation: i32) -> Vec<(i64, i64, i32)> {
    let mut out = Vec::with_capacity(crossings.len() + 1);
    let mut below = i64::MIN;
    let mut k = 0;
    for c in crossings {
        out.push((below, c.after - 1, k * orientation));
        below = c.after;
        // Going up through a surface that faces down enters it.
        k -= c.direction();
    }
    out.push((below, i64::MAX, k * orientation));
    out
}

/// The smallest cube a model is made for: on smaller ones it settles too few
/// centres to pay for itself.
const MODEL_SIZE: i64 = 4;

/// How far beyond a stack of blocks' ball the caps are summed exactly when its centres are
/// resolved (voxels): those farther are modelled, within an error that falls with the fourth
/// power of this.
const FAR_GAP: f64 = 32.0;

/// The height along z of the stacks of blocks that share one split of the caps: two blocks
/// (most blocks resolved one by one lie in pairs along a hole's rim), not more (the far
/// model's error grows with the cube of its ball's radius).
const SPLIT_HEIGHT: i64 = 16;

/// A model's middle centre this close to a cap is not used (voxels).
const ON_CAP: f64 = 1e-9;

/// The winding of a centre outside the region: never inside.
const OUTSIDE_REGION: i32 = i32::MIN;

impl Context<'_> {
    fn block_column(&self, bx: i64, by: i64) -> BlockColumn {
        let special: Vec<(i64, Block)> = self
            .special
            .range([bx, by, i64::MIN]..=[bx, by, i64::MAX])
            .map(|(o, b)| (o[2], *b))
            .collect();
        let is_special = |bz: i64| special.binary_search_by_key(&bz, |s| s.0).is_ok();
        let r = self.region;
        // The inside of each 8^3 block of the column, by its place along z.
        let z0 = r.min[2] & !7;
        let mut masks = vec![[0u64; 8]; ((r.max[2] - z0) / 8 + 1) as usize];
        let slot = |bz: i64| ((bz - z0) / 8) as usize;
        // The integer winding of every centre of the special blocks, by leaf offset.
        let mut windings = vec![[OUTSIDE_REGION; 512]; special.len()];
        let mut out = BlockColumn::default();
        for x in bx.max(r.min[0])..=(bx + 7).min(r.max[0]) {
            let lx = (x - bx) as usize;
            // Blocks of the default threshold: runs of centres with winding >= 1, which the
            // columns read (`ColumnRule::Winding`).
            self.columns.row_spans(x, by, 8, |ly, first, last| {
                let (first, last) = (first.max(r.min[2]), last.min(r.max[2]));
                let mut z = first;
                while z <= last {
                    let bz = z & !7;
                    let end = last.min(bz + 7);
                    if !is_special(bz) {
                        let run = (1u64 << (end - z + 1)) - 1;
                        masks[slot(bz)][lx] |= run << (ly * 8 + (z - bz) as usize);
                    }
                    z = end + 1;
                }
            });
            if special.is_empty() {
                continue;
            }
            for y in by.max(r.min[1])..=(by + 7).min(r.max[1]) {
                let stretches = stretches(self.columns.column(x, y), self.caps.orientation);
                let ly = (y - by) as usize;
                for (&(bz, _), block) in special.iter().zip(&mut windings) {
                    for z in bz.max(r.min[2])..=(bz + 7).min(r.max[2]) {
                        block[lx * 64 + ly * 8 + (z - bz) as usize] = stretches
                            .iter()
                            .find(|s| s.0 <= z && z <= s.1)
                            .map_or(0, |s| s.2);
                    }
                }
            }
        }
        let mut ambiguous: Vec<Leaf> = Vec::new();
        let mut split: Option<(i64, SplitWinding)> = None;
        for (&(bz, block), k) in special.iter().zip(&windings) {
            let origin = [bx, by, bz];
            let mut decided = Decided::default();
            match block {
                Block::Threshold(m) => {
                    for (n, &k) in k.iter().enumerate() {
                        if k != OUTSIDE_REGION && k >= m {
                            decided.inside[n / 64] |= 1 << (n % 64);
                        }
                    }
                }
                Block::Near { low, high } => {
                    if self.settle_by_range(origin, 8, (low, high), k, &mut decided) {
                        let stack = bz.div_euclid(SPLIT_HEIGHT);
                        if split.as_ref().map(|s| s.0) != Some(stack) {
                            split = Some((stack, self.split_around(bx, by, stack)));
                        }
                        let (_, around) = split.as_ref().expect("made for this stack");
                        self.resolve(around, origin, 8, k, &mut decided);
                    }
                }
            }
            masks[slot(bz)] = decided.inside;
            if decided.ambiguous.iter().any(|&w| w != 0) {
                ambiguous.push(Leaf::with_mask(origin, decided.ambiguous));
            }
        }
        for (bz, mask) in (z0..).step_by(8).zip(masks) {
            if mask.iter().all(|&w| w == u64::MAX) {
                out.full_blocks.push([bx, by, bz]);
            } else if mask.iter().any(|&w| w != 0) {
                out.leaves.push(Leaf::with_mask([bx, by, bz], mask));
            }
        }
        out.ambiguous = ambiguous;
        out
    }

    /// The caps split around the `stack`-th stack of `SPLIT_HEIGHT` centres along z in the
    /// column of blocks at (bx, by).
    fn split_around(&self, bx: i64, by: i64, stack: i64) -> SplitWinding {
        let half = [3.5, 3.5, (SPLIT_HEIGHT - 1) as f64 / 2.0];
        let middle = DVec3::new(bx as f64, by as f64, (stack * SPLIT_HEIGHT) as f64)
            + DVec3::from_array(half);
        let reach = DVec3::from_array(half).length();
        self.caps.splitter.around(middle, reach, FAR_GAP)
    }

    /// Decides the centres of the cube at `origin` of edge `size` inside an 8^3 block
    /// (integer windings `k`, by leaf offset), with the caps' number split around the block:
    /// those the second-order model around the cube's middle decides (cubes of `MODEL_SIZE`
    /// and more), those the caps' range over the cube decides from their integer winding alone
    /// (smaller cubes), the rest by the cube's eighths, down to single centres.
    fn resolve(
        &self,
        split: &SplitWinding,
        origin: Coord,
        size: i64,
        k: &[i32; 512],
        decided: &mut Decided,
    ) {
        let pending = cube_centres(origin, size)
            .map(crate::grid::leaf_offset)
            .any(|n| k[n] != OUTSIDE_REGION && !decided.is_settled(n));
        if !pending {
            return;
        }
        if size >= MODEL_SIZE && self.settle_by_model(split, origin, size, k, decided) {
            return;
        }
        if size > 1 && size < MODEL_SIZE {
            let half = (size - 1) as f64 / 2.0;
            let centre = DVec3::from_array(origin.map(|v| v as f64)) + half;
            if let Some(b) = split.range(centre, half * 3f64.sqrt())
                && !self.settle_by_range(origin, size, self.caps.oriented(b), k, decided)
            {
                return;
            }
        }
        if size > 1 {
            for child in eighths(origin, size) {
                self.resolve(split, child, size / 2, k, decided);
            }
            return;
        }
        let n = crate::grid::leaf_offset(origin);
        let p = DVec3::from_array(origin.map(|v| v as f64));
        let (inside, near) = self.evaluate(split, k[n], p);
        decided.settle(n, inside, near);
    }

    /// Settles the centres of the cube at `origin` of edge `size` whose integer winding `k`
    /// the caps' range [low, high] over the cube decides; returns whether any is left.
    fn settle_by_range(
        &self,
        origin: Coord,
        size: i64,
        (low, high): (f64, f64),
        k: &[i32; 512],
        decided: &mut Decided,
    ) -> bool {
        let mut pending = false;
        for n in cube_centres(origin, size).map(crate::grid::leaf_offset) {
            let kn = k[n];
            if kn == OUTSIDE_REGION || decided.is_settled(n) {
                continue;
            }
            let kf = kn as f64;
            if kf <= high + 0.5 + AMBIGUOUS && kf >= low + 0.5 - AMBIGUOUS {
                pending = true;
            } else {
                decided.settle(n, kf > high + 0.5, false);
            }
        }
        pending
    }

    /// Settles the centres of the cube at `origin` of edge `size` (integer windings `k`, by
    /// offset in its block) that a second-order model around the cube's middle centre q
    /// decides. The caps' number c has its gradient and Hessian exactly from the rim (its
    /// Biot-Savart integral and that integral's derivative), and wherever c is smooth along
    /// q + d it lies within |d|^3 / 6 times the rim's bound on its third derivatives of
    /// c(q) + grad c . d + d . H d / 2. Where no cap passes within the cube's ball, c is smooth
    /// there and each centre's own integer winding k gives w = k - c; where the mesh does not
    /// pass, w = k(q) - c is smooth, continuing c smoothly across the caps. Returns whether
    /// every centre is settled.
    fn settle_by_model(
        &self,
        split: &SplitWinding,
        origin: Coord,
        size: i64,
        k: &[i32; 512],
        decided: &mut Decided,
    ) -> bool {
        let middle = origin.map(|v| v + size / 2);
        let kq = k[crate::grid::leaf_offset(middle)];
        if kq == OUTSIDE_REGION {
            return false;
        }
        let q = DVec3::from_array(middle.map(|v| v as f64));
        let reach = (size / 2) as f64 * 3f64.sqrt();
        let caps_smooth = !split.comes_within(q, reach);
        // On a cap the integer winding's tie rule and the caps' number need not agree.
        let winding_smooth =
            !caps_smooth && !self.surface.comes_within(q, reach) && !split.comes_within(q, ON_CAP);
        if !caps_smooth && !winding_smooth {
            return false;
        }
        let Some(model) = split.model(q, reach) else {
            return false;
        };
        let o = self.caps.orientation as f64;
        let most_error = model.most_error(reach);
        let mut all = true;
        for x in origin[0]..origin[0] + size {
            for y in origin[1]..origin[1] + size {
                let (c0, c1, c2) = model.along_z(x as f64, y as f64);
                for z in origin[2]..origin[2] + size {
                    let n = crate::grid::leaf_offset([x, y, z]);
                    if k[n] == OUTSIDE_REGION || decided.is_settled(n) {
                        continue;
                    }
                    let t = (z - middle[2]) as f64;
                    let integer = if caps_smooth { k[n] } else { kq };
                    let from_half = integer as f64 - o * (c0 + t * (c1 + t * c2)) - 0.5;
                    let error = || model.error_at(DVec3::new(x as f64, y as f64, z as f64));
                    if from_half.abs() > most_error + AMBIGUOUS
                        || from_half.abs() > error() + AMBIGUOUS
                    {
                        decided.settle(n, from_half > 0.0, false);
                    } else {
                        all = false;
                    }
                }
            }
        }
        all
    }

    /// Whether the centre `p` of integer winding `k` is inside, and whether its winding number
    /// lies within `AMBIGUOUS` of 1/2: by the caps' tree, or where its bound cannot tell, by
    /// the exact sum.
    fn evaluate(&self, split: &SplitWinding, k: i32, p: DVec3) -> (bool, bool) {
        let o = self.caps.orientation as f64;
        let from_half = |caps: f64| k as f64 - o * caps - 0.5;
        let bounds = split.bounds(p);
        let (d, spread) = (from_half(bounds.value), bounds.spread);
        let d = if d.abs() <= spread || (d.abs() - AMBIGUOUS).abs() <= spread {
            from_half(self.caps.splitter.winding_number(p))
        } else {
            d
        };
        (d >= 0.0, d.abs() <= AMBIGUOUS)
    }
}

/// The centres of the cube at `origin` of edge `size` (a power of two).
fn cube_centres(origin: Coord, size: i64) -> impl Iterator<Item = Coord> {
    let shift = size.trailing_zeros();
    let mask = size - 1;
    (0..size * size * size).map(move |i| {
        [
            origin[0] + (i >> (2 * shift)),
            origin[1] + ((i >> shift) & mask),
            origin[2] + (i & mask),
        ]
    })
}

/// The centres of one 8^3 block decided one by one, by leaf offset.
#[derive(Default)]
struct Decided {
    settled: [u64; 8],
    inside: [u64; 8],
    ambiguous: [u64; 8],
}

impl Decided {
    fn is_settled(&self, n: usize) -> bool {
        self.settled[n / 64] >> (n % 64) & 1 == 1
    }

    fn settle(&mut self, n: usize, inside: bool, ambiguous: bool) {
        let bit = 1u64 << (n % 64);
        self.settled[n / 64] |= bit;
        if inside {
            self.inside[n / 64] |= bit;
        }
        if ambiguous {
            self.ambiguous[n / 64] |= bit;
        }
    }
}
