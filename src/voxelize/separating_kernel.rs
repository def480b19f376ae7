//! The separating criterion's primitives and exact tests (Huang et al. §4–5, see
//! `separating` for the criterion and why it separates): a mesh's triangles, edges and
//! vertices in index space with the faces around each, and the row scans that mark the
//! voxels of a vertex sphere, an edge cylinder or a face's body, each optionally cut by
//! half-spaces. The surface voxelizer (`separating`) and the distance band
//! (`distance_band`) both scan with these, so that both find exactly the same voxels.

use super::Separability;
use super::brick_bins::BrickSink;
use super::vertex_cone::{ConeReach, cone_reach};
use crate::error::{Error, Result};
use crate::grid::{CoordBox, Transform, ceil_int, floor_int};
use crate::huge_pages::vec_to_fill;
use crate::mesh::Mesh;
use crate::mesh::key_groups::group_by_key;
use glam::DVec3;
use rayon::prelude::*;

/// Tolerance, in voxels, added to every inclusion test.
pub(super) const MARGIN: f64 = 1e-9;

/// The slab's bounds on `d = n·(x - p)` for the turned normal (see the module docs): the
/// voxel is in when `lo <= d < hi`.
pub(super) fn slab_bounds(t: f64) -> (f64, f64) {
    (-t - MARGIN, t - MARGIN / 2.0)
}

/// `n` turned so that its largest component is positive: the orientation the half-open slabs
/// are measured in, the same for a face whatever its winding.
pub(super) fn turned(n: DVec3) -> DVec3 {
    if n[n.abs().max_position()] < 0.0 {
        -n
    } else {
        n
    }
}

/// Extra room when clipping candidate rows (the exact tests run on every candidate).
pub(super) const ROW_SLACK: f64 = 1e-6;

pub(super) struct Triangle {
    pub(super) corners: [DVec3; 3],
    pub(super) normal: DVec3,
}

/// A vertex (`a == b`) or an edge, with the faces around it: built from its `Feature` when
/// it is voxelized.
pub(super) struct Primitive {
    pub(super) a: DVec3,
    pub(super) b: DVec3,
    normal: DVec3,
    /// Range of `Adjacency::faces` holding the faces around it.
    pub(super) faces: std::ops::Range<usize>,
}

/// An edge or a vertex (its point as both ends) as the primitives keep it: its ends by
/// number, its normal at the precision it is written in, and its faces: 40 bytes where a
/// `Primitive` takes 88. On a mesh of small faces fresh memory for them cost about as much
/// as voxelizing them (igea at 1024: up to a third of the surface's run).
pub(super) struct Feature {
    ends: [u32; 2],
    normal: glam::Vec3,
    faces: std::ops::Range<usize>,
}

/// A half-space `g·x + h <= 0` that limits a sphere or a cylinder to where its primitive can
/// be the nearest part of the mesh (the distance band's clipping; the separating surface
/// uses whole spheres and cylinders and passes none).
#[derive(Clone, Copy)]
pub(super) struct HalfSpace {
    pub(super) g: DVec3,
    pub(super) h: f64,
}

/// The most half-spaces that cut one primitive: more would only narrow its region further,
/// so a caller leaves the rest out.
pub(super) const MOST_HALVES: usize = 16;

/// Half-spaces solved once per primitive for coordinate `axis`: along a column (the other
/// two coordinates fixed) each bounds that coordinate above or below by an affine function
/// of the column's place, so a column costs a multiply-add per half-space, not a division.
pub(super) struct AxisCut {
    axis: usize,
    /// Per half-space, `bound = base + slope·x` (`slope[axis]` 0) and what it bounds.
    bounds: [(f64, DVec3, Bounds); MOST_HALVES],
    len: usize,
}

/// What a half-space bounds along a column.
#[derive(Clone, Copy)]
enum Bounds {
    /// The coordinate, from above by `bound`.
    Above,
    /// The coordinate, from below by `bound`.
    Below,
    /// Nothing along the column (the half-space is parallel to it): the whole column is out
    /// where `bound` is negative.
    Column,
}

impl AxisCut {
    /// The cut of `halves` (at most `MOST_HALVES`) along `axis`.
    pub(super) fn new(halves: &[HalfSpace], axis: usize) -> AxisCut {
        debug_assert!(halves.len() <= MOST_HALVES);
        let mut bounds = [(0.0, DVec3::ZERO, Bounds::Column); MOST_HALVES];
        for (bound, half) in bounds.iter_mut().zip(halves) {
            // g_axis t <= -(g·x + h), with x_axis = 0.
            let mut g = half.g;
            let ga = g[axis];
            g[axis] = 0.0;
            *bound = if ga == 0.0 {
                (-half.h, -g, Bounds::Column)
            } else if ga > 0.0 {
                (-half.h / ga, -g / ga, Bounds::Above)
            } else {
                (-half.h / ga, -g / ga, Bounds::Below)
            };
        }
        AxisCut {
            axis,
            bounds,
            len: halves.len().min(MOST_HALVES),
        }
    }

