//! Loading: a task's inputs read and checked (meshes, control meshes, formulas, CSG trees,
//! grids), each kept beside the options that act on it, so that pricing and running match
//! one enum and never a task against what was loaded for it.

use super::attribute_grids::Carry;
use super::{
    BrickStage, BrickTask, CsgSource, Fill, GridSource, MeasureSource, MeshSource, ShapeTask,
    SubdivisionOutput, SurfaceMethod, Task, lines_source,
};
use crate::error::{Error, Result};
use crate::grid::SparseGrid;
use crate::implicit::Formula;
use crate::io::vdb::{NORMAL_GRID, SHELL_GRID, read_vdb_grid, read_vdb_info, read_vdb_solid};
use crate::mesh::attributes::{AttributeChoice, AttributeKind};
use crate::mesh::{Mesh, UpAxis};
use crate::ops::csg::BooleanOp;
use crate::solids::csg_tree::{CsgTree, parse_csg_tree, read_csg_tree};
use crate::solids::exterior_flood::FloodMethod;
use crate::solids::inside_rule::InsideRule;
use crate::subd::ControlMesh;
use crate::voxelize::parametric::ParametricOptions;
use crate::voxelize::projective::{Coloring, LineSource};
use crate::voxelize::separating::SeparatingOptions;
use glam::DVec3;
use std::path::Path;
use std::sync::Arc;

/// A task with its inputs in memory.
pub(super) enum Work {
    MeshSurface {
        mesh: Mesh,
        method: SurfaceMethod,
        attributes: AttributeChoice,
    },
    SeparationCheck {
        mesh: Mesh,
        options: SeparatingOptions,
    },
    Lines {
        mesh: Mesh,
        source: LineSource,
        coloring: Coloring,
    },
    Shape(ShapeTask),
    Subdivision {
        control: ControlMesh,
        options: ParametricOptions,
        output: SubdivisionOutput,
    },
    Implicit {
        formula: Formula,
        text: String,
        min: DVec3,
        max: DVec3,
        levels: bool,
        negative_r: bool,
        depth_layers: bool,
    },
    DistanceBand {
        /// Shared with the outcome, whose meshes take their crossings from it.
        mesh: Arc<Mesh>,
        band: f64,
        signed: bool,
        inside: InsideRule,
        attributes: AttributeChoice,
    },
    Solid {
        mesh: Mesh,
        fill: Fill,
        density: f64,
        topology: bool,
        inside: InsideRule,
    },
    MeasureMesh {
        mesh: Mesh,
        flood: FloodMethod,
        density: f64,
        inside: InsideRule,
    },
    /// A surface grid to fill and weigh.
    MeasureSurface {
        surface: SparseGrid,
        flood: FloodMethod,
        density: f64,
    },
    CsgTree(Box<CsgTree>),
    Brick(BrickTask),
    Combine {
        /// At least two.
        operands: Vec<SparseGrid>,
        /// Each operand's normals, where it has them (a `normal` grid).
        normals: Vec<Option<SparseGrid>>,
        op: BooleanOp,
        resample: bool,
        curve: bool,
    },
}

impl Work {
    /// What the input mesh holds that this job does not write: its unread attributes, those
    /// it does not choose, and its vertex colours unless the job colours its voxels with them.
    pub(super) fn unwritten_attributes(&self) -> Option<String> {
        let none = AttributeChoice::None;
        let (mesh, colours_kept, chosen, carry): (&Mesh, bool, &AttributeChoice, Carry) = match self
        {
            Work::MeshSurface {
                mesh,
                method,
                attributes,
            } => (
                mesh,
                matches!(
                    method,
                    SurfaceMethod::Projective(super::ColorChoice::FromMesh)
                ),
                attributes,
                Carry::of(method),
            ),
            Work::Lines { mesh, coloring, .. } => (
                mesh,
                *coloring == Coloring::Vertex,
                &none,
                Carry::Interpolated,
            ),
            Work::DistanceBand {
                mesh, attributes, ..
            } => (mesh, false, attributes, Carry::Nearest),
            Work::SeparationCheck { mesh, .. }
            | Work::Solid { mesh, .. }
            | Work::MeasureMesh { mesh, .. } => (mesh, false, &none, Carry::Nearest),
            _ => return None,
        };
        let written = chosen
            .select(mesh, carry.carries_colours())
            .unwrap_or_default();
        let colours_kept = colours_kept || written.iter().any(|a| a.kind == AttributeKind::Color);
        let mut unwritten: Vec<String> = mesh
            .attributes
            .iter()
            .filter(|a| !written.iter().any(|w| w.name == a.name))
            .map(|a| format!("`{}`", a.name))
            .collect();
        let attributes_dropped = !unwritten.is_empty();
        unwritten.extend(mesh.unread.iter().cloned());
        let colours_dropped = !mesh.colors.is_empty() && !colours_kept;
        if colours_dropped {
            unwritten.insert(0, "vertex colours".into());
        }
        (!unwritten.is_empty()).then(|| {
            format!(
                "{}: its {} are not written (voxelkit writes the shape{}{})",
                mesh.source.display(),
                unwritten.join(", "),
                if colours_dropped {
                    ", vertex colours as `Cd` with --method projective, `lines` or `mesh --attributes Cd`"
                } else {
                    ""
                },
                if attributes_dropped {
                    ", and vertex attributes with `mesh --attributes all` (or their names)"
                } else {
                    ""
                }
            )
        })
    }
}

/// `mesh`, refused before any work when it lacks an attribute `chosen` names.
fn with_attributes(mesh: Mesh, chosen: &AttributeChoice) -> Result<Mesh> {
    chosen.select(&mesh, true)?;
    Ok(mesh)
}

