//! The triangle mesh of a field's zero set: a vertex on every lattice edge whose ends differ
//! in sign (where the values cross zero), one vertex per surface cycle of each cell (see
//! `cell_cycles`) placed by `vertex_placement`, and a fan from that vertex over the cycle.
//!
//! This is Kobbelt et al.'s extended marching cubes in its combinatorics (a cycle's polygon
//! fanned from a feature vertex inside the cell) with dual contouring's vertex placement; the
//! cycles' face rule makes the result closed and 2-manifold by construction, whatever the
//! values: every segment of a cell face is an edge of exactly the two fans of the cells that
//! share the face, and the fans around a crossing close up around it. Crossings stay a
//! hundredth of a voxel from the lattice points and cycle vertices strictly inside their cells,
//! so no triangle is flat and triangles of different cells meet only along shared edges.
//!
//! The work runs block by block (8^3 cells) on all threads: a first pass makes every block's
//! vertices and triangles, naming a crossing owned by a neighbouring block by its place
//! there; a second numbers the vertices and resolves those names.

use super::cell_cycles::{EDGES, case_cycles, edge_axis, edges_share_face};
use super::field::{BlockSign, ScalarField};
use super::hermite::ExactSurface;
use super::vertex_placement::{INSET, cycle_vertex};
use crate::error::{Error, Result};
use crate::grid::{Block, Coord, NODE_DIM};
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

/// A triangle mesh in world space, triangles counter-clockwise seen from outside.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Samples a block gathers: its 9^3 cell corners and one more layer each side for gradients.
const SPAN: usize = 11;
/// Crossing edges a block owns: one per voxel and axis.
const EDGE_WORDS: usize = 512 * 3 / 64;
/// A vertex reference naming a crossing by block and edge, resolved in the second pass.
const CROSSING_REF: u32 = 1 << 31;

struct BlockPiece {
    origin: Coord,
    /// Bit `(x*64 + y*8 + z) * 3 + axis`: the edge from that voxel along that axis crosses.
    crossings: [u64; EDGE_WORDS],
    /// Crossings before each word.
    ranks: [u32; EDGE_WORDS],
    /// The block's crossings in bit order, then its cycle vertices.
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

/// The zero set of `field` as a closed, oriented triangle mesh; where `exact` knows the
/// source, its crossings and normals place the vertices.
pub fn contour(field: &ScalarField, exact: Option<&dyn ExactSurface>) -> Result<TriangleMesh> {
    let blocks = candidate_blocks(field);
    let index: FxHashMap<Coord, u32> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| (*b, i as u32))
        .collect();
    let pieces: Vec<BlockPiece> = blocks
        .par_iter()
        .map_init(Scratch::default, |scratch, &origin| {
            block_piece(field, exact, origin, scratch)
        })
        .collect();
    let mut bases = Vec::with_capacity(pieces.len());
    let mut total = 0u64;
    for p in &pieces {
        bases.push(total as u32);
        total += p.positions.len() as u64;
    }
    if total > u32::MAX as u64 {
        return Err(Error::Unsupported(format!(
            "the surface has {total} vertices: a mesh holds at most {} (32-bit indices)",
            u32::MAX
        )));
    }
    let triangle_count = pieces.iter().map(|p| p.triangles.len()).sum();
    let mut mesh = TriangleMesh {
        positions: vec![DVec3::ZERO; total as usize],
        triangles: vec![[0; 3]; triangle_count],
    };
    // Each block's share of the output, filled on all threads.
    let mut shares = Vec::with_capacity(pieces.len());
    let (mut positions, mut triangles) = (&mut mesh.positions[..], &mut mesh.triangles[..]);
    for p in &pieces {
        let (mine, rest) = positions.split_at_mut(p.positions.len());
        positions = rest;
        let (my_triangles, rest) = triangles.split_at_mut(p.triangles.len());
        triangles = rest;
        shares.push((mine, my_triangles));
    }
    let transform = field.grid.transform;
    // The pieces of a block and of its neighbours up each axis, by a crossing's code (`None`
    // where no piece is: no crossing names it).
    let owners = |piece: &BlockPiece| -> [Option<usize>; 8] {
        std::array::from_fn(|code| {
            let owner = [
                piece.origin[0] + 8 * (code & 1) as i64,
                piece.origin[1] + 8 * (code >> 1 & 1) as i64,
                piece.origin[2] + 8 * (code >> 2 & 1) as i64,
            ];
            index.get(&owner).map(|&i| i as usize)
        })
    };
    let resolve = |owners: &[Option<usize>; 8], base: u32, v: u32| -> u32 {
        if v & CROSSING_REF == 0 {
            return base + v;
        }
        let code = ((v >> 12) & 7) as usize;
        let bit = (v & 0xfff) as usize;
        let i = owners[code].expect("a crossing names a block with a piece");
        let other = &pieces[i];
        let below = other.crossings[bit / 64] & ((1u64 << (bit % 64)) - 1);
        bases[i] + other.ranks[bit / 64] + below.count_ones()
    };
    shares
        .into_par_iter()
        .zip(pieces.par_iter().zip(&bases))
        .for_each(|((positions, triangles), (piece, &base))| {
            for (out, q) in positions.iter_mut().zip(&piece.positions) {
                *out = transform.origin + transform.voxel_size * *q;
            }
            let owners = owners(piece);
            for (out, t) in triangles.iter_mut().zip(&piece.triangles) {
                *out = t.map(|v| resolve(&owners, base, v));
            }
        });
    Ok(mesh)
}

