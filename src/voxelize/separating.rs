//! Separating polygon-mesh voxelization by the distance criterion of Huang, Yagel,
//! Filippov and Kurzion, "An Accurate Method for Voxelizing Polygon Meshes" (1998), §4–5.
//!
//! A voxel (centre `x`, index space, L = 1) belongs to the surface when `x` lies
//! - in a vertex sphere of radius `Rc` (the set S_v),
//! - in an edge cylinder of radius `Rc` capped by the edge's end planes (S_e), or
//! - in a face's body: between the planes at distance `t` from the face and inside the
//!   planes E_i through its edges perpendicular to it (S_b),
//!
//! with `t = t6 = max|n_i|/2, Rc = 1/2` for 6-separating and `t = t26 = sum|n_i|/2,
//! Rc = sqrt(3)/2` for 26-separating surfaces.
//!
//! Why this separates (the paper proves planes only): an N-step between voxel centres A, B
//! that crosses face F at P has `|d_A| + |d_B| = |n·(B-A)| <= 2t`, so the closer centre A
//! has `|d_A| <= t` and `|A-P| <= |B-A|/2 <= Rc`. If A projects into F it is a body voxel;
//! otherwise the segment from A to P leaves F through its boundary, so A lies within
//! `|A-P| <= Rc` of an edge or vertex. Every inside-to-outside path makes such a step.
//!
//! The same argument shows that A needs the sphere or cylinder only where it is also within
//! `t` of the plane of a face around that edge or vertex: `Criterion::Clipped` keeps just
//! those voxels, which removes most simple voxels the paper's full spheres and cylinders add.
//!
//! Slabs are half-open: with the face normal `n` turned so that its largest component is
//! positive, a body voxel has `-t <= d < t` for `d = n·(x - p)`. A face lying exactly half-way
//! between two rows of centres (a box whose faces fall on voxel boundaries, as the grid fit
//! places a bounding box) then keeps one row, not both. The proof still holds: for an N-step
//! from A to B across the face, `d_B - d_A` lies in `[-2t, 2t]` with `d_A, d_B` of opposite
//! signs; if neither lay in `[-t, t)`, the one below would have `d < -t` and the other
//! `d >= t`, a gap over `2t`. The included centre is the closer one except at a tie, where
//! both lie `|B-A|/2 <= Rc` from P, so the edge and vertex part of the argument is unchanged.
//! Spheres and cylinders stay closed; the clipped criterion uses the same half-open slabs.
//!
//! Deviations from the paper:
//! - Polygons are fanned into triangles for the body test. The fan's inner diagonals get
//!   no cylinder when the polygon is planar (a centre projecting inside the polygon projects
//!   into one of its triangles); non-planar polygons keep them, as the proof needs.
//! - Faces of zero area have no plane: their edges and vertices still cover them.
//! - All tests accept a margin of 1e-9 voxels so rounding never opens a hole: a slab is
//!   `-t - margin <= d < t - margin/2`, so that rounding can add a voxel at a tie but never
//!   drop both.
//! - Class counts follow the paper's order: vertex first, then edge, then body; each voxel
//!   is counted once, so the three counts add up to the total.

use super::Progress;
use super::Separability;
use super::brick_bins::{BrickSink, scratch_bytes, voxelize_in_bricks};
use super::separating_kernel::{
    EdgeTest, MARGIN, Primitive, PrimitiveClass, Primitives, Triangle, clipped, cylinder_reach,
    edge_cylinder, edge_planes, face_body, int_range, primitives, slab_bounds, slab_reach, turned,
    vertex_sphere, within_edge_planes,
};
use super::sink::nearest_channels;
use crate::error::Result;
use crate::grid::{CoordBox, SparseGrid, Transform};
use crate::mesh::Mesh;
use glam::DVec3;

/// Which voxels around edges and vertices are kept.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Criterion {
    /// The paper's: whole vertex spheres and edge cylinders of radius `Rc`.
    #[default]
    Huang,
    /// Spheres and cylinders clipped to the slabs (half thickness `t`) of the faces around
    /// them. Still separating (see the module docs) with far fewer simple voxels.
    Clipped,
}

