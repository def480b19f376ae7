//! CSG trees read from a small JSON file (Lai & Cheng §7.3 on whole trees): Booleans over
//! boxes, cylinders, spheres, formulas, meshes (open ones too: their inside by the winding
//! number), Catmull-Clark solids and .vdb grids,
//! evaluated on one grid.
//!
//! ```json
//! { "resolution": 256,
//!   "tree": { "difference": [
//!       { "union": [ { "box": { "min": [-2, -1, 0], "max": [2, 1, 0.5] } },
//!                    { "cylinder": { "base": [0, 0, 0.5], "axis": [0, 0, 1],
//!                                    "radius": 0.8, "height": 1 } } ] },
//!       { "formula": { "text": "(sqrt(x^2 + y^2) - 0.8)^2 + (z - 1)^2 - 0.01",
//!                      "bounds": { "min": [-1, -1, 0.8], "max": [1, 1, 1.2] } } },
//!       { "mesh": "bolt.obj" }, { "subdiv": "knob.obj" },
//!       { "vdb": { "file": "pocket.vdb", "grid": "voxels" } } ] } }
//! ```
//!
//! Every node is an object with one key, its kind (serde's externally tagged enum): `union`,
//! `intersection` and `difference` hold lists of nodes; `formula` holds the text, or an
//! object with `text`, `coordinates` and `bounds`; `vdb` a file name, or `file` and `grid`
//! (a level set stands for its inside, negative values and tiles; other grids for their active
//! voxels);
//! `subdiv` a closed Catmull-Clark control mesh, whose solid is its voxelized limit surface
//! and the inside flooded from seeds (`solids::subdivision`).
//! `union` and `intersection` take any number of operands, `difference` removes all later
//! operands from the first. A formula's solid is where F < 0. `voxel_size` may replace
//! `resolution` (voxels along the longest axis of the bounds); `bounds` (top level) fixes the
//! grid's extent, which otherwise covers every leaf (formulas need their own `bounds` then).
//! Files are found relative to the tree file. Every leaf may carry `"place"` (`csg_placement`):
//! `{"mesh": {"file": "cow.obj", "place": {"translate": [2, 0, 0]}}}`.

use super::csg_leaves::{
    Primitive, formula_solid, grid_bounds, grid_solid, mesh_solid, primitive_solid,
    subdivision_leaf,
};
use super::csg_placement::{PlaceSpec, placed_box, to_world};
use crate::error::{Error, Result};
use crate::grid::{CoordBox, DenseMask, SparseGrid, Transform};
use crate::implicit::{Coordinates, Formula};
use crate::io::vdb::read_vdb_solid;
use crate::mesh::{Aabb, GridFit, Mesh, fit_transform, index_box};
use crate::ops::csg::BooleanOp;
use crate::shapes::{Cuboid, Cylinder, Sphere};
use crate::subd::ControlMesh;
use glam::{DAffine3, DVec3};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A node of the tree. Meshes and control meshes are read placed; the other leaves keep their
/// own frame and the map from the world into it (`to_local`, the identity unless placed).
pub enum CsgNode {
    Boolean {
        op: BooleanOp,
        operands: Vec<CsgNode>,
    },
    Primitive {
        shape: Primitive,
        to_local: DAffine3,
    },
    Formula {
        formula: Formula,
        bounds: Option<Aabb>,
        to_local: DAffine3,
    },
    Mesh(Mesh),
    Subdivision(ControlMesh),
    Grid {
        grid: SparseGrid,
        source: PathBuf,
        to_local: DAffine3,
    },
}

pub struct CsgTree {
    pub root: CsgNode,
    pub fit: GridFit,
    pub bounds: Option<Aabb>,
    pub source: PathBuf,
}

impl CsgTree {
    /// Nodes of the tree: leaves and Booleans.
    pub fn node_count(&self) -> usize {
        fn count(node: &CsgNode) -> usize {
            match node {
                CsgNode::Boolean { operands, .. } => 1 + operands.iter().map(count).sum::<usize>(),
                _ => 1,
            }
        }
        count(&self.root)
    }

