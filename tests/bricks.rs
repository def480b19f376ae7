//! Voxelizing in bricks (the Dask front end's library side), each brick a pipeline job, gives
//! the single run's voxels: the surface of each brick's binned faces clipped to the brick,
//! and solids whose outside components are joined across bricks. Generated fixtures with pockets, holes and nested
//! shells, at brick sizes that cut them anywhere.
#![cfg(feature = "fixtures")]

mod common;

use glam::DVec3;
use std::collections::BTreeMap;
use voxelkit::grid::SparseGrid;
use voxelkit::io::brick_set::fill_box;
use voxelkit::mesh::{GridFit, Mesh, generate};
use voxelkit::pipeline::brick_exterior::exterior_labels;
use voxelkit::pipeline::bricks::{BrickIndex, BrickLayout, BrickRun, FACES, sub_mesh};
use voxelkit::pipeline::request::BricksRequest;
use voxelkit::pipeline::{BrickStage, BrickTask, Details, Job, MeshSource, Outcome, Task};
use voxelkit::progress::{Progress, Unobserved};
use voxelkit::solids::exterior_flood::{FloodMethod, solid_from_surface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

fn options(separability: Separability) -> SeparatingOptions {
    SeparatingOptions {
        separability,
        ..Default::default()
    }
}

/// One brick's job, as a distributed run's worker runs it.
fn brick_job(layout: &BrickLayout, faces: &Mesh, b: BrickIndex, stage: BrickStage) -> Outcome {
    let task = Task::Brick(BrickTask {
        faces: faces.clone(),
        brick: b,
        size: layout.size,
        stage,
    });
    Job::new(task, GridFit::Placed(layout.transform))
        .run(&Unobserved)
        .unwrap()
}

/// The surface and the solid, assembled from bricks of `size`, each brick a job.
fn in_bricks(
    mesh: &Mesh,
    resolution: u32,
    size: u32,
    sep: Separability,
) -> (SparseGrid, SparseGrid) {
    let layout = BrickLayout::new(mesh, GridFit::Resolution(resolution), size).unwrap();
    let bins = layout.bin_faces(mesh);
    let mut surface = SparseGrid::new(layout.transform, Default::default());
    let mut faces = BTreeMap::new();
    let subs: BTreeMap<BrickIndex, Mesh> =
        bins.iter().map(|(b, f)| (*b, sub_mesh(mesh, f))).collect();
    for (b, sub) in &subs {
        surface.union(&brick_job(&layout, sub, *b, BrickStage::Surface(sep)).grid);
        let labels = brick_job(&layout, sub, *b, BrickStage::FaceLabels);
        let Details::BrickFaces(d) = labels.report.details else {
            panic!("no labels for brick {b:?}");
        };
        assert_eq!(d.labels.len(), FACES);
        faces.insert(*b, d.labels);
    }
    let exterior = exterior_labels(&layout, &faces).unwrap();
    let mut solid = SparseGrid::new(layout.transform, Default::default());
    for (b, labels) in &exterior {
        match subs.get(b) {
            Some(sub) => {
                let stage = BrickStage::Solid {
                    exterior: labels.clone(),
                };
                solid.union(&brick_job(&layout, sub, *b, stage).grid)
            }
            None if labels.is_empty() => fill_box(&mut solid, layout.voxels(*b)),
            None => assert_eq!(labels, &[1]),
        }
    }
    (surface, solid)
}

fn same(a: &SparseGrid, b: &SparseGrid) -> bool {
    let mut d = a.clone();
    d.difference(b);
    a.voxel_count() == b.voxel_count() && d.voxel_count() == 0
}

#[test]
fn bricks_give_the_single_runs_surface_and_solid() {
    let fixtures = [
        (
            "torus",
            generate::torus(DVec3::new(0.3, -0.2, 0.1), 1.0, 0.35, 48, 24),
        ),
        ("g shape", generate::g_shape()),
        ("spheres in a box", generate::spheres_in_box()),
        ("random", generate::random_closed(7)),
    ];
    for (name, mesh) in &fixtures {
        for (resolution, size) in [(90, 16), (120, 40), (64, 128)] {
            for sep in [Separability::Six, Separability::TwentySix] {
                let (surface, solid) = in_bricks(mesh, resolution, size, sep);
                let t =
                    voxelkit::mesh::fit_transform(&mesh.bbox(), GridFit::Resolution(resolution))
                        .unwrap();
                let (single, _) = voxelize_mesh(mesh, t, &options(sep), &Progress::none()).unwrap();
                assert!(
                    same(&surface, &single),
                    "{name} {resolution}/{size} {sep:?}: surface"
                );
                let (shell, _) = voxelize_mesh(
                    mesh,
                    t,
                    &options(Separability::TwentySix),
                    &Progress::none(),
                )
                .unwrap();
                let mut whole = solid_from_surface(&shell, FloodMethod::Spans, &Progress::none())
                    .unwrap()
                    .inside;
                whole.union(&shell);
                assert!(same(&solid, &whole), "{name} {resolution}/{size}: solid");
                assert!(
                    whole.voxel_count() > shell.voxel_count(),
                    "{name}: a solid inside"
                );
            }
        }
    }
}

#[test]
fn brick_sizes_must_be_multiples_of_eight() {
    let mesh = generate::torus(DVec3::ZERO, 1.0, 0.3, 16, 8);
    for bad in [0, 4, 12] {
        let e = BrickLayout::new(&mesh, GridFit::Resolution(64), bad).unwrap_err();
        assert!(e.to_string().contains("multiple of 8"), "{e}");
    }
}

/// Without a brick size the run takes the largest of 2048 (a solid's 1024), 1024, ..., 128
/// that gives each worker thread at least 8 bricks with faces (the smallest where none
/// does); a size given stays whatever the threads.
#[test]
fn a_run_without_a_brick_size_fits_its_bricks_to_the_threads() {
    let mesh = generate::torus(DVec3::ZERO, 1.0, 0.3, 64, 32);
    let source = MeshSource::Mesh(mesh.clone());
    let request = |brick| BricksRequest {
        resolution: Some(4096),
        brick,
        ..Default::default()
    };
    let output = std::path::Path::new("torus.vdb");
    let with_faces = |size: u32| {
        let layout = BrickLayout::new(&mesh, GridFit::Resolution(4096), size).unwrap();
        layout.bin_faces(&mesh).len()
    };
    for (solid, sizes) in [
        (false, &[2048u32, 1024, 512, 256][..]),
        (true, &[1024, 512, 256]),
    ] {
        for threads in [1, 2, 4, 16, 64, 1000] {
            let chosen = sizes
                .iter()
                .copied()
                .find(|&size| with_faces(size) >= 8 * threads)
                .unwrap_or(128);
            let mut run = BrickRun::plan(&source, &request(None), solid, output).unwrap();
            let size = run.fit_to_threads(&request(None), threads).unwrap();
            assert_eq!(size, i64::from(chosen), "{threads} threads, solid {solid}");
            assert_eq!(run.layout.size, size);
            assert_eq!(run.bins.len(), with_faces(chosen), "the faces binned anew");
            let mut given = BrickRun::plan(&source, &request(Some(512)), solid, output).unwrap();
            assert_eq!(
                given.fit_to_threads(&request(Some(512)), threads).unwrap(),
                512
            );
        }
    }
    // The thread counts above reach every size but the smallest.
    assert!(with_faces(2048) >= 8 && with_faces(256) < 8 * 1000);
}

/// A brick is a pipeline job: its memory plan refuses it with the brick named, and it runs
/// only on its run's placement.
#[test]
fn a_brick_job_is_planned_and_refused_as_a_job() {
    let mesh = generate::cuboid(DVec3::ZERO, DVec3::ONE);
    let layout = BrickLayout::new(&mesh, GridFit::Resolution(64), 64).unwrap();
    let (b, faces) = layout.bin_faces(&mesh).into_iter().next().unwrap();
    let task = Task::Brick(BrickTask {
        faces: sub_mesh(&mesh, &faces),
        brick: b,
        size: layout.size,
        stage: BrickStage::FaceLabels,
    });
    let mut job = Job::new(task.clone(), GridFit::Placed(layout.transform));
    job.limits.max_memory = Some(1 << 20);
    let refused = job.plan().err().expect("1 MiB is too little").to_string();
    assert!(
        refused.contains("the brick of 64^3 voxels") && refused.contains("use smaller bricks"),
        "{refused}"
    );
    let unplaced = Job::new(task, GridFit::Resolution(64)).plan().err();
    assert!(
        unplaced.is_some_and(|e| e.to_string().contains("GridFit::Placed")),
        "a brick without its run's placement must be refused"
    );
}

/// The bytes of a `.vdb`'s first grid from its tree on (topology and leaf buffers), past its
/// metadata and transform: what two writes of one grid share whatever their metadata.
fn tree_bytes(path: &std::path::Path) -> Vec<u8> {
    let b = std::fs::read(path).unwrap();
    let u32_at = |p: usize| u32::from_le_bytes(b[p..p + 4].try_into().unwrap()) as usize;
    let string = |p: usize| p + 4 + u32_at(p);
    // Magic, versions, offsets flag, UUID, no file metadata, the grid count.
    let mut p = 8 + 4 + 8 + 1 + 36 + 4 + 4;
    (0..3).for_each(|_| p = string(p)); // grid name, tree type, instance parent
    let offset = |p: usize| i64::from_le_bytes(b[p..p + 8].try_into().unwrap()) as usize;
    let (grid, end) = (offset(p), offset(p + 16));
    let entries = u32_at(grid + 4);
    let mut p = grid + 8;
    (0..3 * entries).for_each(|_| p = string(p)); // name, type, value
    b[string(p) + 6 * 24..end].to_vec() // the map's name, then its six vectors
}

/// Bricks on OpenVDB's 128^3 nodes merge by splicing into the tree a single write makes, byte
/// for byte: leaves, 8^3 and 128^3 tiles, and the bricks wholly inside (no file) as tiles;
/// OpenVDB reads the result as voxelkit does.
#[test]
fn node_bricks_splice_into_the_single_writes_tree() {
    use voxelkit::io::brick_set::{BRICK_SET_FORMAT, BrickFile, BrickSet, brick_voxels};
    use voxelkit::io::brick_splice::{EncodedBrick, Spliced, splice_brick_set, write_bricks_into};
    use voxelkit::io::vdb::write_vdb;
    let mesh = generate::cuboid(DVec3::new(-1.0, -0.7, -0.4), DVec3::new(1.0, 0.8, 0.45));
    let t = voxelkit::mesh::fit_transform(&mesh.bbox(), GridFit::Resolution(1100)).unwrap();
    let sep = Separability::TwentySix;
    let (shell, _) = voxelize_mesh(&mesh, t, &options(sep), &Progress::none()).unwrap();
    let mut whole = solid_from_surface(&shell, FloodMethod::Spans, &Progress::none())
        .unwrap()
        .inside;
    whole.union(&shell);
    whole.compact();
    let dir = tempfile::tempdir().unwrap();
    let size = 256;
    let b = whole.bbox().unwrap();
    let mut set = BrickSet {
        format: BRICK_SET_FORMAT.into(),
        voxel_size: t.voxel_size,
        origin: t.origin.to_array(),
        brick_size: size,
        bricks: Vec::new(),
        full_bricks: Vec::new(),
    };
    let range = |a: usize| b.min[a].div_euclid(size)..=b.max[a].div_euclid(size);
    for x in range(0) {
        for y in range(1) {
            for z in range(2) {
                let voxels = brick_voxels([x, y, z], size);
                let mut part = whole.clone();
                part.clip(voxels);
                if part.voxel_count() == (size as u64).pow(3) {
                    set.full_bricks.push([x, y, z]);
                } else if !part.is_empty() {
                    let file = format!("brick_{x}_{y}_{z}.vdb");
                    write_vdb(&dir.path().join(&file), &part, &[]).unwrap();
                    set.bricks.push(BrickFile {
                        brick: [x, y, z],
                        file,
                    });
                }
            }
        }
    }
    assert!(!set.full_bricks.is_empty(), "a brick wholly inside");
    let index = dir.path().join("index.json");
    set.write(&index).unwrap();
    let merged = dir.path().join("merged.vdb");
    let voxels = splice_brick_set(&set, &index, &merged, &[]).unwrap();
    let single = dir.path().join("single.vdb");
    write_vdb(&single, &whole, &[]).unwrap();
    assert_eq!(voxels, whole.voxel_count());
    // 128^3 tiles inside brick files too, besides the eight of each brick wholly inside.
    assert!(whole.tiles().node_tiles().count() > 8 * set.full_bricks.len());
    assert!(
        tree_bytes(&merged) == tree_bytes(&single),
        "the single write's tree"
    );
    common::assert_read_as_openvdb_reads(&merged, "density");
    // Bricks kept in memory (as workers keep them) write their nodes into place, each brick
    // from its own thread as from its own worker, giving the same tree.
    let kept: Vec<EncodedBrick> = set
        .bricks
        .iter()
        .map(|b| {
            let bytes = std::fs::read(dir.path().join(&b.file)).unwrap();
            EncodedBrick::new(bytes, std::path::Path::new(&b.file)).unwrap()
        })
        .collect();
    let nodes: Vec<Vec<u8>> = kept.iter().map(EncodedBrick::nodes).collect();
    let in_place = dir.path().join("in_place.vdb");
    let spliced = Spliced::in_place(&set, &nodes, &in_place, &[]).unwrap();
    assert_eq!(spliced.voxels, whole.voxel_count());
    spliced
        .write_in_place(&in_place, kept.len(), |tmp, placements| {
            assert!(placements.iter().any(|p| p.len() > 1), "bricks in pieces");
            std::thread::scope(|scope| {
                for (brick, ranges) in kept.iter().zip(&placements) {
                    scope
                        .spawn(move || write_bricks_into(tmp, &[(brick, ranges.clone())]).unwrap());
                }
            });
            Ok(())
        })
        .unwrap();
    assert!(
        tree_bytes(&in_place) == tree_bytes(&single),
        "the single write's tree from bricks in memory"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        set.bricks.len() + 4,
        "no temporary file left"
    );
    // A brick's description of its nodes cut short, or with its slots garbled, is refused,
    // naming the brick.
    for garble in [
        |n: &mut Vec<u8>| n.truncate(n.len() - 3),
        |n: &mut Vec<u8>| n[88..].iter_mut().for_each(|b| *b = 0xff),
    ] {
        let mut bad = nodes.clone();
        garble(&mut bad[0]);
        let message = Spliced::in_place(&set, &bad, &in_place, &[])
            .err()
            .expect("refused")
            .to_string();
        assert!(message.contains("brick ["), "{message}");
    }
    // A brick that fails to write leaves no output.
    let failed = dir.path().join("failed.vdb");
    let spliced = Spliced::in_place(&set, &nodes, &failed, &[]).unwrap();
    let refused = spliced.write_in_place(&failed, kept.len(), |_, _| {
        Err(voxelkit::error::Error::InvalidArgument(
            "a brick failed".into(),
        ))
    });
    assert!(refused.is_err() && !failed.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        set.bricks.len() + 4
    );
}