    /// `range`, the values of coordinate `axis` with the others as in `x`, narrowed to where
    /// every half-space holds (widened by `ROW_SLACK`: a candidate range), empty where no value
    /// does. The bounds are gathered as floats and rounded once each way, without a branch on
    /// their values (a short column's cut mispredicted most of them).
    #[inline]
    pub(super) fn range(
        &self,
        range: std::ops::RangeInclusive<i64>,
        mut x: DVec3,
    ) -> std::ops::RangeInclusive<i64> {
        let (start, end) = (*range.start(), *range.end());
        // Kept within a voxel of the range, so that rounding never leaves i64.
        let (mut lo, mut hi) = (start as f64 - 1.0, end as f64 + 1.0);
        let mut outside = false;
        x[self.axis] = 0.0;
        for &(base, slope, bounds) in &self.bounds[..self.len] {
            let bound = base + slope.dot(x);
            match bounds {
                Bounds::Above => hi = hi.min(bound + ROW_SLACK),
                Bounds::Below => lo = lo.max(bound - ROW_SLACK),
                Bounds::Column => outside |= bound < 0.0,
            }
        }
        if outside {
            return int_range(0.0, -1.0);
        }
        ceil_int(lo).max(start)..=floor_int(hi).min(end)
    }
}

/// Faces around edges and vertices, and each face's fan triangles.
pub(super) struct Adjacency {
    pub(super) faces: Vec<u32>,
    /// `triangle_starts[f]..triangle_starts[f+1]`: the kept triangles of face `f`.
    pub(super) triangle_starts: Vec<usize>,
}

impl Adjacency {
    /// Whether `x` lies in the slab (half thickness `t`) of a triangle of a face of `p`.
    pub(super) fn in_face_slab(
        &self,
        p: &Primitive,
        triangles: &[Triangle],
        sep: Separability,
        x: DVec3,
    ) -> bool {
        self.faces[p.faces.clone()].iter().any(|&f| {
            let range = self.triangle_starts[f as usize]..self.triangle_starts[f as usize + 1];
            triangles[range].iter().any(|tri| {
                let (lo, hi) = slab_bounds(sep.slab_half_thickness(tri.normal));
                let d = turned(tri.normal).dot(x - tri.corners[0]);
                lo <= d && d < hi
            })
        })
    }
}

/// The criterion's primitives in the paper's counting order: a voxel counts for the first
/// class that marks it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PrimitiveClass {
    Vertex,
    Edge,
    Body,
}

impl PrimitiveClass {
    /// The classes in counting order.
    pub(super) const ALL: [PrimitiveClass; 3] = [
        PrimitiveClass::Vertex,
        PrimitiveClass::Edge,
        PrimitiveClass::Body,
    ];
}

impl Primitives {
    /// How many primitives of each class, in counting order.
    pub(super) fn counts(&self) -> [usize; 3] {
        [self.vertices.len(), self.edges.len(), self.triangles.len()]
    }

    /// Primitive `i` of all, numbered in counting order: its class and its number in it.
    pub(super) fn numbered(&self, i: usize) -> (PrimitiveClass, usize) {
        let [nv, ne, _] = self.counts();
        if i < nv {
            (PrimitiveClass::Vertex, i)
        } else if i < nv + ne {
            (PrimitiveClass::Edge, i - nv)
        } else {
            (PrimitiveClass::Body, i - nv - ne)
        }
    }

    /// Edge `n`.
    pub(super) fn edge(&self, n: usize) -> Primitive {
        self.primitive(&self.edges[n])
    }

    /// Vertex `n`.
    pub(super) fn vertex(&self, n: usize) -> Primitive {
        self.primitive(&self.vertices[n])
    }

    /// Asks the cache for what voxelizing edge or vertex `n` of `class` reads first: its ends'
    /// points and the triangles of its faces, found by number through two lookups (each a
    /// memory miss on a large mesh). Called a feature ahead, so that the misses overlap the
    /// feature before.
    pub(super) fn warm(&self, class: PrimitiveClass, n: usize, adjacency: &Adjacency) {
        let features = match class {
            PrimitiveClass::Vertex => &self.vertices,
            PrimitiveClass::Edge => &self.edges,
            PrimitiveClass::Body => return,
        };
        let Some(f) = features.get(n) else { return };
        for end in f.ends {
            prefetch(&self.points[end as usize]);
        }
        for &face in &adjacency.faces[f.faces.clone()] {
            if let Some(&first) = adjacency.triangle_starts.get(face as usize)
                && let Some(tri) = self.triangles.get(first)
            {
                prefetch(tri);
            }
        }
    }