    /// The files the tree was read from: the tree file, its meshes and its grids.
    pub fn input_files(&self) -> Vec<PathBuf> {
        fn collect(node: &CsgNode, files: &mut Vec<PathBuf>) {
            match node {
                CsgNode::Boolean { operands, .. } => {
                    operands.iter().for_each(|n| collect(n, files));
                }
                CsgNode::Mesh(mesh) => files.push(mesh.source.clone()),
                CsgNode::Subdivision(control) => files.push(control.source.clone()),
                CsgNode::Grid { source, .. } => files.push(source.clone()),
                CsgNode::Primitive { .. } | CsgNode::Formula { .. } => {}
            }
        }
        let mut files = vec![self.source.clone()];
        collect(&self.root, &mut files);
        files
    }
}

/// A leaf's share of the result, for the summary.
pub struct LeafReport {
    pub what: String,
    pub voxels: u64,
}

/// The file as written: an externally tagged enum per node, read by serde.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TreeFile {
    resolution: Option<f64>,
    voxel_size: Option<f64>,
    bounds: Option<BoundsSpec>,
    tree: NodeSpec,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct BoundsSpec {
    min: [f64; 3],
    max: [f64; 3],
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase")]
enum NodeSpec {
    Union(Vec<NodeSpec>),
    Intersection(Vec<NodeSpec>),
    Difference(Vec<NodeSpec>),
    Box(BoxSpec),
    Cylinder(CylinderSpec),
    Sphere(SphereSpec),
    Formula(FormulaSpec),
    Mesh(FileSpec),
    Subdiv(FileSpec),
    Vdb(VdbSpec),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxSpec {
    min: [f64; 3],
    max: [f64; 3],
    place: Option<Box<PlaceSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CylinderSpec {
    base: [f64; 3],
    axis: [f64; 3],
    radius: f64,
    height: f64,
    place: Option<Box<PlaceSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereSpec {
    center: [f64; 3],
    radius: f64,
    place: Option<Box<PlaceSpec>>,
}

/// `"part.obj"`, or `{"file": "part.obj", "place": {...}}`.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "a file name, or {\"file\": ..., \"place\": ...}"
)]
enum FileSpec {
    File(String),
    Full {
        file: String,
        place: Option<Box<PlaceSpec>>,
    },
}

impl FileSpec {
    fn parts(self) -> (String, Option<Box<PlaceSpec>>) {
        match self {
            FileSpec::File(file) => (file, None),
            FileSpec::Full { file, place } => (file, place),
        }
    }
}

/// `"F"`, or `{"text": "F", "coordinates": "spherical", "bounds": {...}}`.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "the formula as a string, or {\"text\": ..., \"coordinates\": ..., \"bounds\": ...}"
)]
enum FormulaSpec {
    Text(String),
    Full {
        text: String,
        coordinates: Option<String>,
        bounds: Option<BoundsSpec>,
        place: Option<Box<PlaceSpec>>,
    },
}

/// `"grid.vdb"`, or `{"file": "grid.vdb", "grid": "voxels"}`.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "a file name, or {\"file\": ..., \"grid\": ...} with the grid's name"
)]
enum VdbSpec {
    File(String),
    Full {
        file: String,
        grid: Option<String>,
        place: Option<Box<PlaceSpec>>,
    },
}

/// Reads the tree in `path`, loading its meshes and grids. Errors name the file and the
/// place in the tree (`tree.difference[1].cylinder.radius`).
pub fn read_csg_tree(path: &Path) -> Result<CsgTree> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_csg_tree(&text, path, path.parent().unwrap_or(Path::new(".")))
}

