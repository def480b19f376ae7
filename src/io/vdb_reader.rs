//! Reads `.vdb` files without OpenVDB, after `vdb_structure` has checked every length and
//! offset: the grid descriptors, each grid's metadata and transform, its tree's topology
//! (root tiles and children, internal-node tiles, leaf masks) and, for the grids whose voxels
//! are read, the leaf buffers (blosc, zip or raw; full or half precision; OpenVDB's inactive
//! value flags). The layout is OpenVDB's file format 222 and later (`io/Compression.h`,
//! `tree/RootNode.h`, `InternalNode.h`, `LeafNode.h`), the one `vdb_writer` writes.

use super::vdb_chunks::read_chunk;
use super::vdb_format::{
    CHILD_LOG2, COMPRESS_ACTIVE_MASK, NAME_SUFFIX_MARK, NODE_LOG2, ROOT_TILE, VdbFault, value_type,
};
use super::vdb_tree_structure::{LeafKind, TreeFormat};
use rayon::prelude::*;

type Parsed<T> = std::result::Result<T, VdbFault>;

/// One metadata item of a grid, its value as text, with OpenVDB's name of its type
/// (`string`, `int64`, `double`, ...).
#[derive(Clone, Debug, PartialEq)]
pub struct MetaEntry {
    pub key: String,
    pub type_name: String,
    pub value: String,
}

/// What a grid in a `.vdb` file is.
#[derive(Clone, Debug)]
pub struct GridInfo {
    pub name: String,
    /// OpenVDB's value type name: bool, mask, float, double, int32, int64, vec3i, vec3s, vec3d.
    pub value_type: String,
    /// OpenVDB's class name: level set, fog volume, staggered or unknown.
    pub grid_class: String,
    pub voxel_size: [f64; 3],
    /// World position of the centre of voxel (0,0,0).
    pub origin: [f64; 3],
    /// Whether the transform is a uniform scale plus translation (voxelkit's `Transform`).
    pub uniform_linear: bool,
    pub active_voxels: u64,
    pub leaf_count: u64,
    /// Active tiles, counted as 128^3 ones where larger.
    pub tile_count: u64,
    pub bbox_min: [i32; 3],
    pub bbox_max: [i32; 3],
    /// Every metadata item but OpenVDB's `file_` bookkeeping, in the file's (sorted) order.
    pub metadata: Vec<MetaEntry>,
}

/// A leaf read from a file: its origin, mask (OpenVDB's word order) and, for float grids,
/// its 512 values, 3 x 512 for vectors.
pub struct LeafRead {
    pub origin: [i32; 3],
    pub mask: [u64; 8],
    pub values: Vec<f32>,
}

/// A grid's tree as read: leaves with active voxels, and active tiles as (origin, edge 8 or
/// 128; root tiles split into 128^3 ones).
pub struct TreeRead {
    pub leaves: Vec<LeafRead>,
    pub tiles: Vec<([i32; 3], i32)>,
}

/// A little-endian cursor over the file's bytes.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn at(data: &'a [u8], pos: usize) -> Self {
        Cursor { data, pos }
    }

    fn take(&mut self, n: usize) -> Parsed<&'a [u8]> {
        let bytes = self
            .data
            .get(self.pos..self.pos.saturating_add(n))
            .ok_or(VdbFault::Truncated { at: self.pos })?;
        self.pos += n;
        Ok(bytes)
    }

    fn array<const N: usize>(&mut self) -> Parsed<[u8; N]> {
        Ok(self.take(N)?.try_into().expect("N bytes"))
    }

    fn u32(&mut self) -> Parsed<u32> {
        self.array().map(u32::from_le_bytes)
    }

    fn i32(&mut self) -> Parsed<i32> {
        self.array().map(i32::from_le_bytes)
    }

    fn i64(&mut self) -> Parsed<i64> {
        self.array().map(i64::from_le_bytes)
    }

    fn f64(&mut self) -> Parsed<f64> {
        self.array().map(f64::from_le_bytes)
    }

    fn vec3d(&mut self) -> Parsed<[f64; 3]> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }

    fn string(&mut self) -> Parsed<String> {
        let n = self.u32()? as usize;
        Ok(String::from_utf8_lossy(self.take(n)?).into_owned())
    }

    fn mask(&mut self, words: usize) -> Parsed<Vec<u64>> {
        let bytes = self.take(8 * words)?;
        Ok(bytes
            .chunks_exact(8)
            .map(|w| u64::from_le_bytes(w.try_into().expect("8 bytes")))
            .collect())
    }
}