crate::named_choices! {
    Criterion, "the criterion":
    "huang" => Huang,
    "clipped" => Clipped,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct SeparatingOptions {
    pub separability: Separability,
    pub criterion: Criterion,
    /// Keep the nearest face, edge or vertex normal (and its distance) per voxel.
    pub normals: bool,
}

/// What the voxelizer did, like Tables 2–3 of the paper.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SeparatingStats {
    /// Voxels in a vertex sphere.
    pub vertex_voxels: u64,
    /// Voxels in an edge cylinder and in no vertex sphere.
    pub edge_voxels: u64,
    /// Voxels only in a face body.
    pub body_voxels: u64,
    pub vertices: usize,
    pub edges: usize,
    pub triangles: usize,
    /// Faces with (near) zero area or a repeated vertex: voxelized by their edges only.
    pub degenerate_faces: usize,
}

impl SeparatingStats {
    pub fn total_voxels(&self) -> u64 {
        self.vertex_voxels + self.edge_voxels + self.body_voxels
    }
}

/// Work items, as `progress` counts them: vertices, edges and triangles (edges estimated as
/// half the face corners, exact for closed meshes).
pub fn work_items(mesh: &Mesh) -> u64 {
    (mesh.positions.len() + mesh.indices.len() / 2 + mesh.triangle_count()) as u64
}

/// Bytes of the brick scratch each thread of `voxelize_mesh` keeps, with normals or not.
pub fn thread_scratch_bytes(normals: bool) -> u64 {
    scratch_bytes(nearest_channels(normals), PrimitiveClass::ALL.len())
}

/// Voxelizes `mesh` (world units) into a grid with `transform`.
pub fn voxelize_mesh(
    mesh: &Mesh,
    transform: Transform,
    opts: &SeparatingOptions,
    progress: &Progress,
) -> Result<(SparseGrid, SeparatingStats)> {
    let sep = opts.separability;
    let channels = nearest_channels(opts.normals);
    let found = primitives(mesh, transform, opts.normals)?;
    let Primitives {
        triangles,
        adjacency,
        degenerate_faces,
        ..
    } = &found;
    let keep = |p: &Primitive, x: DVec3| match opts.criterion {
        Criterion::Huang => true,
        Criterion::Clipped => adjacency.in_face_slab(p, triangles, sep, x),
    };

    let r = sep.vertex_edge_radius();
    // Whole spheres and cylinders: short edges may take the branch-free path.
    let plain = opts.criterion == Criterion::Huang;
    // One brick class per primitive class, in the paper's counting order.
    let candidates = |class: usize, i: usize| {
        let class = PrimitiveClass::ALL[class];
        let reach = match class {
            PrimitiveClass::Body => sep.slab_half_thickness(triangles[i].normal),
            _ => r,
        };
        found.reach_box_of(class, i, reach + MARGIN)
    };
    let (grid, [vertex_voxels, edge_voxels, body_voxels]) = voxelize_in_bricks(
        found.counts(),
        transform,
        channels,
        progress,
        candidates,
        |class, i, clip, sink| match PrimitiveClass::ALL[class] {
            PrimitiveClass::Vertex => vertex_sphere(&found.vertex(i), r, &keep, &[], clip, sink),
            PrimitiveClass::Edge => {
                let edge = found.edge(i);
                if !(plain && sink.bits_only() && short_edge_cylinder(&edge, r, clip, sink)) {
                    edge_cylinder(&edge, r, &keep, &[], clip, sink)
                }
            }
            PrimitiveClass::Body => {
                let tri = &triangles[i];
                let slab = slab_bounds(sep.slab_half_thickness(tri.normal));
                if !(sink.bits_only() && small_face_body(tri, slab, clip, sink)) {
                    face_body(tri, slab, clip, sink)
                }
            }
        },
    )?;
    let [vertices, edges, _] = found.counts();
    let stats = SeparatingStats {
        vertex_voxels,
        edge_voxels,
        body_voxels,
        vertices,
        edges,
        triangles: triangles.len(),
        degenerate_faces: *degenerate_faces,
    };
    Ok((grid, stats))
}

