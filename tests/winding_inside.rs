//! The inside of any mesh by its generalized winding number (option `inside`, default auto):
//! on open meshes, overlapping parts, hollow parts, stray triangles and flipped components,
//! every voxel that `solid`, `mesh --sdf` and `measure` classify agrees with the exact winding
//! number at its centre (f64, every triangle, no hierarchy) wherever that lies farther than a
//! millionth from 1/2; the union of two overlapping closed parts is the union of their solids;
//! on closed meshes the winding number gives ray parity's level set voxel for voxel.

use glam::DVec3;
use rayon::prelude::*;
use voxelkit::grid::{Block, SparseGrid};
use voxelkit::mesh::winding::winding_number;
use voxelkit::mesh::{Mesh, generate};
use voxelkit::pipeline::request::{MeasureRequest, MeshRequest, Request, SolidRequest};
use voxelkit::pipeline::{Details, MeasureSource, MeshSource, Outcome};
use voxelkit::progress::Progress;
use voxelkit::progress::Unobserved;
use voxelkit::solids::csg_leaves;
use voxelkit::solids::exterior_flood::FloodMethod;
use voxelkit::solids::flooded_mesh::flooded_mesh;
use voxelkit::solids::inside_rule::InsideRule;
use voxelkit::solids::level_set::level_set;

mod common;

/// How far from 1/2 an exact winding number must lie for the test to hold a voxel to it: the
/// f64 sums of solid angles agree far closer than this.
const BOUND: f64 = 1e-6;

fn without_faces(mesh: &Mesh, name: &str, drop: impl Fn(usize) -> bool) -> Mesh {
    let keep: Vec<Vec<u32>> = (0..mesh.face_count())
        .filter(|&f| !drop(f))
        .map(|f| mesh.face(f).to_vec())
        .collect();
    Mesh::from_polygons(name, mesh.positions.clone(), &keep)
}

/// The generated cases the issue names.
fn generated() -> Vec<Mesh> {
    let torus = generate::torus(DVec3::ZERO, 1.0, 0.4, 40, 20);
    let mut inner = generate::cuboid(DVec3::splat(0.3), DVec3::splat(0.7));
    generate::reverse_faces(&mut inner);
    let mut flipped = generate::cuboid(DVec3::new(1.6, -0.3, -0.3), DVec3::new(2.2, 0.3, 0.3));
    generate::reverse_faces(&mut flipped);
    let mut stray = generate::combine(
        "",
        &[
            torus.clone(),
            generate::cuboid(DVec3::ZERO, DVec3::splat(0.01)),
        ],
    );
    // One triangle of the little cube, alone, cutting across the torus's tube.
    let t = stray.positions.len() as u32;
    stray.positions.extend([
        DVec3::new(0.6, -0.5, -0.2),
        DVec3::new(1.5, 0.3, 0.1),
        DVec3::new(0.9, 0.4, 0.3),
    ]);
    let mut faces: Vec<Vec<u32>> = (0..torus.face_count())
        .map(|f| torus.face(f).to_vec())
        .collect();
    faces.push(vec![t, t + 1, t + 2]);
    stray = Mesh::from_polygons(
        "closed torus with a stray triangle",
        stray.positions,
        &faces,
    );
    vec![
        without_faces(
            &generate::cuboid(DVec3::ZERO, DVec3::ONE),
            "cube with one face removed",
            |f| f == 5,
        ),
        generate::combine(
            "two interpenetrating tori",
            &[
                torus.clone(),
                generate::torus(DVec3::new(0.9, 0.1, 0.2), 1.0, 0.4, 40, 20),
            ],
        ),
        generate::combine(
            "nested shells, the inner one inverted",
            &[generate::cuboid(DVec3::ZERO, DVec3::ONE), inner],
        ),
        stray,
        generate::combine("torus and a flipped cube", &[torus, flipped]),
    ]
}

/// The open shared meshes, where the data is present.
fn shared_open() -> Vec<Mesh> {
    let Some(data) = common::data_dir() else {
        return Vec::new();
    };
    ["cube_no_bottom", "stanford-bunny", "teapot", "ogre"]
        .iter()
        .map(|name| Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap())
        .collect()
}

