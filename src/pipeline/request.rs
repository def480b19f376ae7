//! The options of every job, declared once. Each request is a serde struct whose fields,
//! defaults and documentation come from one `request!` declaration; the CLI, the C
//! interface, the Python module, the Blender add-on and the Dask front end all fill these
//! structs (Python and Dask by name, from the table `schema()` exports), and a request turns
//! into a `Task` in one place (`task`). Choices are `crate::choice` tables.
//!
//! What "none" and 0 mean is decided here: `threads` none or 0 is every core;
//! `max_memory_mib` none or 0 is the memory available.

use super::{
    ColorChoice, Fill, GridSource, Job, Limits, MeasureSource, MeshSource, SubdivisionFill,
    SubdivisionOutput, SurfaceMethod, Task,
};
use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::grid::Adjacency;
use crate::implicit::{Coordinates, ThetaRange};
use crate::io::vdb::{Compression, WriteOptions};
use crate::mesh::attributes::AttributeChoice;
use crate::mesh::{Aabb, DEFAULT_RESOLUTION, GridFit, UpAxis};
use crate::ops::csg::BooleanOp;
use crate::ops::flood_xyz::DEFAULT_GRAYSTACK;
use crate::solids::beam::BeamFill;
use crate::solids::depth_layers::{DepthLayerOptions, DirectionSet, Layers, Unclassified};
use crate::solids::exterior_flood::FloodMethod;
use crate::solids::inside_rule::InsideRule;
use crate::voxelize::Separability;
use crate::voxelize::parametric::ParametricOptions;
use crate::voxelize::separating::{Criterion, SeparatingOptions};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The distance band's half width in voxels unless asked otherwise.
const BAND: f64 = 3.0;
/// Mass per unit volume unless asked otherwise.
const DENSITY: f64 = 1.0;

/// What the table says of one field.
#[derive(Clone, Debug, Serialize)]
pub struct FieldSchema {
    pub name: &'static str,
    pub doc: String,
    pub default: Value,
    /// The names it takes, for a choice; empty otherwise.
    pub choices: Vec<&'static str>,
    /// Its type as a Python annotation (for the generated stubs).
    pub python_type: String,
}

/// A request's fields, defaults and docs, for the front ends that fill it by name.
pub trait Schema: Default + Serialize + for<'de> Deserialize<'de> {
    /// The request's name in the table: the Python function it backs.
    const NAME: &'static str;
    fn doc() -> String;
    fn fields() -> Vec<FieldSchema>;

    /// The request of these named values (a JSON object), every other field at its
    /// default; an unknown name or a bad value is refused with the field's name.
    fn from_json(values: Value) -> Result<Self> {
        serde_path_to_error::deserialize(values).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner().to_string();
            Error::InvalidArgument(if path == "." || inner.starts_with("unknown field") {
                inner
            } else {
                format!("{path}: {inner}")
            })
        })
    }
}

/// What the table tells of a field's type: the names a choice takes, the Python annotation.
pub trait FieldType {
    fn choices() -> Vec<&'static str> {
        Vec::new()
    }
    fn python_type() -> String;
}

impl<T: Choice> FieldType for T {
    fn choices() -> Vec<&'static str> {
        T::names()
    }

    /// `Literal[...]` of the names; numbers (separability) unquoted, as Python passes them.
    fn python_type() -> String {
        let names: Vec<String> = T::names()
            .iter()
            .map(|n| {
                if n.parse::<i64>().is_ok() {
                    n.to_string()
                } else {
                    format!("{n:?}")
                }
            })
            .collect();
        format!("Literal[{}]", names.join(", "))
    }
}

impl<T: FieldType> FieldType for Option<T> {
    fn python_type() -> String {
        format!("Optional[{}]", T::python_type())
    }
}

/// Field types that are not choices, with their Python annotations.
macro_rules! plain_fields {
    ($($t:ty => $python:literal),* $(,)?) => {$(
        impl FieldType for $t {
            fn python_type() -> String {
                $python.into()
            }
        }
    )*};
}
plain_fields!(
    bool => "bool",
    f64 => "float",
    u32 => "int",
    u64 => "int",
    usize => "int",
    String => "str",
    Vec<String> => "Sequence[str]",
    Directions => "Union[int, Sequence[Sequence[int]]]",
    Bounds => "Union[Sequence[float], Sequence[Sequence[float]]]",
    [f32; 3] => "Sequence[float]",
    [f64; 3] => "Sequence[float]",
);

