//! Connected components of the clear voxels of a dense box, by face adjacency (the
//! exterior flood's), each with a label of its own.

use crate::error::{Error, Result};
use crate::grid::DenseMask;

/// Per voxel of `blocked`'s box: 0 where it is set, else the label (1, 2, ..) of its
/// 6-connected component of clear voxels; and the number of labels.
pub fn label_clear_components(blocked: &DenseMask) -> Result<(Vec<u32>, u32)> {
    let [nx, ny, nz] = blocked.dims();
    let mut labels = vec![0u32; blocked.len()];
    let mut next = 0u32;
    let mut queue = Vec::new();
    let strides = [ny * nz, nz, 1];
    let dims = [nx, ny, nz];
    for start in 0..labels.len() {
        if labels[start] != 0 || blocked.get_index(start) {
            continue;
        }
        next = next
            .checked_add(1)
            .ok_or_else(|| Error::Unsupported("more than 2^32 components in one box".into()))?;
        labels[start] = next;
        queue.push(start);
        while let Some(i) = queue.pop() {
            let at = [i / strides[0], (i / nz) % ny, i % nz];
            for axis in 0..3 {
                let s = strides[axis];
                let mut visit = |j: usize| {
                    if labels[j] == 0 && !blocked.get_index(j) {
                        labels[j] = next;
                        queue.push(j);
                    }
                };
                if at[axis] > 0 {
                    visit(i - s);
                }
                if at[axis] + 1 < dims[axis] {
                    visit(i + s);
                }
            }
        }
    }
    Ok((labels, next))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::CoordBox;

    #[test]
    fn a_wall_splits_the_box_and_a_diagonal_gap_does_not_join() {
        let bbox = CoordBox {
            min: [0, 0, 0],
            max: [5, 3, 3],
        };
        let mut wall = DenseMask::new(bbox).unwrap();
        for y in 0..4 {
            for z in 0..4 {
                wall.set([2, y, z]);
            }
        }
        let (labels, n) = label_clear_components(&wall).unwrap();
        assert_eq!(n, 2);
        assert_eq!(labels[wall.index([0, 0, 0])], 1);
        assert_eq!(labels[wall.index([5, 3, 3])], 2);
        assert_eq!(labels[wall.index([2, 1, 1])], 0);
        // Two voxels touching only along an edge are not face-connected.
        let mut pair = DenseMask::new(CoordBox {
            min: [0, 0, 0],
            max: [1, 1, 0],
        })
        .unwrap();
        pair.set([0, 1, 0]);
        pair.set([1, 0, 0]);
        assert_eq!(label_clear_components(&pair).unwrap().1, 2);
    }
}