fn run(request: impl Request<Input = MeshSource>, mesh: &Mesh) -> Outcome {
    let limits = Default::default();
    let job = request
        .job(MeshSource::Mesh(mesh.clone()), &limits)
        .unwrap();
    job.plan().unwrap().run(&Unobserved).unwrap()
}

fn in_grid(grid: &SparseGrid, c: [i64; 3]) -> bool {
    grid.contains(c)
}

/// Centres to check: every one of the box (padded by 2) up to `limit`, else a fixed sample.
fn centres(grid: &SparseGrid, pad: i64, limit: usize) -> Vec<[i64; 3]> {
    let b = grid.bbox().unwrap();
    let (lo, hi) = (b.min.map(|v| v - pad), b.max.map(|v| v + pad));
    let dims: Vec<i64> = (0..3).map(|a| hi[a] - lo[a] + 1).collect();
    let total = (dims[0] * dims[1] * dims[2]) as usize;
    let mut rng = generate::SplitMix64(7);
    let pick = |i: usize| {
        let i = i as i64;
        [
            lo[0] + i / (dims[1] * dims[2]),
            lo[1] + i / dims[2] % dims[1],
            lo[2] + i % dims[2],
        ]
    };
    if total <= limit {
        (0..total).map(pick).collect()
    } else {
        (0..limit)
            .map(|_| pick(rng.range(0.0, total as f64) as usize % total))
            .collect()
    }
}

/// Every checked centre of `mesh` whose exact winding number lies beyond the bound agrees with
/// `inside(c)`; returns how many were checked.
fn agrees(
    what: &str,
    mesh: &Mesh,
    grid: &SparseGrid,
    inside: impl Fn([i64; 3]) -> Option<bool> + Sync,
    limit: usize,
) -> usize {
    let t = grid.transform;
    let reversed = mesh.signed_volume() < 0.0;
    let checked: Vec<_> = centres(grid, 2, limit)
        .into_par_iter()
        .filter_map(|c| {
            let decided = inside(c)?;
            let mut w = winding_number(mesh, t.index_to_world(c));
            if reversed {
                w = -w;
            }
            ((w - 0.5).abs() > BOUND).then_some((c, w, decided))
        })
        .collect();
    for &(c, w, decided) in &checked {
        assert_eq!(
            decided,
            w >= 0.5,
            "{what} of {}: voxel {c:?} with winding number {w}",
            mesh.source.display()
        );
    }
    checked.len()
}