/// Where a grid lies in the file, from its descriptor.
struct Descriptor {
    name: String,
    type_name: String,
    /// The grid whose tree this one shares (OpenVDB's instancing), if any.
    instance_of: Option<String>,
    /// The grid's compression flags, metadata and transform start here; its tree follows.
    start: usize,
    /// The leaf buffers start here.
    buffers: usize,
}

/// A `.vdb` file in memory with its grid descriptors.
pub struct VdbFile {
    data: Vec<u8>,
    descriptors: Vec<Descriptor>,
}

/// A grid's header: compression flags, metadata, transform; where its tree starts.
struct Header {
    compression: u32,
    metadata: Vec<MetaEntry>,
    voxel_size: [f64; 3],
    origin: [f64; 3],
    uniform_linear: bool,
    tree: usize,
}

impl VdbFile {
    /// Parses the header and descriptors of `data`, a whole `.vdb` file whose structure
    /// `vdb_structure::check_structure` accepted.
    pub fn parse(data: Vec<u8>) -> Parsed<VdbFile> {
        // After the magic number: the file version (222 or later, checked), the library
        // version, the offsets flag and the UUID.
        let mut c = Cursor::at(&data, 8);
        c.take(4 + 8 + 1 + 36)?;
        read_metadata(&mut c)?; // the file's own, unused
        let count = c.u32()?;
        let mut descriptors = Vec::new();
        for _ in 0..count {
            let name = c.string()?;
            let name = match name.split_once(NAME_SUFFIX_MARK) {
                Some((base, _)) => base.to_string(),
                None => name,
            };
            let type_name = c.string()?;
            let parent = c.string()?;
            let start =
                usize::try_from(c.i64()?).map_err(|e| VdbFault::BadOffset(e.to_string()))?;
            let buffers =
                usize::try_from(c.i64()?).map_err(|e| VdbFault::BadOffset(e.to_string()))?;
            let end = usize::try_from(c.i64()?).map_err(|e| VdbFault::BadOffset(e.to_string()))?;
            descriptors.push(Descriptor {
                name,
                type_name,
                instance_of: (!parent.is_empty()).then_some(parent),
                start,
                buffers,
            });
            c.pos = end;
        }
        Ok(VdbFile { data, descriptors })
    }

    pub fn grid_count(&self) -> usize {
        self.descriptors.len()
    }

    /// The descriptor whose tree grid `index` reads (its own, or its instance parent's).
    fn tree_owner(&self, index: usize) -> Parsed<&Descriptor> {
        let d = &self.descriptors[index];
        match &d.instance_of {
            None => Ok(d),
            Some(parent) => self
                .descriptors
                .iter()
                .find(|p| p.instance_of.is_none() && &p.name == parent)
                .ok_or_else(|| VdbFault::MissingInstance {
                    grid: d.name.clone(),
                    parent: parent.clone(),
                }),
        }
    }

    fn header(&self, d: &Descriptor) -> Parsed<Header> {
        let mut c = Cursor::at(&self.data, d.start);
        let compression = c.u32()?;
        let metadata = read_metadata(&mut c)?;
        let (voxel_size, origin, uniform_linear) = read_transform(&mut c)?;
        Ok(Header {
            compression,
            metadata,
            voxel_size,
            origin,
            uniform_linear,
            tree: c.pos,
        })
    }

