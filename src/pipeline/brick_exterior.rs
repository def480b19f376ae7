//! Which outside components of which bricks are the exterior: the components meeting across
//! brick faces are joined (union-find), and those joined to the layout's outer faces, which
//! lie beyond the surface, are outside the solid.

use super::bricks::{BrickIndex, BrickLayout, FACES};
use crate::error::{Error, Result};
use std::collections::{BTreeMap, HashMap};

/// Union-find over (brick, label) pairs; node 0 is the exterior.
struct Joins {
    ids: HashMap<(BrickIndex, u32), usize>,
    parent: Vec<usize>,
}

impl Joins {
    fn id(&mut self, key: (BrickIndex, u32)) -> usize {
        let next = self.parent.len();
        let id = *self.ids.entry(key).or_insert(next);
        if id == next {
            self.parent.push(next);
        }
        id
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        // The smaller root wins, so the exterior (0) stays a root.
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb);
        }
    }
}

/// `faces`: for each brick holding surface, the labels on its six faces (`BrickOutside::face`).
/// Bricks without an entry hold no surface: one component, label 1, fills them.
/// Returns, for every brick of the layout, its exterior labels in ascending order.
pub fn exterior_labels(
    layout: &BrickLayout,
    faces: &BTreeMap<BrickIndex, Vec<Vec<u32>>>,
) -> Result<BTreeMap<BrickIndex, Vec<u32>>> {
    let cells = (layout.size * layout.size) as usize;
    for (b, f) in faces {
        if f.len() != FACES || f.iter().any(|face| face.len() != cells) {
            return Err(Error::InvalidArgument(format!(
                "brick {b:?}: expected {FACES} faces of {cells} labels"
            )));
        }
    }
    let mut joins = Joins {
        ids: HashMap::new(),
        parent: vec![0],
    };
    let label = |b: BrickIndex, face: usize, i: usize| faces.get(&b).map_or(1, |f| f[face][i]);
    for b in layout.all() {
        for axis in 0..3 {
            if b[axis] == layout.min[axis] || b[axis] == layout.max[axis] {
                let face = 2 * axis + usize::from(b[axis] == layout.max[axis]);
                join_face(&mut joins, b, face, cells, &label, None);
                if layout.min[axis] == layout.max[axis] {
                    join_face(&mut joins, b, 2 * axis, cells, &label, None);
                }
            }
            let mut n = b;
            n[axis] += 1;
            if n[axis] <= layout.max[axis] {
                join_face(&mut joins, b, 2 * axis + 1, cells, &label, Some(n));
            }
        }
    }
    let mut exterior: BTreeMap<BrickIndex, Vec<u32>> = layout.all().map(|b| (b, vec![])).collect();
    let keys: Vec<(BrickIndex, u32)> = joins.ids.keys().copied().collect();
    for key in keys {
        let id = joins.ids[&key];
        if joins.root(id) == 0 {
            exterior.entry(key.0).or_default().push(key.1);
        }
    }
    for labels in exterior.values_mut() {
        labels.sort_unstable();
    }
    Ok(exterior)
}

/// Joins the labels on face `face` of `b` to the facing labels of `neighbour`, or to the
/// exterior when there is no neighbour (the layout's border).
fn join_face(
    joins: &mut Joins,
    b: BrickIndex,
    face: usize,
    cells: usize,
    label: &impl Fn(BrickIndex, usize, usize) -> u32,
    neighbour: Option<BrickIndex>,
) {
    let mut last = (0, 0);
    for i in 0..cells {
        let la = label(b, face, i);
        let lb = match neighbour {
            Some(n) => label(n, face ^ 1, i),
            None => u32::MAX,
        };
        if la == 0 || lb == 0 || (la, lb) == last {
            continue;
        }
        last = (la, lb);
        let a = joins.id((b, la));
        let other = match neighbour {
            Some(n) => joins.id((n, lb)),
            None => 0,
        };
        joins.join(a, other);
    }
}
