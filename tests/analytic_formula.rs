//! Huang et al. §7 on surfaces typed as formulas (`shape formula`): nearest points found
//! numerically give a sphere formula exactly the closed-form sphere's voxels; the step
//! certificate closes what the paper's plain rule leaves open; a torus and a genus-2 surface
//! separate their two sides (checked by flooding); the command line gives the same voxels.

mod cli_support;

use cli_support::{text, voxelkit};
use glam::DVec3;
use voxelkit::grid::{Coord, CoordBox, SparseGrid, Transform};
use voxelkit::implicit::{Coordinates, Formula};
use voxelkit::mesh::Aabb;
use voxelkit::ops::separability::{SeparationReport, check_side_separation};
use voxelkit::progress::Progress;
use voxelkit::shapes::Sphere;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating_analytic::{
    AnalyticSurface, keep_reach, scan_region, voxelize_surface,
};
use voxelkit::voxelize::separating_formula::FormulaSurface;
use voxelkit::voxelize::step_certificate::close_unproven_steps;

fn formula_surface(text: &str, lo: f64, hi: f64) -> FormulaSurface {
    let formula = Formula::parse(text, Coordinates::Cartesian).unwrap();
    FormulaSurface::new(
        formula,
        Aabb {
            min: DVec3::splat(lo),
            max: DVec3::splat(hi),
        },
    )
}

/// The formula's voxels as `shape formula` makes them, and how many the certificate added.
fn formula_voxels(
    f: &FormulaSurface,
    t: Transform,
    sep: Separability,
    margin: bool,
) -> (SparseGrid, u64) {
    let mut grid = voxelize_surface(f, t, sep, true, margin, &Progress::none()).unwrap();
    let region = scan_region(f, &t);
    let added = close_unproven_steps(f, &mut grid, region, sep, &Progress::none()).unwrap();
    (grid, added)
}

fn sorted(grid: &SparseGrid) -> Vec<Coord> {
    let mut v: Vec<Coord> = grid.voxels().collect();
    v.sort_unstable();
    v
}

fn separation(
    grid: &SparseGrid,
    surface: &dyn AnalyticSurface,
    t: Transform,
    sep: Separability,
) -> SeparationReport {
    let b = surface.bbox();
    let bbox = CoordBox {
        min: t.world_to_voxel(b.min).map(|v| v - 2),
        max: t.world_to_voxel(b.max).map(|v| v + 2),
    };
    check_side_separation(
        grid,
        bbox,
        |c| surface.side(t.index_to_world(c)),
        sep.flood_adjacency(),
    )
    .unwrap()
}

#[test]
fn a_sphere_formula_gives_the_sphere_shapes_voxels() {
    // The paper's sphere (radius 61.4 at voxel size 1, off-grid centre) as a distance, and a
    // small one as a polynomial (F is no distance there: the foot point is still exact).
    let cases = [
        (
            Sphere {
                center: DVec3::new(0.3, -0.2, 0.45),
                radius: 61.4,
            },
            "sqrt((x - 0.3)^2 + (y + 0.2)^2 + (z - 0.45)^2) - 61.4",
            Transform::new(DVec3::ZERO, 1.0),
        ),
        (
            Sphere {
                center: DVec3::new(0.1, 0.2, 0.3),
                radius: 3.7,
            },
            "(x - 0.1)^2 + (y - 0.2)^2 + (z - 0.3)^2 - 3.7^2",
            Transform::new(DVec3::ZERO, 0.5),
        ),
    ];
    for (sphere, text, t) in cases {
        let b = sphere.bbox();
        let f = formula_surface(text, b.min.min_element(), b.max.max_element());
        for sep in [Separability::Six, Separability::TwentySix] {
            let shape = voxelize_surface(&sphere, t, sep, true, true, &Progress::none()).unwrap();
            let (formula, added) = formula_voxels(&f, t, sep, true);
            assert!(
                shape.voxel_count() > 500,
                "vacuous: {}",
                shape.voxel_count()
            );
            assert_eq!(added, 0, "{text}, {sep:?}: the certificate added voxels");
            assert!(
                sorted(&shape) == sorted(&formula),
                "{text}, {sep:?}: {} voxels by the closed form, {} by the formula",
                shape.voxel_count(),
                formula.voxel_count()
            );
        }
    }
}

/// The paper's plain 6-separating slabs leave holes in its own sphere (see `tests/analytic.rs`);
/// on the same sphere typed as a formula the certificate finds and closes them.
#[test]
fn the_certificate_closes_the_holes_the_plain_rule_leaves() {
    let sphere = Sphere {
        center: DVec3::new(0.3, -0.2, 0.45),
        radius: 61.4,
    };
    let f = formula_surface(
        "sqrt((x - 0.3)^2 + (y + 0.2)^2 + (z - 0.45)^2) - 61.4",
        -62.0,
        62.0,
    );
    let t = Transform::new(DVec3::ZERO, 1.0);
    let sep = Separability::Six;
    let plain = voxelize_surface(&sphere, t, sep, false, false, &Progress::none()).unwrap();
    assert!(!separation(&plain, &sphere, t, sep).separates());
    let (closed, added) = formula_voxels(&f, t, sep, false);
    assert!(added > 0);
    assert_eq!(closed.voxel_count(), plain.voxel_count() + added);
    assert!(plain.voxels().all(|c| closed.contains(c)));
    let report = separation(&closed, &f, t, sep);
    assert!(report.separates(), "{report:?}");
    eprintln!(
        "paper's sphere, plain 6-separating slabs: {} voxels, which leak; the certificate adds {added}",
        plain.voxel_count()
    );
}