    fn primitive(&self, f: &Feature) -> Primitive {
        Primitive {
            a: self.points[f.ends[0] as usize],
            b: self.points[f.ends[1] as usize],
            normal: f.normal.as_dvec3(),
            faces: f.faces.clone(),
        }
    }

    /// The voxels within `reach` of primitive `n` of `class`.
    pub(super) fn reach_box_of(&self, class: PrimitiveClass, n: usize, reach: f64) -> CoordBox {
        match class {
            PrimitiveClass::Vertex => {
                let a = self.points[self.vertices[n].ends[0] as usize];
                reach_box(a, a, DVec3::splat(reach))
            }
            PrimitiveClass::Edge => {
                let e = self.edge(n);
                reach_box(e.a.min(e.b), e.a.max(e.b), cylinder_reach(e.b - e.a, reach))
            }
            PrimitiveClass::Body => {
                let tri = &self.triangles[n];
                let [a, b, c] = tri.corners;
                reach_box(
                    a.min(b).min(c),
                    a.max(b).max(c),
                    slab_reach(tri.normal, reach),
                )
            }
        }
    }
}

/// A mesh's primitives in index space: its fan triangles, its edges and its vertices.
pub(super) struct Primitives {
    pub(super) triangles: Vec<Triangle>,
    edges: Vec<Feature>,
    vertices: Vec<Feature>,
    /// The mesh's points in index space, which edges and vertices number.
    points: Vec<DVec3>,
    pub(super) adjacency: Adjacency,
    pub(super) degenerate_faces: usize,
}

/// The primitives of `mesh` (world units) on `transform`'s voxels, edges and vertices with
/// their faces' mean normal when `normals` is set.
pub(super) fn primitives(mesh: &Mesh, transform: Transform, normals: bool) -> Result<Primitives> {
    mesh.validate()?;
    if !(transform.voxel_size > 0.0 && transform.voxel_size.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "voxel size must be positive, got {}",
            transform.voxel_size
        )));
    }
    let mut pos: Vec<DVec3> = vec_to_fill(mesh.positions.len());
    pos.par_extend(
        mesh.positions
            .par_iter()
            .map(|&p| transform.world_to_index(p)),
    );
    let mut face_normals: Vec<DVec3> = vec_to_fill(mesh.face_count());
    face_normals.par_extend(
        (0..mesh.face_count())
            .into_par_iter()
            .map(|f| fan_area_normal(mesh.face(f), &pos)),
    );
    let ((triangles, triangle_starts, degenerate_faces), (edges, vertices, faces)) = rayon::join(
        || triangles_of(mesh, &pos),
        || edges_and_vertices(mesh, &pos, &face_normals, normals),
    );
    Ok(Primitives {
        triangles,
        edges,
        vertices,
        points: pos,
        adjacency: Adjacency {
            faces,
            triangle_starts,
        },
        degenerate_faces,
    })
}

/// The voxels within `reach` (by axis) of the box from `lo` to `hi` (rounded without libm
/// calls: every primitive's box is found when binning).
pub(super) fn reach_box(lo: DVec3, hi: DVec3, reach: DVec3) -> CoordBox {
    let (lo, hi) = (lo - reach, hi + reach);
    CoordBox {
        min: [lo.x, lo.y, lo.z].map(floor_int),
        max: [hi.x, hi.y, hi.z].map(ceil_int),
    }
}

/// How far, by axis, a slab of half thickness `half` along the unit normal `n` reaches beyond
/// its triangle's box: `half |n_a|`, with room for rounding. A prism's box, not a cube's:
/// along a smooth mesh's in-plane axes it is several voxels narrower.
pub(super) fn slab_reach(n: DVec3, half: f64) -> DVec3 {
    n.abs() * half + DVec3::splat(ROW_SLACK)
}

/// How far, by axis, the cylinder of radius `r` around the edge `d` (caps flat, across the
/// edge) reaches beyond the box of its ends: `r sqrt(1 - dn_a^2)`, the root taken of the
/// other two components' squares (no cancellation), with room for rounding; `r` all round
/// for an edge of no length.
pub(super) fn cylinder_reach(d: DVec3, r: f64) -> DVec3 {
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return DVec3::splat(r + ROW_SLACK);
    }
    let dn2 = d * d / len2;
    let across = DVec3::new(dn2.y + dn2.z, dn2.z + dn2.x, dn2.x + dn2.y);
    DVec3::new(across.x.sqrt(), across.y.sqrt(), across.z.sqrt()) * r + DVec3::splat(ROW_SLACK)
}

/// Twice the vector area of a polygon's fan (its normal, weighted by area).
pub(super) fn fan_area_normal(face: &[u32], pos: &[DVec3]) -> DVec3 {
    let p0 = pos[face[0] as usize];
    (1..face.len() - 1)
        .map(|k| (pos[face[k] as usize] - p0).cross(pos[face[k + 1] as usize] - p0))
        .sum()
}

