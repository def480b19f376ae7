//! A brick set: the bricks of a distributed run kept as `.vdb` files beside a JSON index,
//! for results too large to merge in one process. Readers (`voxelkit info`, `read_vdb` in
//! Python) take the index file and see one grid.

use super::atomic::write_atomic;
use super::references::referenced_file;
use super::vdb::read_vdb_grid;
use crate::error::{Error, Result};
use crate::grid::{CoordBox, NODE_DIM, SparseGrid, Transform};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` value of an index.
pub const BRICK_SET_FORMAT: &str = "voxelkit-bricks";
/// The largest brick edge an index may give (Dask runs use 1024 by default).
pub const MAX_BRICK_SIZE: i64 = 1 << 16;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BrickSet {
    pub format: String,
    pub voxel_size: f64,
    /// World position of the centre of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// Voxels along a brick's edge; brick `b` covers `b * size ..= b * size + size - 1`.
    pub brick_size: i64,
    /// Bricks held in files (named relative to the index).
    pub bricks: Vec<BrickFile>,
    /// Bricks wholly inside a solid, written as no file.
    #[serde(default)]
    pub full_bricks: Vec<[i64; 3]>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BrickFile {
    pub brick: [i64; 3],
    pub file: String,
}

/// The voxels of brick `b` of edge `size`: `b * size ..= b * size + size - 1`.
pub fn brick_voxels(b: [i64; 3], size: i64) -> CoordBox {
    CoordBox {
        min: b.map(|v| v * size),
        max: b.map(|v| v * size + size - 1),
    }
}

/// Whether `path` names a brick-set index (by extension: `.json`).
pub fn is_brick_set(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

impl BrickSet {
    pub fn read(path: &Path) -> Result<BrickSet> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let set: BrickSet = serde_json::from_str(&text).map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: e.line(),
            message: e.to_string(),
        })?;
        if set.format != BRICK_SET_FORMAT {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!("not a brick set (format `{}`)", set.format),
            });
        }
        set.check().map_err(|message| Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message,
        })?;
        Ok(set)
    }

    /// Refuses an index no run writes: a voxel size or origin that is not a finite number
    /// (a positive one for the size), a brick size that is not a multiple of 8 up to
    /// `MAX_BRICK_SIZE`, a brick whose voxels OpenVDB's 32-bit coordinates cannot hold, a
    /// brick listed twice or a file named for two bricks.
    fn check(&self) -> std::result::Result<(), String> {
        if !(self.voxel_size.is_finite() && self.voxel_size > 0.0) {
            return Err(format!(
                "voxel_size {} is not a positive number",
                self.voxel_size
            ));
        }
        if !self.origin.iter().all(|c| c.is_finite()) {
            return Err(format!(
                "origin {:?} is not three finite numbers",
                self.origin
            ));
        }
        let size = self.brick_size;
        if !(8..=MAX_BRICK_SIZE).contains(&size) || size % 8 != 0 {
            return Err(format!(
                "brick_size {size} is not a multiple of 8 between 8 and {MAX_BRICK_SIZE}"
            ));
        }
        let in_range = |b: &[i64; 3]| {
            b.iter().all(|&v| {
                v.checked_mul(size).is_some_and(|lo| {
                    lo >= i64::from(i32::MIN) && lo + (size - 1) <= i64::from(i32::MAX)
                })
            })
        };
        let mut bricks = std::collections::HashSet::new();
        let listed = self
            .bricks
            .iter()
            .map(|b| &b.brick)
            .chain(&self.full_bricks);
        for b in listed {
            if !in_range(b) {
                return Err(format!(
                    "brick {b:?} lies beyond the coordinates a .vdb holds (32-bit voxel indices)"
                ));
            }
            if !bricks.insert(*b) {
                return Err(format!("brick {b:?} is listed twice"));
            }
        }
        let mut files = std::collections::HashSet::new();
        for b in &self.bricks {
            if !files.insert(b.file.as_str()) {
                return Err(format!("`{}` is named for two bricks", b.file));
            }
        }
        Ok(())
    }

    /// Writes the index atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("an index serializes");
        write_atomic(path, |tmp| {
            std::fs::write(tmp, text.as_bytes()).map_err(|e| Error::io(path, e))
        })
    }

    /// The brick files, in the folder of the index at `index` (regular files inside it: see
    /// `io::references`).
    pub fn files(&self, index: &Path) -> Result<Vec<PathBuf>> {
        self.bricks
            .iter()
            .map(|b| {
                referenced_file(index, &b.file).map_err(|m| Error::Parse {
                    path: index.to_path_buf(),
                    line: 0,
                    message: format!("brick {:?}: {m}", b.brick),
                })
            })
            .collect()
    }

    /// Refuses a brick's file whose voxels (their box `bbox`) leave the brick, or whose grid
    /// (`transform`) is not the set's: what `merge` and `voxelkit info` both check.
    pub fn check_part(
        &self,
        brick: &BrickFile,
        file: &Path,
        bbox: Option<CoordBox>,
        transform: &Transform,
    ) -> Result<()> {
        let refuse = |message: String| {
            Err(Error::Parse {
                path: file.to_path_buf(),
                line: 0,
                message,
            })
        };
        let voxels = brick_voxels(brick.brick, self.brick_size);
        if let Some(b) = bbox
            && !(voxels.contains(b.min) && voxels.contains(b.max))
        {
            return refuse(format!("voxels outside its brick {:?}", brick.brick));
        }
        let set = self.transform();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * set.voxel_size.max(a.abs());
        if !(close(transform.voxel_size, set.voxel_size)
            && (0..3).all(|a| close(transform.origin[a], set.origin[a])))
        {
            return refuse(format!(
                "its grid (voxel size {}, origin {}) is not the brick set's (voxel size {}, \
                 origin {})",
                transform.voxel_size, transform.origin, set.voxel_size, set.origin
            ));
        }
        Ok(())
    }

    pub fn transform(&self) -> Transform {
        Transform::new(DVec3::from_array(self.origin), self.voxel_size)
    }

    /// The whole grid: every brick file's voxels (each checked to lie in its brick) and the
    /// full bricks as tiles.
    pub fn merge(&self, index: &Path) -> Result<SparseGrid> {
        let mut grid = SparseGrid::new(self.transform(), crate::grid::Channels::NONE);
        for (brick, file) in self.bricks.iter().zip(self.files(index)?) {
            let part = read_vdb_grid(&file, None)?;
            self.check_part(brick, &file, part.bbox(), &part.transform)?;
            grid.union(&part);
        }
        for &b in &self.full_bricks {
            fill_box(&mut grid, brick_voxels(b, self.brick_size));
        }
        grid.compact();
        Ok(grid)
    }
}

/// Makes every voxel of `b` (aligned on 8) active: 128^3 node tiles where the box holds
/// whole nodes, 8^3 tiles elsewhere.
pub fn fill_box(grid: &mut SparseGrid, b: CoordBox) {
    let aligned = (0..3).all(|a| b.min[a] % NODE_DIM == 0 && (b.max[a] + 1) % NODE_DIM == 0);
    let step = if aligned { NODE_DIM } else { 8 };
    let mut o = b.min;
    while o[0] <= b.max[0] {
        o[1] = b.min[1];
        while o[1] <= b.max[1] {
            o[2] = b.min[2];
            while o[2] <= b.max[2] {
                if aligned {
                    grid.fill_node_block(o);
                } else {
                    grid.fill_leaf_block(o);
                }
                o[2] += step;
            }
            o[1] += step;
        }
        o[0] += step;
    }
}
