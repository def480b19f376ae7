//! The library pipeline: every task refuses an impossible grid at planning, before anything
//! large is allocated, and stops promptly with `Error::Cancelled` when its observer answers
//! `Break` half-way, without unwinding.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use glam::DVec3;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use voxelkit::Error;
use voxelkit::implicit::Coordinates;
use voxelkit::mesh::attributes::AttributeChoice;
use voxelkit::mesh::{GridFit, generate};
use voxelkit::pipeline::{
    ColorChoice, CsgSource, Fill, Job, MeasureSource, MeshSource, Shape, ShapeTask, SurfaceMethod,
    Task,
};
use voxelkit::progress::Observer;
use voxelkit::shapes::Sphere;
use voxelkit::solids::depth_layers::DepthLayerOptions;
use voxelkit::solids::exterior_flood::FloodMethod;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::parametric::ParametricOptions;
use voxelkit::voxelize::separating::SeparatingOptions;

/// Fixtures written by the test: a closed torus (triangles), a cube control mesh (quads) and
/// a CSG tree at an impossible resolution.
fn fixtures(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let torus = dir.join("torus.obj");
    generate::torus(DVec3::ZERO, 1.0, 0.35, 96, 48)
        .write_obj(&torus)
        .unwrap();
    let cube = dir.join("cube.obj");
    generate::cuboid(DVec3::splat(-1.0), DVec3::ONE)
        .write_obj(&cube)
        .unwrap();
    let tree = dir.join("tree.json");
    std::fs::write(
        &tree,
        r#"{"resolution": 200000, "tree": {"difference": [
            {"box": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
            {"sphere": {"center": [0, 0, 0], "radius": 0.8}}]}}"#,
    )
    .unwrap();
    (torus, cube, tree)
}

/// Every kind of task on the fixtures.
/// A sphere formula's surface, or its solid by depth layers.
fn implicit(depth_layers: bool) -> Task {
    Task::Implicit {
        formula: "x^2 + y^2 + z^2 - 0.5".into(),
        coordinates: Coordinates::Cartesian,
        min: DVec3::splat(-1.0),
        max: DVec3::splat(1.0),
        levels: false,
        negative_r: false,
        theta_range: Default::default(),
        squared: false,
        depth_layers,
    }
}

fn tasks(torus: &Path, cube: &Path) -> Vec<(&'static str, Task)> {
    let mesh = || MeshSource::File(torus.to_path_buf());
    vec![
        (
            "separating",
            Task::MeshSurface {
                mesh: mesh(),
                method: SurfaceMethod::Separating(SeparatingOptions::default()),
                attributes: AttributeChoice::None,
            },
        ),
        (
            "projective",
            Task::MeshSurface {
                mesh: mesh(),
                method: SurfaceMethod::Projective(ColorChoice::FromMesh),
                attributes: AttributeChoice::None,
            },
        ),
        (
            "lines",
            Task::Lines {
                mesh: mesh(),
                edges: true,
                color: ColorChoice::None,
            },
        ),
        (
            "shape",
            Task::Shape(ShapeTask {
                shape: Shape::Sphere(Sphere {
                    center: DVec3::ZERO,
                    radius: 1.0,
                }),
                separability: Separability::TwentySix,
                normals: false,
                curvature_margin: true,
            }),
        ),
        (
            "subdivision",
            Task::Subdivision {
                mesh: MeshSource::File(cube.to_path_buf()),
                options: ParametricOptions::default(),
                output: voxelkit::pipeline::SubdivisionOutput::Surface,
            },
        ),
        ("subdivision solid", subdivision_solid(cube)),
        ("implicit", implicit(false)),
        ("implicit depth layers", implicit(true)),
        (
            "solid flood",
            Task::Solid {
                mesh: mesh(),
                fill: Fill::Flood(FloodMethod::Spans),
                density: 1.0,
                topology: true,
                inside: Default::default(),
            },
        ),
        (
            "solid depth layers",
            Task::Solid {
                mesh: mesh(),
                fill: Fill::DepthLayers(DepthLayerOptions::default()),
                density: 1.0,
                topology: true,
                inside: Default::default(),
            },
        ),
        (
            "solid beam",
            Task::Solid {
                mesh: mesh(),
                fill: Fill::Beam(Default::default()),
                density: 1.0,
                topology: true,
                inside: Default::default(),
            },
        ),
        (
            "measure",
            Task::Measure {
                source: MeasureSource::Mesh(mesh()),
                flood: FloodMethod::Spans,
                density: 1.0,
                inside: Default::default(),
            },
        ),
    ]
}