/// Fan triangles with unit normals (degenerate ones dropped), where each face's triangles
/// start, and the number of degenerate faces.
pub(super) fn triangles_of(mesh: &Mesh, pos: &[DVec3]) -> (Vec<Triangle>, Vec<usize>, usize) {
    let mut triangles = vec_to_fill(mesh.indices.len() - 2 * mesh.face_count());
    let mut starts = Vec::with_capacity(mesh.face_count() + 1);
    let mut degenerate = 0;
    for f in 0..mesh.face_count() {
        starts.push(triangles.len());
        let face = mesh.face(f);
        let mut kept = 0;
        for k in 1..face.len() - 1 {
            let corners = [
                pos[face[0] as usize],
                pos[face[k] as usize],
                pos[face[k + 1] as usize],
            ];
            let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            let len = cross.length();
            // Relative to the longest edge squared: slivers thinner than 1e-12 have no stable plane.
            let scale = (corners[1] - corners[0])
                .length_squared()
                .max((corners[2] - corners[0]).length_squared());
            if len > 1e-12 * scale && len > 0.0 {
                triangles.push(Triangle {
                    corners,
                    normal: cross / len,
                });
                kept += 1;
            }
        }
        if kept == 0 {
            degenerate += 1;
        }
    }
    starts.push(triangles.len());
    (triangles, starts, degenerate)
}

/// Deduplicated edges (polygon sides, plus fan diagonals of non-planar polygons) and the
/// used vertices, each with the faces around it (a range of the returned list) and, when
/// `normals` is set, the normalized sum of their area-weighted normals. Linear time:
/// edges are bucketed by their lower vertex, corners by their vertex (counting sorts).
pub(super) fn edges_and_vertices(
    mesh: &Mesh,
    pos: &[DVec3],
    face_normals: &[DVec3],
    normals: bool,
) -> (Vec<Feature>, Vec<Feature>, Vec<u32>) {
    let planar: Vec<bool> = (0..mesh.face_count())
        .map(|f| mesh.face(f).len() == 3 || is_planar(mesh.face(f), pos, face_normals[f]))
        .collect();
    let for_each_edge = |visit: &mut dyn FnMut(u32, u32, u32)| {
        for (f, &flat) in planar.iter().enumerate() {
            let face = mesh.face(f);
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                if a != b {
                    visit(a.min(b), a.max(b), f as u32);
                }
            }
            if !flat {
                for k in 2..face.len() - 1 {
                    visit(face[0].min(face[k]), face[0].max(face[k]), f as u32);
                }
            }
        }
    };
    // (upper vertex, face) grouped by lower vertex.
    let (start, buckets) = group_by_key(pos.len(), |visit| {
        for_each_edge(&mut |lo, hi, f| visit(lo, (hi, f)))
    });
    let normal_of = |fs: &[u32]| {
        if normals {
            fs.iter()
                .map(|&f| face_normals[f as usize])
                .sum::<DVec3>()
                .normalize_or_zero()
        } else {
            DVec3::ZERO
        }
    };
    let (edges_part, vertices_part) = rayon::join(
        || edges_from_buckets(pos, &start, buckets, &normal_of),
        || vertices_of(mesh, pos, &normal_of),
    );
    let ((edges, mut faces), (mut vertices, vertex_faces)) = (edges_part, vertices_part);
    let shift = faces.len();
    for v in &mut vertices {
        v.faces = v.faces.start + shift..v.faces.end + shift;
    }
    faces.extend(vertex_faces);
    (edges, vertices, faces)
}

/// One edge per distinct (lower, upper) vertex pair of the buckets, with its faces.
pub(super) fn edges_from_buckets(
    pos: &[DVec3],
    start: &[usize],
    mut buckets: Vec<(u32, u32)>,
    normal_of: &(dyn Fn(&[u32]) -> DVec3 + Sync),
) -> (Vec<Feature>, Vec<u32>) {
    let mut faces: Vec<u32> = vec_to_fill(buckets.len());
    let mut edges = vec_to_fill(buckets.len() / 2);
    for lo in 0..pos.len() {
        let bucket = &mut buckets[start[lo]..start[lo + 1]];
        bucket.sort_unstable();
        for group in bucket.chunk_by(|x, y| x.0 == y.0) {
            let first = faces.len();
            for g in group {
                // Sorted within the group: a face listing the edge twice appears once.
                if faces.len() == first || faces[faces.len() - 1] != g.1 {
                    faces.push(g.1);
                }
            }
            edges.push(Feature {
                ends: [lo as u32, group[0].0],
                normal: normal_of(&faces[first..]).as_vec3(),
                faces: first..faces.len(),
            });
        }
    }
    (edges, faces)
}

