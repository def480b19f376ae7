//! Where voxelizers put their voxels: a thread-local grid that keeps, per voxel, the
//! distance to and the normal or colour of the nearest primitive, and the parallel
//! fold/merge that turns many such grids into one.

use crate::grid::{Channels, Coord, Leaf, SparseGrid, Transform};
use crate::progress::Progress;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Channels a distance-criterion voxelizer produces: distance as value, plus the normal.
pub(crate) fn nearest_channels(normals: bool) -> Channels {
    Channels {
        value: normals,
        normal: normals,
        color: false,
    }
}

pub(crate) struct Sink<'g> {
    acc: crate::grid::Accessor<'g>,
    nearest: bool,
}

impl<'g> Sink<'g> {
    pub fn new(grid: &'g mut SparseGrid) -> Self {
        let nearest = grid.channels().value;
        Sink {
            acc: grid.accessor(),
            nearest,
        }
    }

    /// Marks voxel `c` and returns its leaf and offset when the grid keeps the nearest
    /// primitive per voxel and this one, `distance` away, is nearer than any before.
    #[inline]
    fn claim(&mut self, c: Coord, distance: f64) -> Option<(&mut Leaf, usize)> {
        let (leaf, n) = self.acc.leaf_mut(c);
        let was_on = leaf.is_on(n);
        leaf.set_on(n);
        if !self.nearest {
            return None;
        }
        let d = distance as f32;
        let values = leaf.value.as_mut().expect("nearest sink has values");
        if was_on && d >= values[n] {
            return None;
        }
        values[n] = d;
        Some((leaf, n))
    }

    /// Marks voxel `c`; with channels, keeps the nearest primitive's distance and normal.
    #[inline]
    pub fn add(&mut self, c: Coord, distance: f64, normal: DVec3) {
        if let Some((leaf, n)) = self.claim(c, distance) {
            leaf.normal.as_mut().expect("nearest sink has normals")[n] = normal.as_vec3().into();
        }
    }

    /// Marks voxel `c`; with channels, keeps the nearest primitive's distance and colour.
    #[inline]
    pub fn add_color(&mut self, c: Coord, distance: f64, color: Vec3) {
        if let Some((leaf, n)) = self.claim(c, distance) {
            leaf.color.as_mut().expect("colour sink has colours")[n] = color.into();
        }
    }
}

/// ORs `src` into `dst`; where both hold a voxel, keeps the smaller distance and its
/// normal and colour.
pub(crate) fn merge_nearest(dst: &mut Leaf, src: &Leaf) {
    if let (Some(dv), Some(sv)) = (dst.value.as_mut(), src.value.as_ref()) {
        for w in 0..8 {
            let mut b = src.mask[w];
            while b != 0 {
                let n = w * 64 + b.trailing_zeros() as usize;
                if dst.mask[w] >> (n & 63) & 1 == 0 || sv[n] < dv[n] {
                    dv[n] = sv[n];
                    if let (Some(d), Some(s)) = (dst.normal.as_mut(), src.normal.as_ref()) {
                        d[n] = s[n];
                    }
                    if let (Some(d), Some(s)) = (dst.color.as_mut(), src.color.as_ref()) {
                        d[n] = s[n];
                    }
                }
                b &= b - 1;
            }
        }
    }
    for w in 0..8 {
        dst.mask[w] |= src.mask[w];
    }
}

/// Merges two grids of the same channels, the smaller into the larger.
pub(crate) fn merge_grids(a: SparseGrid, b: SparseGrid) -> SparseGrid {
    let (mut big, small) = if a.leaves().len() >= b.leaves().len() {
        (a, b)
    } else {
        (b, a)
    };
    big.merge_with(small, merge_nearest);
    big
}

/// Runs `emit` on every item in parallel chunks, each chunk into a thread-local grid, and
/// merges the grids leaf by leaf.
pub(crate) fn voxelize_parallel<T: Sync>(
    items: &[T],
    transform: Transform,
    channels: Channels,
    progress: &Progress,
    emit: impl Fn(&T, &mut Sink) + Sync,
) -> SparseGrid {
    voxelize_indexed(items.len(), transform, channels, progress, |i, sink| {
        emit(&items[i], sink)
    })
}

/// `voxelize_parallel` over the item numbers `0..count`.
pub(crate) fn voxelize_indexed(
    count: usize,
    transform: Transform,
    channels: Channels,
    progress: &Progress,
    emit: impl Fn(usize, &mut Sink) + Sync,
) -> SparseGrid {
    const CHUNK: usize = 1024;
    (0..count.div_ceil(CHUNK))
        .into_par_iter()
        .fold(
            || SparseGrid::new(transform, channels),
            |mut grid, chunk| {
                let items = chunk * CHUNK..((chunk + 1) * CHUNK).min(count);
                let done = items.len() as u64;
                // Once cancelled, the remaining chunks are skipped (the caller checks).
                if !progress.stopped() {
                    let mut sink = Sink::new(&mut grid);
                    for i in items {
                        emit(i, &mut sink);
                    }
                    progress.advance(done);
                }
                grid
            },
        )
        .reduce(|| SparseGrid::new(transform, channels), merge_grids)
}
