//! A tessellation of a closed limit surface that provably stays within a tolerance of it, so
//! that methods made for meshes (depth layers, parity) decide every point farther than the
//! tolerance from the limit surface exactly as the limit surface would.
//!
//! Each patch's parameter square is split as a quadtree until every leaf square passes
//! `PatchNode::within_tolerance`: triangles spanning points of the leaf's piece lie within the
//! tolerance of the piece at the same parameters (flat parts stay coarse; only the squares
//! towards an extraordinary corner go deep). A leaf side that holds corners of finer leaves,
//! in its own patch or, along a patch side, in the patch across it, takes those points too,
//! and such a leaf becomes a fan around its centre (as does one whose both diagonals join
//! points of the patch's sides): the triangles meet edge to edge, no T-junctions, and map the patches' parameters continuously onto a closed surface T. The
//! straight-line homotopy from the limit surface S to T then moves no point by the tolerance
//! or more, so it never passes a point farther than that from S, and such a point has the
//! same winding number about S and T.
//!
//! Parameters are integers over `2^FINEST` (dyadic squares are exact). A point on patch sides
//! is named by the control mesh's topology (a vertex, a point of a control edge or of an
//! n-gon's spoke, a face centre) and shared by that name: sheets of the surface that touch
//! stay apart.

use super::surface::LimitSurface;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::sync::atomic::{AtomicI64, Ordering};

/// The deepest quadtree level a patch is split to.
const MAX_DEPTH: u32 = 30;
/// Parameters count in units of `2^-FINEST`: one level below the deepest, so that the half of
/// a control edge an n-gon's sub-face spans keeps integer parameters.
const FINEST: u32 = MAX_DEPTH + 1;
/// A whole patch side, in parameter units.
const SIDE: i64 = 1 << FINEST;

/// Bytes a triangle of the tessellation costs while it is built and rendered: its corners and
/// indices, half a vertex, and the vertex placed along each view direction.
pub const TESSELLATION_TRIANGLE_BYTES: u64 = 96;

pub struct CertifiedTessellation {
    /// The closed triangle mesh, in the control mesh's coordinates.
    pub mesh: Mesh,
    /// Every point of the mesh lies within this distance of the limit surface's point at the
    /// same parameters.
    pub tolerance: f64,
    /// The deepest quadtree level any patch took.
    pub deepest: u32,
}

/// The curve of the control mesh a patch side lies on; patches sharing it share its points.
#[derive(Clone, Copy, Debug, Hash, PartialEq, Eq)]
enum Curve {
    /// A control edge, by its vertices in increasing order: a quad's side is all of it, an
    /// n-gon's sub-face side half of it.
    Edge(u32, u32),
    /// The curve from the midpoint of edge `s` of n-gon `face` (the control edge `edge`, its
    /// vertices in increasing order) to the face's centre.
    Spoke { face: u32, s: u32, edge: (u32, u32) },
}

/// A point on the curves, named by the control mesh's topology so that patches sharing it
/// name it alike (points on different sheets that touch stay apart).
#[derive(Clone, Copy, Debug, Hash, PartialEq, Eq)]
enum PointKey {
    Vertex(u32),
    /// A point inside a control edge, at curve parameter `c` (the midpoint at `SIDE / 2`).
    OnEdge(u32, u32, i64),
    OnSpoke(u32, u32, i64),
    Centre(u32),
}

impl Curve {
    fn point(&self, c: i64) -> PointKey {
        match *self {
            Curve::Edge(a, _) if c == 0 => PointKey::Vertex(a),
            Curve::Edge(_, b) if c == SIDE => PointKey::Vertex(b),
            Curve::Edge(a, b) => PointKey::OnEdge(a, b, c),
            Curve::Spoke { edge: (a, b), .. } if c == 0 => PointKey::OnEdge(a, b, SIDE / 2),
            Curve::Spoke { face, .. } if c == SIDE => PointKey::Centre(face),
            Curve::Spoke { face, s, .. } => PointKey::OnSpoke(face, s, c),
        }
    }
}

/// A patch side on its curve: side parameter `σ` (0 at the side's first corner, counter-
/// clockwise) is curve parameter `c = (offset + slope σ) / 2`.
#[derive(Clone, Copy)]
struct Side {
    curve: Curve,
    offset: i64,
    slope: i64,
}

