//! Which voxel centres lie inside a closed mesh, by ray parity along z: every column of
//! centres `(i, j)` casts one ray along +z (exact crossings, see `crossings`), and a centre is
//! inside when it lies between crossings 2m and 2m+1 (sorted); a centre on a crossing lies on
//! the side the shared tie rule puts it (`crossings`), as depth layers put it. The same
//! crossings, signed, count a closed and consistently oriented mesh's winding number
//! (`ColumnRule::Winding`).

use super::crossings::{RayFrame, RayWindow, for_each_crossing};
use crate::error::Result;
use crate::grid::{CoordBox, DenseMask, Transform};
use crate::mesh::Mesh;
use glam::DVec3;
use rayon::prelude::*;

/// One crossing of a column's ray: the ray's number and whether the surface rises there
/// (its normal along +z) share one word, `ray << 1 | rising`, so a crossing stays 16 bytes.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    key: usize,
    /// The first centre above the crossing (the tie rule decides a centre on it).
    pub after: i64,
}

impl Crossing {
    #[inline]
    fn ray(&self) -> usize {
        self.key >> 1
    }

    /// +1 where the surface faces +z (a ray going up leaves an outward shell), -1 otherwise.
    #[inline]
    pub fn direction(&self) -> i32 {
        if self.key & 1 == 1 { 1 } else { -1 }
    }
}

/// Which centres of a column its crossings put inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnRule {
    /// Those between crossings 2m and 2m+1: ray parity.
    Parity,
    /// Those whose integer winding number, the signed count of the crossings below them (read
    /// reversed where `orientation` is -1), is at least 1: a closed, consistently oriented
    /// mesh's generalized winding number is that integer (`solids::winding_inside`).
    Winding { orientation: i32 },
}

/// The inside centres of one column with crossings `column` (ascending in z), by `rule`, as
/// inclusive z spans `span(first, last)`, ascending; some may be empty (`first > last`).
#[inline]
fn column_spans(column: &[Crossing], rule: ColumnRule, mut span: impl FnMut(i64, i64)) {
    match rule {
        ColumnRule::Parity => {
            for pair in column.chunks_exact(2) {
                span(pair[0].after, pair[1].after - 1);
            }
        }
        ColumnRule::Winding { orientation } => {
            let (mut k, mut first) = (0, 0);
            for c in column {
                // Going up through a surface that faces down enters it.
                let next = k - c.direction();
                match (k * orientation >= 1, next * orientation >= 1) {
                    (false, true) => first = c.after,
                    (true, false) => span(first, c.after - 1),
                    _ => {}
                }
                k = next;
            }
        }
    }
}

/// The crossings of a mesh with the z rays of a box's columns, sorted by column, then z, and
/// the rule that reads inside centres from them.
pub struct ColumnCrossings {
    rule: ColumnRule,
    window: RayWindow,
    crossings: Vec<Crossing>,
    /// Where each x row of columns starts in `crossings` (and where the last ends).
    row_starts: Vec<usize>,
    /// Per row, where each of its columns starts, from the row's start (`height + 1` entries
    /// a row, the last the row's length): a column's crossings without a search.
    column_starts: Vec<u32>,
}

/// Triangles per parallel batch of crossings at most, and about how many crossings.
const TRIANGLE_BATCH: usize = 4096;
const CROSSING_BATCH: f64 = (1 << 20) as f64;

/// Consecutive runs of `triangles` (over `pos`, index units) for parallel batches: up to
/// `TRIANGLE_BATCH` triangles or about `CROSSING_BATCH` crossings each, with room for the
/// crossings of each run. A triangle crosses at most its area on the xy plane plus half its
/// perimeter plus one columns (lattice points of a polygon), so each run's crossings fit
/// without the vector growing: a few large triangles (a CAD model's faces) neither leave one
/// thread all the work nor make the peak depend on when vectors doubled.
fn crossing_batches(pos: &[DVec3], triangles: &[[u32; 3]]) -> Vec<(std::ops::Range<usize>, usize)> {
    let room: Vec<f64> = triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| pos[v as usize].truncate());
            let perimeter = a.distance(b) + b.distance(c) + c.distance(a);
            0.5 * (b - a).perp_dot(c - a).abs() + 0.5 * perimeter + 1.0
        })
        .collect();
    let mut batches = Vec::new();
    let (mut start, mut sum) = (0, 0.0);
    for (i, r) in room.iter().enumerate() {
        sum += r;
        if i + 1 - start == TRIANGLE_BATCH || sum >= CROSSING_BATCH || i + 1 == room.len() {
            batches.push((start..i + 1, sum.ceil() as usize));
            (start, sum) = (i + 1, 0.0);
        }
    }
    batches
}