/// The blocks whose cells hold a sign change: those whose cells' corners (the block and the
/// next blocks up on each axis) are not all of one sign. Only a leaf, a tile beside empty
/// space, or a block below one on some axis can be such a block.
fn candidate_blocks(field: &ScalarField) -> Vec<Coord> {
    let grid = &field.grid;
    let leaf_signs: FxHashMap<Coord, BlockSign> = grid
        .leaves()
        .par_iter()
        .map(|l| (l.origin, field.block_sign(Block::Partial(l))))
        .collect();
    let sign = |origin: Coord| match leaf_signs.get(&origin) {
        Some(&s) => s,
        None => field.block_sign(grid.block(origin)),
    };
    let mut seeds: Vec<Coord> = grid.leaves().iter().map(|l| l.origin).collect();
    let beside_empty = |origin: Coord| {
        (0..3).any(|a| {
            [-8, 8].iter().any(|d| {
                let mut n = origin;
                n[a] += d;
                matches!(grid.block(n), Block::Empty)
            })
        })
    };
    let tiles = grid.tiles();
    seeds.extend(tiles.leaf_tiles().filter(|&o| beside_empty(o)));
    for node in tiles.node_tiles() {
        let n = NODE_DIM / 8;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let on_shell = [i, j, k].iter().any(|&v| v == 0 || v == n - 1);
                    let o = [node[0] + 8 * i, node[1] + 8 * j, node[2] + 8 * k];
                    if on_shell && beside_empty(o) {
                        seeds.push(o);
                    }
                }
            }
        }
    }
    let step = |o: Coord, code: i64, d: i64| {
        [
            o[0] + d * (code & 1),
            o[1] + d * (code >> 1 & 1),
            o[2] + d * (code >> 2 & 1),
        ]
    };
    let mut set = FxHashSet::default();
    for s in seeds {
        set.extend((0..8).map(|code| step(s, code, -8)));
    }
    let mut blocks: Vec<Coord> = set
        .into_par_iter()
        .filter(|&b| {
            let first = sign(b);
            first == BlockSign::Both || (1..8).any(|code| sign(step(b, code, 8)) != first)
        })
        .collect();
    blocks.par_sort_unstable();
    blocks
}

/// What a thread reuses from block to block.
#[derive(Default)]
struct Scratch {
    samples: Vec<f32>,
    /// Per edge from a voxel of `[0, 9)^3` along an axis, its crossing in `crossings`.
    slots: Vec<u32>,
    /// Crossings in index space with their unit normals.
    crossings: Vec<(DVec3, DVec3)>,
    points: Vec<DVec3>,
    normals: Vec<DVec3>,
    refs: Vec<u32>,
}

const NO_SLOT: u32 = u32::MAX;

fn slot(c: [i64; 3], axis: usize) -> usize {
    (((c[0] * 9 + c[1]) * 9 + c[2]) * 3) as usize + axis
}

