//! Meshes out of grids (`voxelkit to-mesh`, `contour`): every mesh closed and 2-manifold,
//! consistently oriented outward, free of flat triangles, on random fields full of ambiguous
//! cells as on the shared meshes' level sets, and free of self-intersections on the small ones; and on those, the volume and the two-sided
//! distance to the input mesh.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;
mod common;

use cli_support::{text, voxelkit};
use glam::DVec3;
use rustc_hash::FxHashMap;
use voxelkit::contour::{Meaning, ScalarField, TriangleMesh, contour};
use voxelkit::grid::{Channels, Leaf, SparseGrid, Transform, leaf_offset, leaf_origin};
use voxelkit::mesh::Mesh;
use voxelkit::mesh::generate::icosphere;
use voxelkit::mesh::simplify::simplify;
use voxelkit::mesh::winding::WindingTree;
use voxelkit::random::SplitMix64;

/// Checks that every directed edge is used once and its reverse once (closed, consistently
/// oriented), that the triangles around each vertex form one fan closing on itself (no pinched
/// vertex), that every vertex is used and no triangle is flat (`min_area` in squared world
/// units).
fn assert_closed_manifold(what: &str, positions: &[DVec3], triangles: &[[u32; 3]], min_area: f64) {
    let mut directed: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    for t in triangles {
        for i in 0..3 {
            *directed.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(
            n, 1,
            "{what}: edge {a}->{b} used {n} times in one direction"
        );
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "{what}: edge {a}-{b} has no opposite triangle (open or inconsistently oriented)"
        );
    }
    // Around vertex v, each triangle (v, b, c) links b to c; one fan is one cycle of links.
    let mut links: Vec<Vec<(u32, u32)>> = vec![Vec::new(); positions.len()];
    for t in triangles {
        for i in 0..3 {
            links[t[i] as usize].push((t[(i + 1) % 3], t[(i + 2) % 3]));
        }
    }
    for (v, around) in links.iter().enumerate() {
        assert!(
            around.len() >= 3,
            "{what}: vertex {v} in {} triangles",
            around.len()
        );
        let next: FxHashMap<u32, u32> = around.iter().copied().collect();
        let (mut at, mut steps) = (around[0].0, 0);
        loop {
            at = next[&at];
            steps += 1;
            if at == around[0].0 {
                break;
            }
        }
        assert_eq!(
            steps,
            around.len(),
            "{what}: vertex {v} is pinched (more than one fan)"
        );
    }
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        assert!(area > min_area, "{what}: triangle {t:?} has area {area:e}");
    }
}

/// Whether two triangles meet (closed sets): no separating axis among their normals, the
/// cross products of their edges, and their edges turned in each one's plane.
fn triangles_meet(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
    let edges = |t: [DVec3; 3]| [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
    let (ea, eb) = (edges(a), edges(b));
    let (na, nb) = (ea[0].cross(ea[1]), eb[0].cross(eb[1]));
    let mut axes = vec![na, nb];
    for i in 0..3 {
        axes.extend(eb.iter().map(|e| ea[i].cross(*e)));
        axes.push(na.cross(ea[i]));
        axes.push(nb.cross(eb[i]));
    }
    !axes.iter().any(|axis| {
        if axis.length_squared() < 1e-24 {
            return false;
        }
        let span = |t: [DVec3; 3]| {
            let d = t.map(|p| p.dot(*axis));
            (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
        };
        let ((lo_a, hi_a), (lo_b, hi_b)) = (span(a), span(b));
        hi_a < lo_b || hi_b < lo_a
    })
}

/// Checks that no two triangles meet but at the corners and edges they share, through a grid
/// of buckets of `cell` world units.
fn assert_no_self_intersections(
    what: &str,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cell: f64,
) {
    let key = |p: DVec3| ((p / cell).floor()).as_i64vec3().to_array();
    let mut buckets: FxHashMap<[i64; 3], Vec<usize>> = FxHashMap::default();
    for (n, t) in triangles.iter().enumerate() {
        let c = t.map(|i| positions[i as usize]);
        let (lo, hi) = (key(c[0].min(c[1]).min(c[2])), key(c[0].max(c[1]).max(c[2])));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    buckets.entry([x, y, z]).or_default().push(n);
                }
            }
        }
    }
    for members in buckets.values() {
        for (k, &i) in members.iter().enumerate() {
            for &j in &members[k + 1..] {
                let (s, t) = (triangles[i], triangles[j]);
                let shared = s.iter().filter(|v| t.contains(v)).count();
                if shared > 1 {
                    continue;
                }
                // Triangles with a corner in common may touch there only: shrunk a little
                // towards their centroids they must part.
                let shrink = if shared == 1 { 1e-6 } else { 0.0 };
                let corners = |t: [u32; 3]| {
                    let c = t.map(|v| positions[v as usize]);
                    let mid = (c[0] + c[1] + c[2]) / 3.0;
                    c.map(|p| p + (mid - p) * shrink)
                };
                assert!(
                    !triangles_meet(corners(s), corners(t)),
                    "{what}: triangles {s:?} and {t:?} meet"
                );
            }
        }
    }
}