impl ColumnCrossings {
    /// The crossings of the closed `mesh` (world units) with the columns of `bbox`.
    pub fn new(mesh: &Mesh, transform: &Transform, bbox: CoordBox) -> Self {
        let triangles: Vec<[u32; 3]> = mesh.triangles().map(|(_, t)| t).collect();
        Self::of_triangles(&mesh.positions, &triangles, transform, bbox)
    }

    /// The crossings of `triangles` over `points` (world units) with the columns of `bbox`.
    pub fn of_triangles(
        points: &[DVec3],
        triangles: &[[u32; 3]],
        transform: &Transform,
        bbox: CoordBox,
    ) -> Self {
        let pos: Vec<DVec3> = points
            .par_iter()
            .map(|&p| transform.world_to_index(p))
            .collect();
        let [nx, ny, _] = bbox.dim().map(|v| v as usize);
        let window = RayWindow {
            a0: bbox.min[0],
            b0: bbox.min[1],
            width: nx,
            height: ny,
        };
        // Columns along +z: `(a, b, t) = (x, y, z)`.
        let z_rays = RayFrame::along([0, 0, 1]);
        let batches: Vec<Vec<Crossing>> = crossing_batches(&pos, triangles)
            .into_par_iter()
            .map(|(run, room)| {
                let mut found = Vec::with_capacity(room);
                let batch = triangles[run].iter().copied();
                for_each_crossing(&pos, batch, &z_rays, &window, |c| {
                    found.push(Crossing {
                        key: c.ray << 1 | c.rising as usize,
                        after: c.after,
                    })
                });
                found
            })
            .collect();
        // Placed by counting: every column's crossings counted, each crossing written at its
        // column's next free place, then each column (a handful of crossings) sorted by z,
        // which costs a fraction of one comparison sort of them all.
        let mut at = vec![0u32; nx * ny];
        for c in batches.iter().flatten() {
            at[c.ray()] += 1;
        }
        let mut row_starts = vec![0usize; nx + 1];
        let mut column_starts = vec![0u32; nx * (ny + 1)];
        for x in 0..nx {
            // A row's crossings number far below 2^32: each takes 16 bytes in memory.
            let starts = &mut column_starts[x * (ny + 1)..(x + 1) * (ny + 1)];
            for y in 0..ny {
                starts[y + 1] = starts[y] + at[x * ny + y];
                at[x * ny + y] = starts[y];
            }
            row_starts[x + 1] = row_starts[x] + starts[ny] as usize;
        }
        let unset = Crossing { key: 0, after: 0 };
        let mut crossings = vec![unset; row_starts[nx]];
        for batch in batches {
            for c in batch {
                let ray = c.ray();
                crossings[row_starts[ray / ny] + at[ray] as usize] = c;
                at[ray] += 1;
            }
        }
        drop(at);
        let mut rows = Vec::with_capacity(nx);
        let mut rest = &mut crossings[..];
        for x in 0..nx {
            let (row, after) = rest.split_at_mut(row_starts[x + 1] - row_starts[x]);
            rows.push(row);
            rest = after;
        }
        rows.into_par_iter().enumerate().for_each(|(x, row)| {
            let starts = &column_starts[x * (ny + 1)..(x + 1) * (ny + 1)];
            for y in 0..ny {
                row[starts[y] as usize..starts[y + 1] as usize]
                    .sort_unstable_by_key(|c| (c.after, c.key));
            }
        });
        ColumnCrossings {
            rule: ColumnRule::Parity,
            window,
            crossings,
            row_starts,
            column_starts,
        }
    }

    /// The same crossings with their inside centres read by `rule` (ray parity unless told).
    pub fn read_by(self, rule: ColumnRule) -> Self {
        ColumnCrossings { rule, ..self }
    }

    /// The crossings of columns `(x, y)` for `y` in `ys`, which must lie in the window.
    fn columns_of(&self, x: i64, ys: std::ops::RangeInclusive<i64>) -> &[Crossing] {
        let row = (x - self.window.a0) as usize;
        let starts = &self.column_starts[row * (self.window.height + 1)..];
        let (first, last) = (
            (*ys.start() - self.window.b0) as usize,
            (*ys.end() - self.window.b0) as usize,
        );
        let base = self.row_starts[row];
        &self.crossings[base + starts[first] as usize..base + starts[last + 1] as usize]
    }

    /// The crossings of column `(x, y)`, ascending in z; none outside the box's columns.
    pub fn column(&self, x: i64, y: i64) -> &[Crossing] {
        let w = &self.window;
        if x < w.a0 || x >= w.a0 + w.width as i64 || y < w.b0 || y >= w.b0 + w.height as i64 {
            return &[];
        }
        self.columns_of(x, y..=y)
    }