/// The doc of every `inside` field.
macro_rules! inside_doc {
    () => {
        "How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes)."
    };
}

macro_rules! request {
    // A request on a mesh whose grid may be given a world box to cover.
    ($(#[doc = $sdoc:literal])* $name:ident as $py:literal fitted { $($fields:tt)* }) => {
        request! {
            $(#[doc = $sdoc])*
            $name as $py placed {
                /// The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1,
                /// y1, z1]]` (none: the mesh's box): resolution counts voxels along its
                /// longest side and, unless origin is given, the first centre lies half a
                /// voxel inside its low corner (Open3D's within_bounds grid); only voxels whose
                /// centres lie in it are kept, and dense arrays span it.
                bounds: Option<Bounds> = None,
                $($fields)*
            }
        }
    };
    // A request on a mesh: the grid's placement first, its up axis last.
    ($(#[doc = $sdoc:literal])* $name:ident as $py:literal placed { $($fields:tt)* }) => {
        request! {
            $(#[doc = $sdoc])*
            $name as $py {
                /// Voxels along the longest bounding-box axis (none: the default resolution,
                /// unless voxel_size is given).
                resolution: Option<u32> = None,
                /// Voxel edge length in world units (instead of resolution).
                voxel_size: Option<f64> = None,
                /// The world position of the centre of voxel (0, 0, 0) (none: half a voxel
                /// inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a
                /// multiple of the voxel size, as trimesh does; the mesh's low corner gives
                /// Open3D's VoxelGrid centres.
                origin: Option<[f64; 3]> = None,
                $($fields)*
                /// The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's
                /// importer does.
                up_axis: UpAxis = UpAxis::default(),
            }
        }
    };
    ($(#[doc = $sdoc:literal])* $name:ident as $py:literal {
        $( $(#[doc = $doc:expr])* $field:ident : $ty:ty = $default:expr ),* $(,)?
    }) => {
        $(#[doc = $sdoc])*
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name { $( $(#[doc = $doc])* pub $field: $ty, )* }

        impl Default for $name {
            fn default() -> Self {
                $name { $( $field: $default, )* }
            }
        }

        impl Schema for $name {
            const NAME: &'static str = $py;
            fn doc() -> String {
                [$($sdoc),*].map(str::trim).join(" ")
            }
            fn fields() -> Vec<FieldSchema> {
                let d = Self::default();
                vec![$(FieldSchema {
                    name: stringify!($field),
                    doc: [$($doc),*].map(str::trim).join(" "),
                    default: serde_json::to_value(&d.$field).unwrap_or(Value::Null),
                    choices: <$ty as FieldType>::choices(),
                    python_type: <$ty as FieldType>::python_type(),
                }),*]
            }
        }
    };
}

/// How a polygon mesh becomes a surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceKind {
    /// Huang et al.'s 6/26-separating surface.
    Separating,
    /// Jegathese et al.'s scan-lines in each triangle's dominant plane.
    Projective,
}

crate::named_choices! {
    SurfaceKind, "the surface method":
    "separating" => Separating,
    "projective" => Projective,
}

/// How a mesh's solid is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillKind {
    /// The 26-separating surface plus what the exterior flood cannot reach (Lai & Cheng).
    Flood,
    /// Passalis et al.'s depth layers with a stencil count.
    DepthLayers,
    /// The projective surface plus beams between front and back faces (Jegathese et al.).
    Beam,
}

crate::named_choices! {
    FillKind, "the fill method":
    "flood" => Flood,
    "depth-layers" => DepthLayers,
    "beam" => Beam,
}

/// Which exterior flood.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FloodKind {
    /// Whole empty 8^3 blocks at once (fastest).
    #[default]
    Blocks,
    /// Scanline spans over a dense bit volume.
    Spans,
    /// Lai & Cheng's FloodingXYZ with a GRAYSTACK.
    Xyz,
}

crate::named_choices! {
    FloodKind, "the flood":
    "blocks" => Blocks,
    "spans" => Spans,
    "xyz" => Xyz,
}

impl FloodKind {
    /// The flood with a GRAYSTACK of `graystack` entries (xyz).
    pub fn method(self, graystack: usize) -> FloodMethod {
        match self {
            FloodKind::Blocks => FloodMethod::Blocks,
            FloodKind::Spans => FloodMethod::Spans,
            FloodKind::Xyz => FloodMethod::Xyz {
                capacity: graystack.max(1),
            },
        }
    }
}

/// Depth-layer view directions: a count of the built-in ones, or integer (x, y, z) triples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Directions {
    Count(usize),
    Given(Vec<[i64; 3]>),
}

/// As the CLI takes them: `16`, or `0,0,1;1,1,0`.
impl std::fmt::Display for Directions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Directions::Count(n) => write!(f, "{n}"),
            Directions::Given(list) => {
                let each: Vec<String> = list
                    .iter()
                    .map(|[x, y, z]| format!("{x},{y},{z}"))
                    .collect();
                f.write_str(&each.join(";"))
            }
        }
    }
}

impl Directions {
    pub fn set(&self) -> Result<DirectionSet> {
        match self {
            Directions::Count(n) => DirectionSet::first(*n),
            Directions::Given(list) => DirectionSet::given(list),
        }
    }
}

/// A formula's box: `[lo, hi]` for a cube, or `[[x0, y0, z0], [x1, y1, z1]]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Bounds {
    Cube([f64; 2]),
    Box([[f64; 3]; 2]),
}

/// As the CLI takes them: `lo,hi`, or `x0,y0,z0,x1,y1,z1`.
impl std::fmt::Display for Bounds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let numbers: Vec<String> = match self {
            Bounds::Cube(c) => c.iter().map(f64::to_string).collect(),
            Bounds::Box(b) => b.iter().flatten().map(f64::to_string).collect(),
        };
        f.write_str(&numbers.join(","))
    }
}

