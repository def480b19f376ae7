//! Measuring voxel solids (Lai & Cheng §7.2): volume from the inside voxels and from inside
//! plus surface voxels (the true volume lies between them for a separating surface), mass from a
//! density, 6- or 26-connected components, and the Euler characteristic of the solid as a
//! union of closed unit cubes (χ = vertices - edges + faces - cubes), from which the genus of
//! its boundary follows for solids without cavities: genus = components - χ.

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolidMeasures {
    pub inside_voxels: u64,
    pub surface_voxels: u64,
    /// Volumes in world units: inside voxels only, and inside plus surface voxels.
    pub volume_inside: f64,
    pub volume_with_surface: f64,
}

impl SolidMeasures {
    /// Mass for a uniform `density` (per world unit of volume), on both volumes.
    pub fn mass(&self, density: f64) -> (f64, f64) {
        (
            self.volume_inside * density,
            self.volume_with_surface * density,
        )
    }
}

impl SolidMeasures {
    /// Volumes of a solid from its numbers of `inside` and `surface` voxels (disjoint sets)
    /// and its voxel size.
    pub fn of(inside_voxels: u64, surface_voxels: u64, voxel_size: f64) -> SolidMeasures {
        let cell = voxel_size.powi(3);
        SolidMeasures {
            inside_voxels,
            surface_voxels,
            volume_inside: inside_voxels as f64 * cell,
            volume_with_surface: (inside_voxels + surface_voxels) as f64 * cell,
        }
    }
}