fn signed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// A field of `values(c)` on the voxels of a cube of `edge` voxels, as a level set whose
/// outside beyond it is `outside`.
fn level_set(edge: i64, values: impl Fn([i64; 3]) -> f32) -> SparseGrid {
    let mut leaves: FxHashMap<[i64; 3], Leaf> = FxHashMap::default();
    for x in 0..edge {
        for y in 0..edge {
            for z in 0..edge {
                let c = [x, y, z];
                let leaf = leaves.entry(leaf_origin(c)).or_insert_with(|| {
                    let mut l = Leaf::new(leaf_origin(c), Channels::VALUE);
                    l.value.as_mut().unwrap().fill(1.0);
                    l
                });
                leaf.set_on(leaf_offset(c));
                leaf.value.as_mut().unwrap()[leaf_offset(c)] = values(c);
            }
        }
    }
    SparseGrid::from_leaves(
        Transform::new(DVec3::new(0.5, -1.0, 2.0), 0.25),
        Channels::VALUE,
        leaves.into_values().collect(),
    )
}

/// Random values, positive on the cube's outer layer: every sign case occurs, ambiguous faces
/// and cells by the thousand; the surface must still close up.
#[test]
fn random_fields_give_closed_manifold_meshes() {
    for seed in 1..=6u64 {
        let mut rng = SplitMix64(seed);
        let edge = 20;
        let values: Vec<f32> = (0..edge * edge * edge)
            .map(|_| rng.range(-1.0, 1.0) as f32)
            .collect();
        let grid = level_set(edge, |c| {
            if c.iter().any(|&v| v == 0 || v == edge - 1) {
                1.0
            } else {
                values[((c[0] * edge + c[1]) * edge + c[2]) as usize]
            }
        });
        let voxel = grid.transform.voxel_size;
        let mesh = contour(&ScalarField::level_set(grid, 0.0).unwrap(), None).unwrap();
        assert!(
            mesh.triangles.len() > 10_000,
            "seed {seed}: {}",
            mesh.triangles.len()
        );
        assert_closed_manifold(
            &format!("random field {seed}"),
            &mesh.positions,
            &mesh.triangles,
            1e-7 * voxel * voxel,
        );
        assert!(signed_volume(&mesh.positions, &mesh.triangles) > 0.0);
        assert_no_self_intersections(
            &format!("random field {seed}"),
            &mesh.positions,
            &mesh.triangles,
            voxel,
        );
    }
}

/// Random voxel sets, half full, many voxels touching only along an edge or at a corner.
#[test]
fn random_voxel_sets_give_closed_manifold_meshes() {
    for seed in 1..=4u64 {
        let mut rng = SplitMix64(seed);
        let mut grid = SparseGrid::new(Transform::new(DVec3::ZERO, 1.0), Channels::NONE);
        let mut count = 0;
        for x in 0..24 {
            for y in 0..24 {
                for z in 0..24 {
                    if rng.range(0.0, 1.0) < 0.5 {
                        grid.insert([x, y, z]);
                        count += 1;
                    }
                }
            }
        }
        // A solid block, partly as a tile, beside empty space.
        grid.fill_leaf_block([32, 0, 0]);
        let field = ScalarField {
            grid: std::borrow::Cow::Owned(grid),
            meaning: Meaning::Voxels,
            iso: 0.0,
        };
        let mesh = contour(&field, None).unwrap();
        assert_closed_manifold(
            &format!("random voxels {seed}"),
            &mesh.positions,
            &mesh.triangles,
            1e-7,
        );
        assert_no_self_intersections(
            &format!("random voxels {seed}"),
            &mesh.positions,
            &mesh.triangles,
            1.0,
        );
        let volume = signed_volume(&mesh.positions, &mesh.triangles);
        // Each voxel's surface passes half way to its empty neighbours: about a voxel each.
        let voxels = (count + 512) as f64;
        assert!(
            volume > 0.5 * voxels && volume < 1.5 * voxels,
            "{volume} for {voxels}"
        );
    }
}

/// A sphere's exact distances: vertices on the sphere to a few hundredths of a voxel, the
/// volume to 0.1%.
#[test]
fn a_sphere_level_set_gives_the_sphere() {
    let (edge, r) = (40i64, 15.3f64);
    let centre = DVec3::splat(19.6);
    let grid = level_set(edge, |c| {
        (DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) - centre).length() as f32 - r as f32
    });
    let t = grid.transform;
    let mesh = contour(&ScalarField::level_set(grid, 0.0).unwrap(), None).unwrap();
    assert_closed_manifold("sphere", &mesh.positions, &mesh.triangles, 1e-9);
    assert_no_self_intersections("sphere", &mesh.positions, &mesh.triangles, t.voxel_size);
    let world_centre = t.origin + t.voxel_size * centre;
    let worst = mesh
        .positions
        .iter()
        .map(|p| ((*p - world_centre).length() - r * t.voxel_size).abs() / t.voxel_size)
        .fold(0.0, f64::max);
    assert!(worst < 0.05, "a vertex lies {worst} voxels off the sphere");
    let volume = signed_volume(&mesh.positions, &mesh.triangles);
    let exact = 4.0 / 3.0 * std::f64::consts::PI * (r * t.voxel_size).powi(3);
    assert!(
        (volume / exact - 1.0).abs() < 1e-3,
        "{volume} against {exact}"
    );
}

