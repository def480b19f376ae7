//! voxelkit's bridge to OpenVDB, for Rust programs that have OpenVDB (libopenvdb-dev): a
//! voxelkit result handed to OpenVDB in this process ([`OpenVdbGrids::from_outcome`]: OpenVDB's
//! own trees, transforms, classes and metadata, the grids voxelkit's `.vdb` writer writes), to
//! measure with OpenVDB's tools or write with OpenVDB's own `io::File`
//! ([`write_with_openvdb`], a second writer beside voxelkit's native one that gives the same
//! files); OpenVDB reading `.vdb` files (an independent check of voxelkit's reader and writer);
//! `levelSetVolume`; and OpenVDB's mesh conversions, the benchmarks' reference.
//!
//! It is a crate of its own so that voxelkit's programs do not load OpenVDB, whose 60,000
//! symbol relocations cost every run about 35 ms at start-up. Without OpenVDB's headers it
//! builds empty, with a warning. Errors are OpenVDB's messages.
//!
//! ```no_run
//! use voxelkit::pipeline::{Job, MeshSource, Task};
//! # fn main() -> voxelkit::Result<()> {
//! # let job: Job = todo!();
//! let outcome = job.run(&voxelkit::progress::Unobserved)?;
//! let options = voxelkit::io::vdb::WriteOptions::default();
//! let grids = voxelkit_openvdb::OpenVdbGrids::from_outcome(&outcome, &options)?;
//! println!("{:?}", grids.level_set_volume("surface"));
//! voxelkit_openvdb::write_with_openvdb(&outcome, "bunny.vdb".as_ref(), &options)?;
//! # Ok(())
//! # }
//! ```
#![cfg(openvdb)]

mod bridge;

pub use bridge::ffi::{GridInfo, MeshCounts, MetaEntry};
use std::path::Path;
use voxelkit::io::vdb::{MetaValue, WriteOptions};
use voxelkit::pipeline::Outcome;
use voxelkit::{Error, Result};

/// A grid as OpenVDB reads it: per leaf its origin (3 x i32), mask (8 x u64) and, for float
/// and vector grids, 512 or 3 x 512 values; active tiles as (x, y, z, edge 8 or 128).
pub struct Grid {
    pub info: GridInfo,
    pub origins: Vec<i32>,
    pub masks: Vec<u64>,
    pub values: Vec<f32>,
    pub tiles: Vec<i32>,
}

/// Grids in OpenVDB's memory: read from a `.vdb` file, or built from a voxelkit result.
pub struct OpenVdbGrids {
    set: cxx::UniquePtr<bridge::ffi::GridSet>,
}

// SAFETY: the set is OpenVDB's grid vector, owned by this value alone; OpenVDB's grids may be
// moved between threads and read from several at once, and every method that changes them
// (`write` records the precision on each grid) takes `&mut self`.
unsafe impl Send for OpenVdbGrids {}
unsafe impl Sync for OpenVdbGrids {}

impl OpenVdbGrids {
    /// Every grid of the file at `path`, read by OpenVDB.
    pub fn read(path: &str) -> std::result::Result<OpenVdbGrids, String> {
        let set = bridge::ffi::open_vdb(path).map_err(|e| e.to_string())?;
        Ok(OpenVdbGrids { set })
    }

    /// The grids voxelkit's `.vdb` writer writes for `outcome` (as `options` choose them), built
    /// as OpenVDB grids: leaves, tiles (a level set's interior as inactive tiles), transforms,
    /// classes, vector types and metadata.
    pub fn from_outcome(outcome: &Outcome, options: &WriteOptions) -> Result<OpenVdbGrids> {
        let mut set = bridge::ffi::new_grid_set();
        for g in outcome.export_grids(options, None)? {
            let metadata = g
                .metadata
                .iter()
                .map(|(key, value)| {
                    let mut item = bridge::ffi::MetaItem {
                        key: key.clone(),
                        kind: "string",
                        text: String::new(),
                        integer: 0,
                        real: 0.0,
                    };
                    match value {
                        MetaValue::Text(t) => item.text = t.clone(),
                        MetaValue::Int(n) => (item.kind, item.integer) = ("int64", *n),
                        MetaValue::Real(x) => (item.kind, item.real) = ("double", *x),
                    }
                    item
                })
                .collect();
            let arrays = bridge::ffi::GridArrays {
                name: &g.name,
                value_type: g.value_type,
                grid_class: g.class.unwrap_or(""),
                vector_type: g.vector_type.unwrap_or(""),
                metadata,
                voxel_size: g.voxel_size,
                origin: g.origin,
                background: g.background,
                leaf_origins: &g.leaf_origins,
                masks: &g.masks,
                values: &g.values,
                tiles: &g.tiles,
                tiles_active: g.tiles_active,
                tile_value: g.tile_value,
            };
            set.pin_mut()
                .add_grid(&arrays)
                .map_err(|e| openvdb_error(&g.name, e))?;
        }
        Ok(OpenVdbGrids { set })
    }

