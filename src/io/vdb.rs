//! OpenVDB files, written (`vdb_writer`) and read (`vdb_reader`, after `vdb_structure` has
//! checked the file) by voxelkit itself. A voxel set is written as `density` (a fog volume: 1 on
//! every voxel of the set, what Blender's volume object reads), `normal` (Vec3s,
//! covariant-normalize) when the grid carries normals, `Cd` (Vec3s, the Houdini name for
//! colour) when it carries colours, and on request `voxels` (the same set as a BoolGrid);
//! whole blocks are written as active tiles. A level set is `surface`, Houdini's name. Any
//! Bool, Mask or Float grid reads back, tiles as tiles. The same grids go to a `.nvdb` in
//! NanoVDB's layout (`nvdb_writer`). Writes are atomic (temporary file, then rename).

use super::atomic::write_atomic_timed;
use super::grid_export::{ExportedGrid, export_grid};
use super::grid_out::{GridOut, GridValues};
use super::nvdb_writer::write_nvdb_grids;
use super::vdb_format::{COVARIANT_NORMALIZE, FOG_VOLUME, LEVEL_SET};
pub use super::vdb_format::{Compression, MetaValue};
use super::vdb_writer::{Encoding, encode_grids, write_grids};
use crate::contour::{Meaning, ScalarField};
use crate::error::{Error, Result};
use crate::grid::attribute_grid::{AttributeGrid, AttributeKind};
use crate::grid::{Channels, LEAF_VOXELS, Leaf, SparseGrid, Transform};
use crate::progress::{StageClock, StageTime};
use glam::DVec3;
use std::path::Path;

use super::vdb_reader::VdbFile;
pub use super::vdb_reader::{GridInfo, MetaEntry};
use rayon::prelude::*;

/// The boolean voxel set's name in a `.vdb`.
pub const VOXELS_GRID: &str = "voxels";

/// The level set's name in a `.vdb` (Houdini's VDB from Polygons calls it so).
pub const LEVEL_SET_GRID: &str = "surface";

/// The grid of unsigned distances (`udf`).
pub const DISTANCE_GRID: &str = "distance";

/// The fog volume's name, first in every file voxelkit writes.
pub const DENSITY_GRID: &str = "density";

/// The per-voxel unit normals (Vec3S), with `--normals`.
pub const NORMAL_GRID: &str = "normal";

/// The voxels of a solid with a face towards the outside: the ones that show.
pub const SHELL_GRID: &str = "shell";

/// The per-voxel colours (Vec3S), Houdini's name.
pub const COLOR_GRID: &str = "Cd";

/// OpenVDB 10 refuses transforms whose voxel volume is within about 3e-15 of zero ("Non-zero
/// scale values required"; measured: it writes 1.4423e-5 and refuses 1.4422e-5).
pub const SMALLEST_VOXEL_SIZE: f64 = 1.45e-5;

/// Refuses a voxel size OpenVDB cannot store, before any work is done for `path`.
pub fn check_voxel_size(path: &Path, voxel_size: f64) -> Result<()> {
    if voxel_size >= SMALLEST_VOXEL_SIZE {
        return Ok(());
    }
    Err(vdb_error(
        path,
        format!(
            "OpenVDB cannot store voxel size {voxel_size:.3e} (its transforms need at least              {SMALLEST_VOXEL_SIZE:.2e}); scale the input up (for example to millimetres) or              raise the voxel size"
        ),
    ))
}