    /// Describes grid `index`.
    pub fn grid_info(&self, index: usize) -> Parsed<GridInfo> {
        let d = &self.descriptors[index];
        let header = self.header(d)?;
        let owner = self.tree_owner(index)?;
        let owner_header = self.header(owner)?;
        let format = TreeFormat::of(&owner.type_name).map_err(VdbFault::TreeType)?;
        let topology = read_topology(
            &self.data,
            owner_header.tree,
            format,
            owner_header.compression,
            false,
        )?;
        let mut active = 0u64;
        let mut tile_count = 0u64;
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        let mut extend = |min: [i32; 3], max: [i32; 3]| {
            for a in 0..3 {
                lo[a] = lo[a].min(min[a]);
                hi[a] = hi[a].max(max[a]);
            }
        };
        for leaf in &topology.leaves {
            let ones: u32 = leaf.mask.iter().map(|w| w.count_ones()).sum();
            if ones == 0 {
                continue;
            }
            active += ones as u64;
            let (min, max) = leaf_bounds(&leaf.mask);
            extend(
                std::array::from_fn(|a| leaf.origin[a] + min[a]),
                std::array::from_fn(|a| leaf.origin[a] + max[a]),
            );
        }
        for &(origin, edge) in &topology.tiles {
            active += (edge as u64).pow(3);
            tile_count += 1;
            extend(origin, origin.map(|v| v + edge - 1));
        }
        if active == 0 {
            (lo, hi) = ([0; 3], [-1; 3]);
        }
        let grid_class = header
            .metadata
            .iter()
            .find(|m| m.key == "class")
            .map_or("unknown", |m| m.value.as_str())
            .to_string();
        let metadata = header
            .metadata
            .into_iter()
            .filter(|m| !m.key.starts_with("file_"))
            .collect();
        Ok(GridInfo {
            name: d.name.clone(),
            value_type: value_type(&d.type_name).to_string(),
            grid_class,
            voxel_size: header.voxel_size,
            origin: header.origin,
            uniform_linear: header.uniform_linear,
            active_voxels: active,
            leaf_count: topology.leaves.len() as u64,
            tile_count,
            bbox_min: lo,
            bbox_max: hi,
            metadata,
        })
    }

    /// The active voxels of grid `index` (bool, mask, float or vec3s): its leaves with
    /// active voxels, with their values for float and vector grids, and its active tiles.
    pub fn read_tree(&self, index: usize) -> Parsed<TreeRead> {
        self.read_tree_of(index, false)
    }

    /// A float grid's negative voxels, as a level set's inside: every leaf with its values
    /// (inactive voxels included), and as tiles the tiles of negative value, active or not.
    pub fn read_negative(&self, index: usize) -> Parsed<TreeRead> {
        self.read_tree_of(index, true)
    }

    fn read_tree_of(&self, index: usize, negative: bool) -> Parsed<TreeRead> {
        let owner = self.tree_owner(index)?;
        let header = self.header(owner)?;
        let format = TreeFormat::of(&owner.type_name).map_err(VdbFault::TreeType)?;
        let value_type = value_type(&owner.type_name).to_string();
        let components = match value_type.as_str() {
            "bool" | "mask" => 0,
            "float" => 1,
            "vec3s" => 3,
            other => {
                return Err(VdbFault::ValueType {
                    grid: self.descriptors[index].name.clone(),
                    value_type: other.to_string(),
                });
            }
        };
        let negative = negative && components == 1;
        let topology = read_topology(
            &self.data,
            header.tree,
            format,
            header.compression,
            negative,
        )?;
        if components == 0 {
            let leaves = topology
                .leaves
                .into_iter()
                .filter(|l| l.mask != [0; 8])
                .map(|l| LeafRead {
                    origin: l.origin,
                    mask: l.mask,
                    values: Vec::new(),
                })
                .collect();
            return Ok(TreeRead {
                leaves,
                tiles: topology.tiles,
            });
        }
        // Find every leaf's buffer in order, then decode them on all threads.
        let mut c = Cursor::at(&self.data, owner.buffers);
        let mut starts = Vec::with_capacity(topology.leaves.len());
        for _ in &topology.leaves {
            starts.push(c.pos);
            skip_leaf_buffer(&mut c, format, header.compression)?;
        }
        let background = topology.background;
        let leaves = topology
            .leaves
            .into_par_iter()
            .zip(starts)
            .filter(|(l, _)| negative || l.mask != [0; 8])
            .map(|(l, start)| {
                let mut c = Cursor::at(&self.data, start);
                let values =
                    leaf_values(&mut c, format, header.compression, components, &background)?;
                Ok(LeafRead {
                    origin: l.origin,
                    mask: l.mask,
                    values,
                })
            })
            .collect::<Parsed<Vec<_>>>()?;
        Ok(TreeRead {
            leaves,
            tiles: if negative {
                topology.negative_tiles
            } else {
                topology.tiles
            },
        })
    }
}