impl Side {
    fn curve_at(self, sigma: i64) -> i64 {
        (self.offset + self.slope * sigma) / 2
    }

    /// The side parameter of curve parameter `c`, if the side reaches it.
    fn side_at(self, c: i64) -> Option<i64> {
        let scaled = 2 * c - self.offset;
        (scaled % self.slope == 0)
            .then_some(scaled / self.slope)
            .filter(|sigma| (0..=SIDE).contains(sigma))
    }
}

/// The four sides of patch `pid` in the order its parameter square lists them: `t = 0`
/// (corner 0 to 1), `s = 1`, `t = 1`, `s = 0`.
fn patch_sides(surface: &LimitSurface, pid: usize) -> [Side; 4] {
    let (face, sub) = surface.patch_of_face(pid);
    let corners = surface.control().face_vertices(face);
    // A side along a whole curve, from `a` to `b` (a control edge's vertices, or forward
    // along a spoke when `a < b`).
    let whole = |curve: Curve, forward: bool| Side {
        curve,
        offset: if forward { 0 } else { 2 * SIDE },
        slope: if forward { 2 } else { -2 },
    };
    let edge = |a: u32, b: u32| Curve::Edge(a.min(b), a.max(b));
    let n = corners.len();
    if n == 4 {
        return std::array::from_fn(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            whole(edge(a, b), a < b)
        });
    }
    // Sub-face `sub` is [corner sub, midpoint of edge sub, centre, midpoint of edge sub - 1].
    let before = (sub + n - 1) % n;
    let spoke = |s: usize| Curve::Spoke {
        face: face as u32,
        s: s as u32,
        edge: {
            let (a, b) = (corners[s], corners[(s + 1) % n]);
            (a.min(b), a.max(b))
        },
    };
    let (v, next, prev) = (corners[sub], corners[(sub + 1) % n], corners[before]);
    [
        // From the corner to the edge's midpoint.
        Side {
            curve: edge(v, next),
            offset: if v < next { 0 } else { 2 * SIDE },
            slope: if v < next { 1 } else { -1 },
        },
        whole(spoke(sub), true),
        whole(spoke(before), false),
        // From the previous edge's midpoint to the corner.
        Side {
            curve: edge(prev, v),
            offset: SIDE,
            slope: if v < prev { -1 } else { 1 },
        },
    ]
}

/// A leaf square of a patch's quadtree: its lower corner and side, in parameter units.
#[derive(Clone, Copy)]
struct Square {
    x: i64,
    y: i64,
    side: i64,
}

impl Square {
    fn bounds(&self) -> [f64; 4] {
        let f = |v: i64| v as f64 / SIDE as f64;
        [
            f(self.x),
            f(self.x + self.side),
            f(self.y),
            f(self.y + self.side),
        ]
    }
}

/// Why a patch could not be split.
enum Unsplit {
    /// Squares at `MAX_DEPTH` still fail the test.
    TooDeep,
    /// The leaves of all patches together passed the budget.
    TooMany,
}

/// The leaves of patch `pid`'s quadtree, each taken from `budget`.
fn leaves(
    surface: &LimitSurface,
    pid: usize,
    tolerance: f64,
    budget: &AtomicI64,
) -> std::result::Result<Vec<Square>, Unsplit> {
    let mut out = Vec::new();
    let mut stack = vec![Square {
        x: 0,
        y: 0,
        side: SIDE,
    }];
    while let Some(q) = stack.pop() {
        if surface.within_tolerance(pid, q.bounds(), tolerance) {
            if budget.fetch_sub(1, Ordering::Relaxed) <= 0 {
                return Err(Unsplit::TooMany);
            }
            out.push(q);
            continue;
        }
        if q.side <= SIDE >> MAX_DEPTH {
            return Err(Unsplit::TooDeep);
        }
        let h = q.side / 2;
        for (dx, dy) in [(0, 0), (h, 0), (h, h), (0, h)] {
            stack.push(Square {
                x: q.x + dx,
                y: q.y + dy,
                side: h,
            });
        }
    }
    Ok(out)
}

/// Sorted, distinct values.
fn sorted(mut v: Vec<i64>) -> Vec<i64> {
    v.sort_unstable();
    v.dedup();
    v
}