#[test]
fn solids_level_sets_and_measures_agree_with_the_exact_winding_number() {
    let meshes: Vec<(Mesh, u32, usize)> = generated()
        .into_iter()
        .map(|m| (m, 40, usize::MAX))
        .chain(shared_open().into_iter().map(|m| (m, 64, 4000)))
        .collect();
    for (mesh, r, limit) in &meshes {
        let solid = run(
            SolidRequest {
                resolution: Some(*r),
                ..SolidRequest::default()
            },
            mesh,
        );
        let shell = &solid.extra.iter().find(|(n, _)| n == "shell").unwrap().1;
        let interior = &solid.extra.iter().find(|(n, _)| n == "interior").unwrap().1;
        // The surface's voxels belong to the solid whatever their centre: the rule is for
        // the rest.
        let surface_of = |c| in_grid(&solid.grid, c) && !in_grid(interior, c) && in_grid(shell, c);
        let n = agrees(
            "solid",
            mesh,
            &solid.grid,
            |c| (!surface_of(c) || !in_grid(&solid.grid, c)).then(|| in_grid(&solid.grid, c)),
            *limit,
        );
        assert!(n > 0);

        let sdf = run(
            MeshRequest {
                resolution: Some(*r),
                sdf: true,
                ..MeshRequest::default()
            },
            mesh,
        );
        let interior = sdf.distances.as_ref().unwrap().interior.as_ref().unwrap();
        let band = &sdf.grid;
        let negative = |c: [i64; 3]| {
            let origin = c.map(|v| v & !7);
            let value = band.leaf(origin).and_then(|l| {
                let n = ((c[0] - origin[0]) * 64 + (c[1] - origin[1]) * 8 + (c[2] - origin[2]))
                    as usize;
                (l.mask[n / 64] >> (n % 64) & 1 == 1).then(|| l.value.as_ref().unwrap()[n])
            });
            Some(match value {
                Some(v) => v < 0.0,
                None => matches!(interior.block(origin), Block::Whole) || interior.contains(c),
            })
        };
        agrees("--sdf", mesh, band, negative, *limit);

        // A CSG tree's mesh leaf: the centres inside, on the solid's grid.
        let t = solid.grid.transform;
        let bbox = voxelkit::grid::CoordBox {
            min: solid.grid.bbox().unwrap().min.map(|v| v - 2),
            max: solid.grid.bbox().unwrap().max.map(|v| v + 2),
        };
        let leaf = csg_leaves::mesh_solid(
            mesh,
            &t,
            bbox,
            &voxelkit::solids::depth_layers::DepthLayerOptions::ALL_DIRECTIONS,
        )
        .unwrap();
        agrees(
            "a CSG mesh leaf",
            mesh,
            &solid.grid,
            |c| Some(leaf.get(c)),
            *limit,
        );

        let measure = run_measure(mesh, *r);
        let Details::Solid(m) = &measure.report.details else {
            panic!("measure reports a solid");
        };
        let Details::Solid(s) = &solid.report.details else {
            panic!("solid reports a solid");
        };
        assert_eq!(
            (m.inside_voxels, m.surface_voxels),
            (s.inside_voxels, s.surface_voxels),
            "measure and solid of {}",
            mesh.source.display()
        );
    }
}

fn run_measure(mesh: &Mesh, r: u32) -> Outcome {
    let request = MeasureRequest {
        resolution: Some(r),
        ..MeasureRequest::default()
    };
    let limits = Default::default();
    let job = request
        .job(MeasureSource::Mesh(MeshSource::Mesh(mesh.clone())), &limits)
        .unwrap();
    job.plan().unwrap().run(&Unobserved).unwrap()
}

/// Two closed tori that overlap: their union's inside (winding 2 where they overlap) is the
/// union of their insides, which parity gets wrong (two crossings: outside).
#[test]
fn the_union_of_overlapping_parts_is_the_union_of_their_solids() {
    let a = generate::torus(DVec3::ZERO, 1.0, 0.4, 40, 20);
    let b = generate::torus(DVec3::new(0.9, 0.1, 0.2), 1.0, 0.4, 40, 20);
    let both = generate::combine("two tori", &[a.clone(), b.clone()]);
    // One grid for all three: the union's.
    let t = voxelkit::mesh::fit_transform(&both.bbox(), voxelkit::mesh::GridFit::Resolution(64))
        .unwrap();
    let solid = |mesh: &Mesh| {
        let (choice, parts) = flooded_mesh(
            mesh,
            t,
            FloodMethod::Blocks,
            InsideRule::Auto,
            &Progress::none(),
        )
        .unwrap();
        assert_eq!(choice.name(), "winding");
        parts.whole
    };
    let union = solid(&both);
    let mut parts = solid(&a);
    parts.union(&solid(&b));
    let extra = union.voxels().filter(|&c| !parts.contains(c)).count();
    let missing = parts.voxels().filter(|&c| !union.contains(c)).count();
    assert_eq!(
        (extra, missing),
        (0, 0),
        "the union's solid against the union of the solids ({} voxels)",
        union.voxel_count()
    );
    // Ray parity signs the overlap (two crossings) outside; the winding number, inside.
    let overlap: Vec<[i64; 3]> = union
        .voxels()
        .filter(|&c| (winding_number(&both, t.index_to_world(c)) - 2.0).abs() < 0.1)
        .collect();
    assert!(!overlap.is_empty());
    let interior = |rule: InsideRule, name: &str| {
        let (choice, set) = level_set(&both, t, 3.0, rule, &Progress::none()).unwrap();
        assert_eq!(choice.name(), name);
        set.interior
    };
    let (parity, winding) = (
        interior(InsideRule::Parity, "parity"),
        interior(InsideRule::Winding, "winding"),
    );
    assert!(overlap.iter().all(|&c| winding.contains(c)));
    assert!(overlap.iter().all(|&c| !parity.contains(c)));
}

