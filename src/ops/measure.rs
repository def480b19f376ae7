//! Measuring voxel solids (Lai & Cheng §7.2): volume from the inside voxels and from inside
//! plus surface voxels (the true volume lies between them for a separating surface), mass from a
//! density, 6- or 26-connected components, and the Euler characteristic of the solid as a
//! union of closed unit cubes (χ = vertices - edges + faces - cubes), from which the genus of
//! its boundary follows for solids without cavities: genus = components - χ.

use crate::grid::{Adjacency, DenseMask};
use rustc_hash::FxHashSet;

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

/// Volumes of a solid given its `inside` and `surface` voxels (disjoint) and voxel size.
pub fn measure_solid(inside: &DenseMask, surface: &DenseMask, voxel_size: f64) -> SolidMeasures {
    let cell = voxel_size.powi(3);
    let (inside_voxels, surface_voxels) = (inside.count(), surface.count());
    SolidMeasures {
        inside_voxels,
        surface_voxels,
        volume_inside: inside_voxels as f64 * cell,
        volume_with_surface: (inside_voxels + surface_voxels) as f64 * cell,
    }
}

/// Number of `adjacency`-connected components of the set voxels.
pub fn components(set: &DenseMask, adjacency: Adjacency) -> u64 {
    let [nx, ny, nz] = set.dims();
    let mut seen = DenseMask::new(set.bbox).expect("same box as an existing mask");
    let offsets = adjacency.offsets();
    let mut count = 0;
    let mut stack = Vec::new();
    for start in set.ones() {
        if seen.get_index(start) {
            continue;
        }
        count += 1;
        seen.set_index(start);
        stack.push(start);
        while let Some(i) = stack.pop() {
            let at = [
                (i / (ny * nz)) as i64,
                ((i / nz) % ny) as i64,
                (i % nz) as i64,
            ];
            for d in &offsets {
                let c = [at[0] + d[0], at[1] + d[1], at[2] + d[2]];
                if c[0] < 0
                    || c[1] < 0
                    || c[2] < 0
                    || c[0] >= nx as i64
                    || c[1] >= ny as i64
                    || c[2] >= nz as i64
                {
                    continue;
                }
                let j = ((c[0] as usize) * ny + c[1] as usize) * nz + c[2] as usize;
                if set.get_index(j) && !seen.get_index(j) {
                    seen.set_index(j);
                    stack.push(j);
                }
            }
        }
    }
    count
}

/// Euler characteristic of the union of the closed unit cubes of the set voxels.
pub fn euler_characteristic(set: &DenseMask) -> i64 {
    let [_, ny, nz] = set.dims();
    // Lattice elements of a cube at (x,y,z), in doubled coordinates: a vertex has all three
    // coordinates even, an edge one odd, a face two, the cube three.
    let mut elements: [FxHashSet<[i64; 3]>; 4] = Default::default();
    for i in set.ones() {
        let at = [
            (i / (ny * nz)) as i64,
            ((i / nz) % ny) as i64,
            (i % nz) as i64,
        ];
        for dx in 0..3 {
            for dy in 0..3 {
                for dz in 0..3 {
                    let e = [2 * at[0] + dx, 2 * at[1] + dy, 2 * at[2] + dz];
                    let odd = e.iter().filter(|&&v| v % 2 == 1).count();
                    elements[odd].insert(e);
                }
            }
        }
    }
    elements[0].len() as i64 - elements[1].len() as i64 + elements[2].len() as i64
        - elements[3].len() as i64
}

/// Volume (voxel centres where F < 0) and face-weighted area (normals from the gradient of F)
/// of a formula's solid at `resolution` voxels along the longest side of `bounds`.
pub fn measure_formula_solid(
    formula: &crate::implicit::Formula,
    bounds: &crate::mesh::Aabb,
    resolution: u32,
) -> crate::error::Result<(f64, f64)> {
    use crate::mesh::{GridFit, fit_transform, index_box};
    let transform = fit_transform(bounds, GridFit::Resolution(resolution))?;
    let bbox = index_box(bounds, &transform);
    let solid = super::solid_leaves::formula_solid(formula, bounds, &transform, bbox)?;
    let volume = solid.count() as f64 * transform.voxel_size.powi(3);
    let (area, _) = super::surface_area::face_weighted_area(&solid, &transform, |p| {
        formula.gradient_at(p.to_array(), &mut Vec::new())
    });
    Ok((volume, area))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::CoordBox;

    fn mask(n: i64, inside: impl Fn([i64; 3]) -> bool) -> DenseMask {
        let mut m = DenseMask::new(CoordBox {
            min: [0; 3],
            max: [n; 3],
        })
        .unwrap();
        for i in 0..m.len() {
            if inside(m.coord(i)) {
                m.set_index(i);
            }
        }
        m
    }

    #[test]
    fn euler_characteristic_and_genus_of_simple_solids() {
        let cube = mask(6, |c| c.iter().all(|&v| (1..=4).contains(&v)));
        assert_eq!(euler_characteristic(&cube), 1);
        // A square ring: a solid torus, genus 1.
        let ring = mask(8, |c| {
            (1..=6).contains(&c[0])
                && (1..=6).contains(&c[1])
                && (3..=4).contains(&c[2])
                && !((3..=4).contains(&c[0]) && (3..=4).contains(&c[1]))
        });
        assert_eq!(euler_characteristic(&ring), 0);
        assert_eq!(
            components(&ring, Adjacency::Six) as i64 - euler_characteristic(&ring),
            1
        );
        // Two separate cubes: two components, χ = 2, genus 0.
        let two = mask(10, |c| {
            c.iter().all(|&v| (1..=3).contains(&v)) || c.iter().all(|&v| (6..=8).contains(&v))
        });
        assert_eq!(components(&two, Adjacency::TwentySix), 2);
        assert_eq!(euler_characteristic(&two), 2);
    }
}