/// Reads what `task` needs; mesh files are turned `up`.
pub(super) fn load(task: &Task, up: UpAxis) -> Result<Work> {
    let mesh = |source: &MeshSource| source.load(false, up);
    Ok(match task {
        Task::MeshSurface {
            mesh: m,
            method,
            attributes,
        } => Work::MeshSurface {
            mesh: with_attributes(mesh(m)?, attributes)?,
            method: *method,
            attributes: attributes.clone(),
        },
        Task::SeparationCheck { mesh: m, options } => Work::SeparationCheck {
            mesh: mesh(m)?,
            options: *options,
        },
        Task::Lines {
            mesh: m,
            edges,
            color,
        } => {
            let mesh = m.load(true, up)?;
            Work::Lines {
                source: lines_source(&mesh, *edges),
                coloring: color.coloring(&mesh),
                mesh,
            }
        }
        Task::Shape(s) => Work::Shape(s.clone()),
        Task::Subdivision {
            mesh,
            options,
            output,
        } => Work::Subdivision {
            control: match mesh {
                MeshSource::File(path) => {
                    let mut control = ControlMesh::load(path)?;
                    control.map_points(|p| up.turn(p));
                    control
                }
                MeshSource::Mesh(m) => ControlMesh::from_mesh(m)?,
            },
            options: *options,
            output: *output,
        },
        Task::Implicit {
            formula,
            coordinates,
            min,
            max,
            levels,
            negative_r,
            theta_range,
            squared,
            depth_layers,
        } => {
            // The sign of the squared substitution or of F at negative r does not say inside.
            if *depth_layers && (*squared || *negative_r || *levels) {
                return Err(Error::InvalidArgument(
                    "depth layers make the solid F < 0: they take neither the squared \
                     substitution, negative r nor the octree's levels"
                        .into(),
                ));
            }
            let size = *max - *min;
            if !(size.max_element().is_finite() && size.min_element() > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "the bounds {min} .. {max} must be a box with positive size on every axis"
                )));
            }
            Work::Implicit {
                formula: Formula {
                    squared: *squared,
                    ..Formula::parse_in(formula, *coordinates, *theta_range)?
                },
                text: formula.clone(),
                min: *min,
                max: *max,
                levels: *levels,
                negative_r: *negative_r,
                depth_layers: *depth_layers,
            }
        }
        Task::DistanceBand {
            mesh: m,
            band,
            signed,
            inside,
            attributes,
        } => Work::DistanceBand {
            mesh: Arc::new(with_attributes(mesh(m)?, attributes)?),
            band: *band,
            signed: *signed,
            inside: *inside,
            attributes: attributes.clone(),
        },
        Task::Solid {
            mesh: m,
            fill,
            density,
            topology,
            inside,
        } => Work::Solid {
            mesh: mesh(m)?,
            fill: *fill,
            density: *density,
            topology: *topology,
            inside: *inside,
        },
        Task::Measure {
            source,
            flood,
            density,
            inside,
        } => match source {
            MeasureSource::Mesh(m) => Work::MeasureMesh {
                mesh: mesh(m)?,
                flood: *flood,
                density: *density,
                inside: *inside,
            },
            MeasureSource::Vdb(path) => Work::MeasureSurface {
                surface: read_surface(path)?,
                flood: *flood,
                density: *density,
            },
            MeasureSource::Grid(grid) => Work::MeasureSurface {
                surface: grid.clone(),
                flood: *flood,
                density: *density,
            },
        },
        Task::CsgTree(source) => Work::CsgTree(Box::new(match source {
            CsgSource::File(path) => read_csg_tree(path)?,
            CsgSource::Json { text, folder } => {
                parse_csg_tree(text, Path::new("the CSG tree"), folder)?
            }
        })),
        Task::Brick(brick) => {
            match &brick.stage {
                // A winding brick may lie wholly inside the mesh, without faces of its own.
                BrickStage::Winding { mesh } => {
                    mesh.validate()?;
                    if brick.faces.face_count() > 0 {
                        brick.faces.validate()?;
                    }
                }
                _ => brick.faces.validate()?,
            }
            Work::Brick(brick.clone())
        }
        Task::Combine {
            operands,
            grid,
            op,
            resample,
            curve,
        } => {
            // Operands of a Boolean are solids: a level set stands for its inside. The curve of
            // two surfaces takes their voxels as they are.
            let read = |g: &GridSource| match g {
                GridSource::File(path) if *curve => read_vdb_grid(path, grid.as_deref()),
                GridSource::File(path) => read_vdb_solid(path, grid.as_deref()),
                GridSource::Grid(g) => Ok(g.clone()),
            };
            if operands.len() < 2 {
                return Err(Error::InvalidArgument(format!(
                    "a Boolean needs at least two grids, {} given",
                    operands.len()
                )));
            }
            let normals = |g: &GridSource| match g {
                GridSource::File(path) => read_vdb_info(path)?
                    .iter()
                    .any(|i| i.name == NORMAL_GRID && i.value_type == "vec3s")
                    .then(|| read_vdb_grid(path, Some(NORMAL_GRID)))
                    .transpose(),
                GridSource::Grid(g) => Ok(g.channels().normal.then(|| g.clone())),
            };
            Work::Combine {
                operands: operands.iter().map(read).collect::<Result<_>>()?,
                normals: operands.iter().map(normals).collect::<Result<_>>()?,
                op: *op,
                resample: *resample,
                curve: *curve,
            }
        }
    })
}

/// The surface of a `.vdb` to measure: a solid's `shell` when it is one, else its voxel set.
fn read_surface(path: &Path) -> Result<SparseGrid> {
    read_vdb_grid(path, Some(SHELL_GRID)).or_else(|_| read_vdb_grid(path, None))
}
