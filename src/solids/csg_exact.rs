//! A CSG tree known exactly, for meshing its solid (`contour::ExactSurface`): each leaf's
//! signed distance, exact for boxes, cylinders and spheres, F over the length of its gradient
//! for a formula (the distance to first order, clipped to the centres its bounds keep), in
//! the leaf's own frame and carried into the world by its placement; combined as the Booleans
//! combine the solids (union the least, intersection the greatest, difference the greatest of
//! the first and the others negated). The zero set is the tree's surface, and each value's
//! gradient is the normal of the leaf surface nearest, so the mesh's vertices find the sharp
//! edges and corners where leaves meet. Leaves known only as voxels (meshes, subdivision
//! surfaces, grids) leave the tree without an exact surface.

use super::csg_leaves::Primitive;
use super::csg_tree::{CsgNode, CsgTree};
use crate::contour::{ExactSurface, SegmentCrossings, crossing_of_values};
use crate::grid::{Channels, Leaf, SparseGrid, Transform, offset_coord};
use crate::implicit::Formula;
use crate::mesh::index_box;
use crate::ops::csg::BooleanOp;
use crate::shapes::Cuboid;
use glam::{DAffine3, DVec2, DVec3};
use rayon::prelude::*;

pub struct ExactTree {
    root: ExactNode,
}

enum ExactNode {
    Boolean {
        op: BooleanOp,
        operands: Vec<ExactNode>,
    },
    Primitive {
        shape: Primitive,
        to_local: DAffine3,
    },
    Formula {
        formula: Formula,
        /// The world box of the centres the leaf's bounds keep.
        clip: Option<Cuboid>,
        to_local: DAffine3,
    },
}

impl ExactTree {
    /// The tree as evaluated on `transform`'s grid; none when a leaf is known only as voxels.
    pub fn of(tree: &CsgTree, transform: &Transform) -> Option<ExactTree> {
        Some(ExactTree {
            root: exact_node(&tree.root, transform)?,
        })
    }
}

fn exact_node(node: &CsgNode, transform: &Transform) -> Option<ExactNode> {
    Some(match node {
        CsgNode::Boolean { op, operands } => ExactNode::Boolean {
            op: *op,
            operands: operands
                .iter()
                .map(|n| exact_node(n, transform))
                .collect::<Option<_>>()?,
        },
        CsgNode::Primitive { shape, to_local } => ExactNode::Primitive {
            shape: *shape,
            to_local: *to_local,
        },
        CsgNode::Formula {
            formula, to_local, ..
        } => ExactNode::Formula {
            formula: formula.clone(),
            // As `formula_solid` keeps them: the centres of the bounds' index box.
            clip: node.bounds().map(|b| {
                let kept = index_box(&b, transform);
                let corner = |c: [i64; 3], half: f64| {
                    transform.origin
                        + transform.voxel_size * (DVec3::from_array(c.map(|v| v as f64)) + half)
                };
                Cuboid {
                    min: corner(kept.min, -0.5),
                    max: corner(kept.max, 0.5),
                }
            }),
            to_local: *to_local,
        },
        CsgNode::Mesh(_) | CsgNode::Subdivision(_) | CsgNode::Grid { .. } => return None,
    })
}

impl ExactTree {
    /// The tree's value at `p` and the normal of the leaf surface it measures.
    fn sample(&self, p: DVec3) -> (f64, DVec3) {
        let mut slots = Vec::new();
        self.root.sample(p, &mut slots)
    }

    /// The outward normal at every voxel of `voxels` (a solid's shell): the normal of the leaf
    /// surface the tree measures at the voxel's centre, exact as the leaves are (Lai & Cheng's
    /// Fig. 4 renders Boolean results lit by them).
    pub fn normals_on(&self, voxels: &SparseGrid) -> SparseGrid {
        let t = voxels.transform;
        let channels = Channels {
            normal: true,
            ..Channels::NONE
        };
        let leaves: Vec<Leaf> = voxels
            .leaves()
            .par_iter()
            .map_init(Vec::new, |slots, leaf| {
                let mut out = Leaf::new(leaf.origin, channels);
                out.mask = leaf.mask;
                let normals = out.normal.as_mut().expect("a normal leaf");
                for n in leaf.offsets() {
                    let p = t.index_to_world(offset_coord(leaf.origin, n));
                    normals[n] = self.root.sample(p, slots).1.as_vec3().into();
                }
                out
            })
            .collect();
        SparseGrid::from_distinct_leaves(t, channels, leaves)
    }
}

impl ExactSurface for ExactTree {
    fn near(&self, _lo: DVec3, _hi: DVec3) -> Box<dyn SegmentCrossings + '_> {
        Box::new(self)
    }
}

impl SegmentCrossings for &ExactTree {
    fn crossing(&self, a: DVec3, b: DVec3, a_inside: bool, _guess: f64) -> Option<(f64, DVec3)> {
        crossing_of_values(|p| self.sample(p), a, b, a_inside)
    }
}