/// The values of sorted `v` strictly between `a` and `b`, ascending.
fn between(v: &[i64], a: i64, b: i64) -> &[i64] {
    let start = v.partition_point(|&x| x <= a);
    let end = v.partition_point(|&x| x < b);
    &v[start..end.max(start)]
}

/// For a square with no points but its corners: the first corner of a diagonal that does not
/// join two points of the patch's sides. Such a diagonal could be another patch's as well (two
/// patches around an interior vertex of valence 2 share two sides); where there is none (a
/// whole patch), the square becomes a fan.
fn free_diagonal(around: &[(i64, i64)]) -> Option<usize> {
    let on_sides = |(x, y): (i64, i64)| x == 0 || y == 0 || x == SIDE || y == SIDE;
    if around.len() != 4 {
        return None;
    }
    (0..2).find(|&k| !(on_sides(around[k]) && on_sides(around[k + 2])))
}

/// One patch's points (those on its sides first, with their names) and triangles, in local
/// indices.
struct PatchPiece {
    points: Vec<DVec3>,
    keys: Vec<PointKey>,
    triangles: Vec<[u32; 3]>,
}

/// A patch's leaves with the points along every line they meet on.
struct PatchMesh {
    leaves: Vec<Square>,
    /// Leaf corners by row (`y` -> sorted `x`) and by column (`x` -> sorted `y`).
    rows: FxHashMap<i64, Vec<i64>>,
    columns: FxHashMap<i64, Vec<i64>>,
    /// Points along each patch side, as sorted side parameters.
    sides: [Vec<i64>; 4],
    /// The curves the sides lie on.
    curves: [Side; 4],
}

impl PatchMesh {
    fn new(leaves: Vec<Square>, sides: [Vec<i64>; 4], curves: [Side; 4]) -> PatchMesh {
        let mut rows: FxHashMap<i64, Vec<i64>> = FxHashMap::default();
        let mut columns: FxHashMap<i64, Vec<i64>> = FxHashMap::default();
        for q in &leaves {
            for (x, y) in [
                (q.x, q.y),
                (q.x + q.side, q.y),
                (q.x + q.side, q.y + q.side),
                (q.x, q.y + q.side),
            ] {
                rows.entry(y).or_default().push(x);
                columns.entry(x).or_default().push(y);
            }
        }
        for v in rows.values_mut().chain(columns.values_mut()) {
            *v = sorted(std::mem::take(v));
        }
        PatchMesh {
            leaves,
            rows,
            columns,
            sides,
            curves,
        }
    }

    /// The points of the square's boundary, counter-clockwise from its lower corner: its
    /// corners and every point of finer leaves or of the patch across lying on its sides.
    fn around(&self, q: &Square, out: &mut Vec<(i64, i64)>) {
        out.clear();
        let (x0, y0, x1, y1) = (q.x, q.y, q.x + q.side, q.y + q.side);
        out.push((x0, y0));
        if y0 == 0 {
            out.extend(between(&self.sides[0], x0, x1).iter().map(|&x| (x, 0)));
        } else {
            out.extend(between(&self.rows[&y0], x0, x1).iter().map(|&x| (x, y0)));
        }
        out.push((x1, y0));
        if x1 == SIDE {
            out.extend(between(&self.sides[1], y0, y1).iter().map(|&y| (SIDE, y)));
        } else {
            out.extend(between(&self.columns[&x1], y0, y1).iter().map(|&y| (x1, y)));
        }
        out.push((x1, y1));
        let top: &[i64] = if y1 == SIDE {
            // Side 2 runs from s = 1 to s = 0.
            let xs = between(&self.sides[2], SIDE - x1, SIDE - x0);
            out.extend(xs.iter().map(|&s| (SIDE - s, SIDE)));
            &[]
        } else {
            between(&self.rows[&y1], x0, x1)
        };
        out.extend(top.iter().rev().map(|&x| (x, y1)));
        out.push((x0, y1));
        let left: &[i64] = if x0 == 0 {
            let ys = between(&self.sides[3], SIDE - y1, SIDE - y0);
            out.extend(ys.iter().map(|&s| (0, SIDE - s)));
            &[]
        } else {
            between(&self.columns[&x0], y0, y1)
        };
        out.extend(left.iter().rev().map(|&y| (x0, y)));
    }