    /// The inside centres of column `(x, y)` (inside the box's columns) as inclusive z spans
    /// `span(first, last)`, ascending; some may be empty (`first > last`).
    pub fn spans(&self, x: i64, y: i64, span: impl FnMut(i64, i64)) {
        column_spans(self.columns_of(x, y..=y), self.rule, span);
    }

    /// The spans of inside centres of the `count` columns `(x, y0 + i)`, as `span(i, first z,
    /// last z)`: one search for the row.
    pub fn row_spans(&self, x: i64, y0: i64, count: usize, mut span: impl FnMut(usize, i64, i64)) {
        let (ys, ye) = (
            y0.max(self.window.b0),
            (y0 + count as i64 - 1).min(self.window.b0 + self.window.height as i64 - 1),
        );
        if x < self.window.a0 || x >= self.window.a0 + self.window.width as i64 || ys > ye {
            return;
        }
        let first = self.window.ray(x, ys);
        for column in self
            .columns_of(x, ys..=ye)
            .chunk_by(|a, b| a.ray() == b.ray())
        {
            let i = (column[0].ray() - first) + (ys - y0) as usize;
            column_spans(column, self.rule, |z0, z1| span(i, z0, z1));
        }
    }

    /// Every column's spans of inside centres, as `span(x, y, first z, last z)`.
    pub fn all_spans(&self, mut span: impl FnMut(i64, i64, i64, i64)) {
        let height = self.window.height;
        for column in self.crossings.chunk_by(|a, b| a.ray() == b.ray()) {
            let (x, y) = (column[0].ray() / height, column[0].ray() % height);
            let (x, y) = (self.window.a0 + x as i64, self.window.b0 + y as i64);
            column_spans(column, self.rule, |z0, z1| span(x, y, z0, z1));
        }
    }

    /// The columns' x range and y range, inclusive.
    pub fn columns(&self) -> ([i64; 2], [i64; 2]) {
        let w = &self.window;
        (
            [w.a0, w.a0 + w.width as i64 - 1],
            [w.b0, w.b0 + w.height as i64 - 1],
        )
    }
}

/// Voxel centres inside the closed `mesh` (world units) over `bbox`, with `transform`.
pub fn inside_centres(mesh: &Mesh, transform: &Transform, bbox: CoordBox) -> Result<DenseMask> {
    let mut inside = DenseMask::new(bbox)?;
    let columns = ColumnCrossings::new(mesh, transform, bbox);
    columns.all_spans(|x, y, z0, z1| {
        let (z0, z1) = (z0.max(bbox.min[2]), z1.min(bbox.max[2]));
        if z0 <= z1 {
            let first = inside.index([x, y, z0]);
            inside.set_index_range(first, first + (z1 - z0) as usize);
        }
    });
    Ok(inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A column's crossings at `after`, rising (the surface faces +z) or not.
    fn column(crossings: &[(i64, bool)]) -> Vec<Crossing> {
        crossings
            .iter()
            .map(|&(after, rising)| Crossing {
                key: 7 << 1 | rising as usize,
                after,
            })
            .collect()
    }

    fn spans(column: &[Crossing], rule: ColumnRule) -> Vec<(i64, i64)> {
        let mut found = Vec::new();
        column_spans(column, rule, |z0, z1| found.push((z0, z1)));
        found
    }

    #[test]
    fn winding_counts_overlaps_in_and_reversed_shells_out_where_parity_pairs_crossings() {
        let outward = ColumnRule::Winding { orientation: 1 };
        // Two overlapping outward shells: in at 0 and 4, out at 8 and 12 (winding 2 between).
        let overlap = column(&[(0, false), (4, false), (8, true), (12, true)]);
        assert_eq!(spans(&overlap, ColumnRule::Parity), [(0, 3), (8, 11)]);
        assert_eq!(spans(&overlap, outward), [(0, 11)]);
        // An outward shell holding an inward one (a hollow): winding 0 in the hollow.
        let hollow = column(&[(0, false), (4, true), (8, false), (12, true)]);
        assert_eq!(spans(&hollow, outward), [(0, 3), (8, 11)]);
        assert_eq!(spans(&hollow, ColumnRule::Parity), [(0, 3), (8, 11)]);
        // A mesh read reversed: its inward shells bound the inside.
        let inward = column(&[(0, true), (4, false)]);
        assert_eq!(spans(&inward, outward), []);
        assert_eq!(
            spans(&inward, ColumnRule::Winding { orientation: -1 }),
            [(0, 3)]
        );
        // A column that crosses nothing holds no inside.
        assert_eq!(spans(&[], outward), []);
    }
}