/// The vertices and triangles of the cells whose low corner lies in the block at `origin`.
fn block_piece(
    field: &ScalarField,
    exact: Option<&dyn ExactSurface>,
    origin: Coord,
    scratch: &mut Scratch,
) -> BlockPiece {
    field.gather(origin.map(|v| v - 1), SPAN, &mut scratch.samples);
    let samples = &scratch.samples;
    let s = |x: i64, y: i64, z: i64| -> f64 {
        samples[(((x + 1) * SPAN as i64 + (y + 1)) * SPAN as i64 + (z + 1)) as usize] as f64
    };
    // The signs of the cells' corners, [0, 9)^3; a block of one sign has no surface.
    let mut signs = [false; 729];
    for x in 0..9 {
        for y in 0..9 {
            for z in 0..9 {
                signs[((x * 9 + y) * 9 + z) as usize] = s(x, y, z) < 0.0;
            }
        }
    }
    let mut piece = BlockPiece {
        origin,
        crossings: [0; EDGE_WORDS],
        ranks: [0; EDGE_WORDS],
        positions: Vec::new(),
        triangles: Vec::new(),
    };
    if signs.iter().all(|&b| b == signs[0]) {
        return piece;
    }
    let inside = |x: i64, y: i64, z: i64| signs[((x * 9 + y) * 9 + z) as usize];
    let gradient = |x: i64, y: i64, z: i64| {
        DVec3::new(
            s(x + 1, y, z) - s(x - 1, y, z),
            s(x, y + 1, z) - s(x, y - 1, z),
            s(x, y, z + 1) - s(x, y, z - 1),
        )
    };
    let steer = field.has_gradients();
    let transform = field.grid.transform;
    let world = |c: [i64; 3]| {
        let index = DVec3::from_array(std::array::from_fn(|a| (origin[a] + c[a]) as f64));
        transform.origin + transform.voxel_size * index
    };
    let exact = exact.map(|e| e.near(world([0; 3]), world([8; 3])));
    // The crossing on the edge from local voxel `c` along `axis`, and its unit normal: the
    // source's where it is known exactly, else the samples'.
    let crossing = |c: [i64; 3], axis: usize| -> (DVec3, DVec3) {
        let mut d = c;
        d[axis] += 1;
        let mut p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
        let (g0, g1) = (s(c[0], c[1], c[2]), s(d[0], d[1], d[2]));
        let t = (g0 / (g0 - g1)).clamp(INSET, 1.0 - INSET);
        if let Some(surface) = &exact
            && let Some((t, n)) = surface.crossing(world(c), world(d), inside(c[0], c[1], c[2]), t)
        {
            p[axis] += t.clamp(INSET, 1.0 - INSET);
            return (p, n);
        }
        p[axis] += t;
        let n = if steer {
            let g = gradient(c[0], c[1], c[2]) * (1.0 - t) + gradient(d[0], d[1], d[2]) * t;
            g.try_normalize().unwrap_or(DVec3::ZERO)
        } else {
            DVec3::ZERO
        };
        (p, n)
    };
    let local = |p: DVec3| p + DVec3::new(origin[0] as f64, origin[1] as f64, origin[2] as f64);
    // Every crossing the block's cells use, once: edges from [0, 9)^3, less than 8 along
    // their own axis. Those from [0, 8)^3 are the block's own, in bit order.
    scratch.slots.clear();
    scratch.slots.resize(9 * 9 * 9 * 3, NO_SLOT);
    scratch.crossings.clear();
    for x in 0..9i64 {
        for y in 0..9i64 {
            for z in 0..9i64 {
                let c = [x, y, z];
                let here = inside(x, y, z);
                for axis in 0..3 {
                    if c[axis] == 8 {
                        continue;
                    }
                    let mut d = c;
                    d[axis] += 1;
                    if inside(d[0], d[1], d[2]) == here {
                        continue;
                    }
                    let found = crossing(c, axis);
                    scratch.slots[slot(c, axis)] = scratch.crossings.len() as u32;
                    scratch.crossings.push(found);
                    if x < 8 && y < 8 && z < 8 {
                        let bit = ((x * 64 + y * 8 + z) * 3) as usize + axis;
                        piece.crossings[bit / 64] |= 1 << (bit % 64);
                        piece.positions.push(local(found.0));
                    }
                }
            }
        }
    }
    let mut rank = 0;
    for w in 0..EDGE_WORDS {
        piece.ranks[w] = rank;
        rank += piece.crossings[w].count_ones();
    }
    let table = case_cycles();
    for x in 0..8i64 {
        for y in 0..8i64 {
            for z in 0..8i64 {
                let mut case = 0usize;
                for k in 0..8 {
                    if inside(x + (k & 1), y + (k >> 1 & 1), z + (k >> 2 & 1)) {
                        case |= 1 << k;
                    }
                }
                if case == 0 || case == 255 {
                    continue;
                }
                let cycles = &table[case];
                for cycle in cycles.cycles() {
                    scratch.points.clear();
                    scratch.normals.clear();
                    scratch.refs.clear();
                    for &e in cycle {
                        let e = e as usize;
                        let a = EDGES[e].0 as i64;
                        let c = [x + (a & 1), y + (a >> 1 & 1), z + (a >> 2 & 1)];
                        let axis = edge_axis(e);
                        let (p, n) = scratch.crossings[scratch.slots[slot(c, axis)] as usize];
                        scratch.points.push(p);
                        scratch.normals.push(n);
                        // The crossing's owner: this block, or the next one up on the axes
                        // where the edge starts on the far face.
                        let code = (0..3)
                            .filter(|&i| c[i] == 8)
                            .map(|i| 1u32 << i)
                            .sum::<u32>();
                        let l = c.map(|v| v & 7);
                        let bit = ((l[0] * 64 + l[1] * 8 + l[2]) * 3) as u32 + axis as u32;
                        scratch.refs.push(CROSSING_REF | code << 12 | bit);
                    }
                    let low = DVec3::new(x as f64, y as f64, z as f64);
                    // A cell's several cycles keep to their crossings' means, where their fans
                    // cannot reach into each other.
                    let centre = if cycles.count == 1 {
                        cycle_vertex(&scratch.points, &scratch.normals, low)
                    } else {
                        mean(&scratch.points)
                    };
                    let refs = &scratch.refs;
                    match without_centre(cycle, &scratch.points, &scratch.normals, centre) {
                        Some(split) => piece
                            .triangles
                            .extend(split.iter().map(|t| t.map(|i| refs[i]))),
                        None => {
                            let id = piece.positions.len() as u32;
                            piece.positions.push(local(centre));
                            for i in 0..refs.len() {
                                piece
                                    .triangles
                                    .push([id, refs[i], refs[(i + 1) % refs.len()]]);
                            }
                        }
                    }
                }
            }
        }
    }
    piece
}

