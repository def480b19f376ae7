//! Which axis of a file points up. OBJ and many other formats are written Y-up; Blender and
//! OpenVDB's viewers are Z-up, and Blender's OBJ importer turns a Y-up file a quarter turn
//! about x, (x, y, z) -> (x, -z, y). Reading the file the same way puts the volume where
//! Blender puts the imported mesh; a picture of a Y-up grid turns its camera the other way.

use glam::DVec3;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpAxis {
    /// The file is Y-up: turned to Z-up as Blender's OBJ importer turns it.
    Y,
    /// The file's coordinates are kept.
    #[default]
    Z,
}

crate::named_choices! {
    UpAxis, "the up axis":
    "y" => Y,
    "z" => Z,
}

impl UpAxis {
    /// `p` with this up axis turned to +z (a rotation: orientation and volume kept).
    pub fn turn(self, p: DVec3) -> DVec3 {
        match self {
            UpAxis::Y => DVec3::new(p.x, -p.z, p.y),
            UpAxis::Z => p,
        }
    }
}