fn vdb_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Vdb {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Writes `grid` to `path` as `density` and (when present) `normal` and `Cd` grids, each with
/// `grid.transform` and `metadata` plus `voxelkit_version`.
pub fn write_vdb(path: &Path, grid: &SparseGrid, metadata: &[(&str, MetaValue)]) -> Result<()> {
    write_vdb_as(path, grid, &[], metadata, &WriteOptions::default())
}

/// `write_vdb`, plus one bool grid per `(name, mask)`, each with its own transform, written
/// as `options` say.
pub fn write_vdb_as(
    path: &Path,
    grid: &SparseGrid,
    masks: &[(&str, &SparseGrid)],
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
) -> Result<()> {
    let contents = Contents::Voxels {
        grid,
        masks: masks.to_vec(),
        attributes: &[],
    };
    write_contents(path, &contents, metadata, options)
}

/// What a write holds: a voxel set with bool grids beside it, or a band of distances; each
/// with the mesh attributes carried onto its voxels, a grid per attribute after the others.
pub enum Contents<'a> {
    /// `density` (and `voxels`), `normal` and `Cd` when the grid has them, then one bool
    /// grid per `(name, mask)`.
    Voxels {
        grid: &'a SparseGrid,
        masks: Vec<(&'a str, &'a SparseGrid)>,
        attributes: &'a [AttributeGrid],
    },
    /// Distances in world units on the grid's voxels, `background` elsewhere. With its
    /// `interior`, signed distances: the fog volume `density` and the LEVEL_SET grid `surface`
    /// (Houdini's name) whose inactive voxels and tiles in the interior are -background;
    /// without, unsigned distances: a FloatGrid `distance`.
    Distances {
        grid: &'a SparseGrid,
        background: f32,
        interior: Option<&'a SparseGrid>,
        attributes: &'a [AttributeGrid],
    },
}

impl<'a> Contents<'a> {
    fn attributes(&self) -> &'a [AttributeGrid] {
        match *self {
            Contents::Voxels { attributes, .. } | Contents::Distances { attributes, .. } => {
                attributes
            }
        }
    }
}

/// Writes `contents` to `path` (`.vdb` or `.nvdb`), every grid with `metadata` plus
/// `voxelkit_version`, as `options` say, atomically.
pub fn write_contents(
    path: &Path,
    contents: &Contents,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
) -> Result<()> {
    write_contents_timed(path, contents, metadata, options).map(|_| ())
}

/// `write_contents`, returning where its time went: encoding the grids, writing the bytes,
/// syncing the file.
pub fn write_contents_timed(
    path: &Path,
    contents: &Contents,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
) -> Result<[StageTime; 3]> {
    with_chosen_grids(path, contents, metadata, options, |grids| {
        write_chosen_grids(path, grids, options)
    })
}

/// Writes the chosen `grids` to `path` (`.vdb` or `.nvdb`) atomically; where the time went.
fn write_chosen_grids(
    path: &Path,
    grids: &[GridOut],
    options: &WriteOptions,
) -> Result<[StageTime; 3]> {
    let mut clocks = WriteClocks::new();
    let mut fsync = StageClock::new("fsync");
    if is_nvdb(path) {
        if options.half {
            return Err(Error::InvalidArgument(format!(
                "{}: half precision is written to .vdb only; a .nvdb holds 32-bit floats",
                path.display()
            )));
        }
        write_atomic_timed(path, &mut fsync, |tmp| {
            write_nvdb_grids(tmp, path, grids, &mut clocks)
        })?;
    } else {
        let encoding = encoding(options);
        write_atomic_timed(path, &mut fsync, |tmp| {
            write_grids(tmp, path, grids, encoding, &mut clocks)
        })?;
    }
    Ok([clocks.encode.stage(), clocks.write.stage(), fsync.stage()])
}

/// The bytes of the `.vdb` file `write_contents` would write, in memory (a brick kept by its
/// worker until it is written into the merged file); errors name `what`.
pub fn encode_contents(
    what: &Path,
    contents: &Contents,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
) -> Result<Vec<u8>> {
    with_chosen_grids(what, contents, metadata, options, |grids| {
        encode_grids(
            Vec::new(),
            what,
            grids,
            encoding(options),
            &mut WriteClocks::new(),
        )
    })
}

/// Calls `f` with the grids a write of `contents` with `metadata` makes, as `options` choose
/// them; errors name `what`.
fn with_chosen_grids<T>(
    what: &Path,
    contents: &Contents,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
    f: impl FnOnce(&[GridOut]) -> Result<T>,
) -> Result<T> {
    let meta = meta_entries(metadata);
    f(&chosen(
        what,
        candidates(what, contents, &meta, options)?,
        options,
    )?)
}