fn mean(points: &[DVec3]) -> DVec3 {
    points.iter().copied().sum::<DVec3>() / points.len() as f64
}

/// How far a cycle's vertex may lie off its crossings' plane, in voxels, for the cycle to be
/// drawn without it.
const FLAT: f64 = 0.02;

/// The least cosine between two crossings' normals of a cycle drawn without its vertex: where
/// they turn more, the vertex marks a sharp edge or corner, however near the plane it lies.
const SMOOTH: f64 = 0.9;

/// The triangles (positions in the cycle) of a cycle of three or four crossings drawn without
/// its own vertex, when that vertex adds nothing (it lies within `FLAT` of the crossings'
/// plane and the normals it fits agree) and the split is safe: a quadrilateral's diagonal
/// joins crossings of edges on no common face, so no other cell can draw it, and neither
/// triangle turns against the cycle.
fn without_centre(
    cycle: &[u8],
    points: &[DVec3],
    normals: &[DVec3],
    centre: DVec3,
) -> Option<Vec<[usize; 3]>> {
    let n = points.len();
    if n > 4 {
        return None;
    }
    let turns = normals
        .iter()
        .enumerate()
        .any(|(i, a)| normals[i + 1..].iter().any(|b| a.dot(*b) < SMOOTH));
    if turns && normals.iter().all(|v| *v != DVec3::ZERO) {
        return None;
    }
    let mean = points.iter().copied().sum::<DVec3>() / n as f64;
    let area: DVec3 = (0..n)
        .map(|i| (points[i] - mean).cross(points[(i + 1) % n] - mean))
        .sum();
    let normal = area.try_normalize()?;
    if normal.dot(centre - mean).abs() > FLAT {
        return None;
    }
    let split = if n == 3 {
        vec![[0, 1, 2]]
    } else {
        let share = |a: usize, b: usize| edges_share_face(cycle[a] as usize, cycle[b] as usize);
        if !share(0, 2) {
            vec![[0, 1, 2], [0, 2, 3]]
        } else if !share(1, 3) {
            vec![[1, 2, 3], [1, 3, 0]]
        } else {
            return None;
        }
    };
    let turns_with = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|i| points[i]);
        (b - a).cross(c - a).dot(area) > 0.0
    };
    split.iter().all(turns_with).then_some(split)
}