/// Reads a tree given as JSON text; `path` names it in errors and the files it names are
/// found in `folder`.
pub fn parse_csg_tree(text: &str, path: &Path, folder: &Path) -> Result<CsgTree> {
    let mut json = serde_json::Deserializer::from_str(text);
    let file: TreeFile = serde_path_to_error::deserialize(&mut json).map_err(|e| {
        let at = e.path().to_string();
        let inner = e.into_inner();
        Error::Parse {
            path: path.to_path_buf(),
            line: inner.line(),
            message: if at == "." {
                inner.to_string()
            } else {
                format!("{at}: {inner}")
            },
        }
    })?;
    let reader = Reader { file: path, folder };
    let fit = match (file.resolution, file.voxel_size) {
        (Some(r), None) => {
            if !(1.0..=1e6).contains(&r) || r.fract() != 0.0 {
                return Err(reader.error("resolution", "must be a whole number of voxels"));
            }
            GridFit::Resolution(r as u32)
        }
        (None, Some(h)) => GridFit::VoxelSize(reader.positive(h, "voxel_size")?),
        (None, None) => GridFit::Resolution(256),
        (Some(_), Some(_)) => {
            return Err(reader.error("the file", "give resolution or voxel_size, not both"));
        }
    };
    let bounds = file.bounds.map(|b| reader.aabb(b, "bounds")).transpose()?;
    let root = reader.node(file.tree, "tree")?;
    Ok(CsgTree {
        root,
        fit,
        bounds,
        source: path.to_path_buf(),
    })
}

/// Checks what serde cannot (signs, sizes, files) and builds the nodes, naming the place.
struct Reader<'a> {
    file: &'a Path,
    folder: &'a Path,
}

