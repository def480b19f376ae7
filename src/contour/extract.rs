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

use super::cell_cycles::{EDGES, case_cycles, edge_axis};
use super::field::ScalarField;
use super::vertex_placement::{INSET, cycle_vertex};
use crate::grid::{Block, Coord, NODE_DIM, SparseGrid};
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

/// The zero set of `field` as a closed, oriented triangle mesh.
pub fn contour(field: &ScalarField) -> TriangleMesh {
    let blocks = candidate_blocks(&field.grid);
    let index: FxHashMap<Coord, u32> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| (*b, i as u32))
        .collect();
    let mut pieces: Vec<BlockPiece> = blocks
        .par_iter()
        .map_init(Vec::new, |samples, &origin| {
            block_piece(field, origin, samples)
        })
        .collect();
    let mut bases = Vec::with_capacity(pieces.len());
    let mut total = 0u32;
    for p in &pieces {
        bases.push(total);
        total += p.positions.len() as u32;
    }
    let refs: Vec<([u64; EDGE_WORDS], [u32; EDGE_WORDS])> =
        pieces.iter().map(|p| (p.crossings, p.ranks)).collect();
    pieces
        .par_iter_mut()
        .zip(&bases)
        .for_each(|(piece, &base)| {
            let origin = piece.origin;
            for t in &mut piece.triangles {
                for v in t.iter_mut() {
                    *v = if *v & CROSSING_REF == 0 {
                        base + *v
                    } else {
                        let code = (*v >> 12) & 7;
                        let bit = (*v & 0xfff) as usize;
                        let owner = [
                            origin[0] + 8 * (code & 1) as i64,
                            origin[1] + 8 * (code >> 1 & 1) as i64,
                            origin[2] + 8 * (code >> 2 & 1) as i64,
                        ];
                        let i = index[&owner] as usize;
                        let (words, ranks) = &refs[i];
                        let below = words[bit / 64] & ((1u64 << (bit % 64)) - 1);
                        bases[i] + ranks[bit / 64] + below.count_ones()
                    };
                }
            }
        });
    let mut mesh = TriangleMesh {
        positions: Vec::with_capacity(total as usize),
        triangles: Vec::with_capacity(pieces.iter().map(|p| p.triangles.len()).sum()),
    };
    let transform = field.grid.transform;
    for p in pieces {
        mesh.positions.extend(
            p.positions
                .iter()
                .map(|q| transform.origin + transform.voxel_size * *q),
        );
        mesh.triangles.extend_from_slice(&p.triangles);
    }
    mesh
}

/// The blocks whose cells may hold a sign change: every leaf and every tile beside empty
/// space, each with the blocks below it on any axis (whose cells reach into it).
fn candidate_blocks(grid: &SparseGrid) -> Vec<Coord> {
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
    let mut set = FxHashSet::default();
    for s in seeds {
        for code in 0..8 {
            set.insert([
                s[0] - 8 * (code & 1),
                s[1] - 8 * (code >> 1 & 1),
                s[2] - 8 * (code >> 2 & 1),
            ]);
        }
    }
    let mut blocks: Vec<Coord> = set.into_iter().collect();
    blocks.sort_unstable();
    blocks
}

/// The vertices and triangles of the cells whose low corner lies in the block at `origin`.
fn block_piece(field: &ScalarField, origin: Coord, samples: &mut Vec<f32>) -> BlockPiece {
    field.gather(origin.map(|v| v - 1), SPAN, samples);
    let s = |x: i64, y: i64, z: i64| -> f64 {
        samples[(((x + 1) * SPAN as i64 + (y + 1)) * SPAN as i64 + (z + 1)) as usize] as f64
    };
    let inside = |x: i64, y: i64, z: i64| s(x, y, z) < 0.0;
    let gradient = |x: i64, y: i64, z: i64| {
        DVec3::new(
            s(x + 1, y, z) - s(x - 1, y, z),
            s(x, y + 1, z) - s(x, y - 1, z),
            s(x, y, z + 1) - s(x, y, z - 1),
        )
    };
    let steer = field.has_gradients();
    // The crossing on the edge from local voxel `c` along `axis`, and its unit normal.
    let crossing = |c: [i64; 3], axis: usize| -> (DVec3, DVec3) {
        let mut d = c;
        d[axis] += 1;
        let (g0, g1) = (s(c[0], c[1], c[2]), s(d[0], d[1], d[2]));
        let t = (g0 / (g0 - g1)).clamp(INSET, 1.0 - INSET);
        let mut p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
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
    let mut piece = BlockPiece {
        origin,
        crossings: [0; EDGE_WORDS],
        ranks: [0; EDGE_WORDS],
        positions: Vec::new(),
        triangles: Vec::new(),
    };
    for x in 0..8i64 {
        for y in 0..8i64 {
            for z in 0..8i64 {
                let here = inside(x, y, z);
                for axis in 0..3 {
                    let mut d = [x, y, z];
                    d[axis] += 1;
                    if inside(d[0], d[1], d[2]) != here {
                        let bit = ((x * 64 + y * 8 + z) * 3) as usize + axis;
                        piece.crossings[bit / 64] |= 1 << (bit % 64);
                        piece.positions.push(local(crossing([x, y, z], axis).0));
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
    let (mut points, mut normals, mut refs) = (Vec::new(), Vec::new(), Vec::new());
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
                for cycle in table[case].cycles() {
                    points.clear();
                    normals.clear();
                    refs.clear();
                    for &e in cycle {
                        let e = e as usize;
                        let a = EDGES[e].0 as i64;
                        let c = [x + (a & 1), y + (a >> 1 & 1), z + (a >> 2 & 1)];
                        let axis = edge_axis(e);
                        let (p, n) = crossing(c, axis);
                        points.push(p);
                        normals.push(n);
                        // The crossing's owner: this block, or the next one up on the axes
                        // where the edge starts on the far face.
                        let code = (0..3)
                            .filter(|&i| c[i] == 8)
                            .map(|i| 1u32 << i)
                            .sum::<u32>();
                        let l = c.map(|v| v & 7);
                        let bit = ((l[0] * 64 + l[1] * 8 + l[2]) * 3) as u32 + axis as u32;
                        refs.push(CROSSING_REF | code << 12 | bit);
                    }
                    let low = DVec3::new(x as f64, y as f64, z as f64);
                    let centre = cycle_vertex(&points, &normals, low);
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
    piece
}
