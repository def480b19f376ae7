//! Solid voxelization from depth buffers (Passalis, Kakadiaris & Theoharis), rasterized in
//! software: each view direction `d` casts one orthographic ray through every voxel centre, and
//! the depth buffers keep, per ray, the exact crossings with the mesh (see `ops::crossings`).
//!
//! * **Single layer** is Karabassi et al.'s method generalised to N directions (§3.1): one
//!   buffer pair per direction holds the first and last crossing, and a voxel is inside when it
//!   lies between them for every direction. Concavities that no direction sees are filled.
//! * **Double layers** (§3.2) keep the two nearest crossings from each side (four buffers per
//!   direction pair) and a stencil count of all crossings per ray. A count of 0, 2 or 4 decides
//!   the voxel exactly (inside between the 1st and 2nd or the 3rd and 4th crossing); above four
//!   the direction cannot decide, and a voxel no direction decides is *unclassifiable*. An odd
//!   count means the input is open (or not manifold) along that ray: every voxel on it is
//!   unclassifiable, so open input is reported rather than filled or left hollow.
//!
//! Two decisions differ from the hardware version, both because software crossings are exact.
//! The layers are the nearest crossings, not front and back faces, so the result does not
//! depend on face orientation (inward-oriented meshes work). And by default one direction
//! whose count allows a decision suffices (directions are tried in order: z, x, y, then the
//! diagonals), where the paper gives up as soon as any direction counts more than four;
//! `Unclassified::Paper` applies the paper's rule.
//!
//! The directions are integer vectors with a component of ±1: with `k` that component and
//! `i, j` the others, `(a, b, t) = (p_i - t d_i, p_j - t d_j, p_k d_k)` is a unimodular change
//! of lattice coordinates (`RayFrame`), so the rays `(a, b) = const` through voxel centres are
//! exactly the lattice rays the crossing rasterizer walks, and voxel centres sit at integer
//! `t`. A centre exactly on the surface (a face on a plane of centres, a ray through an edge)
//! is decided by the tie rule every direction and ray parity share (`mesh::crossings`): single
//! layers, double layers and parity agree on it.

use crate::error::{Error, Result};
use crate::grid::{CoordBox, DenseMask, Transform};
use crate::mesh::Mesh;
use crate::mesh::crossings::{RayCrossing, RayFrame, RayWindow, for_each_crossing};
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;

/// The view directions, in the order they are used: the axes first (z, whose rays run along
/// the rows of a dense volume, then x and y), then face and body diagonals.
pub const DIRECTIONS: [[i64; 3]; 16] = [
    [0, 0, 1],
    [1, 0, 0],
    [0, 1, 0],
    [1, 1, 0],
    [1, -1, 0],
    [1, 0, 1],
    [1, 0, -1],
    [0, 1, 1],
    [0, 1, -1],
    [1, 1, 1],
    [1, 1, -1],
    [1, -1, 1],
    [-1, 1, 1],
    [2, 1, 1],
    [1, 2, 1],
    [1, 1, 2],
];

/// Single layer (Karabassi et al.) or double layers with a stencil count (Passalis et al.).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layers {
    Single,
    Double,
}

crate::named_choices! {
    Layers, "the layers":
    "double" => Double,
    "single" => Single,
}

/// Which voxels double layers leave unclassified.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Unclassified {
    /// Those no direction can decide: one direction whose ray counts at most four crossings
    /// decides (exact crossings make every such direction agree).
    #[default]
    NoDirection,
    /// Passalis et al.'s rule: those on a ray of any direction counting more than four.
    Paper,
}

crate::named_choices! {
    Unclassified, "the unclassified rule":
    "no-direction" => NoDirection,
    "paper" => Paper,
}

/// The view directions of a depth-layer solid: the first few of `DIRECTIONS`, or the user's
/// own (§3.1's arbitrary directions, as integer vectors with a ±1 component so that their rays
/// pass through voxel centres).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectionSet {
    len: usize,
    /// Components within ±`MAX_COMPONENT`, small enough to keep the options small.
    list: [[i8; 3]; DIRECTIONS.len()],
}

