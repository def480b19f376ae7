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
//! Deviations from the paper:
//! - Polygons are fanned into triangles for the body test. The fan's inner diagonals get
//!   no cylinder when the polygon is planar (a centre projecting inside the polygon projects
//!   into one of its triangles); non-planar polygons keep them, as the proof needs.
//! - Faces of zero area have no plane: their edges and vertices still cover them.
//! - All tests accept a margin of 1e-9 voxels so rounding never opens a hole.
//! - Class counts follow the paper's order: vertex first, then edge, then body; each voxel
//!   is counted once, so the three counts add up to the total.

use super::Separability;
use super::sink::{Progress, Sink, merge_grids, nearest_channels, voxelize_parallel};
use crate::error::{Error, Result};
use crate::grid::{SparseGrid, Transform};
use crate::mesh::Mesh;
use glam::DVec3;

/// Tolerance, in voxels, added to every inclusion test.
const MARGIN: f64 = 1e-9;

#[derive(Clone, Copy, Debug)]
pub struct SeparatingOptions {
    pub separability: Separability,
    /// Keep the nearest face, edge or vertex normal (and its distance) per voxel.
    pub normals: bool,
}

impl Default for SeparatingOptions {
    fn default() -> Self {
        SeparatingOptions {
            separability: Separability::TwentySix,
            normals: false,
        }
    }
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

struct Triangle {
    corners: [DVec3; 3],
    normal: DVec3,
}

struct Primitive {
    a: DVec3,
    b: DVec3,
    normal: DVec3,
}

/// Work items: number of vertices, edges and triangles the voxelizer will process.
pub fn work_items(mesh: &Mesh) -> u64 {
    (mesh.positions.len() + 2 * mesh.indices.len()) as u64
}

/// Rough peak memory for voxelizing `mesh` with `transform`, in bytes, from its area in
/// voxels (the surface is at most ~2 voxels thick; three class grids live at once).
pub fn estimate_bytes(mesh: &Mesh, transform: &Transform, opts: &SeparatingOptions) -> u64 {
    let area = mesh.area() / (transform.voxel_size * transform.voxel_size);
    let voxels = area * 2.0 + mesh.positions.len() as f64 * 8.0;
    // A surface fills a leaf with ~8x8 voxels per layer; assume a quarter of that.
    let leaves = voxels / 16.0 + 1.0;
    let leaf_bytes = 160.0 + if opts.normals { 512.0 * 16.0 } else { 0.0 };
    (3.0 * leaves * leaf_bytes + mesh.indices.len() as f64 * 120.0) as u64
}

/// Voxelizes `mesh` (world units) into a grid with `transform`.
pub fn voxelize_mesh(
    mesh: &Mesh,
    transform: Transform,
    opts: &SeparatingOptions,
    progress: Progress,
) -> Result<(SparseGrid, SeparatingStats)> {
    mesh.validate()?;
    if !(transform.voxel_size > 0.0 && transform.voxel_size.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "voxel size must be positive, got {}",
            transform.voxel_size
        )));
    }
    let pos: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| transform.world_to_index(p))
        .collect();
    let sep = opts.separability;
    let channels = nearest_channels(opts.normals);

    let (triangles, degenerate_faces, face_normals) = triangles_of(mesh, &pos);
    let (edges, vertices) = edges_and_vertices(mesh, &pos, &face_normals, opts.normals);

    let vertex_grid = voxelize_parallel(&vertices, transform, channels, progress, |v, s| {
        vertex_sphere(v, sep.vertex_edge_radius(), s)
    });
    let edge_grid = voxelize_parallel(&edges, transform, channels, progress, |e, s| {
        edge_cylinder(e, sep.vertex_edge_radius(), s)
    });
    let body_grid = voxelize_parallel(&triangles, transform, channels, progress, |t, s| {
        face_body(t, sep, s)
    });

    let vertex_voxels = vertex_grid.voxel_count();
    let edge_only = count_outside(&edge_grid, &[&vertex_grid]);
    let body_only = count_outside(&body_grid, &[&vertex_grid, &edge_grid]);
    let stats = SeparatingStats {
        vertex_voxels,
        edge_voxels: edge_only,
        body_voxels: body_only,
        vertices: vertices.len(),
        edges: edges.len(),
        triangles: triangles.len(),
        degenerate_faces,
    };
    let grid = merge_grids(merge_grids(vertex_grid, edge_grid), body_grid);
    Ok((grid, stats))
}

