//! Topology of a voxel set without a hash set or a stack entry per voxel, so that it runs on
//! solids of 10^8 and more voxels: connected components by union-find over the z-runs of
//! the rows, and the Euler characteristic of the union of the closed unit cubes by summing a
//! per-lattice-vertex contribution that is zero wherever the eight cubes around a vertex are
//! all set or all clear (so only the surface of the set costs anything).

use crate::grid::{Adjacency, DenseMask};

/// Number of `adjacency`-connected components of the set voxels (6 or 26; 18 counts as 26
/// for rows that touch only at an edge, so it is refused).
pub fn components(set: &DenseMask, adjacency: Adjacency) -> u64 {
    assert!(
        adjacency != Adjacency::Eighteen,
        "components are counted for 6- and 26-adjacency"
    );
    let [nx, ny, _] = set.dims();
    let rows: Vec<Vec<(u32, u32)>> = (0..nx * ny)
        .map(|r| row_runs(set, (r / ny) as i64, (r % ny) as i64))
        .collect();
    let mut first = Vec::with_capacity(rows.len() + 1);
    let mut total = 0usize;
    for r in &rows {
        first.push(total);
        total += r.len();
    }
    let mut parent: Vec<u32> = (0..total as u32).collect();
    // Row (x, y) meets the rows after it: (x, y+1) and, for 26, the rows of x+1 around y.
    let (neighbours, reach): (&[(i64, i64)], u32) = match adjacency {
        Adjacency::Six => (&[(0, 1), (1, 0)], 0),
        _ => (&[(0, 1), (1, -1), (1, 0), (1, 1)], 1),
    };
    for x in 0..nx as i64 {
        for y in 0..ny as i64 {
            let here = x as usize * ny + y as usize;
            for &(dx, dy) in neighbours {
                let (ox, oy) = (x + dx, y + dy);
                if ox >= nx as i64 || oy < 0 || oy >= ny as i64 {
                    continue;
                }
                let there = ox as usize * ny + oy as usize;
                join_overlapping(&rows, &first, here, there, reach, &mut parent);
            }
        }
    }
    (0..total as u32)
        .filter(|&i| parent[i as usize] == i)
        .count() as u64
}