/// How `options` ask a `.vdb`'s values to be encoded.
pub(super) fn encoding(options: &WriteOptions) -> Encoding {
    Encoding {
        compression: options.compression.flags(),
        half: options.half,
    }
}

/// The time a writer spends encoding grids and writing their bytes, grid by grid.
pub(super) struct WriteClocks {
    pub encode: StageClock,
    pub write: StageClock,
}

impl WriteClocks {
    fn new() -> WriteClocks {
        WriteClocks {
            encode: StageClock::new("encode"),
            write: StageClock::new("write"),
        }
    }
}

/// The grids a write of `contents` makes (only the one at index `which` when given), as plain
/// arrays for another library to build its own from (see `grid_export`); errors name `what`,
/// where they are bound.
pub fn export_contents(
    what: &Path,
    contents: &Contents,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
    which: Option<usize>,
) -> Result<Vec<ExportedGrid>> {
    with_chosen_grids(what, contents, metadata, options, |grids| {
        let count = grids.len();
        let grids = match which {
            Some(i) => grids.get(i..=i).ok_or_else(|| {
                Error::InvalidArgument(format!("grid {i} is out of range: the write makes {count}"))
            })?,
            None => grids,
        };
        grids.iter().map(|g| export_grid(what, g)).collect()
    })
}

/// How many grids a write of `contents` makes, as `options` choose them.
pub fn content_grid_count(
    what: &Path,
    contents: &Contents,
    options: &WriteOptions,
) -> Result<usize> {
    Ok(chosen(what, candidates(what, contents, &[], options)?, options)?.len())
}

/// Every grid `contents` can write, before `options` choose among them: its own, then its
/// attributes' (scalars as FloatGrids, texture coordinates and normals as Vec3SGrids).
pub(super) fn candidates<'g>(
    path: &Path,
    contents: &Contents<'g>,
    meta: &'g [(String, MetaValue)],
    options: &WriteOptions,
) -> Result<Vec<GridOut<'g>>> {
    let mut grids = content_candidates(path, contents, meta, options)?;
    for a in contents.attributes() {
        let (values, vector_type) = match a.kind {
            AttributeKind::Scalar => (GridValues::Distances { background: 0.0 }, None),
            AttributeKind::TextureCoordinates | AttributeKind::Color => {
                (GridValues::Colors, Some("invariant"))
            }
            AttributeKind::Normal => (GridValues::Colors, Some(COVARIANT_NORMALIZE)),
        };
        grids.push(GridOut {
            name: a.name.as_str().into(),
            grid: &a.grid,
            values,
            class: None,
            vector_type,
            metadata: meta,
        });
    }
    Ok(grids)
}

