//! The `.vdb` format's vocabulary, declared once for the writer, the structure check and the
//! reader: the header, OpenVDB's standard 5-4-3 tree, compression (flags and the user's
//! choice), grid classes, tree type names, typed metadata values (OpenVDB 10's `io/`,
//! `tree/` and `Metadata.h` headers), and what the reader can find wrong.

/// OpenVDB's magic number, the file's first eight bytes.
pub(super) const MAGIC: i64 = 0x5644_4220;
/// The file format version written (OpenVDB 10's), and the library version beside it.
pub(super) const FILE_VERSION: u32 = 224;
pub(super) const LIBRARY_VERSION: [u32; 2] = [10, 0];
/// The first file version with compression flags at the start of each grid and a flag before
/// each node's values (OpenVDB 2.0, 2013), the oldest read: older layouts are refused rather
/// than read on trust.
pub(super) const NODE_MASK_VERSION: u32 = 222;
/// The type name of OpenVDB's per-leaf delayed-load table.
pub(super) const DELAYED_LOAD: &[u8] = b"__delayedload";
/// OpenVDB appends this and a number to repeated grid names in a file.
pub(super) const NAME_SUFFIX_MARK: char = '\u{1e}';

/// Log2 of the internal node edges of the standard tree, from the root's children down (the
/// 4096^3 and 128^3 nodes), and of their children's edges (128^3 nodes, 8^3 leaves).
pub(super) const NODE_LOG2: [u32; 2] = [5, 4];
pub(super) const CHILD_LOG2: [u32; 2] = [7, 3];
/// The edge of a root child, in voxels.
pub(super) const ROOT_TILE: i32 = 1 << (NODE_LOG2[0] + CHILD_LOG2[0]);
/// A leaf's 8^3 voxel mask, in bytes.
pub(super) const LEAF_MASK_BYTES: u64 = 64;

/// Per-grid compression flags (OpenVDB's `COMPRESS_*`).
pub(super) const COMPRESS_ZIP: u32 = 0x1;
pub(super) const COMPRESS_ACTIVE_MASK: u32 = 0x2;
pub(super) const COMPRESS_BLOSC: u32 = 0x4;
/// OpenVDB pads buffers shorter than this before blosc compresses them.
pub(super) const BLOSC_PAD_BYTES: usize = 128;

/// Grid classes (the `class` metadata) and the vector type of normals.
pub(super) const FOG_VOLUME: &str = "fog volume";
pub(super) const LEVEL_SET: &str = "level set";
pub(super) const COVARIANT_NORMALIZE: &str = "covariant normalize";

/// The suffix OpenVDB adds to a grid type saved at half precision.
pub(super) const HALF_SUFFIX: &str = "_HalfFloat";
const TREE_PREFIX: &str = "Tree_";
const TREE_SUFFIX: &str = "_5_4_3";

/// The standard tree's type name for values of `value_type` (`float` -> `Tree_float_5_4_3`).
pub(super) fn tree_type(value_type: &str) -> String {
    format!("{TREE_PREFIX}{value_type}{TREE_SUFFIX}")
}

/// The value type of a standard tree's type name (`Tree_float_5_4_3_HalfFloat` -> `float`),
/// empty for any other tree.
pub(super) fn value_type(type_name: &str) -> &str {
    type_name
        .strip_suffix(HALF_SUFFIX)
        .unwrap_or(type_name)
        .strip_prefix(TREE_PREFIX)
        .and_then(|t| t.strip_suffix(TREE_SUFFIX))
        .unwrap_or("")
}

/// `.vdb` compression.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compression {
    /// OpenVDB's default: fast, good ratios.
    #[default]
    Blosc,
    Zip,
    None,
}

impl Compression {
    /// OpenVDB's `COMPRESS_*` flags for it (the active-value masks, always on, aside).
    pub fn flags(self) -> u32 {
        match self {
            Compression::Blosc => COMPRESS_BLOSC,
            Compression::Zip => COMPRESS_ZIP,
            Compression::None => 0,
        }
    }
}

crate::named_choices! {
    Compression, "the compression":
    "blosc" => Blosc,
    "zip" => Zip,
    "none" => None,
}

/// A grid's metadata value, written with OpenVDB's type for it (so Houdini and pyopenvdb
/// read numbers as numbers).
#[derive(Clone, Debug, PartialEq)]
pub enum MetaValue {
    Text(String),
    Int(i64),
    Real(f64),
}

impl std::fmt::Display for MetaValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MetaValue::Text(s) => f.write_str(s),
            MetaValue::Int(n) => write!(f, "{n}"),
            MetaValue::Real(x) => write!(f, "{x}"),
        }
    }
}

impl From<String> for MetaValue {
    fn from(s: String) -> Self {
        MetaValue::Text(s)
    }
}

impl From<&str> for MetaValue {
    fn from(s: &str) -> Self {
        MetaValue::Text(s.to_string())
    }
}

impl From<f64> for MetaValue {
    fn from(x: f64) -> Self {
        MetaValue::Real(x)
    }
}

macro_rules! int_meta {
    ($($t:ty),*) => {$(impl From<$t> for MetaValue {
        fn from(n: $t) -> Self {
            MetaValue::Int(i64::try_from(n).unwrap_or(i64::MAX))
        }
    })*};
}
int_meta!(u32, u64, usize, i64);

/// Why the reader cannot read a file whose structure was checked: what it found, typed.
#[derive(Clone, Debug, PartialEq)]
pub enum VdbFault {
    /// The data ends inside a record.
    Truncated { at: usize },
    /// A grid offset that is negative or beyond memory.
    BadOffset(String),
    /// A grid that shares the tree of a grid the file lacks.
    MissingInstance { grid: String, parent: String },
    /// A grid of a value type voxelkit does not read.
    ValueType { grid: String, value_type: String },
    /// A transform of a kind voxelkit does not know.
    Transform(String),
    /// A tree stored in more than one buffer.
    Buffers,
    /// A node whose values carry an unknown compression flag.
    NodeFlag(u8),
    /// A leaf holding fewer values than it has active voxels.
    ShortLeaf,
    /// A compressed chunk that does not decode to what the node holds.
    Chunk(String),
    /// A grid whose tree is not one of OpenVDB's standard trees.
    TreeType(String),
}

impl std::fmt::Display for VdbFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VdbFault::Truncated { at } => write!(f, "it ends inside a record at byte {at}"),
            VdbFault::BadOffset(e) => write!(f, "a grid offset that cannot be: {e}"),
            VdbFault::MissingInstance { grid, parent } => {
                write!(
                    f,
                    "grid `{grid}` shares the tree of a missing grid `{parent}`"
                )
            }
            VdbFault::ValueType { grid, value_type } => write!(
                f,
                "grid `{grid}` has value type {value_type}; only bool, mask, float and vec3s grids can be read"
            ),
            VdbFault::Transform(name) => write!(f, "a transform of unknown kind `{name}`"),
            VdbFault::Buffers => f.write_str("a tree of more than one buffer"),
            VdbFault::NodeFlag(flag) => write!(f, "a node with compression flag {flag}"),
            VdbFault::ShortLeaf => f.write_str("a leaf with fewer values than active voxels"),
            VdbFault::Chunk(e) | VdbFault::TreeType(e) => f.write_str(e),
        }
    }
}