    /// Every grid, described by OpenVDB.
    pub fn infos(&self) -> std::result::Result<Vec<GridInfo>, String> {
        (0..self.set.grid_count())
            .map(|i| self.set.grid_info(i).map_err(|e| e.to_string()))
            .collect()
    }

    /// The grid `name` (bool, mask, float or vec3s) as OpenVDB holds it.
    pub fn grid(&self, name: &str) -> std::result::Result<Grid, String> {
        for (i, info) in self.infos()?.into_iter().enumerate() {
            if info.name != name {
                continue;
            }
            let mut grid = Grid {
                info,
                origins: Vec::new(),
                masks: Vec::new(),
                values: Vec::new(),
                tiles: Vec::new(),
            };
            self.set
                .read_leaves(
                    i,
                    &mut grid.origins,
                    &mut grid.masks,
                    &mut grid.values,
                    &mut grid.tiles,
                )
                .map_err(|e| e.to_string())?;
            return Ok(grid);
        }
        Err(format!("no grid named `{name}`"))
    }

    /// OpenVDB's `tools::levelSetVolume` of the grid `name`.
    pub fn level_set_volume(&self, name: &str) -> std::result::Result<f64, String> {
        self.set.level_set_volume(name).map_err(|e| e.to_string())
    }

    /// OpenVDB's `tools::volumeToMesh` of the float grid `name` (its seconds and counts).
    pub fn volume_to_mesh(
        &self,
        name: &str,
        iso: f64,
        adaptivity: f64,
        threads: usize,
    ) -> std::result::Result<MeshCounts, String> {
        self.set
            .volume_to_mesh(name, iso, adaptivity, threads)
            .map_err(|e| e.to_string())
    }

    /// Writes every grid to `path` with OpenVDB's own `io::File`, compressed and at the
    /// precision `options` say, atomically (a temporary file, then renamed).
    pub fn write(&mut self, path: &Path, options: &WriteOptions) -> Result<()> {
        voxelkit::io::atomic::write_atomic(path, |tmp| {
            let tmp = tmp
                .to_str()
                .ok_or_else(|| openvdb_error(path, "the path is not UTF-8"))?;
            self.set
                .pin_mut()
                .write(tmp, options.compression.flags(), options.half)
                .map_err(|e| openvdb_error(path, e))
        })
    }
}

fn openvdb_error(what: impl AsRef<Path>, e: impl std::fmt::Display) -> Error {
    Error::Vdb {
        path: what.as_ref().to_path_buf(),
        message: format!("OpenVDB: {e}"),
    }
}

/// Writes `outcome` to the `.vdb` at `path` through OpenVDB's own writer: the grids, values,
/// tiles, classes and metadata voxelkit's native writer writes, as `options` say.
pub fn write_with_openvdb(outcome: &Outcome, path: &Path, options: &WriteOptions) -> Result<()> {
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
    {
        return Err(openvdb_error(path, "its writer writes .vdb files"));
    }
    voxelkit::pipeline::check_output_path(path, &[])?;
    OpenVdbGrids::from_outcome(outcome, options)?.write(path, options)
}

/// Every grid of the file at `path`, described by OpenVDB.
pub fn grid_infos(path: &str) -> std::result::Result<Vec<GridInfo>, String> {
    OpenVdbGrids::read(path)?.infos()
}

/// The grid `name` of the file at `path` (bool, mask, float or vec3s), read by OpenVDB.
pub fn read_grid(path: &str, name: &str) -> std::result::Result<Grid, String> {
    OpenVdbGrids::read(path)?.grid(name)
}

/// OpenVDB's `tools::levelSetVolume` of the level set `name` in the file at `path`.
pub fn level_set_volume(path: &str, name: &str) -> std::result::Result<f64, String> {
    bridge::ffi::openvdb_level_set_volume(path, name).map_err(|e| e.to_string())
}

/// Which of OpenVDB's own mesh conversions a benchmark compares against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// `meshToUnsignedDistanceField`: the unsigned band a surface voxelization matches.
    Unsigned,
    /// `meshToLevelSet`: a narrow-band level set.
    LevelSet,
    /// `meshToLevelSet` then `sdfInteriorMask`: a solid.
    Solid,
    /// `meshToVolume` with the interior filled (a slower path to a solid).
    Filled,
}

/// OpenVDB's conversion `kind` of a triangle mesh given in index space, `band` voxels wide,
/// on at most `threads` threads: returns its active voxel count.
pub fn reference(
    kind: Reference,
    index_points: &[f32],
    triangles: &[u32],
    voxel_size: f64,
    band: f32,
    threads: usize,
) -> std::result::Result<u64, String> {
    let name = match kind {
        Reference::Unsigned => "unsigned",
        Reference::LevelSet => "level-set",
        Reference::Solid => "solid",
        Reference::Filled => "filled",
    };
    bridge::ffi::openvdb_reference(name, index_points, triangles, voxel_size, band, threads)
        .map_err(|e| format!("OpenVDB {name}: {e}"))
}