/// The used vertices with the faces around each, by a counting sort of the corners.
pub(super) fn vertices_of(
    mesh: &Mesh,
    pos: &[DVec3],
    normal_of: &(dyn Fn(&[u32]) -> DVec3 + Sync),
) -> (Vec<Feature>, Vec<u32>) {
    let mut faces: Vec<u32> = vec_to_fill(mesh.indices.len());
    let (vstart, mut around) = group_by_key(pos.len(), |visit| {
        for f in 0..mesh.face_count() {
            mesh.face(f).iter().for_each(|&v| visit(v, f as u32));
        }
    });
    let mut vertices = vec_to_fill(pos.len());
    for v in 0..pos.len() {
        let list = &mut around[vstart[v]..vstart[v + 1]];
        if list.is_empty() {
            continue; // not used by any face
        }
        list.sort_unstable();
        let first = faces.len();
        for &f in list.iter() {
            if faces.len() == first || faces[faces.len() - 1] != f {
                faces.push(f);
            }
        }
        vertices.push(Feature {
            ends: [v as u32; 2],
            normal: normal_of(&faces[first..]).as_vec3(),
            faces: first..faces.len(),
        });
    }
    (vertices, faces)
}

/// All corners within 1e-6 voxels of the plane through the first corner with normal `n`.
pub(super) fn is_planar(face: &[u32], pos: &[DVec3], n: DVec3) -> bool {
    let n = n.normalize_or_zero();
    if n == DVec3::ZERO {
        return false;
    }
    let p0 = pos[face[0] as usize];
    face.iter()
        .all(|&i| n.dot(pos[i as usize] - p0).abs() <= 1e-6)
}

/// Integer range `ceil(lo)..=floor(hi)`.
#[inline]
pub(super) fn int_range(lo: f64, hi: f64) -> std::ops::RangeInclusive<i64> {
    ceil_int(lo)..=floor_int(hi)
}

/// Integer range `ceil(lo)..ceil(hi)`: the integers `v` with `lo <= v < hi`.
#[inline]
pub(super) fn half_open_range(lo: f64, hi: f64) -> std::ops::RangeInclusive<i64> {
    ceil_int(lo)..=ceil_int(hi) - 1
}

/// Values of `v` with `a v^2 + 2 b v + c <= 0` (`a > 0`, `inv_a = 1 / a`), widened by
/// `MARGIN`; empty when none. A candidate range: the caller tests each value exactly, and
/// the reciprocal's rounding is far below the margin.
#[inline]
pub(super) fn quadratic_range(a: f64, inv_a: f64, b: f64, c: f64) -> std::ops::RangeInclusive<i64> {
    let disc = b * b - a * c;
    if disc < 0.0 {
        return int_range(0.0, -1.0);
    }
    let root = disc.sqrt();
    int_range((-b - root) * inv_a - MARGIN, (-b + root) * inv_a + MARGIN)
}

/// `range` clipped to `clip`'s extent along `axis`.
#[inline]
pub(super) fn clipped(
    range: std::ops::RangeInclusive<i64>,
    clip: &CoordBox,
    axis: usize,
) -> std::ops::RangeInclusive<i64> {
    (*range.start()).max(clip.min[axis])..=(*range.end()).min(clip.max[axis])
}

/// S_v: voxel centres within `r` of the vertex (that `keep` accepts) and, with `halves`, in
/// the cone they leave (`vertex_cone`), in `clip`.
pub(super) fn vertex_sphere<const C: usize>(
    v: &Primitive,
    r: f64,
    keep: &impl Fn(&Primitive, DVec3) -> bool,
    halves: &[HalfSpace],
    clip: &CoordBox,
    sink: &mut BrickSink<C>,
) {
    let p = v.a;
    let r2 = (r + MARGIN) * (r + MARGIN);
    let ConeReach::Within(lo, hi) = cone_reach(halves, r + MARGIN) else {
        return;
    };
    let cut = AxisCut::new(halves, 2);
    for x in clipped(int_range(p.x + lo.x, p.x + hi.x), clip, 0) {
        for y in clipped(int_range(p.y + lo.y, p.y + hi.y), clip, 1) {
            let column = cut.range(
                clip.min[2]..=clip.max[2],
                DVec3::new(x as f64, y as f64, 0.0),
            );
            if column.is_empty() {
                continue;
            }
            let (dx, dy) = (x as f64 - p.x, y as f64 - p.y);
            // (z - p.z)^2 <= r2 - dx^2 - dy^2
            let near = quadratic_range(1.0, 1.0, -p.z, p.z * p.z + dx * dx + dy * dy - r2);
            let (first, last) = (
                (*near.start()).max(*column.start()),
                (*near.end()).min(*column.end()),
            );
            let kept = |z: i64| {
                let c = DVec3::new(x as f64, y as f64, z as f64);
                let d2 = (c - p).length_squared();
                (d2 <= r2 && keep(v, c)).then_some(d2)
            };
            sink.add_column([x, y, 0], 2, first..=last, kept, f64::sqrt, v.normal);
        }
    }
}

/// Angle (radians) by which a boundary ray of a sector may break a half-space and still
/// bound it: a sector narrower than this keeps both its sides.
pub(super) const SECTOR_ANGLE_SLACK: f64 = 1e-6;

