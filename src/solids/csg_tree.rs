//! CSG trees read from a small JSON file (Lai & Cheng §7.3 on whole trees): Booleans over
//! boxes, cylinders, spheres, formulas, closed meshes and .vdb grids, evaluated on one grid.
//!
//! ```json
//! { "resolution": 256,
//!   "tree": { "difference": [
//!       { "union": [ { "box": { "min": [-2, -1, 0], "max": [2, 1, 0.5] } },
//!                    { "cylinder": { "base": [0, 0, 0.5], "axis": [0, 0, 1],
//!                                    "radius": 0.8, "height": 1 } } ] },
//!       { "formula": "(sqrt(x^2 + y^2) - 0.8)^2 + (z - 1)^2 - 0.01",
//!         "bounds": { "min": [-1, -1, 0.8], "max": [1, 1, 1.2] } },
//!       { "mesh": "bolt.obj" }, { "vdb": "pocket.vdb", "grid": "surface" } ] } }
//! ```
//!
//! `union` and `intersection` take any number of operands, `difference` removes all later
//! operands from the first. A formula's solid is where F < 0. `voxel_size` may replace
//! `resolution` (voxels along the longest axis of the bounds); `bounds` (top level) fixes the
//! grid's extent, which otherwise covers every leaf (formulas need their own `bounds` then).
//! Files are found relative to the tree file.

use super::csg_leaves::{
    ALL_DIRECTIONS, Primitive, formula_solid, grid_bounds, grid_solid, mesh_solid, primitive_solid,
};
use crate::error::{Error, Result};
use crate::grid::{CoordBox, DenseMask, SparseGrid, Transform};
use crate::implicit::{Coordinates, Formula};
use crate::io::vdb::read_vdb_grid;
use crate::mesh::{Aabb, GridFit, Mesh, fit_transform, index_box};
use crate::ops::csg::BooleanOp;
use crate::shapes::{Cuboid, Cylinder, Sphere};
use glam::DVec3;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