/// The inverse of `Display`: `lo,hi` or `x0,y0,z0,x1,y1,z1`.
impl std::str::FromStr for Bounds {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Bounds, String> {
        let v: Vec<f64> = s
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| format!("`{s}`: expected numbers separated by commas"))?;
        match v[..] {
            [lo, hi] => Ok(Bounds::Cube([lo, hi])),
            [x0, y0, z0, x1, y1, z1] => Ok(Bounds::Box([[x0, y0, z0], [x1, y1, z1]])),
            _ => Err(format!("`{s}`: give `lo,hi` or `x0,y0,z0,x1,y1,z1`")),
        }
    }
}

impl Bounds {
    pub fn corners(&self) -> (DVec3, DVec3) {
        match self {
            Bounds::Cube([lo, hi]) => (DVec3::splat(*lo), DVec3::splat(*hi)),
            Bounds::Box([lo, hi]) => (DVec3::from_array(*lo), DVec3::from_array(*hi)),
        }
    }

    pub fn aabb(&self) -> Aabb {
        let (min, max) = self.corners();
        Aabb { min, max }
    }
}

request! {
    /// The limits every job runs under.
    LimitsRequest as "limits" {
        /// Worker threads (none or 0: every core; at most 256).
        threads: Option<u32> = None,
        /// Refuse work estimated above this many MiB before it starts (none or 0: the memory
        /// available).
        max_memory_mib: Option<u64> = None,
    }
}

request! {
    /// How grids are written to a .vdb file.
    WriteRequest as "write" {
        /// Write only these grids, by name (empty: all but `voxels`, the boolean copy of
        /// `density`'s voxels).
        grids: Vec<String> = Vec::new(),
        /// .vdb compression: blosc (OpenVDB's default), zip or none.
        compression: Compression = Compression::default(),
        /// Float and vector grids at half precision (16-bit: half the size).
        half: bool = false,
    }
}