    /// Triangles of the patch: two per leaf, or one per boundary point of a fan (a leaf with
    /// points of finer leaves on its sides, or without a free diagonal).
    fn triangles(&self) -> u64 {
        let mut around = Vec::new();
        self.leaves
            .iter()
            .map(|q| {
                self.around(q, &mut around);
                if free_diagonal(&around).is_some() {
                    2
                } else {
                    around.len() as u64
                }
            })
            .sum()
    }

    fn piece(&self, pid: usize, surface: &LimitSurface) -> PatchPiece {
        let at = |x: i64, y: i64| {
            surface
                .eval_patch(pid, x as f64 / SIDE as f64, y as f64 / SIDE as f64)
                .position
        };
        let mut index: FxHashMap<(i64, i64), u32> = FxHashMap::default();
        let mut points = Vec::new();
        // The side points first: they alone are shared with other patches.
        let mut keys = Vec::new();
        let side_points = [
            self.sides[0].iter().map(|&s| (s, 0)).collect::<Vec<_>>(),
            self.sides[1].iter().map(|&s| (SIDE, s)).collect(),
            self.sides[2].iter().map(|&s| (SIDE - s, SIDE)).collect(),
            self.sides[3].iter().map(|&s| (0, SIDE - s)).collect(),
        ];
        for (k, along) in side_points.iter().enumerate() {
            for (&(x, y), &sigma) in along.iter().zip(&self.sides[k]) {
                index.entry((x, y)).or_insert_with(|| {
                    let side = &self.curves[k];
                    keys.push(side.curve.point(side.curve_at(sigma)));
                    points.push(at(x, y));
                    points.len() as u32 - 1
                });
            }
        }
        let mut triangles = Vec::with_capacity(2 * self.leaves.len());
        let mut around = Vec::new();
        for q in &self.leaves {
            self.around(q, &mut around);
            let ids: Vec<u32> = around
                .iter()
                .map(|&(x, y)| {
                    *index.entry((x, y)).or_insert_with(|| {
                        points.push(at(x, y));
                        points.len() as u32 - 1
                    })
                })
                .collect();
            let diagonal = free_diagonal(&around);
            if diagonal == Some(0) {
                triangles.push([ids[0], ids[1], ids[2]]);
                triangles.push([ids[0], ids[2], ids[3]]);
            } else if diagonal == Some(1) {
                triangles.push([ids[1], ids[2], ids[3]]);
                triangles.push([ids[1], ids[3], ids[0]]);
            } else {
                let centre = points.len() as u32;
                points.push(at(q.x + q.side / 2, q.y + q.side / 2));
                for k in 0..ids.len() {
                    triangles.push([centre, ids[k], ids[(k + 1) % ids.len()]]);
                }
            }
        }
        PatchPiece {
            points,
            keys,
            triangles,
        }
    }
}

/// The leaves the tessellation within `tolerance` splits `surface`'s patches into, counted
/// before any triangle is made (a memory plan's count; a patch that cannot be split counts
/// what it reached).
pub fn certified_leaf_count(surface: &LimitSurface, tolerance: f64) -> u64 {
    let budget = AtomicI64::new(i64::MAX);
    (0..surface.patch_count())
        .into_par_iter()
        .map(|pid| leaves(surface, pid, tolerance, &budget).map_or(0, |l| l.len() as u64))
        .sum()
}