/// Voxels of `grid` in none of `others`.
fn count_outside(grid: &SparseGrid, others: &[&SparseGrid]) -> u64 {
    grid.leaves()
        .iter()
        .map(|leaf| {
            let mut mask = leaf.mask;
            for o in others {
                if let Some(ol) = o.leaf(leaf.origin) {
                    (0..8).for_each(|w| mask[w] &= !ol.mask[w]);
                }
            }
            mask.iter().map(|w| w.count_ones() as u64).sum::<u64>()
        })
        .sum()
}

/// Fan triangles with unit normals (degenerate ones dropped), the number of degenerate
/// faces, and each face's area-weighted normal.
fn triangles_of(mesh: &Mesh, pos: &[DVec3]) -> (Vec<Triangle>, usize, Vec<DVec3>) {
    let mut triangles = Vec::with_capacity(mesh.indices.len());
    let mut degenerate = 0;
    let mut face_normals = Vec::with_capacity(mesh.face_count());
    for f in 0..mesh.face_count() {
        let face = mesh.face(f);
        let mut area_normal = DVec3::ZERO;
        let mut kept = 0;
        for k in 1..face.len() - 1 {
            let corners = [
                pos[face[0] as usize],
                pos[face[k] as usize],
                pos[face[k + 1] as usize],
            ];
            let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            area_normal += cross;
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
        face_normals.push(area_normal);
    }
    (triangles, degenerate, face_normals)
}

/// Deduplicated edges (polygon sides, plus fan diagonals of non-planar polygons) and the
/// used vertices, each with the normal of the faces around it when `normals` is set.
fn edges_and_vertices(
    mesh: &Mesh,
    pos: &[DVec3],
    face_normals: &[DVec3],
    normals: bool,
) -> (Vec<Primitive>, Vec<Primitive>) {
    let mut keyed: Vec<(u64, DVec3)> = Vec::with_capacity(mesh.indices.len() * 2);
    let mut vertex_normal = vec![DVec3::ZERO; pos.len()];
    let mut used = vec![false; pos.len()];
    let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
    for f in 0..mesh.face_count() {
        let face = mesh.face(f);
        let nf = face_normals[f];
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            if a != b {
                keyed.push((key(a, b), nf));
            }
            used[a as usize] = true;
            vertex_normal[a as usize] += nf;
        }
        if face.len() > 3 && !is_planar(face, pos, nf) {
            for k in 2..face.len() - 1 {
                keyed.push((key(face[0], face[k]), nf));
            }
        }
    }
    keyed.sort_unstable_by_key(|e| e.0);
    let mut edges = Vec::with_capacity(keyed.len() / 2);
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i;
        let mut n = DVec3::ZERO;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            n += keyed[j].1;
            j += 1;
        }
        let (a, b) = (
            (keyed[i].0 >> 32) as usize,
            (keyed[i].0 & 0xffff_ffff) as usize,
        );
        edges.push(Primitive {
            a: pos[a],
            b: pos[b],
            normal: if normals {
                n.normalize_or_zero()
            } else {
                DVec3::ZERO
            },
        });
        i = j;
    }
    let vertices = (0..pos.len())
        .filter(|&v| used[v])
        .map(|v| Primitive {
            a: pos[v],
            b: pos[v],
            normal: if normals {
                vertex_normal[v].normalize_or_zero()
            } else {
                DVec3::ZERO
            },
        })
        .collect();
    (edges, vertices)
}

