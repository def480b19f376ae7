//! A brick set: the bricks of a distributed run kept as `.vdb` files beside a JSON index,
//! for results too large to merge in one process. Readers (`voxelkit info`, `read_vdb` in
//! Python) take the index file and see one grid.

use super::atomic::write_atomic;
use super::vdb::read_vdb_grid;
use crate::error::{Error, Result};
use crate::grid::{CoordBox, NODE_DIM, SparseGrid, Transform};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` value of an index.
pub const BRICK_SET_FORMAT: &str = "voxelkit-bricks";

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
        if set.brick_size < 8 || set.brick_size % 8 != 0 {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!("brick_size {} is not a multiple of 8", set.brick_size),
            });
        }
        Ok(set)
    }

    /// Writes the index atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("an index serializes");
        write_atomic(path, |tmp| {
            std::fs::write(tmp, text.as_bytes()).map_err(|e| Error::io(path, e))
        })
    }

    /// The brick files, as paths beside the index at `index`.
    pub fn files(&self, index: &Path) -> Vec<PathBuf> {
        let folder = index.parent().unwrap_or(Path::new("."));
        self.bricks.iter().map(|b| folder.join(&b.file)).collect()
    }

    pub fn transform(&self) -> Transform {
        Transform::new(DVec3::from_array(self.origin), self.voxel_size)
    }

    /// The whole grid: every brick file's voxels (each checked to lie in its brick) and the
    /// full bricks as tiles.
    pub fn merge(&self, index: &Path) -> Result<SparseGrid> {
        let mut grid = SparseGrid::new(self.transform(), crate::grid::Channels::NONE);
        for (brick, file) in self.bricks.iter().zip(self.files(index)) {
            let part = read_vdb_grid(&file, None)?;
            let voxels = brick_voxels(brick.brick, self.brick_size);
            if let Some(b) = part.bbox()
                && !(voxels.contains(b.min) && voxels.contains(b.max))
            {
                return Err(Error::Parse {
                    path: file,
                    line: 0,
                    message: format!("voxels outside its brick {:?}", brick.brick),
                });
            }
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