/// Tessellates the closed limit surface `surface` within `tolerance` (world units) of it, in
/// at most `max_triangles` triangles; `progress` counts the patches twice (split, then
/// triangulated).
pub fn certified_tessellation(
    surface: &LimitSurface,
    tolerance: f64,
    max_triangles: u64,
    progress: &Progress,
) -> Result<CertifiedTessellation> {
    let source = surface.control().source.clone();
    let patches = surface.patch_count();
    let too_large = |triangles: u64| Error::TooLarge {
        estimated_mib: triangles.saturating_mul(TESSELLATION_TRIANGLE_BYTES) >> 20,
        available_mib: max_triangles.saturating_mul(TESSELLATION_TRIANGLE_BYTES) >> 20,
        detail: format!(
            "a tessellation of {} within {tolerance:e} of its limit surface (at least \
             {triangles} triangles)",
            source.display()
        ),
    };
    progress.stage("tessellating", 2 * patches as u64);
    // Every leaf gives at least two triangles.
    let budget = AtomicI64::new((max_triangles / 2).min(i64::MAX as u64) as i64);
    let split = (0..patches)
        .into_par_iter()
        .map(|pid| {
            progress.advance(1);
            if progress.stopped() {
                return Ok(Vec::new());
            }
            leaves(surface, pid, tolerance, &budget).map_err(|why| (pid, why))
        })
        .collect::<std::result::Result<Vec<Vec<Square>>, (usize, Unsplit)>>();
    progress.check()?;
    let split = split.map_err(|(pid, why)| match why {
        Unsplit::TooMany => too_large(max_triangles),
        Unsplit::TooDeep => Error::InvalidArgument(format!(
            "{}: patch {pid} cannot be tessellated within {tolerance:e} in squares of \
             2^-{MAX_DEPTH} of its side (a degenerate patch, or a grid far too fine for the \
             model)",
            source.display()
        )),
    })?;
    let sides: Vec<[Side; 4]> = (0..patches).map(|p| patch_sides(surface, p)).collect();
    // Every curve carries the leaf corners that lie on it in any patch.
    let mut on_curve: FxHashMap<Curve, Vec<i64>> = FxHashMap::default();
    for (squares, sides) in split.iter().zip(&sides) {
        for q in squares {
            let (x1, y1) = (q.x + q.side, q.y + q.side);
            let mut put = |k: usize, sigma: i64| {
                on_curve
                    .entry(sides[k].curve)
                    .or_default()
                    .push(sides[k].curve_at(sigma));
            };
            if q.y == 0 {
                put(0, q.x);
                put(0, x1);
            }
            if x1 == SIDE {
                put(1, q.y);
                put(1, y1);
            }
            if y1 == SIDE {
                put(2, SIDE - x1);
                put(2, SIDE - q.x);
            }
            if q.x == 0 {
                put(3, SIDE - y1);
                put(3, SIDE - q.y);
            }
        }
    }
    for v in on_curve.values_mut() {
        *v = sorted(std::mem::take(v));
    }
    let meshes: Vec<PatchMesh> = split
        .into_par_iter()
        .zip(&sides)
        .map(|(squares, sides)| {
            let along = |s: &Side| {
                sorted(
                    on_curve[&s.curve]
                        .iter()
                        .filter_map(|&c| s.side_at(c))
                        .collect(),
                )
            };
            PatchMesh::new(squares, sides.each_ref().map(along), *sides)
        })
        .collect();
    let triangles: u64 = meshes.par_iter().map(PatchMesh::triangles).sum();
    if triangles > max_triangles {
        return Err(too_large(triangles));
    }
    let pieces: Vec<PatchPiece> = meshes
        .par_iter()
        .enumerate()
        .map(|(pid, mesh)| {
            progress.advance(1);
            if progress.stopped() {
                return PatchPiece {
                    points: Vec::new(),
                    keys: Vec::new(),
                    triangles: Vec::new(),
                };
            }
            mesh.piece(pid, surface)
        })
        .collect();
    progress.check()?;
    let deepest = meshes
        .iter()
        .flat_map(|m| &m.leaves)
        .map(|q| FINEST - q.side.trailing_zeros())
        .max()
        .unwrap_or(0);
    drop(meshes);
    let mut shared: FxHashMap<PointKey, u32> = FxHashMap::default();
    let mut positions = Vec::new();
    let mut indices = Vec::with_capacity(3 * triangles as usize);
    for piece in pieces {
        let ids: Vec<u32> = piece
            .points
            .iter()
            .enumerate()
            .map(|(local, &p)| {
                let mut new = || {
                    positions.push(p);
                    positions.len() as u32 - 1
                };
                match piece.keys.get(local) {
                    Some(&key) => *shared.entry(key).or_insert_with(new),
                    None => new(),
                }
            })
            .collect();
        for t in piece.triangles {
            let [a, b, c] = t.map(|v| ids[v as usize]);
            // A triangle collapsed at a degenerate corner adds nothing to the surface.
            if a != b && b != c && c != a {
                indices.extend([a, b, c]);
            }
        }
    }
    let face_starts = (0..=indices.len() as u32 / 3).map(|f| 3 * f).collect();
    Ok(CertifiedTessellation {
        mesh: Mesh {
            positions,
            indices,
            face_starts,
            source,
            ..Default::default()
        },
        tolerance,
        deepest,
    })
}
