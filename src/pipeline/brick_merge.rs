//! A brick set written as one `.vdb`: spliced node by node where its bricks lie on OpenVDB's
//! 128^3 nodes (`io::brick_splice`: memory that does not grow with the voxels), else read
//! into one grid and written.

use super::Outcome;
use crate::error::Result;
use crate::io::brick_set::BrickSet;
use crate::io::brick_splice::{splice_brick_set, splices};
use crate::io::vdb::{MetaValue, WriteOptions};
use std::path::Path;

/// How a brick set was merged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MergedBy {
    /// Each brick's nodes copied as they are.
    Splicing,
    /// The voxels read into one grid and written again.
    Reading,
}

impl MergedBy {
    pub fn name(self) -> &'static str {
        match self {
            MergedBy::Splicing => "splicing",
            MergedBy::Reading => "reading",
        }
    }
}

/// The metadata of a merged brick set: made of bricks, of `source`.
pub fn brick_metadata(source: &str) -> [(&'static str, MetaValue); 2] {
    [
        ("method", "voxelkit bricks".into()),
        ("source_file", source.into()),
    ]
}

/// Writes the brick set of the index at `index` to the `.vdb` `output` (atomically), its
/// metadata naming `source` as what was voxelized. Returns how it merged and the voxels.
pub fn merge_brick_set(index: &Path, output: &Path, source: &str) -> Result<(MergedBy, u64)> {
    let metadata = brick_metadata(source);
    let set = BrickSet::read(index)?;
    if splices(set.brick_size) {
        let voxels = splice_brick_set(&set, index, output, &metadata)?;
        return Ok((MergedBy::Splicing, voxels));
    }
    let mut outcome = Outcome::read_vdb(index, None)?;
    outcome.metadata = metadata
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    outcome.write(output, &[index], &WriteOptions::default())?;
    Ok((MergedBy::Reading, outcome.grid.voxel_count()))
}
