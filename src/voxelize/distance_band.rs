//! The narrow band of exact distances to a mesh: every voxel whose centre lies within `band`
//! voxels of the mesh, with its distance to the mesh's nearest point, computed in f64 and kept
//! as f32 in voxel units. The sign (inside or outside) is not decided here: see
//! `solids::level_set`.
//!
//! The nearest point of a mesh to a centre lies inside a face, inside an edge or at a vertex,
//! so the distance is the least of: the plane distance to each triangle the centre projects
//! into, the distance to each edge whose span it projects into, and the distance to each
//! vertex. Each feature marks its own region within the band, as the separating voxelizer's
//! bodies, cylinders and spheres do (`separating`), with radius and slab half thickness
//! `band`, and the brick keeps the least distance per voxel. Edges and vertices are shared:
//! each is visited once, not once per triangle around it.
//!
//! Cylinders and spheres are cut to where their feature can be nearest. A centre nearest to
//! the inside of an edge does not project strictly inside a triangle across that edge (the
//! triangle's plane would be nearer), and a centre nearest to a vertex has no edge or fan
//! diagonal from the vertex pointing towards it (a point along it would be nearer). On a
//! smooth mesh these regions are thin wedges and cones, so a mesh of small triangles (seven
//! within the band of each voxel on igea at 1024) costs about one distance per voxel.

use super::Progress;
use super::brick_bins::{scratch_bytes, voxelize_in_bricks};
use super::separating_kernel::{
    Adjacency, HalfSpace, MARGIN, MOST_HALVES, Primitive, PrimitiveClass, Primitives, Triangle,
    edge_cylinder, face_body, primitives, vertex_sphere,
};
use crate::error::{Error, Result};
use crate::grid::{Channels, SparseGrid, Transform};
use crate::mesh::Mesh;
use glam::DVec3;

/// What a brick of the band keeps per voxel: its least distance.
const BAND_CHANNELS: Channels = Channels {
    value: true,
    ..Channels::NONE
};

/// Bytes of the brick scratch each thread of `distance_band` keeps.
pub fn thread_scratch_bytes() -> u64 {
    scratch_bytes(BAND_CHANNELS, 1)
}

/// Unsigned distances in voxels (value channel) on every voxel within `band` voxels of
/// `mesh`, computed in 128^3 bricks on all threads; `progress` counts vertices, edges and
/// triangles (`separating::work_items`).
pub fn distance_band(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    progress: &Progress,
) -> Result<SparseGrid> {
    if !(band.is_finite() && band >= 1.0) {
        return Err(Error::InvalidArgument(format!(
            "the band must be at least one voxel wide, got {band}"
        )));
    }
    let found = primitives(mesh, transform, false)?;
    let Primitives {
        triangles,
        adjacency,
        ..
    } = &found;
    let channels = BAND_CHANNELS;
    // A closed slab: plane distances up to the band on both sides.
    let slab = (-band - MARGIN, band + MARGIN);
    let every = |_: &Primitive, _: DVec3| true;
    // One brick class for all: the brick keeps the least distance, whichever feature gave it.
    let candidates = |_, i: usize| {
        let (class, n) = found.numbered(i);
        found.reach_box_of(class, n, band + MARGIN)
    };
    let (grid, _) = voxelize_in_bricks(
        [found.counts().iter().sum()],
        transform,
        channels,
        progress,
        candidates,
        |_, i, clip, sink| match found.numbered(i) {
            (PrimitiveClass::Vertex, v) => {
                found.warm(PrimitiveClass::Vertex, v + 1, adjacency);
                let vertex = found.vertex(v);
                let halves = vertex_halves(&vertex, adjacency, triangles);
                vertex_sphere(&vertex, band, &every, halves.as_slice(), clip, sink)
            }
            (PrimitiveClass::Edge, e) => {
                found.warm(PrimitiveClass::Edge, e + 1, adjacency);
                let edge = found.edge(e);
                let halves = edge_halves(&edge, adjacency, triangles);
                edge_cylinder(&edge, band, &every, halves.as_slice(), clip, sink)
            }
            (PrimitiveClass::Body, t) => face_body(&triangles[t], slab, clip, sink),
        },
    )?;
    Ok(grid)
}

/// Up to `MOST_HALVES` half-spaces.
struct Halves {
    list: [HalfSpace; MOST_HALVES],
    len: usize,
}

impl Halves {
    fn new() -> Self {
        Halves {
            list: [HalfSpace {
                g: DVec3::ZERO,
                h: 0.0,
            }; MOST_HALVES],
            len: 0,
        }
    }

    /// Keeps the points `x` with `g·(x - p) <= MARGIN` (`g` a unit vector); a repeated one
    /// (an edge seen from both its triangles) is kept once.
    fn push(&mut self, g: DVec3, p: DVec3) {
        if self.len < MOST_HALVES && !self.as_slice().iter().any(|h| h.g == g) {
            self.list[self.len] = HalfSpace {
                g,
                h: -g.dot(p) - MARGIN,
            };
            self.len += 1;
        }
    }

    fn as_slice(&self) -> &[HalfSpace] {
        &self.list[..self.len]
    }
}

/// The triangles of the faces around `p`.
fn triangles_around<'t>(
    p: &Primitive,
    adjacency: &'t Adjacency,
    triangles: &'t [Triangle],
) -> impl Iterator<Item = &'t Triangle> {
    adjacency.faces[p.faces.clone()].iter().flat_map(move |&f| {
        let f = f as usize;
        &triangles[adjacency.triangle_starts[f]..adjacency.triangle_starts[f + 1]]
    })
}