/// Slack on bounds taken from `sector_directions`: the half-spaces' margins widen the exact
/// sector by at most 2 MARGIN / SECTOR_ANGLE_SLACK = 0.002 voxels.
pub(super) const SECTOR_SLACK: f64 = 0.01;

/// The unit directions across an edge (along the unit vector `dn`) at which a linear function
/// of the direction can be extreme over the sector that `halves`, planes through the edge,
/// cut from the disc across it: each of `toward` (directions across the edge, where the
/// functions are extreme on the whole disc) and each plane's two boundary rays, both ways,
/// kept where they lie in every half-space.
pub(super) fn sector_directions<const N: usize>(
    dn: DVec3,
    halves: &[HalfSpace],
    toward: [DVec3; N],
) -> impl Iterator<Item = DVec3> + '_ {
    let rays = halves
        .iter()
        .map(move |h| dn.cross(h.g).normalize_or_zero());
    toward
        .into_iter()
        .chain(rays)
        .flat_map(|u| [u, -u])
        .filter(|u| halves.iter().all(|h| h.g.dot(*u) <= SECTOR_ANGLE_SLACK))
}

/// S_e: voxel centres within `r` of the edge whose projection falls on the edge (and that
/// `keep` accepts), in `clip`.
pub(super) fn edge_cylinder<const C: usize>(
    e: &Primitive,
    r: f64,
    keep: &impl Fn(&Primitive, DVec3) -> bool,
    halves: &[HalfSpace],
    clip: &CoordBox,
    sink: &mut BrickSink<C>,
) {
    let (p, d) = (e.a, e.b - e.a);
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return; // both ends are one vertex: its sphere covers it
    }
    let w = d.abs().max_position();
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let r = r + MARGIN;
    let dn = d / len2.sqrt();
    // In a plane across axis w the whole cylinder's section is an ellipse reaching
    // `reach` = r sqrt(1 - dn_v^2) / |dn_w| from the axis along u; the caps, discs of radius r
    // across the edge, reach `cap` = r sqrt(1 - dn_w^2) beyond its ends along w.
    // Planes through the edge (`halves`) cut the disc across it to a sector. A point rho q
    // off the axis (q across the edge) lies in the plane across axis w through the axis's
    // point c when moved back along the edge by rho q_w / dn_w, which puts it rho q.f from
    // c along u, for f = e_u - (dn_u / dn_w) e_w (itself across the edge, |f| r = reach):
    // so the sector's rows lie within r [min q.f, max q.f] of c, 0 (the axis) included.
    // Along w the sector reaches r [min q_w, max q_w] beyond the edge's ends, where the
    // whole disc's caps reach `cap` both ways: a thin sector's planes are about half.
    let (reach_lo, reach_hi, cap_lo, cap_hi) = if halves.is_empty() {
        let reach = r * (1.0 - dn[v] * dn[v]).sqrt() / dn[w].abs() + ROW_SLACK;
        let cap = cylinder_reach(d, r)[w];
        (-reach, reach, -cap, cap)
    } else {
        let mut f = DVec3::ZERO;
        f[u] = 1.0;
        f[w] = -dn[u] / dn[w];
        // e_w less its part along the edge: across it, where q_w is extreme on the disc.
        let mut g = -dn * dn[w];
        g[w] += 1.0;
        let ([f_lo, f_hi], [w_lo, w_hi]) =
            sector_directions(dn, halves, [f.normalize(), g.normalize_or_zero()]).fold(
                ([0.0f64; 2], [0.0f64; 2]),
                |(f_range, w_range), q| {
                    let (l, m) = (q.dot(f), q[w]);
                    (
                        [f_range[0].min(l), f_range[1].max(l)],
                        [w_range[0].min(m), w_range[1].max(m)],
                    )
                },
            );
        (
            r * f_lo - SECTOR_SLACK,
            r * f_hi + SECTOR_SLACK,
            r * w_lo - SECTOR_SLACK,
            r * w_hi + SECTOR_SLACK,
        )
    };
    let tau_margin = MARGIN / len2.sqrt();
    let test = EdgeTest::new(e, r);
    // The quadratic's leading coefficient is the edge's: 1 - dn_v^2 >= 2/3, as v is not
    // its longest axis.
    let a = 1.0 - dn[v] * dn[v];
    let inv_a = 1.0 / a;
    // Reciprocals for the candidate ranges (the exact tests below divide).
    let inv_len2 = 1.0 / len2;
    let dt = d[v] * inv_len2;
    let inv_dt = 1.0 / dt;
    let columns = clip.min[v]..=clip.max[v];
    let cut = AxisCut::new(halves, v);
    for k in clipped(
        int_range(p[w].min(e.b[w]) + cap_lo, p[w].max(e.b[w]) + cap_hi),
        clip,
        w,
    ) {
        let c = p + d * ((k as f64 - p[w]) / d[w]);
        for iu in clipped(int_range(c[u] + reach_lo, c[u] + reach_hi), clip, u) {
            let mut row = DVec3::ZERO;
            row[w] = k as f64;
            row[u] = iu as f64;
            let span = cut.range(columns.clone(), row);
            if span.is_empty() {
                continue;
            }
            // y = x - p with x_v = 0; dist^2(v) = |y + v e_v|^2 - ((y + v e_v)·dn)^2 <= r^2.
            let y0 = row - p;
            // tau is linear along the row: keep the values of iv whose projection can fall on
            // the edge (most of a short edge's rows lie beyond its ends).
            let t0 = y0.dot(d) * inv_len2;
            let on_edge = if dt == 0.0 {
                if (-tau_margin..=1.0 + tau_margin).contains(&t0) {
                    span
                } else {
                    continue;
                }
            } else {
                let (e0, e1) = (
                    (-tau_margin - t0) * inv_dt,
                    (1.0 + tau_margin - t0) * inv_dt,
                );
                let along = int_range(e0.min(e1) - ROW_SLACK, e0.max(e1) + ROW_SLACK);
                (*span.start()).max(*along.start())..=(*span.end()).min(*along.end())
            };
            if on_edge.is_empty() {
                continue;
            }
            let along = y0.dot(dn);
            let b = y0[v] - along * dn[v];
            let cc = y0.length_squared() - along * along - r * r;
            let near = quadratic_range(a, inv_a, b, cc);
            let first = (*near.start()).max(*on_edge.start());
            let last = (*near.end()).min(*on_edge.end());
            let kept = |iv: i64| {
                let mut x = row;
                x[v] = iv as f64;
                let (inside, d2) = test.at(x);
                (inside && keep(e, x)).then_some(d2)
            };
            sink.add_column(to_coord(row), v, first..=last, kept, f64::sqrt, e.normal);
        }
    }
}