/// The grids of `contents` itself.
fn content_candidates<'g>(
    path: &Path,
    contents: &Contents<'g>,
    meta: &'g [(String, MetaValue)],
    options: &WriteOptions,
) -> Result<Vec<GridOut<'g>>> {
    let grid_out = |name: &'g str, grid, values, class, vector_type| GridOut {
        name: name.into(),
        grid,
        values,
        class,
        vector_type,
        metadata: meta,
    };
    match *contents {
        Contents::Voxels {
            grid, ref masks, ..
        } => {
            check_voxel_size(path, grid.transform.voxel_size)?;
            let mut candidates = vec![
                grid_out(
                    DENSITY_GRID,
                    grid,
                    GridValues::Constant(1.0),
                    Some(FOG_VOLUME),
                    None,
                ),
                grid_out(VOXELS_GRID, grid, GridValues::Bool, None, None),
            ];
            // Normals transform covariantly; colours are plain triples.
            if grid.channels().normal {
                candidates.push(grid_out(
                    NORMAL_GRID,
                    grid,
                    GridValues::Normals,
                    None,
                    Some(COVARIANT_NORMALIZE),
                ));
            }
            if grid.channels().color {
                candidates.push(grid_out(
                    COLOR_GRID,
                    grid,
                    GridValues::Colors,
                    None,
                    Some("invariant"),
                ));
            }
            for (name, mask) in masks {
                check_voxel_size(path, mask.transform.voxel_size)?;
                // Normals on the voxels that show (a solid's shell) are the result's normals.
                if *name == NORMAL_GRID && mask.channels().normal {
                    candidates.push(grid_out(
                        NORMAL_GRID,
                        mask,
                        GridValues::Normals,
                        None,
                        Some(COVARIANT_NORMALIZE),
                    ));
                    continue;
                }
                candidates.push(grid_out(name, mask, GridValues::Bool, None, None));
                // A mask with normals (an octree level) writes them beside it.
                if mask.channels().normal {
                    candidates.push(GridOut {
                        name: format!("{name}_normal").into(),
                        ..grid_out(
                            name,
                            mask,
                            GridValues::Normals,
                            None,
                            Some(COVARIANT_NORMALIZE),
                        )
                    });
                }
            }
            Ok(candidates)
        }
        Contents::Distances {
            grid,
            background,
            interior,
            ..
        } => {
            check_voxel_size(path, grid.transform.voxel_size)?;
            if grid.leaves().iter().any(|l| l.value.is_none()) {
                return Err(vdb_error(path, "a distance band needs distances"));
            }
            if options.half {
                check_half_range(path, grid, background)?;
            }
            Ok(match interior {
                Some(interior) => vec![
                    // Blender's volume object shows `density`: the fog volume of the same solid.
                    grid_out(
                        DENSITY_GRID,
                        interior,
                        GridValues::Fog {
                            band: grid,
                            background,
                        },
                        Some(FOG_VOLUME),
                        None,
                    ),
                    grid_out(
                        LEVEL_SET_GRID,
                        grid,
                        GridValues::LevelSet {
                            background,
                            interior,
                        },
                        Some(LEVEL_SET),
                        None,
                    ),
                ],
                None => vec![grid_out(
                    DISTANCE_GRID,
                    grid,
                    GridValues::Distances { background },
                    None,
                    None,
                )],
            })
        }
    }
}

/// The grids of `candidates` that `options` asks for; a grid asked for that is not among them
/// is an error naming those there are.
fn chosen<'g>(
    path: &Path,
    mut candidates: Vec<GridOut<'g>>,
    options: &WriteOptions,
) -> Result<Vec<GridOut<'g>>> {
    if let Some(missing) = options
        .grids
        .iter()
        .find(|n| !candidates.iter().any(|g| g.name == n.as_str()))
    {
        let names: Vec<&str> = candidates.iter().map(|g| g.name.as_ref()).collect();
        return Err(vdb_error(
            path,
            format!(
                "no grid `{missing}` to write; this output has {}",
                names.join(", ")
            ),
        ));
    }
    candidates.retain(|g| options.wants(&g.name));
    Ok(candidates)
}

/// Whether `path` names a NanoVDB file (`.nvdb`): the same grids in NanoVDB's layout,
/// uncompressed, without the `.vdb` metadata (NanoVDB keeps names, transforms and classes).
pub fn is_nvdb(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nvdb"))
}

/// How a `.vdb` is written: which grids, compressed how, floats at what precision.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WriteOptions {
    /// The grids to write, by name (when empty: all but `voxels`, which repeats `density`'s
    /// voxels as booleans).
    pub grids: Vec<String>,
    pub compression: Compression,
    /// Float and vector grids as 16-bit halves (half the size, about 3 decimal digits).
    pub half: bool,
}

impl WriteOptions {
    /// Whether the grid `name` is to be written.
    pub fn wants(&self, name: &str) -> bool {
        if self.grids.is_empty() {
            name != VOXELS_GRID
        } else {
            self.grids.iter().any(|g| g == name)
        }
    }
}

/// The metadata entries of every grid: the caller's plus `voxelkit_version`.
pub fn meta_entries(metadata: &[(&str, MetaValue)]) -> Vec<(String, MetaValue)> {
    let mut meta: Vec<(String, MetaValue)> = metadata
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    meta.push(("voxelkit_version".into(), env!("CARGO_PKG_VERSION").into()));
    meta
}