/// Unites the runs of two rows that overlap when the first's are widened by `reach`.
fn join_overlapping(
    rows: &[Vec<(u32, u32)>],
    first: &[usize],
    a: usize,
    b: usize,
    reach: u32,
    parent: &mut [u32],
) {
    let (ra, rb) = (&rows[a], &rows[b]);
    let (mut i, mut j) = (0, 0);
    while i < ra.len() && j < rb.len() {
        let (lo, hi) = (ra[i].0.saturating_sub(reach), ra[i].1 + reach);
        let (blo, bhi) = rb[j];
        if blo <= hi && lo <= bhi {
            union(parent, (first[a] + i) as u32, (first[b] + j) as u32);
        }
        if bhi < hi { j += 1 } else { i += 1 }
    }
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// The runs of set voxels of row `(x, y)`, as inclusive `(first, last)` z offsets.
fn row_runs(set: &DenseMask, x: i64, y: i64) -> Vec<(u32, u32)> {
    let nz = set.dims()[2];
    let mut runs: Vec<(u32, u32)> = Vec::new();
    let mut z = 0;
    while z < nz {
        let n = (nz - z).min(64);
        let mut word = set.row_bits(x, y, z, n);
        while word != 0 {
            let start = word.trailing_zeros();
            let len = (!(word >> start)).trailing_zeros().min(64 - start);
            let (s, e) = ((z as u32) + start, (z as u32) + start + len - 1);
            match runs.last_mut() {
                Some(last) if last.1 + 1 == s => last.1 = e,
                _ => runs.push((s, e)),
            }
            word = if start + len >= 64 {
                0
            } else {
                word & !(((1u64 << len) - 1) << start)
            };
        }
        z += n;
    }
    runs
}

/// Eight times the Euler characteristic contributed by a lattice vertex whose eight cubes are
/// set as `config` (bit `i + 2j + 4k` for the cube at offset (i, j, k) from (-1,-1,-1)): the
/// vertex, minus half of each edge, plus a quarter of each face, minus an eighth of each cube
/// present at it.
fn vertex_contribution(config: u8) -> i64 {
    let cube = |i: usize, j: usize, k: usize| config >> (i + 2 * j + 4 * k) & 1 == 1;
    let any = |f: &dyn Fn(usize, usize) -> bool| (0..2).any(|a| (0..2).any(|b| f(a, b)));
    let mut sum = if config != 0 { 8 } else { 0 };
    for side in 0..2 {
        // The edges from the vertex towards -x/+x (side 0/1), and likewise y and z.
        sum -= 4 * i64::from(any(&|a, b| cube(side, a, b)));
        sum -= 4 * i64::from(any(&|a, b| cube(a, side, b)));
        sum -= 4 * i64::from(any(&|a, b| cube(a, b, side)));
    }
    for a in 0..2 {
        for b in 0..2 {
            // The faces at the vertex perpendicular to x, y and z.
            sum += 2 * i64::from(cube(0, a, b) || cube(1, a, b));
            sum += 2 * i64::from(cube(a, 0, b) || cube(a, 1, b));
            sum += 2 * i64::from(cube(a, b, 0) || cube(a, b, 1));
        }
    }
    sum - i64::from(config.count_ones())
}

/// Euler characteristic of the union of the closed unit cubes of the set voxels.
pub fn euler_characteristic(set: &DenseMask) -> i64 {
    let table: Vec<i64> = (0..=255u8).map(vertex_contribution).collect();
    let [nx, ny, nz] = set.dims();
    let mut eighths = 0i64;
    // Lattice vertex (x, y, z) has the cubes x-1..x, y-1..y, z-1..z around it.
    for x in 0..=nx as i64 {
        for y in 0..=ny as i64 {
            let mut z0 = 0;
            while z0 <= nz {
                // Vertices z0 .. z0+63: cube bits z (`now`) and z-1 (`before`) of 4 rows.
                let mut now = [0u64; 4];
                let mut before = [0u64; 4];
                for (r, (dx, dy)) in [(1, 1), (0, 1), (1, 0), (0, 0)].into_iter().enumerate() {
                    let (rx, ry) = (x - dx, y - dy);
                    let n = nz.saturating_sub(z0).min(64);
                    now[r] = if n > 0 {
                        set.row_bits(rx, ry, z0, n)
                    } else {
                        0
                    };
                    let below = z0 > 0 && set.row_bits(rx, ry, z0 - 1, 1) == 1;
                    before[r] = (now[r] << 1) | u64::from(below);
                }
                let vertices = (nz + 1 - z0).min(64);
                let valid = if vertices == 64 {
                    u64::MAX
                } else {
                    (1u64 << vertices) - 1
                };
                let all_set = now.iter().chain(&before).fold(valid, |a, w| a & w);
                let any_set = now.iter().chain(&before).fold(0, |a, w| a | w) & valid;
                // Vertices with all eight cubes set, or none, contribute nothing.
                let mut mixed = any_set & !all_set;
                while mixed != 0 {
                    let k = mixed.trailing_zeros();
                    let mut config = 0u8;
                    for r in 0..4 {
                        // Row r holds cubes (i, j) = (1 - dx, 1 - dy); k-bits pick z.
                        let (i, j) = [(0, 0), (1, 0), (0, 1), (1, 1)][r];
                        config |= ((before[r] >> k & 1) as u8) << (i + 2 * j);
                        config |= ((now[r] >> k & 1) as u8) << (i + 2 * j + 4);
                    }
                    eighths += table[config as usize];
                    mixed &= mixed - 1;
                }
                z0 += 64;
            }
        }
    }
    eighths / 8
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::CoordBox;

    fn mask(voxels: &[[i64; 3]]) -> DenseMask {
        let mut m = DenseMask::new(CoordBox {
            min: [0; 3],
            max: [9, 9, 70],
        })
        .unwrap();
        for &v in voxels {
            m.set(v);
        }
        m
    }

    #[test]
    fn a_cube_a_ring_and_two_diagonal_voxels() {
        assert_eq!(euler_characteristic(&mask(&[[1, 1, 1]])), 1);
        assert_eq!(components(&mask(&[[1, 1, 1]]), Adjacency::Six), 1);
        // A ring of 8 voxels around (2,2,z): a solid torus, χ = 0.
        let ring: Vec<[i64; 3]> = [
            [1, 1],
            [1, 2],
            [1, 3],
            [2, 3],
            [3, 3],
            [3, 2],
            [3, 1],
            [2, 1],
        ]
        .iter()
        .map(|&[x, y]| [x, y, 63])
        .collect();
        assert_eq!(euler_characteristic(&mask(&ring)), 0);
        assert_eq!(components(&mask(&ring), Adjacency::Six), 1);
        // Corner-touching voxels: one 26-component, two 6-components; the union of closed
        // cubes is connected and contractible.
        let pair = mask(&[[1, 1, 63], [2, 2, 64]]);
        assert_eq!(components(&pair, Adjacency::Six), 2);
        assert_eq!(components(&pair, Adjacency::TwentySix), 1);
        assert_eq!(euler_characteristic(&pair), 1);
    }

    fn mask_where(n: i64, inside: impl Fn([i64; 3]) -> bool) -> DenseMask {
        let mut m = DenseMask::new(CoordBox {
            min: [0; 3],
            max: [n; 3],
        })
        .unwrap();
        for i in 0..m.len() {
            if inside(m.coord(i)) {
                m.set_index(i);
            }
        }
        m
    }

    #[test]
    fn euler_characteristic_and_genus_of_simple_solids() {
        let cube = mask_where(6, |c| c.iter().all(|&v| (1..=4).contains(&v)));
        assert_eq!(euler_characteristic(&cube), 1);
        // A square ring: a solid torus, genus 1.
        let ring = mask_where(8, |c| {
            (1..=6).contains(&c[0])
                && (1..=6).contains(&c[1])
                && (3..=4).contains(&c[2])
                && !((3..=4).contains(&c[0]) && (3..=4).contains(&c[1]))
        });
        assert_eq!(euler_characteristic(&ring), 0);
        assert_eq!(
            components(&ring, Adjacency::Six) as i64 - euler_characteristic(&ring),
            1
        );
        // Two separate cubes: two components, χ = 2, genus 0.
        let two = mask_where(10, |c| {
            c.iter().all(|&v| (1..=3).contains(&v)) || c.iter().all(|&v| (6..=8).contains(&v))
        });
        assert_eq!(components(&two, Adjacency::TwentySix), 2);
        assert_eq!(euler_characteristic(&two), 2);
    }
}