/// The solid of the cube control mesh's limit surface.
fn subdivision_solid(cube: &Path) -> Task {
    Task::Subdivision {
        mesh: MeshSource::File(cube.to_path_buf()),
        options: ParametricOptions::default(),
        output: voxelkit::pipeline::SubdivisionOutput::Solid(voxelkit::pipeline::SubdivisionFill {
            depth_layers: false,
            graystack: 1 << 10,
            density: 1.0,
            topology: true,
        }),
    }
}

#[test]
fn every_task_refuses_an_impossible_grid_at_planning() {
    let dir = tempfile::tempdir().unwrap();
    let (torus, cube, tree) = fixtures(dir.path());
    let mut all = tasks(&torus, &cube);
    all.push(("csg tree", Task::CsgTree(CsgSource::File(tree))));
    for (name, task) in all {
        for fit in [GridFit::Resolution(1 << 22), GridFit::VoxelSize(1e-30)] {
            let start = Instant::now();
            let refused = Job::new(task.clone(), fit).plan();
            let elapsed = start.elapsed();
            match refused {
                Err(e @ Error::TooLarge { .. }) => {
                    assert!(e.to_string().contains("MiB"), "{name}: {e}")
                }
                Err(Error::InvalidArgument(m)) if name.starts_with("implicit") => {
                    assert!(m.contains("65536"), "{name}: {m}")
                }
                Err(e) => panic!("{name} at {fit:?}: refused with the wrong error: {e}"),
                Ok(p) => panic!("{name} at {fit:?}: planned {:?}", p.plan()),
            }
            assert!(
                elapsed < Duration::from_secs(1),
                "{name} at {fit:?}: refusing took {elapsed:?}"
            );
        }
    }
}

/// Stops the work once half of the stage's items are done.
struct StopHalfWay {
    total: AtomicU64,
    done: AtomicU64,
}