impl Reader<'_> {
    fn error(&self, at: &str, message: &str) -> Error {
        Error::InvalidArgument(format!("{}: {at}: {message}", self.file.display()))
    }

    fn positive(&self, x: f64, at: &str) -> Result<f64> {
        if x > 0.0 && x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(at, "must be positive"))
        }
    }

    fn vec3(&self, v: [f64; 3], at: &str) -> Result<DVec3> {
        let p = DVec3::from_array(v);
        if p.is_finite() {
            Ok(p)
        } else {
            Err(self.error(at, "must be finite numbers"))
        }
    }

    /// The map from a leaf's frame into the world, the identity when it is not placed.
    fn to_world(&self, place: Option<Box<PlaceSpec>>, at: &str) -> Result<DAffine3> {
        place.map_or(Ok(DAffine3::IDENTITY), |p| {
            to_world(&p).map_err(|e| {
                let (field, message) = e.split_once(": ").unwrap_or(("", &e));
                self.error(&format!("{at}.place.{field}"), message)
            })
        })
    }

    fn aabb(&self, b: BoundsSpec, at: &str) -> Result<Aabb> {
        let min = self.vec3(b.min, &format!("{at}.min"))?;
        let max = self.vec3(b.max, &format!("{at}.max"))?;
        if !min.cmplt(max).all() {
            return Err(self.error(at, "min must be below max on every axis"));
        }
        Ok(Aabb { min, max })
    }

    fn primitive(
        &self,
        shape: Primitive,
        place: Option<Box<PlaceSpec>>,
        at: &str,
    ) -> Result<CsgNode> {
        Ok(CsgNode::Primitive {
            shape,
            to_local: self.to_world(place, at)?.inverse(),
        })
    }

    fn node(&self, spec: NodeSpec, at: &str) -> Result<CsgNode> {
        let boolean = |op: BooleanOp, name: &str, items: Vec<NodeSpec>| -> Result<CsgNode> {
            let at = format!("{at}.{name}");
            if items.is_empty() {
                return Err(self.error(&at, "needs at least one operand"));
            }
            let operands = items
                .into_iter()
                .enumerate()
                .map(|(i, item)| self.node(item, &format!("{at}[{i}]")))
                .collect::<Result<_>>()?;
            Ok(CsgNode::Boolean { op, operands })
        };
        match spec {
            NodeSpec::Union(items) => boolean(BooleanOp::Union, "union", items),
            NodeSpec::Intersection(items) => {
                boolean(BooleanOp::Intersection, "intersection", items)
            }
            NodeSpec::Difference(items) => boolean(BooleanOp::Difference, "difference", items),
            NodeSpec::Box(b) => {
                let at = format!("{at}.box");
                let BoxSpec { min, max, place } = b;
                let Aabb { min, max } = self.aabb(BoundsSpec { min, max }, &at)?;
                self.primitive(Primitive::Cuboid(Cuboid { min, max }), place, &at)
            }
            NodeSpec::Cylinder(c) => {
                let at = format!("{at}.cylinder");
                let axis = self.vec3(c.axis, &format!("{at}.axis"))?;
                let axis = axis
                    .try_normalize()
                    .ok_or_else(|| self.error(&format!("{at}.axis"), "must not be zero"))?;
                let shape = Primitive::Cylinder(Cylinder::from_base(
                    self.vec3(c.base, &format!("{at}.base"))?,
                    axis,
                    self.positive(c.radius, &format!("{at}.radius"))?,
                    self.positive(c.height, &format!("{at}.height"))?,
                ));
                self.primitive(shape, c.place, &at)
            }
            NodeSpec::Sphere(s) => {
                let at = format!("{at}.sphere");
                let shape = Primitive::Sphere(Sphere {
                    center: self.vec3(s.center, &format!("{at}.center"))?,
                    radius: self.positive(s.radius, &format!("{at}.radius"))?,
                });
                self.primitive(shape, s.place, &at)
            }
            NodeSpec::Formula(f) => {
                let at = format!("{at}.formula");
                let (text, coordinates, bounds, place) = match f {
                    FormulaSpec::Text(text) => (text, None, None, None),
                    FormulaSpec::Full {
                        text,
                        coordinates,
                        bounds,
                        place,
                    } => (text, coordinates, bounds, place),
                };
                let coordinates = match coordinates {
                    None => Coordinates::Cartesian,
                    Some(c) => c
                        .parse()
                        .map_err(|e: String| self.error(&format!("{at}.coordinates"), &e))?,
                };
                let formula = Formula::parse(&text, coordinates)
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                let bounds = bounds
                    .map(|b| self.aabb(b, &format!("{at}.bounds")))
                    .transpose()?;
                let to_local = self.to_world(place, &at)?.inverse();
                Ok(CsgNode::Formula {
                    formula,
                    bounds,
                    to_local,
                })
            }
            NodeSpec::Mesh(spec) => {
                let at = format!("{at}.mesh");
                let (file, place) = spec.parts();
                let to_world = self.to_world(place, &at)?;
                let mut mesh = Mesh::load(&self.folder.join(file))
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                for p in &mut mesh.positions {
                    *p = to_world.transform_point3(*p);
                }
                Ok(CsgNode::Mesh(mesh))
            }
            NodeSpec::Subdiv(spec) => {
                let at = format!("{at}.subdiv");
                let (file, place) = spec.parts();
                let to_world = self.to_world(place, &at)?;
                let mut control = ControlMesh::load(&self.folder.join(file))
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                control.map_points(|p| to_world.transform_point3(p));
                Ok(CsgNode::Subdivision(control))
            }
            NodeSpec::Vdb(v) => {
                let at = format!("{at}.vdb");
                let (file, name, place) = match v {
                    VdbSpec::File(file) => (file, None, None),
                    VdbSpec::Full { file, grid, place } => (file, grid, place),
                };
                let to_local = self.to_world(place, &at)?.inverse();
                let source = self.folder.join(file);
                let grid = read_vdb_solid(&source, name.as_deref())
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                Ok(CsgNode::Grid {
                    grid,
                    source,
                    to_local,
                })
            }
        }
    }
}

fn union(a: Option<Aabb>, b: Option<Aabb>) -> Option<Aabb> {
    match (a, b) {
        (Some(a), Some(b)) => Some(Aabb {
            min: a.min.min(b.min),
            max: a.max.max(b.max),
        }),
        (a, b) => a.or(b),
    }
}