pub enum CsgNode {
    Boolean {
        op: BooleanOp,
        operands: Vec<CsgNode>,
    },
    Primitive(Primitive),
    Formula {
        formula: Formula,
        bounds: Option<Aabb>,
    },
    Mesh(Mesh),
    Grid {
        grid: SparseGrid,
        source: PathBuf,
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
                CsgNode::Grid { source, .. } => files.push(source.clone()),
                CsgNode::Primitive(_) | CsgNode::Formula { .. } => {}
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

/// Reads the tree in `path`, loading its meshes and grids.
pub fn read_csg_tree(path: &Path) -> Result<CsgTree> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let json: Value = serde_json::from_str(&text).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: e.line(),
        message: e.to_string(),
    })?;
    let reader = Reader {
        file: path,
        folder: path.parent().unwrap_or(Path::new(".")),
    };
    let top = reader.object(&json, "the file")?;
    let fit = match (top.get("resolution"), top.get("voxel_size")) {
        (Some(r), None) => {
            let r = reader.number(r, "resolution")?;
            if r < 1.0 || r.fract() != 0.0 || r > 1e6 {
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
    let bounds = top
        .get("bounds")
        .map(|b| reader.aabb(b, "bounds"))
        .transpose()?;
    let root = reader.node(
        top.get("tree")
            .ok_or_else(|| reader.error("the file", "has no \"tree\""))?,
        "tree",
    )?;
    Ok(CsgTree {
        root,
        fit,
        bounds,
        source: path.to_path_buf(),
    })
}

struct Reader<'a> {
    file: &'a Path,
    folder: &'a Path,
}

impl Reader<'_> {
    fn error(&self, at: &str, message: &str) -> Error {
        Error::InvalidArgument(format!("{}: {at}: {message}", self.file.display()))
    }

    fn object<'v>(&self, v: &'v Value, at: &str) -> Result<&'v Map<String, Value>> {
        v.as_object()
            .ok_or_else(|| self.error(at, "expected a JSON object"))
    }

    fn number(&self, v: &Value, at: &str) -> Result<f64> {
        v.as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| self.error(at, "expected a number"))
    }

    fn positive(&self, v: &Value, at: &str) -> Result<f64> {
        let x = self.number(v, at)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.error(at, "must be positive"))
        }
    }

    fn vec3(&self, v: &Value, at: &str) -> Result<DVec3> {
        match v.as_array().map(|a| a.as_slice()) {
            Some([x, y, z]) => Ok(DVec3::new(
                self.number(x, at)?,
                self.number(y, at)?,
                self.number(z, at)?,
            )),
            _ => Err(self.error(at, "expected [x, y, z]")),
        }
    }

    fn field<'v>(&self, m: &'v Map<String, Value>, key: &str, at: &str) -> Result<&'v Value> {
        m.get(key)
            .ok_or_else(|| self.error(at, &format!("needs \"{key}\"")))
    }

    fn aabb(&self, v: &Value, at: &str) -> Result<Aabb> {
        let m = self.object(v, at)?;
        let min = self.vec3(self.field(m, "min", at)?, &format!("{at}.min"))?;
        let max = self.vec3(self.field(m, "max", at)?, &format!("{at}.max"))?;
        if !min.cmplt(max).all() {
            return Err(self.error(at, "min must be below max on every axis"));
        }
        Ok(Aabb { min, max })
    }

    fn path(&self, v: &Value, at: &str) -> Result<PathBuf> {
        v.as_str()
            .map(|p| self.folder.join(p))
            .ok_or_else(|| self.error(at, "expected a file name"))
    }

    fn node(&self, v: &Value, at: &str) -> Result<CsgNode> {
        let m = self.object(v, at)?;
        let kinds = [
            "union",
            "intersection",
            "difference",
            "box",
            "cylinder",
            "sphere",
            "formula",
            "mesh",
            "vdb",
        ];
        let found: Vec<&str> = kinds
            .iter()
            .copied()
            .filter(|k| m.contains_key(*k))
            .collect();
        let [kind] = found[..] else {
            return Err(self.error(at, &format!("needs exactly one of {}", kinds.join(", "))));
        };
        let at = format!("{at}.{kind}");
        let value = &m[kind];
        match kind {
            "union" | "intersection" | "difference" => {
                let items = value
                    .as_array()
                    .filter(|a| !a.is_empty())
                    .ok_or_else(|| self.error(&at, "expected a list of operands"))?;
                let operands = items
                    .iter()
                    .enumerate()
                    .map(|(i, item)| self.node(item, &format!("{at}[{i}]")))
                    .collect::<Result<_>>()?;
                Ok(CsgNode::Boolean {
                    op: kind.parse().expect("a Boolean name"),
                    operands,
                })
            }
            "box" => {
                let b = self.aabb(value, &at)?;
                Ok(CsgNode::Primitive(Primitive::Cuboid(Cuboid {
                    min: b.min,
                    max: b.max,
                })))
            }
            "cylinder" => {
                let c = self.object(value, &at)?;
                let axis = self.vec3(self.field(c, "axis", &at)?, &format!("{at}.axis"))?;
                if axis.length() == 0.0 {
                    return Err(self.error(&at, "the axis must not be zero"));
                }
                Ok(CsgNode::Primitive(Primitive::Cylinder(
                    Cylinder::from_base(
                        self.vec3(self.field(c, "base", &at)?, &format!("{at}.base"))?,
                        axis.normalize(),
                        self.positive(self.field(c, "radius", &at)?, &format!("{at}.radius"))?,
                        self.positive(self.field(c, "height", &at)?, &format!("{at}.height"))?,
                    ),
                )))
            }
            "sphere" => {
                let s = self.object(value, &at)?;
                Ok(CsgNode::Primitive(Primitive::Sphere(Sphere {
                    center: self.vec3(self.field(s, "center", &at)?, &format!("{at}.center"))?,
                    radius: self
                        .positive(self.field(s, "radius", &at)?, &format!("{at}.radius"))?,
                })))
            }
            "formula" => {
                let text = value
                    .as_str()
                    .ok_or_else(|| self.error(&at, "expected the formula as a string"))?;
                let coordinates = match m.get("coordinates") {
                    None => Coordinates::Cartesian,
                    Some(c) => c
                        .as_str()
                        .ok_or_else(|| self.error(&at, "coordinates must be a string"))?
                        .parse()
                        .map_err(|e: String| self.error(&at, &e))?,
                };
                let formula = Formula::parse(text, coordinates)
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                let bounds = m
                    .get("bounds")
                    .map(|b| self.aabb(b, &format!("{at}.bounds")))
                    .transpose()?;
                Ok(CsgNode::Formula { formula, bounds })
            }
            "mesh" => Mesh::load(&self.path(value, &at)?)
                .map(CsgNode::Mesh)
                .map_err(|e| self.error(&at, &e.to_string())),
            _ => {
                let source = self.path(value, &at)?;
                let name = match m.get("grid") {
                    None => "surface",
                    Some(g) => g
                        .as_str()
                        .ok_or_else(|| self.error(&at, "grid must be a string"))?,
                };
                let grid = read_vdb_grid(&source, Some(name))
                    .map_err(|e| self.error(&at, &e.to_string()))?;
                Ok(CsgNode::Grid { grid, source })
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
    fn bounds(&self) -> Option<Aabb> {
        match self {
            CsgNode::Boolean { operands, .. } => {
                operands.iter().map(CsgNode::bounds).fold(None, union)
            }
            CsgNode::Primitive(p) => Some(p.bounds()),
            CsgNode::Formula { bounds, .. } => *bounds,
            CsgNode::Mesh(m) => Some(m.bbox()),
            CsgNode::Grid { grid, .. } => grid_bounds(grid),
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
            CsgNode::Primitive(p) => (p.describe(), primitive_solid(p, transform, bbox)?),
            CsgNode::Formula { formula, bounds } => (
                format!("formula {}", formula.text),
                formula_solid(formula, &bounds.unwrap_or(*whole), transform, bbox)?,
            ),
            CsgNode::Mesh(m) => (
                format!("mesh {}", m.source.display()),
                mesh_solid(m, transform, bbox, &ALL_DIRECTIONS)?,
            ),
            CsgNode::Grid { grid, source } => (
                format!("vdb {}", source.display()),
                grid_solid(grid, transform, bbox)?,
            ),
        };
        leaves.push(LeafReport {
            what,
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