/// The lowest and highest voxel offsets, per axis, of a non-empty leaf mask (bit
/// `x << 6 | y << 3 | z`: word x, byte y, bit z).
fn leaf_bounds(mask: &[u64; 8]) -> ([i32; 3], [i32; 3]) {
    let xs: Vec<i32> = (0..8).filter(|&x| mask[x] != 0).map(|x| x as i32).collect();
    let all = mask.iter().fold(0u64, |a, &w| a | w);
    let ys: Vec<i32> = (0..8).filter(|y| all >> (8 * y) & 0xff != 0).collect();
    let zbits = (0..8).fold(0u64, |a, y| a | (all >> (8 * y) & 0xff)) as u8;
    (
        [xs[0], ys[0], zbits.trailing_zeros() as i32],
        [
            xs[xs.len() - 1],
            ys[ys.len() - 1],
            7 - zbits.leading_zeros() as i32,
        ],
    )
}

/// A metadata map, each value as text (OpenVDB's `str()`: numbers, `true`/`false`,
/// vectors as `[x, y, z]`); values of other types are skipped.
fn read_metadata(c: &mut Cursor) -> Parsed<Vec<MetaEntry>> {
    let count = c.u32()?;
    let mut entries = Vec::new();
    for _ in 0..count {
        let key = c.string()?;
        let type_name = c.string()?;
        let len = c.u32()? as usize;
        let bytes = c.take(len)?;
        let value = match type_name.as_str() {
            "string" => Some(String::from_utf8_lossy(bytes).into_owned()),
            _ => metadata_text(&type_name, bytes),
        };
        if let Some(value) = value {
            entries.push(MetaEntry {
                key,
                type_name,
                value,
            });
        }
    }
    Ok(entries)
}

/// The text of a fixed-size metadata value of `type_name`.
fn metadata_text(type_name: &str, bytes: &[u8]) -> Option<String> {
    let words = |size: usize| bytes.chunks_exact(size).map(|w| w.to_vec());
    let int = |w: Vec<u8>| match w.len() {
        4 => i32::from_le_bytes(w.try_into().expect("4")).to_string(),
        _ => i64::from_le_bytes(w.try_into().expect("8")).to_string(),
    };
    let real = |w: Vec<u8>| match w.len() {
        4 => f32::from_le_bytes(w.try_into().expect("4")).to_string(),
        _ => f64::from_le_bytes(w.try_into().expect("8")).to_string(),
    };
    let vector = |parts: Vec<String>| format!("[{}]", parts.join(", "));
    Some(match type_name {
        "bool" => (bytes.first()? != &0).to_string(),
        "int32" => int(bytes.to_vec()),
        "int64" => int(bytes.to_vec()),
        "float" | "double" => real(bytes.to_vec()),
        "vec3i" | "vec2i" => vector(words(4).map(int).collect()),
        "vec3s" | "vec2s" => vector(words(4).map(real).collect()),
        "vec3d" | "vec2d" => vector(words(8).map(real).collect()),
        _ => return None,
    })
}

/// A grid's transform: voxel size per axis, the world position of voxel (0,0,0), and whether
/// it is a uniform scale plus translation.
fn read_transform(c: &mut Cursor) -> Parsed<([f64; 3], [f64; 3], bool)> {
    let name = c.string()?;
    if name == "NonlinearFrustumMap" {
        c.take(64)?; // bounding box, taper, depth
        let inner = c.string()?;
        let (size, origin, _) = linear_map(c, &inner)?;
        return Ok((size, origin, false));
    }
    linear_map(c, &name)
}