impl ExactNode {
    fn sample(&self, p: DVec3, slots: &mut Vec<crate::implicit::Dual>) -> (f64, DVec3) {
        match self {
            ExactNode::Boolean { op, operands } => {
                let mut values = operands.iter().map(|n| n.sample(p, slots));
                let first = values.next().unwrap_or((f64::INFINITY, DVec3::ZERO));
                let greatest = |a: (f64, DVec3), b: (f64, DVec3)| if b.0 > a.0 { b } else { a };
                match op {
                    BooleanOp::Union => values.fold(first, |a, b| if b.0 < a.0 { b } else { a }),
                    BooleanOp::Intersection => values.fold(first, greatest),
                    BooleanOp::Difference => values.map(|(v, n)| (-v, -n)).fold(first, greatest),
                }
            }
            ExactNode::Primitive { shape, to_local } => {
                let local = to_local.transform_point3(p);
                let (value, normal) = match shape {
                    Primitive::Cuboid(b) => b.signed_distance(local),
                    Primitive::Cylinder(c) => {
                        let d = local - c.center;
                        let along = d.dot(c.axis);
                        let radial = d - along * c.axis;
                        let out = radial
                            .try_normalize()
                            .unwrap_or_else(|| c.axis.any_orthonormal_vector());
                        let (v, g) = rectangle_distance(
                            DVec2::new(radial.length(), along.abs()),
                            DVec2::new(c.radius, 0.5 * c.height),
                        );
                        (v, g.x * out + g.y * along.signum() * c.axis)
                    }
                    Primitive::Sphere(s) => {
                        let d = local - s.center;
                        (d.length() - s.radius, d.normalize_or_zero())
                    }
                };
                to_world(to_local, value, normal)
            }
            ExactNode::Formula {
                formula,
                clip,
                to_local,
            } => {
                let local = to_local.transform_point3(p);
                let (d, n) = formula.first_order_distance(local.to_array(), slots);
                let leaf = to_world(to_local, d, n);
                match clip {
                    Some(b) => {
                        let c = b.signed_distance(p);
                        if c.0 > leaf.0 { c } else { leaf }
                    }
                    None => leaf,
                }
            }
        }
    }
}

/// A leaf's value and unit normal in its own frame carried into the world through the map
/// `to_local`: the normal by the transposed linear part, the value divided by that gradient's
/// length (a distance in the leaf's frame over its scale).
fn to_world(to_local: &DAffine3, value: f64, normal: DVec3) -> (f64, DVec3) {
    let g = to_local.matrix3.transpose() * normal;
    let length = g.length();
    if length > 0.0 {
        (value / length, g / length)
    } else {
        (value, DVec3::ZERO)
    }
}

/// The signed distance from the point `(a, b)`, both non-negative, to the rectangle of half
/// sides `half` about the origin, and its gradient in those two coordinates.
fn rectangle_distance(p: DVec2, half: DVec2) -> (f64, DVec2) {
    let q = p - half;
    let outside = q.max(DVec2::ZERO);
    let length = outside.length();
    if length > 0.0 {
        (length, outside / length)
    } else if q.x >= q.y {
        (q.x, DVec2::X)
    } else {
        (q.y, DVec2::Y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::Cylinder;

    fn leaf(shape: Primitive) -> ExactNode {
        ExactNode::Primitive {
            shape,
            to_local: DAffine3::IDENTITY,
        }
    }

    /// A box less a cylinder: the values' signs are the solid's at random points, and near
    /// the surface the values are the distances to it.
    #[test]
    fn a_box_less_a_cylinder_is_known_exactly() {
        let cuboid = Cuboid {
            min: DVec3::ZERO,
            max: DVec3::ONE,
        };
        let cylinder = Cylinder::from_base(DVec3::new(1.0, 1.0, -0.5), DVec3::Z, 0.4, 2.0);
        let tree = ExactTree {
            root: ExactNode::Boolean {
                op: BooleanOp::Difference,
                operands: vec![
                    leaf(Primitive::Cuboid(cuboid)),
                    leaf(Primitive::Cylinder(cylinder)),
                ],
            },
        };
        let mut rng = crate::random::SplitMix64(9);
        for _ in 0..2000 {
            let p = DVec3::new(
                rng.range(-0.5, 1.5),
                rng.range(-0.5, 1.5),
                rng.range(-0.5, 1.5),
            );
            let (v, n) = tree.sample(p);
            let inside = cuboid.contains(p) && !cylinder.contains(p);
            assert_eq!(v <= 0.0, inside, "{p}: {v}");
            assert!((n.length() - 1.0).abs() < 1e-9);
        }
        // On the curved face, the normal points into the cylinder's hollow.
        let on_face = DVec3::new(1.0 - 0.4 * 0.6, 1.0 - 0.4 * 0.8, 0.5);
        let (v, n) = tree.sample(on_face);
        assert!(v.abs() < 1e-12);
        assert!((n - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-9, "{n}");
    }

    /// A placed (scaled and turned) sphere: zero on its placed surface, the normal outward.
    #[test]
    fn placed_leaves_are_measured_in_the_world() {
        let to_world = DAffine3::from_scale_rotation_translation(
            DVec3::splat(2.0),
            glam::DQuat::from_rotation_z(0.7),
            DVec3::new(1.0, 0.0, 0.0),
        );
        let node = ExactNode::Primitive {
            shape: Primitive::Sphere(crate::shapes::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            }),
            to_local: to_world.inverse(),
        };
        let p = DVec3::new(1.0, 0.0, 3.0);
        let (v, n) = node.sample(p, &mut Vec::new());
        assert!((v - 1.0).abs() < 1e-9, "{v}");
        assert!((n - DVec3::Z).length() < 1e-9, "{n}");
    }
}
