//! Connected components of the clear voxels of a dense box, by face adjacency (the
//! exterior flood's), each with a label of its own. The clear voxels are taken as runs along
//! z (a row of the box is one contiguous bit range), and runs are joined by union-find to the
//! overlapping runs of the rows at y - 1 and x - 1: the work grows with the runs, not the
//! voxels.

use crate::error::{Error, Result};
use crate::grid::DenseMask;

/// The clear runs of a box and their components.
pub struct ClearRuns {
    /// `row_starts[r]..row_starts[r + 1]` are the runs of row `r = x * ny + y`.
    pub row_starts: Vec<usize>,
    /// Each run's first and last z (offsets in the box).
    pub runs: Vec<(u32, u32)>,
    /// Each run's component, 1, 2, ...
    pub labels: Vec<u32>,
    pub components: u32,
}

impl ClearRuns {
    /// The component of the voxel at offsets `(x, y, z)` in the box, 0 when it is set.
    pub fn label_at(&self, ny: usize, x: usize, y: usize, z: u32) -> u32 {
        let row = x * ny + y;
        let runs = &self.runs[self.row_starts[row]..self.row_starts[row + 1]];
        // Runs are ascending and disjoint: the last one starting at or before z.
        let i = runs.partition_point(|r| r.0 <= z);
        match i.checked_sub(1) {
            Some(k) if runs[k].1 >= z => self.labels[self.row_starts[row] + k],
            _ => 0,
        }
    }
}

/// The runs of clear voxels of `blocked`'s box, labelled by 6-connected component.
pub fn label_clear_runs(blocked: &DenseMask) -> Result<ClearRuns> {
    let [nx, ny, nz] = blocked.dims();
    let mut row_starts = Vec::with_capacity(nx * ny + 1);
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for x in 0..nx {
        for y in 0..ny {
            row_starts.push(runs.len());
            clear_runs_of_row(blocked, x as i64, y as i64, nz, &mut runs);
        }
    }
    row_starts.push(runs.len());
    let mut parent: Vec<u32> = (0..runs.len() as u32).collect();
    for x in 0..nx {
        for y in 0..ny {
            let row = x * ny + y;
            if y > 0 {
                join_overlaps(&row_starts, &runs, row, row - 1, &mut parent);
            }
            if x > 0 {
                join_overlaps(&row_starts, &runs, row, row - ny, &mut parent);
            }
        }
    }
    let mut labels = vec![0u32; runs.len()];
    let mut components = 0u32;
    for i in 0..runs.len() {
        let root = find(&mut parent, i as u32) as usize;
        if labels[root] == 0 {
            components = components
                .checked_add(1)
                .ok_or_else(|| Error::Unsupported("more than 2^32 components in one box".into()))?;
            labels[root] = components;
        }
        labels[i] = labels[root];
    }
    Ok(ClearRuns {
        row_starts,
        runs,
        labels,
        components,
    })
}

/// Appends the runs of clear voxels of row `(x, y)`, 64 voxels at a time.
fn clear_runs_of_row(blocked: &DenseMask, x: i64, y: i64, nz: usize, runs: &mut Vec<(u32, u32)>) {
    let mut open: Option<u32> = None;
    let mut z = 0;
    while z < nz {
        let n = (nz - z).min(64);
        let mut clear = !blocked.row_bits(x, y, z, n);
        if n < 64 {
            clear &= (1u64 << n) - 1;
        }
        let mut at = 0;
        while at < n {
            let rest = clear >> at;
            match open {
                None if rest == 0 => break,
                None => {
                    at += rest.trailing_zeros() as usize;
                    open = Some((z + at) as u32);
                }
                Some(first) => {
                    let set = !rest;
                    if set == 0 || at + set.trailing_zeros() as usize >= n {
                        break;
                    }
                    at += set.trailing_zeros() as usize;
                    runs.push((first, (z + at - 1) as u32));
                    open = None;
                }
            }
        }
        z += n;
    }
    if let Some(first) = open {
        runs.push((first, nz as u32 - 1));
    }
}

/// Joins the runs of row `a` to the runs of row `b` that share a z with them.
fn join_overlaps(
    row_starts: &[usize],
    runs: &[(u32, u32)],
    a: usize,
    b: usize,
    parent: &mut [u32],
) {
    let (mut i, mut j) = (row_starts[a], row_starts[b]);
    let (end_i, end_j) = (row_starts[a + 1], row_starts[b + 1]);
    while i < end_i && j < end_j {
        let (ri, rj) = (runs[i], runs[j]);
        if ri.0 <= rj.1 && rj.0 <= ri.1 {
            let (pi, pj) = (find(parent, i as u32), find(parent, j as u32));
            if pi != pj {
                parent[pi.max(pj) as usize] = pi.min(pj);
            }
        }
        if ri.1 < rj.1 {
            i += 1;
        } else {
            j += 1;
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::CoordBox;
    use crate::random::SplitMix64;

    /// Labels by a plain breadth-first flood, voxel by voxel: the reference.
    fn flood_labels(blocked: &DenseMask) -> Vec<u32> {
        let [nx, ny, nz] = blocked.dims();
        let mut labels = vec![0u32; blocked.len()];
        let mut next = 0;
        for start in 0..labels.len() {
            if labels[start] != 0 || blocked.get_index(start) {
                continue;
            }
            next += 1;
            labels[start] = next;
            let mut queue = vec![start];
            while let Some(i) = queue.pop() {
                let c = blocked.coord(i);
                for (axis, size) in [nx, ny, nz].into_iter().enumerate() {
                    for step in [-1i64, 1] {
                        let mut n = c;
                        n[axis] += step;
                        let off = n[axis] - blocked.bbox.min[axis];
                        if off < 0 || off >= size as i64 {
                            continue;
                        }
                        let j = blocked.index(n);
                        if labels[j] == 0 && !blocked.get_index(j) {
                            labels[j] = next;
                            queue.push(j);
                        }
                    }
                }
            }
        }
        labels
    }

    #[test]
    fn runs_give_the_components_of_a_voxel_flood() {
        let mut rng = SplitMix64(11);
        for case in 0..40 {
            let dims = [3 + case % 5, 2 + case % 7, 1 + (case * 13) % 150];
            let bbox = CoordBox {
                min: [-3, 5, 7],
                max: [-4 + dims[0] as i64, 4 + dims[1] as i64, 6 + dims[2] as i64],
            };
            let mut blocked = DenseMask::new(bbox).unwrap();
            let density = 0.2 + 0.5 * (case % 3) as f64 / 2.0;
            for i in 0..blocked.len() {
                if rng.range(0.0, 1.0) < density {
                    blocked.set_index(i);
                }
            }
            let runs = label_clear_runs(&blocked).unwrap();
            let reference = flood_labels(&blocked);
            // The same partition: labels map one to one.
            let mut map = std::collections::HashMap::new();
            let [_, ny, _] = blocked.dims();
            for (i, &want) in reference.iter().enumerate() {
                let c = blocked.coord(i);
                let off = [0, 1, 2].map(|a| (c[a] - bbox.min[a]) as usize);
                let got = runs.label_at(ny, off[0], off[1], off[2] as u32);
                assert_eq!(got == 0, want == 0, "case {case} at {c:?}");
                if want != 0 {
                    assert_eq!(*map.entry(want).or_insert(got), got, "case {case} at {c:?}");
                }
            }
            assert_eq!(map.len() as u32, runs.components, "case {case}");
        }
    }
}