/// How far, relative to the voxel size, a matrix entry may stray from a uniform scale: a
/// transform composed in single precision, or beside a large translation, rounds its
/// diagonal apart by some 1e-8 (0.01 and 0.0099999998); a millionth keeps every voxel of a
/// grid a million voxels wide within one voxel of where the uniform scale puts it.
const UNIFORM_SCALE_TOLERANCE: f64 = 1e-6;

fn linear_map(c: &mut Cursor, name: &str) -> Parsed<([f64; 3], [f64; 3], bool)> {
    // Rows of the 4x4 matrix that maps (i, j, k, 1) to world coordinates.
    let rows: [[f64; 3]; 4] = match name {
        "TranslationMap" => {
            let t = c.vec3d()?;
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], t]
        }
        "ScaleMap" | "UniformScaleMap" | "ScaleTranslateMap" | "UniformScaleTranslateMap" => {
            let t = if name.ends_with("TranslateMap") {
                c.vec3d()?
            } else {
                [0.0; 3]
            };
            let s = c.vec3d()?;
            for _ in 0..4 {
                c.vec3d()?; // voxel size and inverses, derived from the scale
            }
            [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]], t]
        }
        "AffineMap" | "UnitaryMap" => {
            let mut m = [[0.0; 4]; 4];
            for row in &mut m {
                for v in row.iter_mut() {
                    *v = c.f64()?;
                }
            }
            m.map(|r| [r[0], r[1], r[2]])
        }
        _ => return Err(VdbFault::Transform(name.to_string())),
    };
    let size = std::array::from_fn(|a| rows[a].iter().map(|v| v * v).sum::<f64>().sqrt());
    let h = rows[0][0];
    let close = |v: f64, want: f64| (v - want).abs() <= UNIFORM_SCALE_TOLERANCE * h.abs();
    let uniform =
        h > 0.0 && (0..3).all(|a| (0..3).all(|b| close(rows[a][b], if a == b { h } else { 0.0 })));
    Ok((size, rows[3], uniform))
}

/// A leaf of the topology: origin and mask.
struct LeafTopology {
    origin: [i32; 3],
    mask: [u64; 8],
}

struct Topology {
    /// The background value's bytes (full precision).
    background: Vec<u8>,
    /// Leaves in the order of their buffers: root children by origin, below them by position.
    leaves: Vec<LeafTopology>,
    tiles: Vec<([i32; 3], i32)>,
    /// Tiles, active or not, whose value is negative (float trees read with `tile_values`).
    negative_tiles: Vec<([i32; 3], i32)>,
}

/// The root's tiles and children, down to the leaves' masks; with `tile_values` (float trees)
/// the tiles' values are decoded too, for the negative ones.
fn read_topology(
    data: &[u8],
    at: usize,
    format: TreeFormat,
    compression: u32,
    tile_values: bool,
) -> Parsed<Topology> {
    let mut c = Cursor::at(data, at);
    if c.u32()? != 1 {
        return Err(VdbFault::Buffers);
    }
    let background = c.take(format.value as usize)?.to_vec();
    let (tile_count, child_count) = (c.u32()?, c.u32()?);
    let mut tiles = Vec::new();
    let mut negative_tiles = Vec::new();
    for _ in 0..tile_count {
        let origin = [c.i32()?, c.i32()?, c.i32()?];
        let value = c.take(format.value as usize)?;
        let negative = tile_values
            && value.len() == 4
            && f32::from_le_bytes(value.try_into().expect("4 bytes")) < 0.0;
        let active = c.array::<1>()?[0] != 0;
        for x in (0..ROOT_TILE).step_by(128) {
            for y in (0..ROOT_TILE).step_by(128) {
                for z in (0..ROOT_TILE).step_by(128) {
                    let node = ([origin[0] + x, origin[1] + y, origin[2] + z], 128);
                    if active {
                        tiles.push(node);
                    }
                    if negative {
                        negative_tiles.push(node);
                    }
                }
            }
        }
    }
    let mut children = Vec::new();
    for _ in 0..child_count {
        let origin = [c.i32()?, c.i32()?, c.i32()?];
        let mut leaves = Vec::new();
        let mut node = Node {
            format,
            compression,
            background: tile_values.then_some(&background[..]),
            leaves: &mut leaves,
            tiles: &mut tiles,
            negative_tiles: &mut negative_tiles,
        };
        node.read(&mut c, 0, origin)?;
        children.push((origin, leaves));
    }
    children.sort_by_key(|(origin, _)| *origin);
    Ok(Topology {
        background,
        leaves: children.into_iter().flat_map(|(_, l)| l).collect(),
        tiles,
        negative_tiles,
    })
}