/// The exact test of S_e for an edge of non-zero length, with radius `r` (margin included):
/// a centre within `r` of the edge whose projection falls on it (`tau` in `[0, 1]`, widened
/// by `MARGIN` voxels along the edge).
pub(super) struct EdgeTest {
    p: DVec3,
    d: DVec3,
    inv_len2: f64,
    tau_margin: f64,
    r2: f64,
}

impl EdgeTest {
    pub(super) fn new(e: &Primitive, r: f64) -> Self {
        let d = e.b - e.a;
        let len2 = d.length_squared();
        EdgeTest {
            p: e.a,
            d,
            inv_len2: 1.0 / len2,
            tau_margin: MARGIN / len2.sqrt(),
            r2: r * r,
        }
    }

    /// Whether `x` is in, and its squared distance to the edge's line; without a branch or
    /// a division (a division per voxel took a twentieth of a surface's voxelizing).
    #[inline]
    pub(super) fn at(&self, x: DVec3) -> (bool, f64) {
        let tau = (x - self.p).dot(self.d) * self.inv_len2;
        let d2 = (x - self.p - self.d * tau).length_squared();
        let inside = (tau >= -self.tau_margin) & (tau <= 1.0 + self.tau_margin) & (d2 <= self.r2);
        (inside, d2)
    }
}

