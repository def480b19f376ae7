//! Attributes carried by the nearest feature: every voxel of a separating surface or a
//! distance band takes each attribute's value at the point of the mesh nearest its centre
//! (on the nearest triangle, by its barycentric weights there). One nearest-point query per
//! voxel serves every attribute.

use super::Mesh;
use super::attributes::{ATTRIBUTE_CHANNELS, AttributeGrid, VertexAttribute};
use super::winding::WindingTree;
use crate::error::Result;
use crate::grid::{Leaf, SparseGrid};
use crate::progress::Progress;
use rayon::prelude::*;

/// The grids of `attributes` on the voxels of `voxels`, each voxel's value taken at the
/// point of `mesh` nearest its centre. `progress` counts leaves.
pub fn carry_nearest(
    mesh: &Mesh,
    voxels: &SparseGrid,
    attributes: &[&VertexAttribute],
    progress: &Progress,
) -> Result<Vec<AttributeGrid>> {
    if attributes.is_empty() {
        return Ok(Vec::new());
    }
    let tree = WindingTree::new(mesh);
    // The corners of each triangle in `indices`, in the tree's numbering.
    let slots: Vec<[usize; 3]> = (0..mesh.face_count())
        .flat_map(|f| mesh.fan_corners(f))
        .collect();
    let transform = voxels.transform;
    let leaves: Vec<Vec<Leaf>> = voxels
        .leaves()
        .par_iter()
        .map(|leaf| {
            let mut out: Vec<Leaf> = attributes
                .iter()
                .map(|_| Leaf::new(leaf.origin, ATTRIBUTE_CHANNELS))
                .collect();
            if progress.stopped() {
                return out;
            }
            for (n, c) in leaf.offsets().zip(leaf.coords()) {
                let centre = transform.index_to_world(c);
                let Some((t, w)) = tree.nearest_point(centre) else {
                    continue;
                };
                for (a, o) in attributes.iter().zip(out.iter_mut()) {
                    let [x, y, z] = mesh.attribute_corners(a, slots[t]);
                    let value = w.x * x + w.y * y + w.z * z;
                    o.set_on(n);
                    o.color.as_mut().expect("attribute channels")[n] = value.as_vec3().to_array();
                }
            }
            progress.advance(1);
            out
        })
        .collect();
    progress.check()?;
    let mut per_attribute: Vec<Vec<Leaf>> = attributes.iter().map(|_| Vec::new()).collect();
    for leaf_set in leaves {
        for (k, leaf) in leaf_set.into_iter().enumerate() {
            per_attribute[k].push(leaf);
        }
    }
    Ok(attributes
        .iter()
        .zip(per_attribute)
        .map(|(a, leaves)| {
            let grid = SparseGrid::from_distinct_leaves(transform, ATTRIBUTE_CHANNELS, leaves);
            AttributeGrid::finished(a, grid)
        })
        .collect())
}