/// The origin of slot `n` of a node at `depth` whose origin is `origin`.
fn slot_origin(origin: [i32; 3], depth: usize, n: usize) -> [i32; 3] {
    let log2 = NODE_LOG2[depth];
    let per_axis = (1usize << log2) - 1;
    let offsets = [n >> (2 * log2), n >> log2 & per_axis, n & per_axis];
    std::array::from_fn(|a| origin[a] + ((offsets[a] as i32) << CHILD_LOG2[depth]))
}

/// What reading the internal nodes collects.
struct Node<'a> {
    format: TreeFormat,
    compression: u32,
    /// The background, where the tiles' values are decoded.
    background: Option<&'a [u8]>,
    leaves: &'a mut Vec<LeafTopology>,
    tiles: &'a mut Vec<([i32; 3], i32)>,
    negative_tiles: &'a mut Vec<([i32; 3], i32)>,
}

impl Node<'_> {
    fn read(&mut self, c: &mut Cursor, depth: usize, origin: [i32; 3]) -> Parsed<()> {
        let words = (1usize << (3 * NODE_LOG2[depth])) / 64;
        let child_mask = c.mask(words)?;
        let value_mask = c.mask(words)?;
        let tile_edge = 1 << CHILD_LOG2[depth];
        match self.background {
            Some(background) => {
                let values =
                    node_values(c, self.format, self.compression, 1, background, &value_mask)?;
                for (n, v) in values.iter().enumerate() {
                    if *v < 0.0 && child_mask[n / 64] >> (n % 64) & 1 == 0 {
                        self.negative_tiles
                            .push((slot_origin(origin, depth, n), tile_edge));
                    }
                }
            }
            None => skip_compressed_values(c, self.format, self.compression, &value_mask)?,
        }
        let tile_slots: Vec<u64> = value_mask
            .iter()
            .zip(&child_mask)
            .map(|(v, ch)| v & !ch)
            .collect();
        for n in set_bits(&tile_slots) {
            self.tiles.push((slot_origin(origin, depth, n), tile_edge));
        }
        for n in set_bits(&child_mask) {
            let child = slot_origin(origin, depth, n);
            if depth + 1 == NODE_LOG2.len() {
                let mask: [u64; 8] = c.mask(8)?.try_into().expect("8 words");
                self.leaves.push(LeafTopology {
                    origin: child,
                    mask,
                });
            } else {
                self.read(c, depth + 1, child)?;
            }
        }
        Ok(())
    }
}

/// The numbers of the set bits of `mask`, ascending.
fn set_bits(mask: &[u64]) -> Vec<usize> {
    let mut out = Vec::new();
    for (w, &word) in mask.iter().enumerate() {
        let mut bits = word;
        while bits != 0 {
            out.push(64 * w + bits.trailing_zeros() as usize);
            bits &= bits - 1;
        }
    }
    out
}

/// The flag before a node's values, and what it implies: how many inactive values follow
/// (at full precision) and whether a selection mask does.
fn value_flag(c: &mut Cursor) -> Parsed<(u8, usize, bool)> {
    let flag = c.array::<1>()?[0];
    let (inactive, selection) = match flag {
        0 | 1 | 6 => (0, false),
        2 => (1, false),
        3 => (0, true),
        4 => (1, true),
        5 => (2, true),
        _ => return Err(VdbFault::NodeFlag(flag)),
    };
    Ok((flag, inactive, selection))
}