/// The largest direction component accepted (steeper directions add nothing at voxel scale).
const MAX_COMPONENT: i64 = 100;

impl DirectionSet {
    /// All of `DIRECTIONS`, the most that can be decided.
    pub const ALL: DirectionSet = DirectionSet::all();

    const fn all() -> DirectionSet {
        let mut list = [[0i8; 3]; DIRECTIONS.len()];
        let mut n = 0;
        while n < DIRECTIONS.len() {
            let d = DIRECTIONS[n];
            list[n] = [d[0] as i8, d[1] as i8, d[2] as i8];
            n += 1;
        }
        DirectionSet {
            len: DIRECTIONS.len(),
            list,
        }
    }

    /// The first `n` of `DIRECTIONS` (3 = the axes, Karabassi's six z-buffers), 3 to 16.
    pub fn first(n: usize) -> Result<DirectionSet> {
        if !(3..=DIRECTIONS.len()).contains(&n) {
            return Err(Error::InvalidArgument(format!(
                "depth layers take 3 to {} directions, not {n}",
                DIRECTIONS.len()
            )));
        }
        DirectionSet::given(&DIRECTIONS[..n])
    }

    /// The user's directions, 1 to 16 of them, in the order given: integer vectors, each with
    /// a component of ±1 and no two parallel.
    pub fn given(list: &[[i64; 3]]) -> Result<DirectionSet> {
        if list.is_empty() || list.len() > DIRECTIONS.len() {
            return Err(Error::InvalidArgument(format!(
                "depth layers take 1 to {} directions, not {}",
                DIRECTIONS.len(),
                list.len()
            )));
        }
        for (n, d) in list.iter().enumerate() {
            if !d.iter().any(|c| c.abs() == 1) {
                return Err(Error::InvalidArgument(format!(
                    "direction {d:?}: a depth-layer direction needs a component of 1 or -1 (its \
                     rays then pass through voxel centres), e.g. 2,1,3"
                )));
            }
            if d.iter().any(|c| c.abs() > MAX_COMPONENT) {
                return Err(Error::InvalidArgument(format!(
                    "direction {d:?}: components are at most {MAX_COMPONENT} in size"
                )));
            }
            let parallel = |e: &[i64; 3]| {
                let c = [
                    d[1] * e[2] - d[2] * e[1],
                    d[2] * e[0] - d[0] * e[2],
                    d[0] * e[1] - d[1] * e[0],
                ];
                c == [0, 0, 0]
            };
            if let Some(e) = list[..n].iter().find(|e| parallel(e)) {
                return Err(Error::InvalidArgument(format!(
                    "directions {e:?} and {d:?} are parallel: they see the same rays"
                )));
            }
        }
        let mut set = DirectionSet {
            len: list.len(),
            list: [[0; 3]; DIRECTIONS.len()],
        };
        for (to, from) in set.list.iter_mut().zip(list) {
            *to = from.map(|c| c as i8);
        }
        Ok(set)
    }