/// The largest distance from any of `points` to the mesh of `tree`.
fn farthest(points: &[DVec3], tree: &WindingTree) -> f64 {
    use rayon::prelude::*;
    points
        .par_iter()
        .map(|p| tree.distance(*p))
        .reduce(|| 0.0, f64::max)
}

/// A mesh's vertices, triangle centroids and edge midpoints: where it is farthest from a
/// surface close to it.
fn probe_points(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut points = positions.to_vec();
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        points.extend([
            (a + b + c) / 3.0,
            0.5 * (a + b),
            0.5 * (b + c),
            0.5 * (c + a),
        ]);
    }
    points
}

fn triangles_of(mesh: &Mesh) -> Vec<[u32; 3]> {
    (0..mesh.face_count())
        .flat_map(|f| {
            let face = mesh.face(f);
            (1..face.len() - 1).map(move |i| [face[0], face[i], face[i + 1]])
        })
        .collect()
}

/// The shared closed meshes' level sets at 128 and 256, through the CLI and back from the
/// file by voxelkit's own reader: closed, manifold, outward, free of self-intersections (at
/// 128), the volume within 0.5% of the
/// mesh's, and the two-sided distance to the mesh within the figures measured (a level set
/// sampled at voxel centres cannot show a feature thinner than a voxel: the bunny's ear tips and
/// the rocker arm's sharp rims are where the mesh lies farthest from it).
#[test]
fn shared_level_sets_give_closed_accurate_meshes() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for name in common::CLOSED_MESHES {
        let input = data.join("meshes").join(format!("{name}.obj"));
        let source = Mesh::load(&input).unwrap();
        let source_triangles = triangles_of(&source);
        let source_tree = WindingTree::new(&source);
        let source_volume = signed_volume(&source.positions, &source_triangles).abs();
        for r in [128, 256] {
            let vdb = dir.path().join(format!("{name}{r}.vdb"));
            let ply = dir.path().join(format!("{name}{r}.ply"));
            let o = voxelkit(&[
                "mesh",
                input.to_str().unwrap(),
                "--sdf",
                "-r",
                &r.to_string(),
                "-o",
                vdb.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", text(&o));
            let o = voxelkit(&[
                "to-mesh",
                vdb.to_str().unwrap(),
                "-o",
                ply.to_str().unwrap(),
                "--json",
            ]);
            assert!(o.status.success(), "{}", text(&o));
            let out = Mesh::load(&ply).unwrap();
            let triangles = triangles_of(&out);
            let voxel = source.bbox().extent().max_element() / r as f64;
            let what = format!("{name} at {r}");
            assert_closed_manifold(&what, &out.positions, &triangles, 1e-9 * voxel * voxel);
            if r == 128 {
                assert_no_self_intersections(&what, &out.positions, &triangles, voxel);
            }
            let volume = signed_volume(&out.positions, &triangles);
            assert!(volume > 0.0, "{what}: the mesh faces inward");
            let error = (volume / source_volume - 1.0).abs();
            assert!(
                error < 0.005,
                "{what}: volume {volume} against {source_volume}"
            );
            let out_tree = WindingTree::new(&out);
            let to_source =
                farthest(&probe_points(&out.positions, &triangles), &source_tree) / voxel;
            let to_out = farthest(
                &probe_points(&source.positions, &source_triangles),
                &out_tree,
            ) / voxel;
            eprintln!(
                "{what}: volume error {:.3}%, distance out->in {to_source:.3}, in->out {to_out:.3} voxels",
                100.0 * error
            );
            assert!(
                to_source < 0.7,
                "{what}: the mesh lies {to_source} voxels off the input"
            );
            assert!(
                to_out < 1.7,
                "{what}: the input lies {to_out} voxels off the mesh"
            );
        }
    }
}

fn corners_of(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[DVec3; 3]> {
    triangles
        .iter()
        .map(|t| t.map(|i| positions[i as usize]))
        .collect()
}

/// The two-sided distance, in voxels, between two meshes, over each one's probe points.
fn mesh_distance(a: &TriangleMesh, b: &TriangleMesh, voxel: f64) -> (f64, f64) {
    let tree_a = WindingTree::of_triangles(corners_of(&a.positions, &a.triangles));
    let tree_b = WindingTree::of_triangles(corners_of(&b.positions, &b.triangles));
    (
        farthest(&probe_points(&a.positions, &a.triangles), &tree_b) / voxel,
        farthest(&probe_points(&b.positions, &b.triangles), &tree_a) / voxel,
    )
}

/// Checks a mesh merged from `full` at `adaptivity`: closed, manifold, free of flat triangles
/// and self-intersections, outward, and within `adaptivity` of `full` both ways.
fn assert_merged_within(
    what: &str,
    merged: &TriangleMesh,
    full: &TriangleMesh,
    adaptivity: f64,
    voxel: f64,
) {
    let (positions, triangles) = (&merged.positions, &merged.triangles);
    assert_closed_manifold(what, positions, triangles, 1e-9 * voxel * voxel);
    assert_no_self_intersections(what, positions, triangles, voxel);
    assert!(signed_volume(positions, triangles) > 0.0, "{what}: inward");
    let (to_full, from_full) = mesh_distance(merged, full, voxel);
    eprintln!(
        "{what}: {} -> {} triangles, distance {to_full:.3} / {from_full:.3} voxels",
        full.triangles.len(),
        triangles.len()
    );
    assert!(
        to_full <= adaptivity && from_full <= adaptivity,
        "{what}: {to_full} / {from_full} voxels from the full mesh"
    );
}

/// The triangles of `mesh` that face along an axis.
fn on_faces(mesh: &TriangleMesh) -> usize {
    corners_of(&mesh.positions, &mesh.triangles)
        .iter()
        .filter(|c| {
            let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
            n.abs().max_element() > 0.99999
        })
        .count()
}

/// Merging flat regions: a box's faces fall to a few triangles, a sphere keeps its shape;
/// every mesh stays closed, manifold, outward and free of self-intersections, and lies within
/// the adaptivity of the mesh it was merged from, both ways.
#[test]
fn adaptivity_merges_flat_regions_within_its_bound() {
    let centre = DVec3::splat(19.6);
    let box_distance = |c: [i64; 3]| {
        let q = (DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) - centre).abs()
            - DVec3::new(12.2, 9.7, 7.4);
        (q.max(DVec3::ZERO).length() + q.max_element().min(0.0)) as f32
    };
    let sphere = |c: [i64; 3]| {
        ((DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) - centre).length() - 15.3) as f32
    };
    for (name, grid) in [
        ("box", level_set(40, box_distance)),
        ("sphere", level_set(40, sphere)),
    ] {
        let voxel = grid.transform.voxel_size;
        let full = contour(&ScalarField::level_set(grid, 0.0).unwrap(), None).unwrap();
        let full_volume = signed_volume(&full.positions, &full.triangles);
        for adaptivity in [0.1, 0.25, 0.5] {
            let mut merged = full.clone();
            let done = simplify(&mut merged, adaptivity, voxel).unwrap();
            let what = format!("{name} at adaptivity {adaptivity}");
            assert_eq!(done.triangles_before, full.triangles.len());
            assert_merged_within(&what, &merged, &full, adaptivity, voxel);
            let volume = signed_volume(&merged.positions, &merged.triangles);
            assert!(
                (volume / full_volume - 1.0).abs() < 0.01,
                "{what}: volume {volume} against {full_volume}"
            );
            // The box's faces: a flat region merges into about as few triangles as its border
            // allows (its edges, rounded by the values, are not flat).
            if name == "box" {
                let (before, after) = (on_faces(&full), on_faces(&merged));
                assert!(
                    after * 4 < before,
                    "{what}: {after} of {before} triangles on the faces left"
                );
            }
        }
    }
}