request! {
    /// A polygon mesh's surface: 6- or 26-separating (Huang et al.) or projective (Jegathese
    /// et al.); with `sdf` or `udf`, exact distances within `band` voxels instead.
    MeshRequest as "mesh" fitted {
        /// 6: thin surface blocking face-connected paths; 26: blocks every path.
        separability: Separability = Separability::default(),
        /// separating: Huang et al.'s surface; projective: Jegathese et al.'s scan-lines
        /// (colours, no separability guarantee where triangles meet).
        method: SurfaceKind = SurfaceKind::Separating,
        /// huang: the paper's full vertex spheres and edge cylinders; clipped: the same
        /// clipped to the face slabs (still separating, far fewer redundant voxels).
        criterion: Criterion = Criterion::default(),
        /// Also keep a `normal` grid (nearest face, edge or vertex normal per voxel).
        normals: bool = false,
        /// Projective: carry the mesh's vertex colours into a `Cd` grid.
        colors: bool = true,
        /// The mesh's vertex attributes to write, each as a grid of its name (`uv`,
        /// `vertex_normal`, a PLY property's name, `Cd` for vertex colours where the method
        /// does not colour its voxels itself): `["all"]`, `["none"]` or names (none:
        /// all with the projective method, none otherwise). The projective method
        /// interpolates them across each triangle; separating surfaces and distance bands
        /// take each voxel's value at the mesh's nearest point.
        attributes: Option<Vec<String>> = None,
        /// Projective: one (r, g, b) colour for every voxel instead.
        color: Option<[f32; 3]> = None,
        /// Exact signed distances (a level set) within `band`, signed by `inside`.
        sdf: bool = false,
        /// Exact unsigned distances within `band` (open meshes too).
        udf: bool = false,
        /// Half width of the distance band, in voxels.
        band: f64 = BAND,
        #[doc = inside_doc!()]
        inside: InsideRule = InsideRule::default(),
    }
}

request! {
    /// A closed mesh's solid: flood (the 26-separating surface and everything the exterior
    /// flood cannot reach), depth-layers (Passalis et al.) or beam (Jegathese et al.); with
    /// `sdf`, its level set.
    SolidRequest as "solid" fitted {
        /// flood, depth-layers or beam.
        method: FillKind = FillKind::Flood,
        /// The exterior flood of inside parity: blocks (fastest), spans, or xyz (Lai & Cheng's
        /// FloodingXYZ).
        flood: FloodKind = FloodKind::default(),
        /// GRAYSTACK capacity of the xyz flood (entries; when full, sweeps resume the flood).
        graystack: usize = DEFAULT_GRAYSTACK,
        /// Depth layers: a count of the 16 built-in directions, or integer (x, y, z)
        /// triples, each with a component of 1 or -1, none parallel.
        directions: Directions = Directions::Count(16),
        /// Depth layers: double (a stencil count, Passalis et al.) or single (Karabassi et al.).
        layers: Layers = Layers::Double,
        /// Depth layers: no-direction (a voxel no direction decides) or paper (a voxel on a
        /// ray of any direction crossing more than four times).
        unclassified: Unclassified = Unclassified::default(),
        /// Beam: parity (centres between exact crossings) or paper (from each back-face voxel
        /// up to the next front-face voxel).
        fill: BeamFill = BeamFill::default(),
        /// Mass per unit volume.
        density: f64 = DENSITY,
        /// Also count components (26-connected) and genus.
        topology: bool = false,
        /// Write the solid's level set instead: exact signed distances within `band`.
        sdf: bool = false,
        /// Half width of the distance band, in voxels.
        band: f64 = BAND,
        #[doc = inside_doc!()]
        inside: InsideRule = InsideRule::default(),
    }
}

request! {
    /// Volume, mass, area, components and genus of a closed mesh (its flooded 26-separating
    /// surface) or of a closed voxel surface.
    MeasureRequest as "measure" fitted {
        /// The exterior flood of inside parity: blocks (fastest), spans, or xyz (Lai & Cheng's
        /// FloodingXYZ).
        flood: FloodKind = FloodKind::default(),
        /// GRAYSTACK capacity of the xyz flood (entries; when full, sweeps resume the flood).
        graystack: usize = DEFAULT_GRAYSTACK,
        /// Mass per unit volume.
        density: f64 = DENSITY,
        #[doc = inside_doc!()]
        inside: InsideRule = InsideRule::default(),
    }
}

request! {
    /// A Catmull-Clark limit surface from its control mesh (Lai & Cheng); with `solid`, the
    /// solid it bounds, flooded from seeds against the limit normals by FloodingXYZ.
    SubdivRequest as "subdiv" fitted {
        /// The adjacency (6, 18 or 26) every voxel meets between its sub-patches' corners.
        adjacency: Adjacency = Adjacency::TwentySix,
        /// Every voxel the surface touches (an enveloping voxelization).
        enclose: bool = false,
        /// Each face's patch split K x K before the adaptive subdivision.
        presplit: u32 = ParametricOptions::default().presplit,
        /// The solid of the closed limit surface, with its volume and mass.
        solid: bool = false,
        /// With `solid`: fill by Passalis et al.'s double depth layers along z, x and y on a
        /// tessellation certified within 0.45 voxel of the limit surface, united with the
        /// enclosing surface, instead of seeds and FloodingXYZ (every pocket filled).
        depth_layers: bool = false,
        /// GRAYSTACK capacity of FloodingXYZ (entries).
        graystack: usize = DEFAULT_GRAYSTACK,
        /// Mass per unit volume.
        density: f64 = DENSITY,
        /// Also count components and genus.
        topology: bool = false,
    }
}