impl CsgNode {
    /// The world box the leaves cover (formulas only with their own bounds).
    pub(super) fn bounds(&self) -> Option<Aabb> {
        match self {
            CsgNode::Boolean { operands, .. } => {
                operands.iter().map(CsgNode::bounds).fold(None, union)
            }
            CsgNode::Primitive { shape, to_local } => {
                Some(placed_box(&shape.bounds(), &to_local.inverse()))
            }
            CsgNode::Formula {
                bounds, to_local, ..
            } => bounds.map(|b| placed_box(&b, &to_local.inverse())),
            CsgNode::Mesh(m) => Some(m.bbox()),
            CsgNode::Subdivision(c) => Some(c.bbox()),
            CsgNode::Grid { grid, to_local, .. } => {
                grid_bounds(grid).map(|b| placed_box(&b, &to_local.inverse()))
            }
        }
    }

    /// The map from the world into a leaf's own frame (the identity for meshes, read placed).
    fn to_local(&self) -> &DAffine3 {
        match self {
            CsgNode::Primitive { to_local, .. }
            | CsgNode::Formula { to_local, .. }
            | CsgNode::Grid { to_local, .. } => to_local,
            _ => &DAffine3::IDENTITY,
        }
    }

    fn evaluate(
        &self,
        transform: &Transform,
        bbox: CoordBox,
        whole: &Aabb,
        leaves: &mut Vec<LeafReport>,
    ) -> Result<DenseMask> {
        let (what, mask) = match self {
            CsgNode::Boolean { op, operands } => {
                let mut acc = operands[0].evaluate(transform, bbox, whole, leaves)?;
                for operand in &operands[1..] {
                    let m = operand.evaluate(transform, bbox, whole, leaves)?;
                    match op {
                        BooleanOp::Union => acc.combine_words(&m, |a, b| a | b),
                        BooleanOp::Intersection => acc.combine_words(&m, |a, b| a & b),
                        BooleanOp::Difference => acc.combine_words(&m, |a, b| a & !b),
                    }
                }
                return Ok(acc);
            }
            CsgNode::Primitive { shape, to_local } => (
                shape.describe(),
                primitive_solid(shape, to_local, transform, bbox)?,
            ),
            CsgNode::Formula { formula, .. } => (
                format!("formula {}", formula.text),
                formula_solid(
                    formula,
                    &self.bounds().unwrap_or(*whole),
                    self.to_local(),
                    transform,
                    bbox,
                )?,
            ),
            CsgNode::Mesh(m) => (
                format!("mesh {}", m.source.display()),
                mesh_solid(
                    m,
                    transform,
                    bbox,
                    &crate::solids::depth_layers::DepthLayerOptions::ALL_DIRECTIONS,
                )?,
            ),
            CsgNode::Subdivision(c) => (
                format!("subdiv {}", c.source.display()),
                subdivision_leaf(c, transform, bbox)?,
            ),
            CsgNode::Grid {
                grid,
                source,
                to_local,
            } => (
                format!("vdb {}", source.display()),
                grid_solid(grid, to_local, transform, bbox)?,
            ),
        };
        let placed = *self.to_local() != DAffine3::IDENTITY;
        leaves.push(LeafReport {
            what: if placed {
                format!("{what} (placed)")
            } else {
                what
            },
            voxels: mask.count(),
        });
        Ok(mask)
    }
}

impl CsgTree {
    /// The grid the tree is evaluated on.
    pub fn transform(&self) -> Result<(Transform, Aabb)> {
        let bounds = self.bounds.or_else(|| self.root.bounds()).ok_or_else(|| {
            Error::InvalidArgument(format!(
                "{}: no leaf has bounds; give \"bounds\" at the top or on the formulas",
                self.source.display()
            ))
        })?;
        Ok((fit_transform(&bounds, self.fit)?, bounds))
    }

    /// The solid (voxels by their centres) and what each leaf contributed.
    pub fn evaluate(&self) -> Result<(Transform, DenseMask, Vec<LeafReport>)> {
        let (transform, bounds) = self.transform()?;
        let bbox = index_box(&bounds, &transform);
        let mut leaves = Vec::new();
        let solid = self.root.evaluate(&transform, bbox, &bounds, &mut leaves)?;
        Ok((transform, solid, leaves))
    }
}
