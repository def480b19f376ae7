//! Per-vertex attributes of a mesh file besides colour: texture coordinates and normals
//! (OBJ `vt`/`vn`, per face corner), and PLY vertex properties (normals, texture coordinates,
//! named scalars). Each is written into a grid of its own: interpolated across each triangle
//! by the projective method, taken at each voxel's nearest point of the mesh by the separating
//! method and the distance bands.

use super::Mesh;
use crate::error::{Error, Result};
pub use crate::grid::attribute_grid::{ATTRIBUTE_CHANNELS, AttributeGrid, AttributeKind};
use glam::{DVec3, Vec3};
use std::borrow::Cow;

/// The name vertex colours take as an attribute carried from the nearest point.
pub const COLOR_ATTRIBUTE: &str = "Cd";

/// One attribute: its values, and which value each face corner takes.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexAttribute {
    /// The grid's name: `uv`, `vertex_normal`, or the PLY property's own name.
    pub name: String,
    pub kind: AttributeKind,
    /// The values, three numbers each (a scalar in x; texture coordinates in x and y).
    pub values: Vec<Vec3>,
    /// Per face corner, parallel to `Mesh::indices`: the value of that corner (OBJ's
    /// `f v/vt/vn`, where one vertex takes several values along a seam). Empty: every corner
    /// takes its vertex's value.
    pub corners: Vec<u32>,
}

impl VertexAttribute {
    /// The value of the corner at `slot` of `Mesh::indices`.
    #[inline]
    pub fn at_corner(&self, indices: &[u32], slot: usize) -> DVec3 {
        let i = if self.corners.is_empty() {
            indices[slot]
        } else {
            self.corners[slot]
        };
        self.values[i as usize].as_dvec3()
    }

    /// The value a voxel keeps of an interpolated `v`: normals back to unit length.
    #[inline]
    pub fn finish(&self, v: DVec3) -> Vec3 {
        match self.kind {
            AttributeKind::Normal => v.normalize_or_zero().as_vec3(),
            _ => v.as_vec3(),
        }
    }
}

/// Which attributes a job writes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AttributeChoice {
    #[default]
    None,
    All,
    Named(Vec<String>),
}

impl AttributeChoice {
    /// The choice a list of names asks for: `all`, `none` (or no names), or the names.
    pub fn of_names(names: &[String]) -> AttributeChoice {
        match names {
            [] => AttributeChoice::None,
            [one] if one == "none" => AttributeChoice::None,
            [one] if one == "all" => AttributeChoice::All,
            _ => AttributeChoice::Named(names.to_vec()),
        }
    }

    /// The attributes of `mesh` chosen, its vertex colours among them (as `Cd`) when
    /// `colours`; a name the mesh does not carry is refused, naming the file and what it
    /// carries.
    pub fn select<'m>(
        &self,
        mesh: &'m Mesh,
        colours: bool,
    ) -> Result<Vec<Cow<'m, VertexAttribute>>> {
        let colour = colours.then(|| mesh.color_attribute()).flatten();
        let carried: Vec<Cow<VertexAttribute>> = mesh
            .attributes
            .iter()
            .map(Cow::Borrowed)
            .chain(colour.map(Cow::Owned))
            .collect();
        match self {
            AttributeChoice::None => Ok(Vec::new()),
            AttributeChoice::All => Ok(carried),
            AttributeChoice::Named(names) => {
                let mut chosen = Vec::new();
                for name in names {
                    let Some(a) = carried.iter().find(|a| &a.name == name) else {
                        let names: Vec<&str> = carried.iter().map(|a| a.name.as_str()).collect();
                        return Err(Error::InvalidArgument(format!(
                            "{}: the mesh carries no attribute `{name}`; it carries {}",
                            mesh.source.display(),
                            if names.is_empty() {
                                "none".to_string()
                            } else {
                                names.join(", ")
                            }
                        )));
                    };
                    chosen.push(a.clone());
                }
                Ok(chosen)
            }
        }
    }
}

impl Mesh {
    /// Every attribute refers to values it has, one per vertex or per corner.
    pub(super) fn validate_attributes(&self) -> Result<()> {
        for a in &self.attributes {
            let bad = |what: String| {
                Error::InvalidArgument(format!(
                    "{}: attribute `{}`: {what}",
                    self.source.display(),
                    a.name
                ))
            };
            if a.corners.is_empty() {
                if a.values.len() != self.positions.len() {
                    return Err(bad(format!(
                        "{} values for {} vertices",
                        a.values.len(),
                        self.positions.len()
                    )));
                }
            } else if a.corners.len() != self.indices.len() {
                return Err(bad(format!(
                    "{} corners for {} face corners",
                    a.corners.len(),
                    self.indices.len()
                )));
            } else if let Some(&i) = a.corners.iter().find(|&&i| i as usize >= a.values.len()) {
                return Err(bad(format!(
                    "a corner takes value {i}, of {}",
                    a.values.len()
                )));
            }
        }
        Ok(())
    }

    /// The vertex colours as an attribute, when the mesh has them.
    pub fn color_attribute(&self) -> Option<VertexAttribute> {
        (!self.colors.is_empty()).then(|| VertexAttribute {
            name: COLOR_ATTRIBUTE.into(),
            kind: AttributeKind::Color,
            values: self.colors.clone(),
            corners: Vec::new(),
        })
    }

    /// The values of attribute `a` at the corners of fan triangle `slots` (positions in
    /// `indices`).
    #[inline]
    pub fn attribute_corners(&self, a: &VertexAttribute, slots: [usize; 3]) -> [DVec3; 3] {
        slots.map(|s| a.at_corner(&self.indices, s))
    }
}

impl AttributeGrid {
    /// The grid of `attribute` from interpolated values in `grid`'s colour channel: normals
    /// back to unit length, a scalar copied into the value channel.
    pub fn finished(
        attribute: &VertexAttribute,
        mut grid: crate::grid::SparseGrid,
    ) -> AttributeGrid {
        use rayon::prelude::*;
        grid.leaves_mut().par_iter_mut().for_each(|leaf| {
            let offsets: Vec<usize> = leaf.offsets().collect();
            let (Some(colors), Some(values)) = (leaf.color.as_mut(), leaf.value.as_mut()) else {
                unreachable!("attribute grids carry colours and values");
            };
            for n in offsets {
                let v = attribute.finish(Vec3::from_array(colors[n]).as_dvec3());
                colors[n] = v.to_array();
                values[n] = v.x;
            }
        });
        AttributeGrid {
            name: attribute.name.clone(),
            kind: attribute.kind,
            grid,
        }
    }
}