request! {
    /// The surface F = 0 of a formula, by interval octree (Stolte & Kaufman).
    ImplicitRequest as "implicit" {
        /// cartesian (x, y, z), spherical (r, theta, phi) or cylindrical (r, theta, y: r and
        /// theta in the XZ plane, y along the axis).
        coords: Coordinates = Coordinates::Cartesian,
        /// The box: [lo, hi] for a cube, or [[x0, y0, z0], [x1, y1, z1]].
        bounds: Bounds = Bounds::Cube([-1.0, 1.0]),
        /// Voxels along the box's longest side.
        resolution: u32 = DEFAULT_RESOLUTION,
        /// Also keep every level of the octree (each envelops the surface).
        levels: bool = false,
        /// Spherical and cylindrical: the surface where r < 0 too.
        negative_r: bool = false,
        /// positive (the paper's [0, 2pi)) or symmetric ((-pi, pi]).
        theta_range: ThetaRange = ThetaRange::default(),
        /// The paper's [G]^2 - r^2 = 0 for F = G - r (the surface r = |G|).
        squared: bool = false,
        /// The solid F < 0 within the bounds instead of the surface, by Passalis et al.'s
        /// double depth layers along z, x and y, each ray's crossings of F = 0 isolated by
        /// interval arithmetic.
        depth_layers: bool = false,
    }
}

request! {
    /// 3D lines (Jegathese et al.): the polylines (OBJ `l`) of a mesh, and with `edges` (or
    /// when there are none) the faces' edges.
    LinesRequest as "lines" fitted {
        /// Also the faces' edges.
        edges: bool = false,
        /// Carry the mesh's vertex colours into a `Cd` grid.
        colors: bool = true,
        /// One (r, g, b) colour for every voxel instead.
        color: Option<[f32; 3]> = None,
    }
}

request! {
    /// Exact distances from points to a mesh, and whether each point lies inside it.
    QueryRequest as "query" {
        #[doc = inside_doc!()]
        inside: InsideRule = InsideRule::default(),
    }
}

request! {
    /// A Boolean of two grids.
    CombineRequest as "combine" {
        /// union, intersection or difference.
        op: BooleanOp = BooleanOp::Union,
        /// The grid read from files (none: `voxels`, else `density`, else the first bool,
        /// mask or float grid).
        grid: Option<String> = None,
        /// Resample the second grid onto the first's transform when they differ.
        resample: bool = false,
    }
}

request! {
    /// A mesh drawn from a grid: the closed, manifold surface of a level set's zero set, a fog
    /// volume's iso surface or a voxel set's boundary.
    ToMeshRequest as "to_mesh" {
        /// The grid read from a file (none: the level set `surface` when there is one, else
        /// `voxels`, else `density`, else the first bool, mask or float grid).
        grid: Option<String> = None,
        /// The value the surface passes through (none: 0 for a level set, 0.5 for a fog
        /// volume; a voxel set takes none).
        iso: Option<f64> = None,
        /// Merge the triangles of flat regions, moving the surface by at most about this many
        /// voxels: every vertex stays within half of it of the plane of each triangle it
        /// replaces (0: every cell keeps its vertex).
        adaptivity: f64 = 0.0,
    }
}

request! {
    /// The separating surface (or solid) of a mesh cut into bricks and voxelized by Dask
    /// workers, merged into one .vdb.
    BricksRequest as "distributed" placed {
        /// Voxels along a brick's edge, a multiple of 8 (none: chosen for the cluster, the
        /// largest of 2048 (a surface's; a solid's 1024), 1024, 512, 256 and 128 that gives
        /// every worker thread at least 8 bricks with faces).
        brick: Option<u32> = None,
        /// 6 or 26 (the surface; a solid is always 26).
        separability: Separability = Separability::default(),
        /// Refuse a brick estimated above this many MiB (none or 0: the memory available).
        max_memory_mib: Option<u64> = None,
        #[doc = inside_doc!()]
        inside: InsideRule = InsideRule::default(),
    }
}