/// Writes the value channel of `grid` (distances in world units on its active voxels) as a
/// narrow band with `background` outside it, atomically, with `metadata` (see
/// `Contents::Distances`).
pub fn write_distance_band(
    path: &Path,
    grid: &SparseGrid,
    background: f32,
    interior: Option<&SparseGrid>,
    metadata: &[(&str, MetaValue)],
    options: &WriteOptions,
) -> Result<()> {
    let contents = Contents::Distances {
        grid,
        background,
        interior,
        attributes: &[],
    };
    write_contents(path, &contents, metadata, options)
}

/// Refuses half precision for distances beyond its range (65504), which it would store as
/// infinities.
fn check_half_range(path: &Path, grid: &SparseGrid, background: f32) -> Result<()> {
    let largest = grid
        .leaves()
        .par_iter()
        .filter_map(|l| l.value.as_deref())
        .map(|values| values.iter().fold(0f32, |m, v| m.max(v.abs())))
        .reduce(|| background.abs(), f32::max);
    let most = half::f16::MAX.to_f32();
    if largest > most {
        return Err(Error::InvalidArgument(format!(
            "{}: distances up to {largest} exceed half precision's range ({most}) and would be \
             written as infinities; write at full precision (without option `half`)",
            path.display()
        )));
    }
    Ok(())
}

fn open(path: &Path) -> Result<VdbFile> {
    if !path.exists() {
        return Err(Error::io(
            path,
            std::io::Error::from(std::io::ErrorKind::NotFound),
        ));
    }
    // The whole file is held while its grids are read: plan that memory before any is taken.
    let tree_bytes = super::vdb_structure::check_structure(path)?;
    let file_bytes = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    crate::system::check_fits(
        tree_bytes.saturating_add(file_bytes),
        None,
        &format!("{}: reading its trees", path.display()),
    )?;
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    VdbFile::parse(data).map_err(|e| unreadable(path, e))
}

/// A file that cannot be read: say so plainly, with the reason cut short.
fn unreadable(path: &Path, e: impl std::fmt::Display) -> Error {
    let mut detail = e.to_string();
    if detail.len() > 300 {
        let cut = (0..=300)
            .rev()
            .find(|&i| detail.is_char_boundary(i))
            .unwrap_or(0);
        detail.truncate(cut);
        detail.push_str("...");
    }
    vdb_error(
        path,
        format!("cannot read it: not a .vdb file, or a damaged or truncated one ({detail})"),
    )
}

/// Describes every grid in the file.
pub fn read_vdb_info(path: &Path) -> Result<Vec<GridInfo>> {
    grid_infos(path, &open(path)?)
}

/// Reads the Bool, Mask, Float or Vec3S grid `name` into a grid, or without a name the voxel
/// set voxelkit writes (`voxels`, else `density`, else the first bool, mask or float grid).
/// Float values land in the value channel; vectors in the normal channel for a grid named
/// `normal` and in the colour channel otherwise (`Cd`); tiles stay tiles (their values are
/// not kept).
pub fn read_vdb_grid(path: &Path, name: Option<&str>) -> Result<SparseGrid> {
    read_grid(path, name, false)
}

/// The solid a grid of a `.vdb` file stands for, as an operand of a Boolean: a level set's
/// inside (the voxels of negative value, active or not, and its negative tiles: OpenVDB keeps
/// a level set's interior as inactive tiles at minus the background), any other grid's active
/// voxels. The grid is chosen as `read_vdb_grid` chooses it.
pub fn read_vdb_solid(path: &Path, name: Option<&str>) -> Result<SparseGrid> {
    read_grid(path, name, true)
}

fn read_grid(path: &Path, name: Option<&str>, solid: bool) -> Result<SparseGrid> {
    let file = open(path)?;
    let infos = grid_infos(path, &file)?;
    let index = choose_grid(path, &infos, name)?;
    read_chosen(path, &file, &infos[index], index, solid)
}