    /// The directions, in order.
    pub fn to_vec(&self) -> Vec<[i64; 3]> {
        self.list[..self.len]
            .iter()
            .map(|d| d.map(i64::from))
            .collect()
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DepthLayerOptions {
    pub directions: DirectionSet,
    pub layers: Layers,
    pub unclassified: Unclassified,
}

impl DepthLayerOptions {
    /// Double layers over all directions, the most that can be decided.
    pub const ALL_DIRECTIONS: DepthLayerOptions = DepthLayerOptions {
        directions: DirectionSet::ALL,
        layers: Layers::Double,
        unclassified: Unclassified::NoDirection,
    };
}

impl Default for DepthLayerOptions {
    fn default() -> Self {
        DepthLayerOptions {
            directions: DirectionSet::first(3).expect("three directions"),
            layers: Layers::Double,
            unclassified: Unclassified::NoDirection,
        }
    }
}

/// Rays of one direction by their stencil count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub direction: [i64; 3],
    pub rays: u64,
    /// Rays crossed 0, 2 and 4 times, more than 4 times (even), and an odd number of times.
    pub none: u64,
    pub two: u64,
    pub four: u64,
    pub more: u64,
    pub odd: u64,
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DepthLayerStats {
    pub per_direction: Vec<RayCounts>,
    pub inside_voxels: u64,
    pub unclassified_voxels: u64,
    /// Voxels left unclassified because a ray through them has an odd count (open input).
    pub open_voxels: u64,
    pub voxels: u64,
}

impl DepthLayerStats {
    /// Rays with an odd stencil count, over all directions: nonzero means open input.
    pub fn odd_rays(&self) -> u64 {
        self.per_direction.iter().map(|c| c.odd).sum()
    }
}

pub struct DepthLayerSolid {
    /// Voxels whose centre is classified inside.
    pub inside: DenseMask,
    /// Voxels no direction could classify (always empty with single layers).
    pub unclassified: DenseMask,
    pub stats: DepthLayerStats,
}

/// One direction's depth buffers: the stencil count and the two nearest crossings from
/// either end of every ray, each kept as the first centre beyond it (`RayCrossing::after`).
struct View {
    frame: RayFrame,
    window: RayWindow,
    count: Vec<u16>,
    /// Per ray: the two smallest and the two largest crossings.
    near: Vec<[i32; 2]>,
    far: Vec<[i32; 2]>,
}

/// What one direction says of one voxel.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Verdict {
    Inside,
    Outside,
    /// More than four crossings.
    Undecided,
    /// An odd number of crossings.
    Open,
}

impl View {
    /// Ray number and `t` of the voxel at `p` (relative to the volume's first voxel).
    #[inline]
    fn voxel_ray(&self, p: [i64; 3]) -> (usize, i64) {
        let ([a, b], t) = self.frame.lattice_ray(p);
        (self.window.ray(a, b), t)
    }

    /// Renders `surface` into the buffers of direction `d` over a volume of `dims` voxels.
    fn render(d: [i64; 3], dims: [usize; 3], surface: &dyn RaySurface) -> Result<View> {
        let frame = RayFrame::along(d);
        // The window: the (a, b) range of the volume's corners.
        let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
        for corner in 0..8 {
            let p: [i64; 3] = std::array::from_fn(|a| {
                if corner >> a & 1 == 1 {
                    dims[a] as i64 - 1
                } else {
                    0
                }
            });
            let (ab, _) = frame.lattice_ray(p);
            for c in 0..2 {
                lo[c] = lo[c].min(ab[c]);
                hi[c] = hi[c].max(ab[c]);
            }
        }
        let window = RayWindow {
            a0: lo[0],
            b0: lo[1],
            width: (hi[0] - lo[0] + 1) as usize,
            height: (hi[1] - lo[1] + 1) as usize,
        };
        let rays = window.len();
        let bytes = rays as u64 * 18;
        if bytes > 8 << 30 {
            return Err(Error::TooLarge {
                estimated_mib: bytes >> 20,
                available_mib: 8 << 10,
                detail: format!("depth buffers of {rays} rays along {d:?}"),
            });
        }
        let mut view = View {
            frame,
            window,
            count: vec![0; rays],
            near: vec![[i32::MAX; 2]; rays],
            far: vec![[i32::MIN; 2]; rays],
        };
        let (count, near, far) = (&mut view.count, &mut view.near, &mut view.far);
        surface.crossings(&frame, &view.window, &mut |c| {
            let (ray, t) = (
                c.ray,
                c.after.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            );
            count[ray] = count[ray].saturating_add(1);
            let n = &mut near[ray];
            if t < n[0] {
                *n = [t, n[0]];
            } else if t < n[1] {
                n[1] = t;
            }
            let f = &mut far[ray];
            if t > f[0] {
                *f = [t, f[0]];
            } else if t > f[1] {
                f[1] = t;
            }
        });
        Ok(view)
    }