/// The grid fit of `resolution` or `voxel_size` (not both), checked.
pub fn grid_fit(
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    origin: Option<[f64; 3]>,
) -> Result<GridFit> {
    if resolution.is_some() && voxel_size.is_some() {
        return Err(Error::InvalidArgument(
            "give resolution or voxel_size, not both".into(),
        ));
    }
    if resolution == Some(0) {
        return Err(Error::InvalidArgument(
            "resolution must be at least 1".into(),
        ));
    }
    if let Some(h) = voxel_size {
        positive("voxel_size", h)?;
    }
    Ok(GridFit::from_options(resolution, voxel_size).with_origin(origin.map(DVec3::from_array)))
}

/// Refuses a value that is not a positive, finite number, naming the option.
pub fn positive(name: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{name} must be a positive number, not {v}"
        )))
    }
}

fn color_choice(colors: bool, color: Option<[f32; 3]>) -> ColorChoice {
    match (color, colors) {
        (Some(c), _) => ColorChoice::Constant(Vec3::from_array(c)),
        (None, true) => ColorChoice::FromMesh,
        (None, false) => ColorChoice::None,
    }
}

fn distance_band(
    mesh: MeshSource,
    band: f64,
    signed: bool,
    inside: InsideRule,
    attributes: AttributeChoice,
) -> Result<Task> {
    positive("band", band)?;
    Ok(Task::DistanceBand {
        mesh,
        band,
        signed,
        inside,
        attributes,
    })
}

impl LimitsRequest {
    /// The limits, 0 read as none.
    pub fn limits(&self) -> Limits {
        Limits {
            threads: self.threads.filter(|&n| n > 0).map(|n| n as usize),
            max_memory: mib_limit(self.max_memory_mib),
        }
    }
}

/// A memory limit in MiB as bytes, 0 read as none.
pub fn mib_limit(mib: Option<u64>) -> Option<u64> {
    mib.filter(|&m| m > 0).map(|m| m.saturating_mul(1 << 20))
}

impl WriteRequest {
    pub fn options(&self) -> WriteOptions {
        WriteOptions {
            grids: self.grids.clone(),
            compression: self.compression,
            half: self.half,
        }
    }
}

/// A request that makes a job: what it takes as input, the task and the grid it asks for.
pub trait Request: Schema {
    /// What the job reads besides the options: a mesh, a formula, two grids.
    type Input;

    /// The task, its options checked.
    fn task(&self, input: Self::Input) -> Result<Task>;

    /// The grid fit (the task's inputs decide the grid where the request has no fit).
    fn fit(&self) -> Result<GridFit> {
        Ok(GridFit::from_options(None, None))
    }

    /// Which axis of a mesh file points up.
    fn up_axis(&self) -> UpAxis {
        UpAxis::default()
    }

    /// The job under `limits`.
    fn job(&self, input: Self::Input, limits: &LimitsRequest) -> Result<Job> {
        Ok(Job {
            limits: limits.limits(),
            up_axis: self.up_axis(),
            ..Job::new(self.task(input)?, self.fit()?)
        })
    }
}

/// Where a mesh's grid lies: the placement fields of a `fitted` request, which the C
/// interface also sets on their own (one grid shared by every call).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    pub resolution: Option<u32>,
    pub voxel_size: Option<f64>,
    pub origin: Option<[f64; 3]>,
    pub bounds: Option<Bounds>,
}

impl Placement {
    /// The names of its fields, as the requests name them.
    pub const FIELDS: [&str; 4] = ["resolution", "voxel_size", "origin", "bounds"];

    /// The grid fit, checked.
    pub fn fit(&self) -> Result<GridFit> {
        grid_fit(self.resolution, self.voxel_size, self.origin)?
            .within(self.bounds.as_ref().map(Bounds::aabb))
    }
}

/// `fit` and `up_axis` of a `fitted` request.
macro_rules! fitted {
    () => {
        fn fit(&self) -> Result<GridFit> {
            Placement {
                resolution: self.resolution,
                voxel_size: self.voxel_size,
                origin: self.origin,
                bounds: self.bounds,
            }
            .fit()
        }

        fn up_axis(&self) -> UpAxis {
            self.up_axis
        }
    };
}