#[test]
fn a_torus_and_a_genus_two_surface_separate_at_128() {
    let surfaces = [
        ("(sqrt(x^2 + z^2) - 0.6)^2 + y^2 - 0.25^2", 1.0),
        ("((x^2 + y^2)^2 - x^2 + y^2)^2 + z^2 - 0.01", 1.2),
    ];
    for (text, half) in surfaces {
        let f = formula_surface(text, -half, half);
        let t = Transform::new(DVec3::splat(-half + half / 128.0), 2.0 * half / 128.0);
        for sep in [Separability::Six, Separability::TwentySix] {
            for margin in [true, false] {
                let (grid, added) = formula_voxels(&f, t, sep, margin);
                let report = separation(&grid, &f, t, sep);
                assert!(
                    report.inside_empty > 0 && report.exterior > 0,
                    "vacuous: {report:?}"
                );
                assert!(report.separates(), "{text}, {sep:?}: {report:?}");
                // No voxel where interval arithmetic proves the surface farther than the
                // rule (or, for the certificate's, a step) reaches.
                let reach = keep_reach(sep, margin).max(3f64.sqrt()) * t.voxel_size;
                for c in grid.voxels() {
                    let p = t.index_to_world(c);
                    assert!(!f.box_is_empty(p - reach, p + reach), "{text}: {c:?}");
                }
                eprintln!(
                    "{text}, {sep:?}, margin {margin}: {} voxels, {added} added by the certificate",
                    grid.voxel_count()
                );
            }
        }
    }
}

#[test]
fn shape_formula_on_the_command_line_equals_shape_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("f.vdb"), dir.path().join("s.vdb"));
    let formula = voxelkit(&[
        "shape",
        "formula",
        "--example",
        "sphere",
        "-r",
        "96",
        "-o",
        a.to_str().unwrap(),
    ]);
    assert!(formula.status.success(), "{}", text(&formula));
    assert!(
        text(&formula).contains("0 voxel(s) added"),
        "{}",
        text(&formula)
    );
    let sphere = voxelkit(&[
        "shape",
        "sphere",
        "--radius",
        "0.8",
        "--bounds",
        "-1,1",
        "-r",
        "96",
        "-o",
        b.to_str().unwrap(),
    ]);
    assert!(sphere.status.success(), "{}", text(&sphere));
    let read = |p: &std::path::Path| voxelkit::io::vdb::read_vdb_grid(p, Some("density")).unwrap();
    let (ga, gb) = (read(&a), read(&b));
    assert!(gb.voxel_count() > 1000);
    assert!(
        sorted(&ga) == sorted(&gb),
        "{} against {}",
        ga.voxel_count(),
        gb.voxel_count()
    );
    // A formula that does not parse is refused by column.
    let bad = voxelkit(&["shape", "formula", "x^2 +* y", "-o", a.to_str().unwrap()]);
    assert!(!bad.status.success());
    assert!(text(&bad).contains("column"), "{}", text(&bad));
}

/// `intersect --formula A --formula B`: the common voxels of two formula surfaces made on one
/// grid, a sphere of radius 0.8 and the plane z = 0.3x, form one closed curve (a single
/// 26-component) whose voxels all lie near both surfaces.
#[test]
fn two_formula_surfaces_meet_in_one_curve() {
    use voxelkit::grid::{Adjacency, DenseMask};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("circle.vdb");
    let o = voxelkit(&[
        "intersect",
        "--formula",
        "sqrt(x^2 + y^2 + z^2) - 0.8",
        "--formula",
        "z - 0.3*x",
        "-r",
        "96",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let grid = voxelkit::io::vdb::read_vdb_grid(&out, None).unwrap();
    let mask = DenseMask::from_grid(&grid, grid.bbox().unwrap()).unwrap();
    assert_eq!(
        voxelkit::ops::topology::components(&mask, Adjacency::TwentySix),
        1
    );
    let h = grid.transform.voxel_size;
    // The circle is 2 pi 0.8 long: at least one voxel per voxel of length.
    assert!(grid.voxel_count() as f64 > 2.0 * std::f64::consts::PI * 0.8 / h);
    for leaf in grid.leaves() {
        for c in leaf.coords() {
            let p = grid.transform.index_to_world(c);
            assert!((p.length() - 0.8).abs() < h, "{p} off the sphere");
            assert!(
                (p.z - 0.3 * p.x).abs() / 1.09f64.sqrt() < h,
                "{p} off the plane"
            );
        }
    }
    let o = voxelkit(&["intersect", "--formula", "x", "-o", out.to_str().unwrap()]);
    assert!(!o.status.success() && text(&o).contains("two or more surfaces"));
}