/// All corners within 1e-6 voxels of the plane through the first corner with normal `n`.
fn is_planar(face: &[u32], pos: &[DVec3], n: DVec3) -> bool {
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
fn int_range(lo: f64, hi: f64) -> std::ops::RangeInclusive<i64> {
    (lo.ceil() as i64)..=(hi.floor() as i64)
}

/// S_v: voxel centres within `r` of the vertex.
fn vertex_sphere(v: &Primitive, r: f64, sink: &mut Sink) {
    let p = v.a;
    let r2 = (r + MARGIN) * (r + MARGIN);
    for x in int_range(p.x - r, p.x + r + MARGIN) {
        for y in int_range(p.y - r, p.y + r + MARGIN) {
            for z in int_range(p.z - r - MARGIN, p.z + r + MARGIN) {
                let d2 = (DVec3::new(x as f64, y as f64, z as f64) - p).length_squared();
                if d2 <= r2 {
                    sink.add([x, y, z], d2.sqrt(), v.normal);
                }
            }
        }
    }
}

/// S_e: voxel centres within `r` of the edge whose projection falls on the edge.
fn edge_cylinder(e: &Primitive, r: f64, sink: &mut Sink) {
    let (p, d) = (e.a, e.b - e.a);
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return; // both ends are one vertex: its sphere covers it
    }
    let w = d.abs().max_position();
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let r = r + MARGIN;
    // In a plane across axis w, the cylinder's section stays within r / |unit d_w| of the axis.
    let reach = r * len2.sqrt() / d[w].abs();
    let tau_margin = MARGIN / len2.sqrt();
    for k in int_range(p[w].min(e.b[w]) - r, p[w].max(e.b[w]) + r) {
        let c = p + d * ((k as f64 - p[w]) / d[w]);
        for iu in int_range(c[u] - reach, c[u] + reach) {
            for iv in int_range(c[v] - reach, c[v] + reach) {
                let mut x = DVec3::ZERO;
                x[w] = k as f64;
                x[u] = iu as f64;
                x[v] = iv as f64;
                let tau = (x - p).dot(d) / len2;
                if !(-tau_margin..=1.0 + tau_margin).contains(&tau) {
                    continue;
                }
                let d2 = (x - p - d * tau).length_squared();
                if d2 <= r * r {
                    sink.add(to_coord(x), d2.sqrt(), e.normal);
                }
            }
        }
    }
}

/// S_b: voxel centres within `t` of the triangle's plane whose projection lies inside it.
fn face_body(tri: &Triangle, sep: Separability, sink: &mut Sink) {
    let n = tri.normal;
    let [a, b, c] = tri.corners;
    let t = sep.slab_half_thickness(n) + MARGIN;
    let w = n.abs().max_position();
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    // In-plane inward normals of the edges: the planes E_i of the paper.
    let sides = [(a, b), (b, c), (c, a)].map(|(p, q)| {
        let m = n.cross(q - p);
        (m / m.length(), p)
    });
    let lo = a.min(b).min(c) - DVec3::splat(t);
    let hi = a.max(b).max(c) + DVec3::splat(t);
    for iu in int_range(lo[u], hi[u]) {
        for iv in int_range(lo[v], hi[v]) {
            let s = n[u] * (iu as f64 - a[u]) + n[v] * (iv as f64 - a[v]);
            // -t <= s + n_w (k - a_w) <= t, solved for k.
            let k0 = a[w] + (-t - s) / n[w];
            let k1 = a[w] + (t - s) / n[w];
            for k in int_range(k0.min(k1), k0.max(k1)) {
                let mut x = DVec3::ZERO;
                x[w] = k as f64;
                x[u] = iu as f64;
                x[v] = iv as f64;
                if sides.iter().all(|(m, p)| m.dot(x - *p) >= -MARGIN) {
                    sink.add(to_coord(x), n.dot(x - a).abs(), n);
                }
            }
        }
    }
}

#[inline]
fn to_coord(x: DVec3) -> [i64; 3] {
    [x.x as i64, x.y as i64, x.z as i64]
}