impl MeshRequest {
    /// The attributes asked for, or `default` when none are named.
    fn attributes_or(&self, default: AttributeChoice) -> AttributeChoice {
        self.attributes
            .as_deref()
            .map_or(default, AttributeChoice::of_names)
    }

    pub fn separating(&self) -> SeparatingOptions {
        SeparatingOptions {
            separability: self.separability,
            criterion: self.criterion,
            normals: self.normals,
        }
    }
}

impl Request for MeshRequest {
    type Input = MeshSource;
    fitted!();

    fn task(&self, mesh: MeshSource) -> Result<Task> {
        if self.sdf && self.udf {
            return Err(Error::InvalidArgument(
                "sdf and udf exclude each other".into(),
            ));
        }
        if self.sdf || self.udf {
            let attributes = self.attributes_or(AttributeChoice::None);
            return distance_band(mesh, self.band, self.sdf, self.inside, attributes);
        }
        let method = match self.method {
            SurfaceKind::Separating => SurfaceMethod::Separating(self.separating()),
            SurfaceKind::Projective if self.normals => {
                return Err(Error::InvalidArgument(
                    "normals are written by the separating method (the nearest face, edge or \
                     vertex normal per voxel); the projective method writes colours"
                        .into(),
                ));
            }
            SurfaceKind::Projective => {
                SurfaceMethod::Projective(color_choice(self.colors, self.color))
            }
        };
        let attributes = self.attributes_or(match method {
            SurfaceMethod::Projective(_) => AttributeChoice::All,
            SurfaceMethod::Separating(_) => AttributeChoice::None,
        });
        Ok(Task::MeshSurface {
            mesh,
            method,
            attributes,
        })
    }
}

impl SolidRequest {
    pub fn depth_layers(&self) -> Result<DepthLayerOptions> {
        Ok(DepthLayerOptions {
            directions: self.directions.set()?,
            layers: self.layers,
            unclassified: self.unclassified,
        })
    }
}

impl Request for SolidRequest {
    type Input = MeshSource;
    fitted!();

    fn task(&self, mesh: MeshSource) -> Result<Task> {
        if self.sdf {
            return distance_band(mesh, self.band, true, self.inside, AttributeChoice::None);
        }
        positive("density", self.density)?;
        let fill = match self.method {
            FillKind::Flood => Fill::Flood(self.flood.method(self.graystack)),
            FillKind::DepthLayers => Fill::DepthLayers(self.depth_layers()?),
            FillKind::Beam => Fill::Beam(self.fill),
        };
        Ok(Task::Solid {
            mesh,
            fill,
            density: self.density,
            topology: self.topology,
            inside: self.inside,
        })
    }
}

impl Request for MeasureRequest {
    type Input = MeasureSource;
    fitted!();

    fn task(&self, source: MeasureSource) -> Result<Task> {
        positive("density", self.density)?;
        Ok(Task::Measure {
            source,
            flood: self.flood.method(self.graystack),
            density: self.density,
            inside: self.inside,
        })
    }
}

impl SubdivRequest {
    pub fn options(&self) -> Result<ParametricOptions> {
        if self.presplit == 0 {
            return Err(Error::InvalidArgument("presplit must be at least 1".into()));
        }
        Ok(ParametricOptions {
            adjacency: self.adjacency,
            presplit: self.presplit,
            enclose: self.enclose,
        })
    }
}

impl Request for SubdivRequest {
    type Input = MeshSource;
    fitted!();

    fn task(&self, mesh: MeshSource) -> Result<Task> {
        if self.solid {
            positive("density", self.density)?;
        } else if self.depth_layers {
            return Err(Error::InvalidArgument(
                "depth_layers fills the solid: set solid as well".into(),
            ));
        }
        Ok(Task::Subdivision {
            mesh,
            options: self.options()?,
            output: if self.solid {
                SubdivisionOutput::Solid(SubdivisionFill {
                    depth_layers: self.depth_layers,
                    graystack: self.graystack.max(1),
                    density: self.density,
                    topology: self.topology,
                })
            } else {
                SubdivisionOutput::Surface
            },
        })
    }
}

impl Request for ImplicitRequest {
    type Input = String;

    fn fit(&self) -> Result<GridFit> {
        grid_fit(Some(self.resolution), None, None)
    }