/// On closed, consistently oriented meshes the winding number's level set is ray parity's.
#[test]
fn on_closed_meshes_winding_and_parity_give_the_same_level_set() {
    let mut meshes = vec![
        generate::torus(DVec3::ZERO, 1.0, 0.4, 40, 20),
        generate::random_closed(5),
    ];
    if let Some(data) = common::data_dir() {
        for name in common::CLOSED_MESHES {
            meshes.push(Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap());
        }
    }
    for mesh in &meshes {
        for r in [64, 128] {
            let of = |inside| {
                let o = run(
                    MeshRequest {
                        resolution: Some(r),
                        sdf: true,
                        inside,
                        ..MeshRequest::default()
                    },
                    mesh,
                );
                let interior = o.distances.unwrap().interior.unwrap();
                let band: Vec<_> = o
                    .grid
                    .leaves()
                    .iter()
                    .map(|l| (l.origin, l.value.clone().unwrap()))
                    .collect();
                (band, interior.voxel_count())
            };
            let (parity, winding) = (of(InsideRule::Parity), of(InsideRule::Winding));
            assert!(
                parity == winding,
                "{} at {r}: the level sets differ",
                mesh.source.display()
            );
        }
    }
}

/// A distributed run's solid by the winding number: every brick (with faces or only within the
/// mesh's box) keeps its surface and the centres the single run keeps, so the bricks together
/// are the single run's solid, at brick sizes that cut the generated cases anywhere.
#[test]
fn winding_bricks_give_the_single_runs_solid() {
    use voxelkit::pipeline::bricks::{BrickRun, sub_mesh};
    use voxelkit::pipeline::request::BricksRequest;
    use voxelkit::pipeline::{BrickStage, BrickTask, Job, Task};
    for mesh in generated() {
        let single = run(
            SolidRequest {
                resolution: Some(40),
                ..SolidRequest::default()
            },
            &mesh,
        )
        .grid;
        for size in [8, 24] {
            let request = BricksRequest {
                resolution: Some(40),
                brick: Some(size),
                ..BricksRequest::default()
            };
            let source = MeshSource::Mesh(mesh.clone());
            let plan =
                BrickRun::plan(&source, &request, true, std::path::Path::new("bricks")).unwrap();
            assert!(plan.winding, "{}", mesh.source.display());
            let mut bricks = SparseGrid::new(plan.layout.transform, Default::default());
            let without_faces = plan
                .winding_bricks()
                .into_iter()
                .map(|b| {
                    let faces = plan.bins.get(&b).map_or(&[][..], Vec::as_slice);
                    let task = Task::Brick(BrickTask {
                        faces: sub_mesh(&plan.mesh, faces),
                        brick: b,
                        size: i64::from(size),
                        stage: BrickStage::Winding {
                            mesh: plan.mesh.clone(),
                        },
                    });
                    let placed = voxelkit::mesh::GridFit::Placed(plan.layout.transform);
                    bricks.union(&Job::new(task, placed).run(&Unobserved).unwrap().grid);
                    faces.is_empty()
                })
                .filter(|&empty| empty)
                .count();
            let mut extra = bricks.clone();
            extra.difference(&single);
            let mut missing = single.clone();
            missing.difference(&bricks);
            assert_eq!(
                (extra.voxel_count(), missing.voxel_count()),
                (0, 0),
                "{} in bricks of {size}: {} voxels",
                mesh.source.display(),
                single.voxel_count()
            );
            if size == 8 {
                assert!(without_faces > 0, "bricks wholly inside or outside run too");
            }
        }
    }
}
