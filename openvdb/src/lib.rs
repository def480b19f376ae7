//! OpenVDB's own tools for voxelkit's tests and benchmarks, kept apart from voxelkit so that
//! its programs do not load OpenVDB (whose 60,000 symbol relocations cost every run about
//! 35 ms at start-up): OpenVDB reading a `.vdb` file, an independent check of voxelkit's own
//! reader and writer; `levelSetVolume`; and its mesh conversions, the benchmarks' reference.
//! Errors are OpenVDB's messages.
#![cfg(openvdb)]

mod bridge;

pub use bridge::ffi::{GridInfo, MetaEntry};

/// A grid as OpenVDB reads it: per leaf its origin (3 x i32), mask (8 x u64) and, for float
/// and vector grids, 512 or 3 x 512 values; active tiles as (x, y, z, edge 8 or 128).
pub struct Grid {
    pub info: GridInfo,
    pub origins: Vec<i32>,
    pub masks: Vec<u64>,
    pub values: Vec<f32>,
    pub tiles: Vec<i32>,
}

/// Every grid of the file at `path`, described by OpenVDB.
pub fn grid_infos(path: &str) -> Result<Vec<GridInfo>, String> {
    let file = bridge::ffi::open_vdb(path).map_err(|e| e.to_string())?;
    (0..file.grid_count())
        .map(|i| file.grid_info(i).map_err(|e| e.to_string()))
        .collect()
}

/// The grid `name` of the file at `path` (bool, mask, float or vec3s), read by OpenVDB.
pub fn read_grid(path: &str, name: &str) -> Result<Grid, String> {
    let file = bridge::ffi::open_vdb(path).map_err(|e| e.to_string())?;
    for i in 0..file.grid_count() {
        let info = file.grid_info(i).map_err(|e| e.to_string())?;
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
        file.read_leaves(
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

/// OpenVDB's `tools::levelSetVolume` of the level set `name` in the file at `path`.
pub fn level_set_volume(path: &str, name: &str) -> Result<f64, String> {
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
) -> Result<u64, String> {
    let name = match kind {
        Reference::Unsigned => "unsigned",
        Reference::LevelSet => "level-set",
        Reference::Solid => "solid",
        Reference::Filled => "filled",
    };
    bridge::ffi::openvdb_reference(name, index_points, triangles, voxel_size, band, threads)
        .map_err(|e| format!("OpenVDB {name}: {e}"))
}