    fn task(&self, formula: String) -> Result<Task> {
        let (min, max) = self.bounds.corners();
        Ok(Task::Implicit {
            formula,
            coordinates: self.coords,
            min,
            max,
            levels: self.levels,
            negative_r: self.negative_r,
            theta_range: self.theta_range,
            squared: self.squared,
            depth_layers: self.depth_layers,
        })
    }
}

impl Request for LinesRequest {
    type Input = MeshSource;
    fitted!();

    fn task(&self, mesh: MeshSource) -> Result<Task> {
        Ok(Task::Lines {
            mesh,
            edges: self.edges,
            color: color_choice(self.colors, self.color),
        })
    }
}

impl Request for CombineRequest {
    type Input = (GridSource, GridSource);

    fn task(&self, (a, b): (GridSource, GridSource)) -> Result<Task> {
        Ok(Task::Combine {
            operands: vec![a, b],
            grid: self.grid.clone(),
            op: self.op,
            resample: self.resample,
            curve: false,
        })
    }
}

impl BricksRequest {
    pub fn fit(&self) -> Result<GridFit> {
        grid_fit(self.resolution, self.voxel_size, self.origin)
    }
}

fn entry<R: Schema>() -> (String, Value) {
    let fields: Vec<Value> = R::fields()
        .into_iter()
        .map(|f| serde_json::to_value(f).unwrap_or(Value::Null))
        .collect();
    (
        R::NAME.to_string(),
        serde_json::json!({ "doc": R::doc(), "fields": fields }),
    )
}

/// Every request's fields: name, doc, default and choices, keyed by the request's name
/// (`mesh`, `solid`, ..., `limits`, `write`). The front ends that fill requests by name
/// (Python, Blender, Dask) take their parameters, defaults and choices from it.
pub fn schema() -> Value {
    Value::Object(
        [
            entry::<MeshRequest>(),
            entry::<SolidRequest>(),
            entry::<MeasureRequest>(),
            entry::<SubdivRequest>(),
            entry::<ImplicitRequest>(),
            entry::<LinesRequest>(),
            entry::<CombineRequest>(),
            entry::<ToMeshRequest>(),
            entry::<QueryRequest>(),
            entry::<BricksRequest>(),
            entry::<LimitsRequest>(),
            entry::<WriteRequest>(),
        ]
        .into_iter()
        .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_is_documented_and_its_default_round_trips() {
        for (name, request) in schema().as_object().unwrap() {
            for f in request["fields"].as_array().unwrap() {
                assert!(
                    !f["doc"].as_str().unwrap().is_empty(),
                    "{name}.{} has no doc",
                    f["name"]
                );
            }
        }
        let defaults = serde_json::to_value(SolidRequest::default()).unwrap();
        assert_eq!(
            SolidRequest::from_json(defaults).unwrap(),
            SolidRequest::default()
        );
    }

    #[test]
    fn bad_names_and_values_are_refused_with_the_field() {
        let e = MeshRequest::from_json(serde_json::json!({"separability": 7})).unwrap_err();
        assert_eq!(
            e.to_string(),
            "invalid argument: separability: separability must be 6 or 26, not `7`"
        );
        let e = MeshRequest::from_json(serde_json::json!({"sepability": 6})).unwrap_err();
        assert!(e.to_string().contains("unknown field `sepability`"), "{e}");
        let r = MeshRequest::from_json(serde_json::json!({"separability": "6"})).unwrap();
        assert_eq!(r.separability, Separability::Six);
        let r = MeshRequest {
            band: f64::INFINITY,
            sdf: true,
            ..MeshRequest::default()
        };
        let e = Request::task(&r, MeshSource::File("m.obj".into())).unwrap_err();
        assert!(
            e.to_string().contains("band must be a positive number"),
            "{e}"
        );
    }

    #[test]
    fn zero_threads_and_memory_mean_the_defaults() {
        let zero = LimitsRequest {
            threads: Some(0),
            max_memory_mib: Some(0),
        };
        assert_eq!(zero.limits().threads, None);
        assert_eq!(zero.limits().max_memory, None);
        let some = LimitsRequest {
            threads: Some(3),
            max_memory_mib: Some(2),
        };
        assert_eq!(some.limits().threads, Some(3));
        assert_eq!(some.limits().max_memory, Some(2 << 20));
    }
}
