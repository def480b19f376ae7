//! The cxx bridge to OpenVDB (`cpp/vdb_bridge.cc`): OpenVDB grids in memory, read from `.vdb`
//! files or built from voxelkit's arrays and written by OpenVDB, and its own tools. Leaves
//! cross in bulk: per grid one call with, for every 8^3 leaf, its origin (3 x i32), its mask (8 x u64,
//! OpenVDB's word order) and, for value grids, its 512 values (or 3 x 512 for vectors) in
//! OpenVDB's voxel order. Every C++ function catches its exceptions and turns them into
//! `Result` errors.

#[cxx::bridge(namespace = "voxelkit")]
pub mod ffi {
    /// One string metadata item of a grid.
    struct MetaEntry {
        key: String,
        value: String,
    }

    /// What a grid in a .vdb file is.
    struct GridInfo {
        name: String,
        value_type: String,
        grid_class: String,
        voxel_size: [f64; 3],
        /// World position of the centre of voxel (0,0,0).
        origin: [f64; 3],
        /// Whether the transform is a uniform scale plus translation (our Transform).
        uniform_linear: bool,
        active_voxels: u64,
        leaf_count: u64,
        /// Active tiles, counted as 128^3 ones where larger.
        tile_count: u64,
        bbox_min: [i32; 3],
        bbox_max: [i32; 3],
        metadata: Vec<MetaEntry>,
    }

    /// One metadata item to store: `kind` `string`, `int64` or `double` says which of
    /// `text`, `integer` and `real` holds it.
    struct MetaItem {
        key: String,
        kind: &'static str,
        text: String,
        integer: i64,
        real: f64,
    }

    /// A grid to build, as `voxelkit::io::grid_export::ExportedGrid` gives it; empty
    /// `grid_class` and `vector_type` when it has none.
    struct GridArrays<'a> {
        name: &'a str,
        value_type: &'a str,
        grid_class: &'a str,
        vector_type: &'a str,
        metadata: Vec<MetaItem>,
        voxel_size: f64,
        origin: [f64; 3],
        background: f32,
        leaf_origins: &'a [i32],
        masks: &'a [u64],
        values: &'a [f32],
        tiles: &'a [i32],
        tiles_active: bool,
        tile_value: f32,
    }

    /// What OpenVDB's `tools::volumeToMesh` made, and its seconds.
    struct MeshCounts {
        seconds: f64,
        points: u64,
        triangles: u64,
        quads: u64,
    }

    unsafe extern "C++" {
        include!("voxelkit-openvdb/cpp/vdb_bridge.h");

        /// Grids in OpenVDB's memory.
        type GridSet;

        fn open_vdb(path: &str) -> Result<UniquePtr<GridSet>>;
        fn new_grid_set() -> UniquePtr<GridSet>;
        fn grid_count(self: &GridSet) -> usize;
        fn grid_info(self: &GridSet, index: usize) -> Result<GridInfo>;
        /// Builds an OpenVDB grid of the arrays (its tree, transform, class, vector type and
        /// metadata) and adds it to the set.
        fn add_grid(self: Pin<&mut GridSet>, arrays: &GridArrays) -> Result<()>;
        /// OpenVDB's `tools::levelSetVolume` of the grid `name`.
        fn level_set_volume(self: &GridSet, name: &str) -> Result<f64>;
        /// OpenVDB's `tools::volumeToMesh` of the float grid `name` at `iso` with `adaptivity`,
        /// on at most `threads` threads, timed on the call alone.
        fn volume_to_mesh(
            self: &GridSet,
            name: &str,
            iso: f64,
            adaptivity: f64,
            threads: usize,
        ) -> Result<MeshCounts>;
        /// Writes every grid with OpenVDB's `io::File`, with its `COMPRESS_*` flags
        /// `compression` (active masks added) and floats at half precision when `half` (which
        /// it records on the grids: the set changes).
        fn write(self: Pin<&mut GridSet>, path: &str, compression: u32, half: bool) -> Result<()>;
        /// Active voxels of a Bool, Mask, Float or Vec3S grid, leaf by leaf, and its active
        /// tiles as (x, y, z, edge) with edge 8 or 128 (larger tiles split into 128^3 ones);
        /// `values` gets 512 floats per leaf for Float grids, 3 x 512 for Vec3S grids, and
        /// stays empty otherwise.
        fn read_leaves(
            self: &GridSet,
            index: usize,
            leaf_origins: &mut Vec<i32>,
            masks: &mut Vec<u64>,
            values: &mut Vec<f32>,
            tiles: &mut Vec<i32>,
        ) -> Result<()>;

        /// OpenVDB's `tools::levelSetVolume` of the level set `name` in the file at `path`.
        fn openvdb_level_set_volume(path: &str, name: &str) -> Result<f64>;

        /// OpenVDB's own conversion of a triangle mesh given in index space, for benchmarks,
        /// on at most `threads` threads: `kind` "unsigned" (`meshToUnsignedDistanceField`),
        /// "level-set" (`meshToLevelSet`), "solid" (`meshToLevelSet` then `sdfInteriorMask`)
        /// or "filled" (`meshToVolume` with the interior filled), `band` voxels wide.
        /// Returns the number of active voxels of the result.
        fn openvdb_reference(
            kind: &str,
            points: &[f32],
            triangles: &[u32],
            voxel_size: f64,
            band: f32,
            threads: usize,
        ) -> Result<u64>;
    }
}
