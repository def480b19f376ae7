//! Catmull-Clark subdivision surfaces: control meshes, and exact evaluation of the limit
//! surface (position, derivatives, normal) in OpenSubdiv's parametrization.

mod area;
mod bicubic;
mod certified_tessellation;
mod compare;
mod control_mesh;
mod crease;
mod limit_masks;
mod local_eigen;
#[cfg(feature = "osd")]
pub mod opensubdiv;
mod patch;
mod points_file;
mod poly_mesh;
mod subdivide;
mod surface;
mod tags;

pub use area::{limit_area, limit_volume, limit_volume_and_area};
pub use certified_tessellation::{
    CertifiedTessellation, TESSELLATION_TRIANGLE_BYTES, certified_leaf_count,
    certified_tessellation,
};
pub use compare::{Comparison, angle_between, compare_points};
pub use control_mesh::{ControlMesh, ControlStats};
pub use patch::LimitSample;
pub use points_file::{SurfacePoint, parse_points, read_points};
pub use surface::{LimitSurface, PatchDomain, subface_tiles};
pub use tags::Tags;
