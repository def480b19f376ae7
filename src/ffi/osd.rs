//! The cxx bridge to OpenSubdiv (`cpp/osd_bridge.cc`): limit points computed by OpenSubdiv
//! itself, with the Catmull-Clark scheme and VTX_BOUNDARY_EDGE_AND_CORNER. The control mesh
//! crosses as flat arrays; every C++ function turns its exceptions into `Result` errors.

#[cxx::bridge(namespace = "voxelkit::osd")]
pub mod bridge {
    /// Points of the limit surface: per point its face, (u, v), position and unit normal.
    struct LimitPoints {
        face: Vec<u32>,
        uv: Vec<f64>,
        position: Vec<f64>,
        normal: Vec<f64>,
    }

    /// A control mesh with its creases and corners, as OpenSubdiv's `TopologyDescriptor`
    /// takes it.
    struct ControlCage {
        positions: Vec<f64>,
        face_sizes: Vec<i32>,
        face_verts: Vec<i32>,
        /// Vertex pairs of the sharp edges, and one sharpness per pair.
        crease_verts: Vec<i32>,
        crease_weights: Vec<f32>,
        corner_verts: Vec<i32>,
        corner_weights: Vec<f32>,
    }

    unsafe extern "C++" {
        include!("voxelkit/cpp/osd_bridge.h");

        fn limit_at_dyadic(
            cage: &ControlCage,
            level: i32,
            lattice_level: i32,
        ) -> Result<LimitPoints>;

        fn limit_at(
            cage: &ControlCage,
            faces: &[u32],
            uv: &[f64],
            approx_level: i32,
        ) -> Result<LimitPoints>;
    }
}