    fn counts(&self) -> RayCounts {
        let mut c = RayCounts {
            direction: self.frame.d,
            rays: self.count.len() as u64,
            ..Default::default()
        };
        for &n in &self.count {
            match n {
                0 => c.none += 1,
                2 => c.two += 1,
                4 => c.four += 1,
                n if n % 2 == 1 => c.odd += 1,
                _ => c.more += 1,
            }
        }
        c
    }

    /// The inside stretches of `ray` in `t` (centres `first ..= last`), when its count
    /// decides.
    fn inside_spans(&self, ray: usize) -> std::result::Result<[[i64; 2]; 2], Verdict> {
        let (n, f) = (self.near[ray].map(i64::from), self.far[ray].map(i64::from));
        match self.count[ray] {
            0 => Ok([[1, 0]; 2]),
            // With two crossings near = [t1, t2] and far = [t2, t1]: both spans are t1..t2.
            2 | 4 => Ok([[n[0], n[1] - 1], [f[1], f[0] - 1]]),
            c if c % 2 == 1 => Err(Verdict::Open),
            _ => Err(Verdict::Undecided),
        }
    }

    #[inline]
    fn double(&self, p: [i64; 3]) -> Verdict {
        let (ray, t) = self.voxel_ray(p);
        match self.inside_spans(ray) {
            Ok(spans) => {
                if spans.iter().any(|s| s[0] <= t && t <= s[1]) {
                    Verdict::Inside
                } else {
                    Verdict::Outside
                }
            }
            Err(v) => v,
        }
    }

    /// Karabassi's test: between the first and the last crossing.
    #[inline]
    fn single(&self, p: [i64; 3]) -> bool {
        let (ray, t) = self.voxel_ray(p);
        self.count[ray] > 0 && i64::from(self.near[ray][0]) <= t && t < i64::from(self.far[ray][0])
    }
}

/// What the views say of one voxel with double layers: `Some(inside)` or `None`
/// (unclassifiable), and whether an odd count was among the reasons.
fn classify_double(
    views: &[View],
    p: [i64; 3],
    open_input: bool,
    rule: Unclassified,
) -> (Option<bool>, bool) {
    // Every ray is looked at when an odd one (open input) or, by the paper's rule, one
    // counting more than four could leave the voxel unclassified.
    let look_at_all = open_input || rule == Unclassified::Paper;
    let mut decided = None;
    for v in views {
        match v.double(p) {
            Verdict::Open => return (None, true),
            Verdict::Undecided if rule == Unclassified::Paper => return (None, false),
            Verdict::Undecided => {}
            verdict => {
                if decided.is_none() {
                    decided = Some(verdict == Verdict::Inside);
                    if !look_at_all {
                        break;
                    }
                }
            }
        }
    }
    (decided, false)
}

/// Runs of linear indices (first, last) of one x-slab: inside, unclassified, and the number of
/// unclassified voxels with an odd ray.
type SlabRuns = (Vec<(usize, usize)>, Vec<(usize, usize)>, u64);

fn push_voxel(runs: &mut Vec<(usize, usize)>, index: usize) {
    match runs.last_mut() {
        Some(r) if r.1 + 1 == index => r.1 = index,
        _ => runs.push((index, index)),
    }
}

/// What the rays of the depth buffers cross: a surface that reports every crossing of the
/// rays of a window, in index units relative to the volume's first voxel.
pub trait RaySurface: Sync {
    fn crossings(&self, frame: &RayFrame, window: &RayWindow, cross: &mut dyn FnMut(RayCrossing));
}

/// A mesh's triangles, their corners relative to the volume's first voxel.
struct MeshRays<'m> {
    points: Vec<DVec3>,
    mesh: &'m Mesh,
}

impl RaySurface for MeshRays<'_> {
    fn crossings(&self, frame: &RayFrame, window: &RayWindow, cross: &mut dyn FnMut(RayCrossing)) {
        let ray_points: Vec<DVec3> = self.points.iter().map(|&p| frame.to_ray(p)).collect();
        let triangles = self.mesh.triangles().map(|(_, t)| t);
        for_each_crossing(&ray_points, triangles, frame, window, cross);
    }
}

