//! A mesh attribute on a job's voxels (`mesh::attributes` makes them): how it is written, and
//! its grid.

use super::{Channels, SparseGrid};

/// How an attribute's values are written and turned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttributeKind {
    /// One number per vertex (a FloatGrid).
    Scalar,
    /// Texture coordinates `(u, v, 0)` (a Vec3SGrid whose vectors do not turn with the grid).
    TextureCoordinates,
    /// Unit normals, renormalized after interpolation (a Vec3SGrid of covariant normals).
    Normal,
    /// Vertex colours (a Vec3SGrid `Cd`, as the projective method writes its own).
    Color,
}

/// An attribute on a job's voxels: its values in the grid's colour channel (a scalar in its
/// value channel), written as a grid of the attribute's name.
pub struct AttributeGrid {
    pub name: String,
    pub kind: AttributeKind,
    pub grid: SparseGrid,
}

/// The channels an attribute grid holds.
pub const ATTRIBUTE_CHANNELS: Channels = Channels {
    value: true,
    normal: false,
    color: true,
};