/// `--adaptivity` on the shared closed meshes' level sets at 128: fewer triangles, still
/// closed, manifold, outward and free of self-intersections, within the adaptivity of the
/// full mesh both ways, the same at any number of threads; a negative adaptivity is refused;
/// `--mesh-out` takes it, and a voxelizing command refuses it without one.
#[test]
fn to_mesh_adaptivity_on_the_shared_meshes() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let adaptivity = 0.25;
    for name in common::CLOSED_MESHES {
        let input = data.join("meshes").join(format!("{name}.obj"));
        let p = |n: &str| {
            dir.path()
                .join(format!("{name}{n}"))
                .to_str()
                .unwrap()
                .to_string()
        };
        let o = voxelkit(&[
            "mesh",
            input.to_str().unwrap(),
            "--sdf",
            "-r",
            "128",
            "-o",
            &p(".vdb"),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let o = voxelkit(&["to-mesh", &p(".vdb"), "-o", &p("-full.ply")]);
        assert!(o.status.success(), "{}", text(&o));
        let o = voxelkit(&[
            "to-mesh",
            &p(".vdb"),
            "-o",
            &p("-merged.ply"),
            "--adaptivity",
            &adaptivity.to_string(),
            "--json",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let load = |n: &str| {
            let m = Mesh::load(std::path::Path::new(&p(n))).unwrap();
            TriangleMesh {
                triangles: triangles_of(&m),
                positions: m.positions,
            }
        };
        let (full, merged) = (load("-full.ply"), load("-merged.ply"));
        // The cubes of space the threads share out decide, not the threads: one thread
        // writes the same bytes.
        let o = voxelkit(&[
            "to-mesh",
            &p(".vdb"),
            "-o",
            &p("-one-thread.ply"),
            "--adaptivity",
            &adaptivity.to_string(),
            "--threads",
            "1",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        assert_eq!(
            std::fs::read(p("-merged.ply")).unwrap(),
            std::fs::read(p("-one-thread.ply")).unwrap(),
            "{name}: one thread merged otherwise"
        );
        assert_eq!(report["triangles"], merged.triangles.len() as u64);
        assert_eq!(
            report["triangles_before_merging"],
            full.triangles.len() as u64
        );
        let voxel = Mesh::load(&input).unwrap().bbox().extent().max_element() / 128.0;
        let what = format!("{name} at 128, adaptivity {adaptivity}");
        assert_merged_within(&what, &merged, &full, adaptivity, voxel);
        assert!(
            merged.triangles.len() * 3 < full.triangles.len() * 2,
            "{what}: little merged"
        );
    }
    let o = voxelkit(&[
        "to-mesh",
        dir.path().join("fandisk.vdb").to_str().unwrap(),
        "-o",
        dir.path().join("x.ply").to_str().unwrap(),
        "--adaptivity=-1",
    ]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("adaptivity must be 0 or a positive number of voxels, not -1"),
        "{}",
        text(&o)
    );
    assert!(!dir.path().join("x.ply").exists());
    // With --mesh-out on a voxelizing command, and refused without one.
    let fandisk = data.join("meshes/fandisk.obj");
    let (vdb, ply) = (dir.path().join("f.vdb"), dir.path().join("f.ply"));
    let mut args = vec![
        "mesh",
        fandisk.to_str().unwrap(),
        "--sdf",
        "-r",
        "64",
        "-o",
        vdb.to_str().unwrap(),
        "--adaptivity",
        "0.25",
    ];
    let o = voxelkit(&args);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("--adaptivity shapes the mesh of --mesh-out"),
        "{}",
        text(&o)
    );
    assert!(!vdb.exists());
    args.extend(["--mesh-out", ply.to_str().unwrap(), "--json"]);
    let o = voxelkit(&args);
    assert!(o.status.success(), "{}", text(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mesh = &report["mesh"];
    assert!(mesh["triangles_before_merging"].as_u64() > mesh["triangles"].as_u64());
    assert_eq!(mesh["adaptivity"], 0.25);
    assert_eq!(
        Mesh::load(&ply).unwrap().face_count() as u64,
        mesh["triangles"].as_u64().unwrap()
    );
}

/// Every format reads back as the same mesh; a fog volume and a voxel set give meshes too;
/// bad requests are refused with the file named.
#[test]
fn to_mesh_writes_each_format_and_refuses_bad_requests() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    icosphere(DVec3::ZERO, 1.0, 4)
        .write_obj(std::path::Path::new(&p("s.obj")))
        .unwrap();
    let o = voxelkit(&["mesh", &p("s.obj"), "--sdf", "-r", "40", "-o", &p("s.vdb")]);
    assert!(o.status.success(), "{}", text(&o));
    let exact = signed_volume(
        &icosphere(DVec3::ZERO, 1.0, 4).positions,
        &triangles_of(&icosphere(DVec3::ZERO, 1.0, 4)),
    );
    let mut counts = Vec::new();
    for ext in ["obj", "ply", "stl", "glb"] {
        let out = p(&format!("out.{ext}"));
        let o = voxelkit(&["to-mesh", &p("s.vdb"), "-o", &out]);
        assert!(o.status.success(), "{}", text(&o));
        let m = Mesh::load(std::path::Path::new(&out)).unwrap();
        counts.push(m.face_count());
        let volume = signed_volume(&m.positions, &triangles_of(&m));
        assert!(
            (volume / exact - 1.0).abs() < 0.005,
            "{ext}: {volume} against {exact}"
        );
    }
    assert!(counts.iter().all(|&c| c == counts[0]), "{counts:?}");
    for grid in ["density", "voxels"] {
        let o = voxelkit(&[
            "mesh",
            &p("s.obj"),
            "-r",
            "40",
            "--grids",
            "density,voxels",
            "-o",
            &p("f.vdb"),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let o = voxelkit(&["to-mesh", &p("f.vdb"), "--grid", grid, "-o", &p("f.ply")]);
        assert!(o.status.success(), "{grid}: {}", text(&o));
    }
    let (s_vdb, f_vdb, n_obj) = (p("s.vdb"), p("f.vdb"), p("n.obj"));
    let (s_txt, s_obj) = (p("s.txt"), p("s.obj"));
    let refused = [
        (
            vec!["to-mesh", s_vdb.as_str(), "-o", &s_txt],
            ".obj, .ply, .stl or .glb",
        ),
        (
            vec!["to-mesh", s_vdb.as_str(), "--grid", "nope", "-o", &n_obj],
            "no grid named `nope`",
        ),
        (
            vec!["to-mesh", s_vdb.as_str(), "--iso", "9", "-o", &n_obj],
            "beyond the band",
        ),
        (
            vec![
                "to-mesh",
                f_vdb.as_str(),
                "--grid",
                "voxels",
                "--iso",
                "0.2",
                "-o",
                &n_obj,
            ],
            "no values",
        ),
        (
            vec![
                "to-mesh",
                f_vdb.as_str(),
                "--grid",
                "density",
                "--iso",
                "0",
                "-o",
                &n_obj,
            ],
            "must be above 0",
        ),
        (vec!["to-mesh", s_vdb.as_str(), "-o", &s_vdb], "s.vdb"),
        (vec!["to-mesh", s_obj.as_str(), "-o", &n_obj], "s.obj"),
    ];
    for (args, message) in refused {
        let o = voxelkit(&args);
        assert!(!o.status.success(), "{args:?}");
        assert!(text(&o).contains(message), "{args:?}: {}", text(&o));
    }
    assert!(
        !dir.path().join("n.obj").exists(),
        "a refused run left a file"
    );
}

/// `--mesh-out` beside a run's `.vdb`: an open scan's level set (signed by the winding
/// number) and a CSG tree's solid come out closed and manifold, the scan's volume within 0.5%
/// of the solid `measure` reports; a batch or an input as the mesh is refused before any work.
#[test]
fn mesh_out_writes_closed_meshes_beside_the_runs() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let tree = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/csg/flange.json");
    let o = voxelkit(&[
        "csg",
        "--tree",
        tree,
        "-o",
        &p("flange.vdb"),
        "--mesh-out",
        &p("flange.glb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("closed and manifold"), "{}", text(&o));
    let flange = Mesh::load(std::path::Path::new(&p("flange.glb"))).unwrap();
    assert_closed_manifold("flange", &flange.positions, &triangles_of(&flange), 0.0);
    let icosphere_file = p("ball.obj");
    icosphere(DVec3::ZERO, 1.0, 3)
        .write_obj(std::path::Path::new(&icosphere_file))
        .unwrap();
    let ball = icosphere_file.as_str();
    let out_dir = dir.path().to_str().unwrap();
    let batch = [
        "mesh",
        ball,
        ball,
        "--out-dir",
        out_dir,
        "--mesh-out",
        "m.obj",
    ];
    let refused: [&[&str]; 3] = [
        &batch,
        &["mesh", ball, "-o", "x.vdb", "--mesh-out", ball],
        &["mesh", ball, "-o", "x.vdb", "--mesh-out", "x.off"],
    ];
    for args in refused {
        let o = voxelkit(args);
        assert!(!o.status.success(), "{args:?}");
        assert!(
            !std::path::Path::new("x.vdb").exists(),
            "{args:?} wrote its .vdb"
        );
    }
    let Some(data) = common::data_dir() else {
        return;
    };
    let scan = data.join("meshes/stanford-bunny.obj");
    let o = voxelkit(&[
        "mesh",
        scan.to_str().unwrap(),
        "--sdf",
        "-r",
        "128",
        "-o",
        &p("scan.vdb"),
        "--mesh-out",
        &p("scan.ply"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let out = Mesh::load(std::path::Path::new(&p("scan.ply"))).unwrap();
    let triangles = triangles_of(&out);
    assert_closed_manifold("stanford-bunny", &out.positions, &triangles, 0.0);
    let o = voxelkit(&["measure", scan.to_str().unwrap(), "-r", "512", "--json"]);
    assert!(o.status.success(), "{}", text(&o));
    let (inside, with_surface) = (
        cli_support::json_field(&text(&o), "volume_inside"),
        cli_support::json_field(&text(&o), "volume_with_surface"),
    );
    let volume = signed_volume(&out.positions, &triangles);
    let measured = 0.5 * (inside + with_surface);
    assert!(
        (volume / measured - 1.0).abs() < 0.005,
        "{volume} against {measured}"
    );
}

/// `remesh`: a closed mesh comes back closed and manifold within the level-set figures of
/// its distance; a mesh with a face removed comes back closed (the winding number fills the
/// hole), and the report's two-sided distance agrees with the one measured here.
#[test]
fn remesh_closes_any_mesh_and_reports_its_distance() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let mut holed = icosphere(DVec3::ZERO, 1.0, 4);
    let mut polygons: Vec<Vec<u32>> = (0..holed.face_count())
        .map(|f| holed.face(f).to_vec())
        .collect();
    polygons.remove(7);
    holed = Mesh::from_polygons("holed", holed.positions.clone(), &polygons);
    holed.write_obj(&p("holed.obj")).unwrap();
    let o = voxelkit(&[
        "remesh",
        p("holed.obj").to_str().unwrap(),
        "-r",
        "64",
        "-o",
        p("closed.ply").to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let report = text(&o);
    let out = Mesh::load(&p("closed.ply")).unwrap();
    let triangles = triangles_of(&out);
    assert_closed_manifold("remeshed", &out.positions, &triangles, 0.0);
    let voxel = 2.0 / 64.0;
    let to_source = cli_support::json_field(&report, "distance_to_source");
    let from_source = cli_support::json_field(&report, "source_to_mesh");
    assert!(
        to_source < 0.6 * voxel && from_source < 0.6 * voxel,
        "{report}"
    );
    // The hole's cap lies within the sphere's sagitta over one triangle: the measure here, by
    // the same points, agrees to rounding (the file holds 32-bit floats).
    let corners = |m: &Mesh| -> Vec<[DVec3; 3]> {
        triangles_of(m).iter().map(|t| t.map(|i| m.p(i))).collect()
    };
    let d = voxelkit::mesh::surface_distance::two_sided_distance(&corners(&out), &corners(&holed));
    assert!(
        (d.a_to_b - to_source).abs() < 1e-6 && (d.b_to_a - from_source).abs() < 1e-6,
        "{d:?}"
    );
    let volume = signed_volume(&out.positions, &triangles);
    assert!((volume / signed_volume(&holed.positions, &triangles_of(&holed)) - 1.0).abs() < 0.01);
}

/// The farthest, in voxels of `voxel`, that any of `corners` lies from a vertex of `mesh`.
fn farthest_corner(mesh: &Mesh, corners: &[DVec3], voxel: f64) -> f64 {
    corners
        .iter()
        .map(|c| {
            mesh.positions
                .iter()
                .map(|p| p.distance(*c))
                .fold(f64::INFINITY, f64::min)
                / voxel
        })
        .fold(0.0, f64::max)
}

/// Sharp corners from the source's own Hermite data: `--mesh-out` of a CSG tree of shapes
/// puts a vertex within 0.1 voxel of every corner of the exact solid (the flange's box, a box
/// less a cylinder through its edge, at three resolutions), closed, manifold and without
/// self-intersections; placed turned about a slanted axis, closed and manifold too.
#[test]
fn csg_meshes_keep_the_sharp_corners_of_the_exact_solid() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let run = |tree: &str, name: &str| -> (Mesh, f64) {
        let mesh = p(&format!("{name}.obj"));
        let o = voxelkit(&[
            "csg",
            "--tree",
            tree,
            "-o",
            &p(&format!("{name}.vdb")),
            "--mesh-out",
            &mesh,
            "--json",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let voxel = cli_support::json_field(&text(&o), "voxel_size");
        (Mesh::load(std::path::Path::new(&mesh)).unwrap(), voxel)
    };
    let flange_tree = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/csg/flange.json");
    let (flange, voxel) = run(flange_tree, "flange");
    let box_corners: Vec<DVec3> = (0..8)
        .map(|k| {
            let pick = |bit: usize, lo: f64, hi: f64| if k >> bit & 1 == 1 { hi } else { lo };
            DVec3::new(pick(0, -2.0, 2.0), pick(1, -1.0, 1.0), pick(2, 0.0, 0.5))
        })
        .collect();
    let worst = farthest_corner(&flange, &box_corners, voxel);
    assert!(worst < 0.1, "flange: a corner {worst} voxel from the mesh");
    // A box less a cylinder along z through its edge x = y = 1: seven of the box's corners,
    // and four where the cylinder meets the edges of the top and bottom faces.
    let axis = DVec3::new(1.0, 2.0, 0.5).normalize();
    let turn = glam::DQuat::from_axis_angle(axis, 35f64.to_radians());
    for (resolution, turned) in [(64, false), (128, false), (256, false), (128, true)] {
        let place = if turned {
            format!(
                r#", "place": {{"rotate": {{"axis": [{}, {}, {}], "degrees": 35}}}}"#,
                axis.x, axis.y, axis.z
            )
        } else {
            String::new()
        };
        let tree = format!(
            r#"{{"resolution": {resolution}, "tree": {{"difference": [
                {{"box": {{"min": [0, 0, 0], "max": [1, 1, 1]{place}}}}},
                {{"cylinder": {{"base": [1, 1, -0.5], "axis": [0, 0, 1], "radius": 0.4,
                  "height": 2{place}}}}} ] }} }}"#
        );
        let name = format!("box-less-cylinder-{resolution}-{turned}");
        std::fs::write(p(&format!("{name}.json")), tree).unwrap();
        let (mesh, voxel) = run(&p(&format!("{name}.json")), &name);
        let mut corners: Vec<DVec3> = (0..8)
            .map(|k| DVec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2) as f64))
            .filter(|c| !(c.x == 1.0 && c.y == 1.0))
            .collect();
        for z in [0.0, 1.0] {
            corners.extend([DVec3::new(1.0, 0.6, z), DVec3::new(0.6, 1.0, z)]);
        }
        if turned {
            corners.iter_mut().for_each(|c| *c = turn * *c);
        }
        // Turned, a corner's tip may poke into a cell none of whose lattice corners it holds:
        // no edge there crosses, and dual contouring cannot see it (measured, not asserted).
        let worst = farthest_corner(&mesh, &corners, voxel);
        assert!(
            turned || worst < 0.1,
            "{name}: a corner {worst} voxel from the mesh"
        );
        let triangles = triangles_of(&mesh);
        assert_closed_manifold(&name, &mesh.positions, &triangles, 0.0);
        if resolution <= 64 {
            assert_no_self_intersections(&name, &mesh.positions, &triangles, 2.0 * voxel);
        }
    }
}

/// A mesh's level set meshed from the mesh's own crossings and face planes: a box remeshed at
/// 32 keeps its eight corners within 0.1 voxel of a vertex, and its edges are cut only where
/// they cross the cells' faces (both ways within 0.25 voxel of the input), through `remesh` and
/// `mesh --sdf --mesh-out` alike; `to-mesh` of the same level set, which has only the values,
/// rounds them off at least twice as far.
#[test]
fn a_meshs_own_planes_keep_its_edges_and_corners() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let (lo, hi) = (DVec3::new(-0.3, 0.1, 0.2), DVec3::new(0.9, 0.8, 0.65));
    let source = voxelkit::mesh::generate::cuboid(lo, hi);
    source
        .write_obj(std::path::Path::new(&p("box.obj")))
        .unwrap();
    let corners_of = |m: &Mesh| -> Vec<[DVec3; 3]> {
        triangles_of(m).iter().map(|t| t.map(|i| m.p(i))).collect()
    };
    let distance = |out: &str| {
        let mesh = Mesh::load(std::path::Path::new(&p(out))).unwrap();
        let d = voxelkit::mesh::surface_distance::two_sided_distance(
            &corners_of(&mesh),
            &corners_of(&source),
        );
        (mesh, d.a_to_b.max(d.b_to_a))
    };
    let runs: [&[&str]; 2] = [
        &[
            "remesh",
            &p("box.obj"),
            "-r",
            "32",
            "-o",
            &p("remeshed.ply"),
            "--json",
        ],
        &[
            "mesh",
            &p("box.obj"),
            "--sdf",
            "-r",
            "32",
            "-o",
            &p("box.vdb"),
            "--mesh-out",
            &p("level.ply"),
            "--json",
        ],
    ];
    let mut sharp: f64 = 0.0;
    let mut voxel = 0.0;
    for (args, out) in runs.iter().zip(["remeshed.ply", "level.ply"]) {
        let o = voxelkit(args);
        assert!(o.status.success(), "{}", text(&o));
        voxel = cli_support::json_field(&text(&o), "voxel_size");
        let (mesh, d) = distance(out);
        let corners: Vec<DVec3> = (0..8)
            .map(|k| DVec3::select(glam::BVec3::new(k & 1 == 1, k & 2 == 2, k & 4 == 4), hi, lo))
            .collect();
        let worst = farthest_corner(&mesh, &corners, voxel);
        assert!(worst < 0.1, "{out}: a corner {worst} voxel from the mesh");
        assert_closed_manifold(out, &mesh.positions, &triangles_of(&mesh), 0.0);
        assert!(
            d < 0.25 * voxel,
            "{out}: {} voxel from the input",
            d / voxel
        );
        sharp = sharp.max(d);
    }
    let o = voxelkit(&["to-mesh", &p("box.vdb"), "-o", &p("values.ply")]);
    assert!(o.status.success(), "{}", text(&o));
    let (_, rounded) = distance("values.ply");
    assert!(
        rounded > 2.0 * sharp,
        "from the values {} voxel, from the mesh {} voxel",
        rounded / voxel,
        sharp / voxel
    );
}

/// `implicit --mesh-out` draws the formula's solid F < 0 within the bounds, not the boundary
/// of its enveloping voxels: a sphere's vertices on the sphere and its volume; a half-space
/// cut by the bounds is the box, with its corners; the gear closed and manifold.
#[test]
fn implicit_meshes_are_the_formulas_solid() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let run = |args: &[&str], name: &str| -> (Mesh, f64) {
        let mut all = vec!["implicit"];
        all.extend_from_slice(args);
        let (vdb, mesh) = (p(&format!("{name}.vdb")), p(&format!("{name}.obj")));
        all.extend_from_slice(&["-o", &vdb, "--mesh-out", &mesh, "--json"]);
        let o = voxelkit(&all);
        assert!(o.status.success(), "{}", text(&o));
        let voxel = cli_support::json_field(&text(&o), "voxel_size");
        let m = Mesh::load(std::path::Path::new(&mesh)).unwrap();
        assert_closed_manifold(name, &m.positions, &triangles_of(&m), 0.0);
        (m, voxel)
    };
    let (sphere, voxel) = run(&["x^2 + y^2 + z^2 - 0.64", "-r", "64"], "sphere");
    let off = sphere
        .positions
        .iter()
        .map(|v| (v.length() - 0.8).abs())
        .fold(0.0, f64::max);
    assert!(
        off < 0.05 * voxel,
        "a vertex {} voxel off the sphere",
        off / voxel
    );
    let volume = signed_volume(&sphere.positions, &triangles_of(&sphere));
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.8f64.powi(3);
    assert!(
        (volume / exact - 1.0).abs() < 0.001,
        "{volume} against {exact}"
    );
    let (half, voxel) = run(&["z - 0.3", "-r", "32"], "half-space");
    let volume = signed_volume(&half.positions, &triangles_of(&half));
    assert!((volume / 5.2 - 1.0).abs() < 0.001, "{volume} against 5.2");
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            let pick = |bit: usize, lo: f64, hi: f64| if k >> bit & 1 == 1 { hi } else { lo };
            DVec3::new(pick(0, -1.0, 1.0), pick(1, -1.0, 1.0), pick(2, -1.0, 0.3))
        })
        .collect();
    let worst = farthest_corner(&half, &corners, voxel);
    assert!(worst < 0.1, "a corner {worst} voxel from the mesh");
    run(&["--example", "gear", "-r", "64"], "gear");
}