/// The field whose zero set `voxelkit to-mesh` draws, from grid `name`, or without a name the
/// level set (`surface`) when the file has one, else the grid `read_vdb_grid` chooses: a level
/// set's values (every leaf voxel's, inactive ones too) less `iso` (default 0), a fog volume's
/// `iso` (default 0.5) less its density, a voxel set's voxels.
pub fn read_vdb_field(
    path: &Path,
    name: Option<&str>,
    iso: Option<f64>,
) -> Result<ScalarField<'static>> {
    let file = open(path)?;
    let infos = grid_infos(path, &file)?;
    let level_set = infos
        .iter()
        .position(|i| i.name == LEVEL_SET_GRID && is_level_set(i));
    let chosen = match (name, level_set) {
        (None, Some(i)) => i,
        _ => choose_grid(path, &infos, name)?,
    };
    let info = &infos[chosen];
    if !matches!(info.value_type.as_str(), "bool" | "mask" | "float") {
        return Err(vdb_error(
            path,
            format!(
                "grid `{}` holds {} values: a mesh is drawn from a level set, a fog volume or a \
                 voxel set (float, bool or mask grids)",
                info.name, info.value_type
            ),
        ));
    }
    if is_level_set(info) {
        let iso = iso.unwrap_or(0.0) as f32;
        plan_read(path, info)?;
        let tree = file
            .read_negative(chosen)
            .map_err(|e| unreadable(path, e))?;
        let leaves = tree
            .leaves
            .into_par_iter()
            .map(|read| {
                let mut leaf = Leaf::new(read.origin.map(i64::from), Channels::VALUE);
                leaf.mask = read.mask;
                if let Some(v) = leaf.value.as_mut() {
                    v.copy_from_slice(&read.values);
                }
                leaf
            })
            .collect();
        let mut grid = SparseGrid::from_leaves(transform_of(info), Channels::VALUE, leaves);
        fill_tiles(&mut grid, tree.tiles);
        return ScalarField::level_set(grid, iso).ok_or_else(|| {
            vdb_error(
                path,
                format!(
                    "iso {iso} lies beyond the band of level set `{}`: its values are known \
                     only within the band",
                    info.name
                ),
            )
        });
    }
    let grid = read_chosen(path, &file, info, chosen, false)?;
    let fog = info.value_type == "float";
    if !fog && iso.is_some() {
        return Err(vdb_error(
            path,
            format!(
                "grid `{}` is a voxel set ({}): it has no values for an iso value to choose \
                 among",
                info.name, info.value_type
            ),
        ));
    }
    let iso = iso.unwrap_or(if fog { 0.5 } else { 0.0 });
    if fog && !(iso > 0.0 && iso.is_finite()) {
        return Err(vdb_error(
            path,
            format!(
                "grid `{}` is a fog volume (density 0 outside): its iso value must be above 0, \
                 not {iso}",
                info.name
            ),
        ));
    }
    Ok(ScalarField {
        grid: std::borrow::Cow::Owned(grid),
        meaning: if fog { Meaning::Fog } else { Meaning::Voxels },
        iso: iso as f32,
    })
}

fn is_level_set(info: &GridInfo) -> bool {
    info.grid_class == "level set" && info.value_type == "float"
}

fn grid_infos(path: &Path, file: &VdbFile) -> Result<Vec<GridInfo>> {
    (0..file.grid_count())
        .map(|i| file.grid_info(i).map_err(|e| unreadable(path, e)))
        .collect()
}

fn transform_of(info: &GridInfo) -> Transform {
    Transform::new(DVec3::from_array(info.origin), info.voxel_size[0])
}