/// The solid of `mesh` on `transform` over `bbox`: depth buffers along `options.directions`,
/// classified with single or double layers; `progress` counts the directions
/// rendered, then the x slabs classified (two stages).
pub fn depth_layer_solid(
    mesh: &Mesh,
    transform: &Transform,
    bbox: CoordBox,
    options: &DepthLayerOptions,
    progress: &Progress,
) -> Result<DepthLayerSolid> {
    let origin = DVec3::from_array(bbox.min.map(|v| v as f64));
    let points = mesh
        .positions
        .iter()
        .map(|&p| transform.world_to_index(p) - origin)
        .collect();
    depth_layers_of(&MeshRays { points, mesh }, bbox, options, progress)
}

/// The solid `surface` bounds over `bbox`, as `depth_layer_solid`.
pub fn depth_layers_of(
    surface: &dyn RaySurface,
    bbox: CoordBox,
    options: &DepthLayerOptions,
    progress: &Progress,
) -> Result<DepthLayerSolid> {
    let mut inside = DenseMask::new(bbox)?;
    let mut unclassified = DenseMask::new(bbox)?;
    let dims = inside.dims();
    let directions = options.directions.to_vec();
    progress.stage("depth buffers", directions.len() as u64);
    let views = directions
        .par_iter()
        .map(|&d| {
            let view = View::render(d, dims, surface);
            progress.advance(1);
            view
        })
        .collect::<Result<Vec<View>>>()?;
    progress.check()?;
    let per_direction: Vec<RayCounts> = views.iter().map(View::counts).collect();
    let open_input = per_direction.iter().any(|c| c.odd > 0);
    let [_, ny, nz] = dims;
    let z_view = &views[0];
    progress.stage("classifying", dims[0] as u64);
    let slabs: Vec<SlabRuns> = (0..dims[0])
        .into_par_iter()
        .map(|x| {
            let (mut ins, mut unc, mut open) = (Vec::new(), Vec::new(), 0);
            // Once cancelled, the remaining slabs are skipped (the call then fails).
            if progress.stopped() {
                return (ins, unc, open);
            }
            progress.advance(1);
            for y in 0..ny {
                let row = (x * ny + y) * nz;
                let (ray, _) = z_view.voxel_ray([x as i64, y as i64, 0]);
                // The z ray decides the whole row when its count allows (and no other
                // direction can overrule it).
                if options.layers == Layers::Double
                    && !open_input
                    && options.unclassified == Unclassified::NoDirection
                    && z_view.frame.d == [0, 0, 1]
                    && let Ok(spans) = z_view.inside_spans(ray)
                {
                    for s in spans {
                        let z0 = s[0].max(0);
                        let z1 = s[1].min(nz as i64 - 1);
                        if z0 <= z1 {
                            ins.push((row + z0 as usize, row + z1 as usize));
                        }
                    }
                    continue;
                }
                for z in 0..nz {
                    let p = [x as i64, y as i64, z as i64];
                    match options.layers {
                        Layers::Single => {
                            if views.iter().all(|v| v.single(p)) {
                                push_voxel(&mut ins, row + z);
                            }
                        }
                        Layers::Double => {
                            match classify_double(&views, p, open_input, options.unclassified) {
                                (Some(true), _) => push_voxel(&mut ins, row + z),
                                (Some(false), _) => {}
                                (None, odd) => {
                                    push_voxel(&mut unc, row + z);
                                    open += odd as u64;
                                }
                            }
                        }
                    }
                }
            }
            (ins, unc, open)
        })
        .collect();
    progress.check()?;
    let mut open_voxels = 0;
    for (ins, unc, open) in slabs {
        for (a, b) in ins {
            inside.set_index_range(a, b);
        }
        for (a, b) in unc {
            unclassified.set_index_range(a, b);
        }
        open_voxels += open;
    }
    let stats = DepthLayerStats {
        per_direction,
        inside_voxels: inside.count(),
        unclassified_voxels: unclassified.count(),
        open_voxels,
        voxels: inside.len() as u64,
    };
    Ok(DepthLayerSolid {
        inside,
        unclassified,
        stats,
    })
}