/// How many values a node of `mask` stores after its flag.
fn stored_count(compression: u32, flag: u8, mask: &[u64]) -> usize {
    if compression & COMPRESS_ACTIVE_MASK != 0 && flag != 6 {
        mask.iter().map(|w| w.count_ones() as usize).sum()
    } else {
        64 * mask.len()
    }
}

/// Skips a node's values: flag, inactive values, selection mask, the chunk.
fn skip_compressed_values(
    c: &mut Cursor,
    format: TreeFormat,
    compression: u32,
    mask: &[u64],
) -> Parsed<()> {
    let (flag, inactive, selection) = value_flag(c)?;
    c.take(inactive * format.value as usize)?;
    if selection {
        c.take(8 * mask.len())?;
    }
    let count = stored_count(compression, flag, mask);
    if format.half && count == 0 {
        return Ok(());
    }
    let (_, used) = read_chunk(
        &c.data[c.pos..],
        count * format.stored as usize,
        compression,
    )
    .map_err(VdbFault::Chunk)?;
    c.pos += used;
    Ok(())
}

/// Skips one leaf's buffer.
fn skip_leaf_buffer(c: &mut Cursor, format: TreeFormat, compression: u32) -> Parsed<()> {
    match format.leaf {
        LeafKind::Bool => c.take(64 + 12 + 64).map(|_| ()),
        LeafKind::Mask => c.take(64 + 12).map(|_| ()),
        LeafKind::Values => {
            let mask = c.mask(8)?;
            skip_compressed_values(c, format, compression, &mask)
        }
    }
}

/// A value leaf's 512 values (`components` floats each), inactive ones included.
fn leaf_values(
    c: &mut Cursor,
    format: TreeFormat,
    compression: u32,
    components: usize,
    background: &[u8],
) -> Parsed<Vec<f32>> {
    let mask = c.mask(8)?;
    node_values(c, format, compression, components, background, &mask)
}

/// A node's values, one per bit of its value mask `mask` (`components` floats each), inactive
/// ones included: OpenVDB writes a leaf's and an internal node's alike.
fn node_values(
    c: &mut Cursor,
    format: TreeFormat,
    compression: u32,
    components: usize,
    background: &[u8],
    mask: &[u64],
) -> Parsed<Vec<f32>> {
    let slots = 64 * mask.len();
    let (flag, inactive, selection) = value_flag(c)?;
    let full = |bytes: &[u8]| -> Vec<f32> {
        bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
            .collect()
    };
    let negated = |v: &[f32]| v.iter().map(|x| -x).collect::<Vec<f32>>();
    let bg = full(background);
    // OpenVDB's inactive values: the first for unselected voxels, the second for selected.
    let mut first = if flag == 0 { bg.clone() } else { negated(&bg) };
    let mut second = bg;
    if inactive >= 1 {
        first = full(c.take(4 * components)?);
    }
    if inactive == 2 {
        second = full(c.take(4 * components)?);
    }
    let selected = if selection {
        c.mask(mask.len())?
    } else {
        vec![0; mask.len()]
    };
    let count = stored_count(compression, flag, mask);
    let stored = if format.half && count == 0 {
        Vec::new()
    } else {
        let (bytes, used) = read_chunk(
            &c.data[c.pos..],
            count * format.stored as usize,
            compression,
        )
        .map_err(VdbFault::Chunk)?;
        c.pos += used;
        if format.half {
            bytes
                .chunks_exact(2)
                .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
                .collect()
        } else {
            full(&bytes)
        }
    };
    if count == slots {
        return Ok(stored);
    }
    let bit = |m: &[u64], n: usize| m[n >> 6] >> (n & 63) & 1 != 0;
    let mut values = Vec::with_capacity(slots * components);
    let mut next = stored.chunks_exact(components);
    for n in 0..slots {
        let value = if bit(mask, n) {
            next.next().ok_or(VdbFault::ShortLeaf)?
        } else if bit(&selected, n) {
            &second[..]
        } else {
            &first[..]
        };
        values.extend_from_slice(value);
    }
    Ok(values)
}