/// Where edge `e` can be nearest: not strictly inside any triangle across it (each
/// triangle holding both its ends, seen from its in-plane inward normal there).
fn edge_halves(e: &Primitive, adjacency: &Adjacency, triangles: &[Triangle]) -> Halves {
    let mut halves = Halves::new();
    for tri in triangles_around(e, adjacency, triangles) {
        let [a, b, c] = tri.corners;
        let third = match ([a, b, c].contains(&e.a), [a, b, c].contains(&e.b)) {
            (true, true) => [a, b, c].into_iter().find(|&q| q != e.a && q != e.b),
            _ => None,
        };
        let Some(third) = third else { continue };
        let inward = tri.normal.cross(e.b - e.a);
        let inward = if inward.dot(third - e.a) < 0.0 {
            -inward
        } else {
            inward
        };
        if let Some(g) = inward.try_normalize() {
            halves.push(g, e.a);
        }
    }
    halves
}

/// Where vertex `v` can be nearest: behind every edge and fan diagonal leaving it. Each
/// neighbour is seen from the two triangles beside it and normalized once: the
/// normalizations were half of this function's time.
fn vertex_halves(v: &Primitive, adjacency: &Adjacency, triangles: &[Triangle]) -> Halves {
    let mut halves = Halves::new();
    let mut seen = [v.a; 2 * MOST_HALVES];
    let mut seen_count = 1;
    for tri in triangles_around(v, adjacency, triangles) {
        if !tri.corners.contains(&v.a) {
            continue;
        }
        for q in tri.corners {
            if seen[..seen_count].contains(&q) {
                continue;
            }
            if seen_count < seen.len() {
                seen[seen_count] = q;
                seen_count += 1;
            }
            if let Some(g) = (q - v.a).try_normalize() {
                halves.push(g, v.a);
            }
        }
    }
    halves
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{leaf_offset, leaf_origin};
    use crate::mesh::generate::{self, SplitMix64};
    use crate::mesh::triangle_distance::triangle_distance;
    use crate::mesh::{GridFit, fit_transform};

    const BAND: f64 = 3.0;

    /// Every voxel of the box around `mesh` (at `resolution`) against the least distance to
    /// its triangles, brute force: active at that distance (to f32 rounding) where it is
    /// within the band, inactive beyond it (a millionth of a voxel either side may go
    /// either way). The regions' cuts (edge sectors, vertex cones, face prisms) leave out no
    /// voxel and keep none past the band. The mesh is centred on a corner of eight bricks, so
    /// that every brick a primitive reaches must have been found for it.
    fn check(name: &str, mesh: &Mesh, resolution: u32) {
        let fit = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
        let half = i64::from(resolution / 2);
        let t = Transform::new(fit.origin + fit.voxel_size * half as f64, fit.voxel_size);
        let grid = distance_band(mesh, t, BAND, &Progress::none()).unwrap();
        let triangles: Vec<[DVec3; 3]> = mesh
            .triangles()
            .map(|(_, tri)| tri.map(|i| t.world_to_index(mesh.p(i))))
            .collect();
        let reach = BAND as i64 + 1;
        let (mut inside, mut checked) = (0, 0);
        let along = -half - reach..resolution as i64 - half + reach;
        for x in along.clone() {
            for y in along.clone() {
                for z in along.clone() {
                    let c = DVec3::new(x as f64, y as f64, z as f64);
                    let exact = triangles
                        .iter()
                        .map(|&tri| triangle_distance(c, tri))
                        .fold(f64::INFINITY, f64::min);
                    let value = grid.leaf(leaf_origin([x, y, z])).and_then(|l| {
                        let n = leaf_offset([x, y, z]);
                        l.is_on(n).then(|| l.value.as_ref().unwrap()[n])
                    });
                    match value {
                        Some(v) => {
                            assert!(
                                (f64::from(v) - exact).abs() <= 1e-5 * exact.max(1.0),
                                "{name}: voxel {:?} holds {v}, the exact distance is {exact}",
                                [x, y, z]
                            );
                            assert!(exact <= BAND + 1e-6, "{name}: {v} beyond the band");
                            inside += 1;
                        }
                        None => assert!(
                            exact > BAND - 1e-6,
                            "{name}: voxel {:?} at {exact} is not in the band",
                            [x, y, z]
                        ),
                    }
                    checked += 1;
                }
            }
        }
        assert!(
            inside > 1000 && inside < checked,
            "{name}: {inside} of {checked} in the band"
        );
        assert_eq!(grid.voxel_count(), inside, "{name}: voxels outside the box");
    }

    #[test]
    fn the_band_is_every_voxel_within_it_at_its_exact_distance() {
        for seed in [1, 2] {
            check("random closed", &generate::random_closed(seed), 20);
        }
        // Jagged: every vertex moved at random, so that edges fold sharply and vertices
        // have wide cones of their own.
        let mut jagged = generate::icosphere(DVec3::ZERO, 1.0, 2);
        let mut random = SplitMix64(5);
        for p in &mut jagged.positions {
            *p *= random.range(0.75, 1.25);
        }
        check("jagged", &jagged, 20);
        // Open: a torus with every fifth face gone (boundary edges and vertices).
        let torus = generate::torus(DVec3::ZERO, 1.0, 0.4, 24, 12);
        let kept: Vec<Vec<u32>> = (0..torus.face_count())
            .filter(|f| f % 5 != 0)
            .map(|f| torus.face(f).to_vec())
            .collect();
        let open = Mesh::from_polygons("open torus", torus.positions.clone(), &kept);
        check("open torus", &open, 20);
    }
}