/// Grid `name`, or the voxel set voxelkit writes (`voxels`, else `density`, else the first
/// bool, mask or float grid).
fn choose_grid(path: &Path, infos: &[GridInfo], name: Option<&str>) -> Result<usize> {
    let readable = |i: &GridInfo| matches!(i.value_type.as_str(), "bool" | "mask" | "float");
    let named = |n: &str| infos.iter().position(|i| i.name == n && readable(i));
    let index = match name {
        Some(n) => infos.iter().position(|i| i.name == n),
        None => named(VOXELS_GRID)
            .or_else(|| named(DENSITY_GRID))
            .or_else(|| infos.iter().position(readable)),
    }
    .ok_or_else(|| match name {
        Some(n) => vdb_error(path, format!("no grid named `{n}`")),
        None => vdb_error(path, "no bool, mask or float grid in the file"),
    })?;
    Ok(index)
}

/// Checks that `info`'s grid is placed as voxelkit places grids, and that its copy fits
/// before anything is allocated: leaves with their values, tiles as origins.
fn plan_read(path: &Path, info: &GridInfo) -> Result<()> {
    if !info.uniform_linear {
        return Err(vdb_error(
            path,
            format!(
                "grid `{}` has a transform voxelkit cannot use (voxel size {:?}): it reads grids \
                 placed by one uniform scale and a translation, without rotation, mirroring or \
                 a different scale per axis",
                info.name, info.voxel_size
            ),
        ));
    }
    let per_leaf = match info.value_type.as_str() {
        "float" => 3 * 4 * LEAF_VOXELS,
        "vec3s" => 3 * 3 * 4 * LEAF_VOXELS,
        _ => 400,
    } as u64;
    crate::system::check_fits(
        info.leaf_count
            .saturating_mul(per_leaf)
            .saturating_add(info.tile_count.saturating_mul(64)),
        None,
        &format!(
            "{}: grid `{}` holds {} active voxels",
            path.display(),
            info.name,
            info.active_voxels
        ),
    )
}

fn read_chosen(
    path: &Path,
    file: &VdbFile,
    info: &GridInfo,
    index: usize,
    solid: bool,
) -> Result<SparseGrid> {
    plan_read(path, info)?;
    let transform = transform_of(info);
    if solid && is_level_set(info) {
        let tree = file.read_negative(index).map_err(|e| unreadable(path, e))?;
        let leaves = tree
            .leaves
            .into_par_iter()
            .filter_map(|read| {
                let mut leaf = Leaf::new(read.origin.map(i64::from), Channels::NONE);
                for (n, v) in read.values.iter().enumerate() {
                    if *v < 0.0 {
                        leaf.mask[n / 64] |= 1 << (n % 64);
                    }
                }
                (!leaf.is_empty()).then_some(leaf)
            })
            .collect();
        let mut grid = SparseGrid::from_leaves(transform, Channels::NONE, leaves);
        fill_tiles(&mut grid, tree.tiles);
        return Ok(grid);
    }
    let tree = file.read_tree(index).map_err(|e| unreadable(path, e))?;
    let vectors = info.value_type == "vec3s";
    let channels = Channels {
        value: info.value_type == "float",
        normal: vectors && info.name == NORMAL_GRID,
        color: vectors && info.name != NORMAL_GRID,
    };
    let leaves = tree
        .leaves
        .into_par_iter()
        .map(|read| {
            let mut leaf = Leaf::new(read.origin.map(i64::from), channels);
            leaf.mask = read.mask;
            if let Some(v) = leaf.value.as_mut() {
                v.copy_from_slice(&read.values);
            }
            if let Some(v) = leaf.normal.as_mut().or(leaf.color.as_mut()) {
                for (n, xyz) in read.values.chunks_exact(3).enumerate() {
                    v[n] = [xyz[0], xyz[1], xyz[2]];
                }
            }
            leaf
        })
        .collect();
    let mut grid = SparseGrid::from_leaves(transform, channels, leaves);
    fill_tiles(&mut grid, tree.tiles);
    Ok(grid)
}

/// Fills the tiles read (origin, edge 8 or 128) into `grid`.
fn fill_tiles(grid: &mut SparseGrid, tiles: Vec<([i32; 3], i32)>) {
    for (origin, edge) in tiles {
        let origin = origin.map(i64::from);
        match edge {
            8 => grid.fill_leaf_block(origin),
            _ => grid.fill_node_block(origin),
        }
    }
}
