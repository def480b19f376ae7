//! The inside centres of a closed mesh read from its columns' crossings (`ColumnCrossings`)
//! only where a grid near its surface has leaves: the narrow band of a level set, the
//! 26-separating surface of a solid. Such a grid has a voxel in every 8^3 block the surface
//! passes through, so a block without one holds centres on one side only, and its first
//! centre decides it whole: the columns are read at each leaf's 64 rows and at one centre of
//! each other block, not at every block of the box.

use super::winding_inside::{closed_by_caps, winds_reversed};
use crate::grid::{Channels, Coord, CoordBox, Leaf, NODE_DIM, NodeMask, SparseGrid, Transform};
use crate::mesh::Mesh;
use crate::mesh::boundary_caps::BoundaryCaps;
use crate::mesh::inside::{ColumnCrossings, ColumnRule};
use rayon::prelude::*;

/// The columns of `bbox` of a closed, consistently oriented mesh (closed by `caps`, none on
/// a closed mesh), read by its winding number: the signed count of crossings below a centre,
/// taken in the mesh's orientation.
pub fn winding_columns(
    mesh: &Mesh,
    caps: &BoundaryCaps,
    transform: &Transform,
    bbox: CoordBox,
) -> ColumnCrossings {
    let (points, triangles) = closed_by_caps(mesh, caps);
    let orientation = if winds_reversed(&points, &triangles) {
        -1
    } else {
        1
    };
    ColumnCrossings::of_triangles(&points, &triangles, transform, bbox)
        .read_by(ColumnRule::Winding { orientation })
}

/// The inside centres of the leaf at `origin`, as a leaf mask.
pub fn leaf_inside(columns: &ColumnCrossings, origin: Coord) -> [u64; 8] {
    let mut mask = [0u64; 8];
    for (x, word) in mask.iter_mut().enumerate() {
        columns.row_spans(origin[0] + x as i64, origin[1], 8, |y, z0, z1| {
            let (z0, z1) = ((z0 - origin[2]).max(0), (z1 - origin[2]).min(7));
            if z0 <= z1 {
                let run = (1u64 << (z1 - z0 + 1)) - 1;
                *word |= run << (y * 8 + z0 as usize);
            }
        });
    }
    mask
}

/// The inside centres: `leaves` (those of `near`'s blocks, found by `leaf_inside`) and every
/// block of `near`'s columns without a leaf of `near` whose first centre is inside, as a tile.
pub fn interior(
    columns: &ColumnCrossings,
    near: &SparseGrid,
    leaves: impl IntoIterator<Item = Leaf> + Send,
    transform: Transform,
) -> SparseGrid {
    // The leaves' index is made (on one thread) while the whole blocks are found.
    let (mut interior, blocks) = rayon::join(
        || {
            let leaves = leaves.into_iter().collect();
            SparseGrid::from_distinct_leaves(transform, Channels::NONE, leaves)
        },
        || inside_blocks(columns, near),
    );
    interior.fill_free_node_masks(&blocks);
    interior
}

/// The inside centres near `near` (`interior`), each of its leaves' found by `leaf_inside`.
pub fn interior_near(columns: &ColumnCrossings, near: &SparseGrid) -> SparseGrid {
    let leaves: Vec<Leaf> = near
        .leaves()
        .par_iter()
        .map(|l| Leaf::with_mask(l.origin, leaf_inside(columns, l.origin)))
        .filter(|l| !l.is_empty())
        .collect();
    interior(columns, near, leaves, near.transform)
}

/// The 8^3 blocks wholly inside, as each 128^3 node's mask of them: those without a leaf of
/// `near` whose first centre is inside (only blocks in the columns' box can be). Found on all
/// threads by column of nodes, each node's blocks kept as its bits: listed one by one, a
/// large inside's blocks (igea's level set at 1024: 557,000) were joined and sorted into their
/// nodes on one thread.
fn inside_blocks(columns: &ColumnCrossings, near: &SparseGrid) -> Vec<NodeMask> {
    let ([x0, x1], [y0, y1]) = columns.columns();
    let first = |v: i64| (v + 7) & !7;
    let node = |v: i64| v & !(NODE_DIM - 1);
    let node_columns: Vec<(i64, i64)> = (node(x0)..=x1)
        .step_by(NODE_DIM as usize)
        .flat_map(|nx| {
            (node(y0)..=y1)
                .step_by(NODE_DIM as usize)
                .map(move |ny| (nx, ny))
        })
        .collect();
    node_columns
        .par_iter()
        .with_max_len(1)
        .flat_map_iter(|&(nx, ny)| {
            // The column's nodes as their first blocks are found: a few, each found by a
            // look along them.
            let mut masks: Vec<NodeMask> = Vec::new();
            for x in (first(x0.max(nx))..=x1.min(nx + NODE_DIM - 1)).step_by(8) {
                for y in (first(y0.max(ny))..=y1.min(ny + NODE_DIM - 1)).step_by(8) {
                    columns.spans(x, y, |z0, z1| {
                        for z in (first(z0)..=z1).step_by(8) {
                            if near.leaf([x, y, z]).is_some() {
                                continue;
                            }
                            let at = [nx, ny, node(z)];
                            let k = masks.iter().position(|m| m.node() == at);
                            let k = k.unwrap_or_else(|| {
                                masks.push(NodeMask::new(at));
                                masks.len() - 1
                            });
                            masks[k].insert([x, y, z]);
                        }
                    });
                }
            }
            masks
        })
        .collect()
}