impl Observer for StopHalfWay {
    fn stage(&self, _name: &str, total: u64) {
        self.total.store(total, Ordering::SeqCst);
    }
    fn advance(&self, n: u64) -> ControlFlow<()> {
        let done = self.done.fetch_add(n, Ordering::SeqCst) + n;
        if 2 * done >= self.total.load(Ordering::SeqCst) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

#[test]
fn a_break_half_way_cancels_promptly_without_unwinding() {
    let dir = tempfile::tempdir().unwrap();
    let (torus, cube, _) = fixtures(dir.path());
    for (name, task) in tasks(&torus, &cube) {
        let fit = if name == "implicit" || name == "shape" {
            GridFit::Resolution(512)
        } else {
            GridFit::Resolution(256)
        };
        let start = Instant::now();
        let full = Job::new(task.clone(), fit)
            .run(&voxelkit::progress::Unobserved)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let whole = start.elapsed();
        assert!(full.grid.voxel_count() > 0, "{name}");
        let observer = StopHalfWay {
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
        };
        let start = Instant::now();
        let cancelled = Job::new(task, fit).run(&observer);
        let took = start.elapsed();
        assert!(
            matches!(cancelled, Err(Error::Cancelled)),
            "{name}: expected Cancelled, got {:?}",
            cancelled.map(|o| o.grid.voxel_count())
        );
        assert!(
            observer.done.load(Ordering::SeqCst) < observer.total.load(Ordering::SeqCst),
            "{name}: the work ran to the end"
        );
        eprintln!("{name}: whole run {whole:?}, cancelled half-way after {took:?}");
    }
}

/// Lets the surface finish and stops at the first poll of a later stage (the flood).
struct StopWhenPolled;

impl Observer for StopWhenPolled {
    fn advance(&self, n: u64) -> ControlFlow<()> {
        if n == 0 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

#[test]
fn the_exterior_flood_stops_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let (torus, _, _) = fixtures(dir.path());
    let xyz = FloodMethod::Xyz { capacity: 1 << 20 };
    for (measure, flood) in [
        (false, FloodMethod::Spans),
        (true, FloodMethod::Spans),
        (false, xyz),
    ] {
        let mesh = MeshSource::File(torus.clone());
        let task = if measure {
            Task::Measure {
                source: MeasureSource::Mesh(mesh),
                flood,
                density: 1.0,
                inside: voxelkit::solids::inside_rule::InsideRule::Parity,
            }
        } else {
            Task::Solid {
                mesh,
                fill: Fill::Flood(flood),
                density: 1.0,
                topology: true,
                inside: voxelkit::solids::inside_rule::InsideRule::Parity,
            }
        };
        let result = Job::new(task, GridFit::Resolution(256)).run(&StopWhenPolled);
        assert!(
            matches!(result, Err(Error::Cancelled)),
            "measure: {measure}, {flood:?}"
        );
    }
}

/// Hears every stage: its name, its total and the items counted in it.
#[derive(Default)]
struct Recording(std::sync::Mutex<Vec<(String, u64, u64)>>);

impl Observer for Recording {
    fn stage(&self, name: &str, total: u64) {
        let mut heard = self.0.lock().unwrap();
        heard.push((name.to_string(), total, 0));
    }
    fn advance(&self, n: u64) -> ControlFlow<()> {
        if let Some(last) = self.0.lock().unwrap().last_mut() {
            last.2 += n;
        }
        ControlFlow::Continue(())
    }
}

#[test]
fn every_stage_of_a_fill_is_heard_and_counted_to_its_total() {
    use voxelkit::solids::inside_rule::InsideRule;
    let dir = tempfile::tempdir().unwrap();
    let (torus, cube, _) = fixtures(dir.path());
    // A closed cube with one face turned over: its orientations disagree, so the inside
    // chosen beside its surface is the flood's.
    let flipped = dir.path().join("flipped.obj");
    let mut box_mesh = generate::cuboid(DVec3::splat(-1.0), DVec3::ONE);
    let first_face = box_mesh.face_starts[0] as usize..box_mesh.face_starts[1] as usize;
    box_mesh.indices[first_face].reverse();
    box_mesh.write_obj(&flipped).unwrap();
    let mesh = || MeshSource::File(torus.clone());
    let solid = |fill, inside| Task::Solid {
        mesh: mesh(),
        fill,
        density: 1.0,
        topology: false,
        inside,
    };
    let cases = [
        (
            solid(Fill::Flood(FloodMethod::Blocks), InsideRule::Winding),
            vec!["surface and inside"],
        ),
        (
            Task::Solid {
                mesh: MeshSource::File(flipped),
                fill: Fill::Flood(FloodMethod::Blocks),
                density: 1.0,
                topology: false,
                inside: InsideRule::Auto,
            },
            vec!["surface and inside", "filling"],
        ),
        (
            solid(Fill::Flood(FloodMethod::Blocks), InsideRule::Parity),
            vec!["surface", "filling"],
        ),
        (
            solid(
                Fill::DepthLayers(DepthLayerOptions::default()),
                InsideRule::Auto,
            ),
            vec!["depth buffers", "classifying"],
        ),
        (
            Task::DistanceBand {
                mesh: mesh(),
                band: 3.0,
                signed: true,
                inside: InsideRule::Winding,
                attributes: AttributeChoice::None,
            },
            vec!["distances and inside"],
        ),
        (subdivision_solid(&cube), vec!["voxelizing", "filling"]),
    ];
    for (task, stages) in cases {
        let heard = Recording::default();
        Job::new(task, GridFit::Resolution(128))
            .run(&heard)
            .unwrap();
        let heard = heard.0.into_inner().unwrap();
        // The stages the work itself begins: each counted to its total, none silent.
        let worked: Vec<&(String, u64, u64)> = heard.iter().filter(|s| s.2 > 0).collect();
        let names: Vec<&str> = worked.iter().map(|s| s.0.as_str()).collect();
        assert_eq!(names, stages, "{heard:?}");
        for (name, total, done) in worked {
            assert!(*total > 0 && done == total, "{name}: {done} of {total}");
        }
    }
}

#[test]
fn the_report_says_where_the_time_went_stage_by_stage() {
    let dir = tempfile::tempdir().unwrap();
    let (torus, _, _) = fixtures(dir.path());
    let task = Task::Solid {
        mesh: MeshSource::File(torus),
        fill: Fill::Flood(FloodMethod::Blocks),
        density: 1.0,
        topology: false,
        inside: voxelkit::solids::inside_rule::InsideRule::Parity,
    };
    let mut outcome = Job::new(task, GridFit::Resolution(256))
        .run(&voxelkit::progress::Unobserved)
        .unwrap();
    let out = dir.path().join("solid.vdb");
    outcome
        .write(&out, &[], &voxelkit::io::vdb::WriteOptions::default())
        .unwrap();
    let report = &outcome.report;
    let names: Vec<&str> = report.stages.iter().map(|s| s.stage.as_str()).collect();
    assert_eq!(
        names,
        [
            "read", "plan", "surface", "filling", "encode", "write", "fsync"
        ]
    );
    // The stages before the write cover the run, one after another.
    let run: f64 = report.stages[..4].iter().map(|s| s.seconds).sum();
    assert!(
        run <= report.seconds && run >= 0.9 * report.seconds - 0.005,
        "{run} of {}",
        report.seconds
    );
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
    for s in &report.stages {
        assert!(
            s.seconds >= 0.0 && (0.0..=cores + 0.5).contains(&s.threads_busy),
            "{s:?}"
        );
    }
    assert!(report.summary().contains("stages: read "));
}
