//! Cavities: the regions a closed mesh's surface encloses that are not inside it. The
//! exterior flood calls everything it cannot reach inside, which for a solid with an inward
//! shell (a hollow part: a box with a box-shaped void) fills the void too. The winding number
//! says which enclosed region is inside: only a mesh of several shells can enclose one that
//! is not, so each shell seeds its own region with a voxel just behind it, and a region whose
//! winding number is 0 is flooded within the inside and taken out of it.

use crate::error::Result;
use crate::grid::{Adjacency, Coord, CoordBox, DenseMask, SparseGrid};
use crate::mesh::shells::shells;
use crate::mesh::winding::WindingTree;
use crate::mesh::{Mesh, index_box};
use crate::ops::flood::flood;

/// Steps (in voxels) from a face's centre to the voxel behind it that seeds its region.
const SEED_STEPS: [f64; 4] = [0.75, 1.5, 2.5, 3.5];

/// Bytes the removal may allocate: three bits per voxel (the region, what blocks it and what
/// the flood reached) over the box of the second-largest shell, the largest a cavity's
/// boundary can be (the outer shell encloses it). Zero for a mesh of one shell.
pub fn cavity_bytes(mesh: &Mesh, voxel_size: f64) -> f64 {
    let mut volumes: Vec<f64> = shells(mesh)
        .iter()
        .map(|faces| {
            let b = mesh.bbox_of(faces);
            ((b.max - b.min) / voxel_size + 3.0).element_product()
        })
        .collect();
    volumes.sort_by(|a, b| b.total_cmp(a));
    volumes.get(1).map_or(0.0, |v| 3.0 * v / 8.0)
}

/// A voxel of `inside` just behind `faces` (against their orientation, so on the side the
/// shell encloses), from the face of largest area.
fn seed_behind(mesh: &Mesh, faces: &[u32], inside: &SparseGrid) -> Option<Coord> {
    let orientation = mesh.signed_volume_of(faces).signum();
    let (area, centre, normal) = faces
        .iter()
        .flat_map(|&f| mesh.fan(f as usize))
        .map(|[a, b, c]| {
            let n = (mesh.p(b) - mesh.p(a)).cross(mesh.p(c) - mesh.p(a));
            (n.length(), (mesh.p(a) + mesh.p(b) + mesh.p(c)) / 3.0, n)
        })
        .max_by(|x, y| x.0.total_cmp(&y.0))?;
    if area <= 0.0 {
        return None;
    }
    let behind = -normal / area * orientation;
    let t = inside.transform;
    SEED_STEPS.iter().find_map(|&step| {
        let p = t.world_to_index(centre + behind * step * t.voxel_size);
        let c = p.round().as_i64vec3().to_array();
        inside.contains(c).then_some(c)
    })
}

/// Takes out of `inside` (what the exterior flood could not reach) every region enclosed by
/// `mesh` whose winding number is 0; returns the voxels taken out.
pub fn remove_cavities(mesh: &Mesh, inside: &mut SparseGrid) -> Result<u64> {
    let shells = shells(mesh);
    if shells.len() < 2 {
        return Ok(0);
    }
    let t = inside.transform;
    // Seeds lie in regions of integer winding (0 or not): the tree's error cannot blur them.
    let winding = WindingTree::new(mesh);
    let mut removed = 0;
    for faces in &shells {
        let Some(seed) = seed_behind(mesh, faces, inside) else {
            continue;
        };
        if winding.winding_number(t.index_to_world(seed)).abs() >= 0.5 {
            continue;
        }
        let Some(region) =
            index_box(&mesh.bbox_of(faces), &t).intersection(&inside.bbox().unwrap_or(CoordBox {
                min: seed,
                max: seed,
            }))
        else {
            continue;
        };
        let enclosed = DenseMask::from_grid(inside, region)?;
        let mut blocked = DenseMask::new(region)?;
        blocked.set_box(region);
        let blocked = blocked.minus(&enclosed);
        let mut seeds = DenseMask::new(region)?;
        seeds.set(seed);
        let cavity = flood(&blocked, &seeds, Adjacency::Six)?;
        removed += cavity.count();
        inside.difference(&cavity.to_grid(t));
    }
    Ok(removed)
}
