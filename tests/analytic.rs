//! Huang et al. §7 on analytic surfaces: the voxelized sphere, closed cylinder and
//! `x^2 + k y + k z = 0` separate their two sides (checked by flooding), and every voxel
//! lies within the criterion's distance of the surface.

use glam::DVec3;
use voxelkit::grid::{CoordBox, Transform};
use voxelkit::ops::separability::check_side_separation;
use voxelkit::shapes::{Cylinder, Quadric, Sphere};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating_analytic::{AnalyticSurface, voxelize_surface};

fn check(surface: &dyn AnalyticSurface, transform: Transform, pad: i64) {
    for sep in [Separability::Six, Separability::TwentySix] {
        let adjacency = sep.flood_adjacency();
        let grid = voxelize_surface(
            surface,
            transform,
            sep,
            true,
            true,
            &voxelkit::progress::Progress::none(),
        )
        .unwrap();
        let b = surface.bbox();
        let bbox = CoordBox {
            min: transform.world_to_voxel(b.min).map(|v| v - pad),
            max: transform.world_to_voxel(b.max).map(|v| v + pad),
        };
        let report = check_side_separation(
            &grid,
            bbox,
            |c| surface.side(transform.index_to_world(c)),
            adjacency,
        )
        .unwrap();
        assert!(
            report.inside_empty > 0 && report.exterior > 0,
            "vacuous: {report:?}"
        );
        assert!(report.separates(), "{sep:?}: {report:?}");
        // Every voxel is near the surface: within Rc (the loosest limit) plus the curvature
        // margin (at most 3k/2 voxels) of it.
        for c in grid.voxels() {
            let near = surface.nearest(transform.index_to_world(c), f64::INFINITY);
            let k = near.curvature * transform.voxel_size;
            let limit = (sep.vertex_edge_radius() + 1.5 * k / (1.0 - k)) * transform.voxel_size;
            assert!(near.distance <= limit + 1e-9);
        }
        // Normals are unit vectors.
        for leaf in grid.leaves() {
            let normals = leaf.normal.as_ref().unwrap();
            for n in leaf.offsets() {
                let len = glam::Vec3::from(normals[n]).length();
                assert!((len - 1.0).abs() < 1e-5);
            }
        }
    }
}

#[test]
fn sphere_separates() {
    // The paper's scene: radius 61.4 at voxel size 1, off-grid centre.
    let s = Sphere {
        center: DVec3::new(0.3, -0.2, 0.45),
        radius: 61.4,
    };
    check(&s, Transform::new(DVec3::ZERO, 1.0), 2);
    let small = Sphere {
        center: DVec3::new(0.1, 0.2, 0.3),
        radius: 3.7,
    };
    check(&small, Transform::new(DVec3::ZERO, 0.5), 2);
}

#[test]
fn closed_cylinder_separates_with_rims() {
    let upright = Cylinder {
        center: DVec3::new(0.2, 0.1, 0.0),
        axis: DVec3::Z,
        radius: 49.7,
        height: 158.2,
    };
    check(&upright, Transform::new(DVec3::ZERO, 1.0), 2);
    let tilted = Cylinder {
        center: DVec3::new(0.3, 0.0, -0.4),
        axis: DVec3::new(1.0, 2.0, 0.5).normalize(),
        radius: 7.3,
        height: 21.0,
    };
    check(&tilted, Transform::new(DVec3::ZERO, 0.5), 2);
}

#[test]
fn parabolic_quadric_separates_its_box() {
    // The paper's k = 10 at 128^3 over [-64, 64]^3; the surface crosses the box, so the
    // flood starts from the positive side inside the box.
    let q = Quadric {
        k: 10.0,
        half_extent: 64.0,
    };
    check(&q, Transform::new(DVec3::ZERO, 1.0), 0);
}

/// `--no-curvature-margin`: the paper's plain rule. On the paper's own sphere (radius 61.4
/// voxels) plain 6-separating slabs leave holes, which the margin closes (see the module docs);
/// the plain rule keeps fewer voxels.
#[test]
fn the_plain_rule_leaks_on_the_papers_sphere_and_the_margin_closes_it() {
    let s = Sphere {
        center: DVec3::new(0.3, -0.2, 0.45),
        radius: 61.4,
    };
    let t = Transform::new(DVec3::ZERO, 1.0);
    let b = s.bbox();
    let bbox = CoordBox {
        min: t.world_to_voxel(b.min).map(|v| v - 2),
        max: t.world_to_voxel(b.max).map(|v| v + 2),
    };
    let run = |margin: bool| {
        let sep = Separability::Six;
        let grid = voxelize_surface(
            &s,
            t,
            sep,
            false,
            margin,
            &voxelkit::progress::Progress::none(),
        )
        .unwrap();
        let report = check_side_separation(
            &grid,
            bbox,
            |c| s.side(t.index_to_world(c)),
            sep.flood_adjacency(),
        )
        .unwrap();
        (grid.voxel_count(), report)
    };
    let ((plain, plain_report), (widened, report)) = (run(false), run(true));
    eprintln!(
        "paper's sphere, 6-separating: plain {plain} voxels ({plain_report:?}); with the margin {widened} ({report:?})"
    );
    assert!(
        !plain_report.separates(),
        "the plain rule was expected to leak"
    );
    assert!(report.separates());
    assert!(plain < widened);
}
