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

/// A face's labels as runs in cell order: (label, cells in a row). A face that the surface
/// crosses holds a few runs a row, so a brick's faces travel to the client and wait there in
/// kilobytes, not in a label per cell.
pub type FaceRuns = Vec<(u32, u32)>;

/// The runs of a face's labels (a run longer than a `u32` counts split in several).
pub fn face_runs(labels: &[u32]) -> FaceRuns {
    let mut runs: FaceRuns = Vec::new();
    for &l in labels {
        match runs.last_mut() {
            Some((label, n)) if *label == l && *n < u32::MAX => *n += 1,
            _ => runs.push((l, 1)),
        }
    }
    runs
}

/// A face of `cells` cells, all labelled `label`.
fn uniform(label: u32, cells: u64) -> FaceRuns {
    let full = cells / u64::from(u32::MAX);
    let rest = (cells % u64::from(u32::MAX)) as u32;
    let mut runs = vec![(label, u32::MAX); full as usize];
    if rest > 0 {
        runs.push((label, rest));
    }
    runs
}

/// `faces`: for each brick holding surface, the labels on its six faces (`BrickOutside::face`)
/// as runs. Bricks without an entry hold no surface: one component, label 1, fills them.
/// Returns, for every brick of the layout, its exterior labels in ascending order.
pub fn exterior_labels(
    layout: &BrickLayout,
    faces: &BTreeMap<BrickIndex, Vec<FaceRuns>>,
) -> Result<BTreeMap<BrickIndex, Vec<u32>>> {
    let cells = (layout.size as u64).pow(2);
    for (b, f) in faces {
        let covers = |face: &FaceRuns| face.iter().map(|r| u64::from(r.1)).sum::<u64>() == cells;
        if f.len() != FACES || !f.iter().all(covers) {
            return Err(Error::InvalidArgument(format!(
                "brick {b:?}: expected {FACES} faces of {cells} labels"
            )));
        }
    }
    let mut joins = Joins {
        ids: HashMap::new(),
        parent: vec![0],
    };
    let whole = uniform(1, cells);
    let runs = |b: BrickIndex, face: usize| faces.get(&b).map_or(&whole, |f| &f[face]);
    let exterior = uniform(u32::MAX, cells);
    for b in layout.all() {
        for axis in 0..3 {
            if b[axis] == layout.min[axis] || b[axis] == layout.max[axis] {
                let face = 2 * axis + usize::from(b[axis] == layout.max[axis]);
                join_face(&mut joins, (b, runs(b, face)), None, &exterior);
                if layout.min[axis] == layout.max[axis] {
                    join_face(&mut joins, (b, runs(b, 2 * axis)), None, &exterior);
                }
            }
            let mut n = b;
            n[axis] += 1;
            if n[axis] <= layout.max[axis] {
                let face = 2 * axis + 1;
                let facing = (n, runs(n, face ^ 1));
                join_face(&mut joins, (b, runs(b, face)), Some(facing), &exterior);
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

/// Joins the labels on a face of brick `b` (its runs) to the facing labels of the neighbour
/// brick, or to the exterior (whose runs are `exterior`) where there is none: the layout's
/// border. The two faces' runs are walked together, one overlap at a time.
fn join_face(
    joins: &mut Joins,
    (b, runs): (BrickIndex, &FaceRuns),
    neighbour: Option<(BrickIndex, &FaceRuns)>,
    exterior: &FaceRuns,
) {
    let facing = neighbour.map_or(exterior, |n| n.1);
    let (mut i, mut j) = (0, 0);
    let (mut left_a, mut left_b) = (0, 0);
    let mut last = (0, 0);
    loop {
        while left_a == 0 && i < runs.len() {
            left_a = runs[i].1;
            i += 1;
        }
        while left_b == 0 && j < facing.len() {
            left_b = facing[j].1;
            j += 1;
        }
        if left_a == 0 || left_b == 0 {
            return;
        }
        let (la, lb) = (runs[i - 1].0, facing[j - 1].0);
        if la != 0 && lb != 0 && (la, lb) != last {
            last = (la, lb);
            let a = joins.id((b, la));
            let other = match neighbour {
                Some((n, _)) => joins.id((n, lb)),
                None => 0,
            };
            joins.join(a, other);
        }
        let step = left_a.min(left_b);
        left_a -= step;
        left_b -= step;
    }
}