/// S_b: voxel centres in the triangle's slab `d_lo <= d < d_hi` (`d` along the turned normal:
/// see the module docs) whose projection lies inside it, in `clip`.
pub(super) fn face_body<const C: usize>(
    tri: &Triangle,
    (d_lo, d_hi): (f64, f64),
    clip: &CoordBox,
    sink: &mut BrickSink<C>,
) {
    // The slab is measured along the turned normal; the row bounds below do not depend on
    // the normal's sign, the edge planes do (they point inwards for the face's own normal).
    let n = turned(tri.normal);
    let [a, b, c] = tri.corners;
    let t = (-d_lo).max(d_hi);
    let w = n.abs().max_position();
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let sides = edge_planes(tri);
    // The same planes as half-spaces, to cut each column to the prism before the exact test:
    // worth it where columns are long (a thick slab, as the distance band's), not for the
    // one or two voxels of a separating surface's.
    let inside_sides = sides.map(|(m, p)| HalfSpace {
        g: -m,
        h: m.dot(p) - MARGIN,
    });
    let column_cut = ((d_hi - d_lo) / n[w] > 4.0).then(|| AxisCut::new(&inside_sides, w));
    let reach = slab_reach(n, t);
    let (lo, hi) = (a.min(b).min(c) - reach, a.max(b).max(c) + reach);
    let half = t / n[w].abs();
    let inv_nw = 1.0 / n[w];
    // Clip each row to the columns whose slab segment can reach inside every edge plane: the
    // best k of the slab turns each plane test into a linear bound on iv, `at(iu) + slope iv
    // >= 0` with `at(iu) = at0 + at1 iu`, set up once per triangle. The worst k of the slab
    // (`at0` less `across`) bounds the columns whose whole segment lies inside every plane,
    // with room for rounding: those need no cut.
    let bounds = sides.map(|(m, p)| {
        let slope = m[v] - m[w] * n[v] / n[w];
        let at1 = m[u] - m[w] * n[u] / n[w];
        let at0 = -m[u] * p[u] - m[v] * p[v]
            + m[w] * (a[w] - p[w])
            + m[w] * (n[u] * a[u] + n[v] * a[v]) / n[w]
            + m[w].abs() * half
            + ROW_SLACK;
        let across = 2.0 * (m[w].abs() * half + ROW_SLACK);
        (slope, at0, at1, across)
    });
    let row = |iu: i64, inner: bool| {
        let (mut v_lo, mut v_hi) = (lo[v], hi[v]);
        for &(slope, at0, at1, across) in &bounds {
            let at_zero = at0 + at1 * iu as f64 - if inner { across } else { 0.0 };
            if slope > 0.0 {
                v_lo = v_lo.max(-at_zero / slope);
            } else if slope < 0.0 {
                v_hi = v_hi.min(-at_zero / slope);
            } else if at_zero < 0.0 {
                v_hi = f64::NEG_INFINITY;
            }
        }
        // Checked before converting: a near-zero slope puts a bound far beyond i64.
        if v_lo > v_hi {
            return int_range(0.0, -1.0);
        }
        int_range(v_lo, v_hi)
    };
    for iu in clipped(int_range(lo[u], hi[u]), clip, u) {
        let reached = clipped(row(iu, false), clip, v);
        if reached.is_empty() {
            continue;
        }
        let uncut = if column_cut.is_some() {
            row(iu, true)
        } else {
            int_range(0.0, -1.0)
        };
        for iv in reached {
            let s = n[u] * (iu as f64 - a[u]) + n[v] * (iv as f64 - a[v]);
            // d_lo <= s + n_w (k - a_w) < d_hi with n_w > 0, solved for k (the slab's
            // margins dwarf the reciprocal's rounding).
            let k0 = a[w] + (d_lo - s) * inv_nw;
            let k1 = a[w] + (d_hi - s) * inv_nw;
            let mut column = DVec3::ZERO;
            column[u] = iu as f64;
            column[v] = iv as f64;
            let slab = clipped(half_open_range(k0, k1), clip, w);
            if let Some(cut) = &column_cut {
                let ks = if uncut.contains(&iv) {
                    slab
                } else {
                    cut.range(slab, column)
                };
                // A cut column is exact to 1e-6 voxels, which moves a plane distance by less
                // than 1e-12: the distance band needs no test per voxel.
                let distance = plane_distance_along(n, a, column, w);
                sink.add_column(to_coord(column), w, ks, Some, distance, tri.normal);
                continue;
            }
            for k in slab {
                let mut x = column;
                x[w] = k as f64;
                if within_edge_planes(&sides, x) {
                    sink.add(to_coord(x), || n.dot(x - a).abs(), tri.normal);
                }
            }
        }
    }
}

/// `|n·(x - a)|` at the centres `x` of `column` along `axis` (`x[axis] = k`), the sum taken
/// in the order `DVec3::dot` takes it, so that each value is the same to the bit; the two
/// fixed products once per column.
#[inline]
fn plane_distance_along(n: DVec3, a: DVec3, column: DVec3, axis: usize) -> impl Fn(i64) -> f64 {
    let p = n * (column - a);
    move |k| {
        let q = n[axis] * (k as f64 - a[axis]);
        match axis {
            0 => ((q + p.y) + p.z).abs(),
            1 => ((p.x + q) + p.z).abs(),
            _ => ((p.x + p.y) + q).abs(),
        }
    }
}

/// In-plane inward normals of the triangle's edges, each with a point on it: the planes E_i
/// of the paper.
pub(super) fn edge_planes(tri: &Triangle) -> [(DVec3, DVec3); 3] {
    let [a, b, c] = tri.corners;
    [(a, b), (b, c), (c, a)].map(|(p, q)| {
        let m = tri.normal.cross(q - p);
        (m / m.length(), p)
    })
}

/// Whether `x` lies inside every edge plane (`edge_planes`), up to `MARGIN`; without a
/// branch.
#[inline]
pub(super) fn within_edge_planes(sides: &[(DVec3, DVec3); 3], x: DVec3) -> bool {
    sides
        .iter()
        .fold(true, |all, (m, p)| all & (m.dot(x - *p) >= -MARGIN))
}

#[inline]
pub(super) fn to_coord(x: DVec3) -> [i64; 3] {
    [x.x as i64, x.y as i64, x.z as i64]
}

/// A hint that `x` will be read soon; nothing where the target has no such hint.
#[inline]
fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing and cannot fault; the pointer is a valid reference's.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            (x as *const T).cast(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