/// Most voxels in the box of a primitive that `short_edge_cylinder` or `small_face_body`
/// tests one by one.
const SMALL_BOX_CELLS: i64 = 256;

/// `lo..=hi` by axis, clipped to `clip`, when it holds at most `SMALL_BOX_CELLS` voxels and
/// at most 64 along z (`mark_box`'s runs are words).
fn small_box(lo: DVec3, hi: DVec3, clip: &CoordBox) -> Option<[std::ops::RangeInclusive<i64>; 3]> {
    let ranges = [0, 1, 2].map(|a| clipped(int_range(lo[a], hi[a]), clip, a));
    let lengths = ranges
        .clone()
        .map(|range| (range.end() - range.start() + 1).max(0));
    (lengths.iter().product::<i64>() <= SMALL_BOX_CELLS && lengths[2] <= 64).then_some(ranges)
}

/// Marks, column by column along z, the voxels of the box (within one brick) that `inside`
/// accepts, each column as one run.
#[inline]
fn mark_box<const C: usize>(
    [xs, ys, zs]: [std::ops::RangeInclusive<i64>; 3],
    inside: impl Fn(DVec3) -> bool,
    sink: &mut BrickSink<C>,
) {
    let z0 = *zs.start();
    for x in xs {
        for y in ys.clone() {
            let mut run = 0u64;
            for z in zs.clone() {
                let c = DVec3::new(x as f64, y as f64, z as f64);
                run |= u64::from(inside(c)) << (z - z0);
            }
            if run != 0 {
                sink.add_z_run(x, y, z0, run);
            }
        }
    }
}

/// S_e as `edge_cylinder` marks it with whole cylinders and bits alone (no half-spaces, no
/// channels), for an edge whose box holds at most `SMALL_BOX_CELLS` voxels: every voxel of
/// the box gets `edge_cylinder`'s exact test, without a branch (its rows' set-up costs more
/// than so few tests). Returns false, marking nothing, for a longer edge.
fn short_edge_cylinder<const C: usize>(
    e: &Primitive,
    r: f64,
    clip: &CoordBox,
    sink: &mut BrickSink<C>,
) -> bool {
    let (p, d) = (e.a, e.b - e.a);
    if d.length_squared() == 0.0 {
        return true; // both ends are one vertex: its sphere covers it
    }
    let r = r + MARGIN;
    let reach = cylinder_reach(d, r);
    let Some(cells) = small_box(p.min(e.b) - reach, p.max(e.b) + reach, clip) else {
        return false;
    };
    let test = EdgeTest::new(e, r);
    mark_box(cells, |c| test.at(c).0, sink);
    true
}

/// S_b as `face_body` marks it, with bits alone, for a triangle whose box (and slab) holds
/// at most `SMALL_BOX_CELLS` voxels: every voxel of the box is tested against the slab
/// `d_lo <= d < d_hi` and the edge planes without a branch. Returns false, marking
/// nothing, for a larger triangle.
fn small_face_body<const C: usize>(
    tri: &Triangle,
    (d_lo, d_hi): (f64, f64),
    clip: &CoordBox,
    sink: &mut BrickSink<C>,
) -> bool {
    let [a, b, c] = tri.corners;
    let n = turned(tri.normal);
    let reach = slab_reach(n, (-d_lo).max(d_hi));
    let Some(cells) = small_box(a.min(b).min(c) - reach, a.max(b).max(c) + reach, clip) else {
        return false;
    };
    let sides = edge_planes(tri);
    mark_box(
        cells,
        |x| {
            let d = n.dot(x - a);
            (d_lo <= d) & (d < d_hi) & within_edge_planes(&sides, x)
        },
        sink,
    );
    true
}
