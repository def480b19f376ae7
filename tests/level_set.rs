//! Level sets (`--sdf`): every active value is the exact signed distance to the mesh (to 0.01
//! voxel), every voxel within band - 1 of the surface is active, the interior (inactive
//! voxels and tiles included) is negative, and OpenVDB's own `levelSetVolume` of the file
//! agrees with the mesh's volume. The sign is checked against the winding number, which is
//! independent of the ray parity the level set uses here. Open meshes: `--sdf` signs them by
//! the winding number (tests/winding_inside.rs), `--inside parity` refuses them, `--udf` writes
//! unsigned distances.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use glam::DVec3;
use std::path::Path;
mod cli_support;
mod common;

use cli_support::{run_pyopenvdb, text, voxelkit};
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, generate};
use voxelkit::progress::Progress;
use voxelkit::random::SplitMix64;
use voxelkit::solids::inside_rule::InsideRule;
use voxelkit::solids::level_set::level_set;

const BAND: f64 = 3.0;

/// The closest point of triangle `abc` to `p`, by its Voronoi regions (Ericson, Real-Time
/// Collision Detection, 5.1.5): an evaluation independent of the band's, which takes faces,
/// edges and vertices apart.
fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Exact unsigned distance from `p` to the mesh.
fn distance(mesh: &Mesh, p: DVec3) -> f64 {
    mesh.triangles()
        .map(|(_, [a, b, c])| {
            p.distance(closest_point_on_triangle(
                p,
                mesh.p(a),
                mesh.p(b),
                mesh.p(c),
            ))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The winding number of the mesh about `p` (|w| ~ 1 inside, ~ 0 outside).
fn winding(mesh: &Mesh, p: DVec3) -> f64 {
    let mut solid_angle = 0.0;
    for (_, [a, b, c]) in mesh.triangles() {
        let (a, b, c) = (mesh.p(a), mesh.p(b), mesh.p(c));
        // Van Oosterom & Strackee: the solid angle of the triangle seen from p.
        let (x, y, z) = (a - p, b - p, c - p);
        let (lx, ly, lz) = (x.length(), y.length(), z.length());
        let numerator = x.dot(y.cross(z));
        let denominator = lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly;
        solid_angle += 2.0 * numerator.atan2(denominator);
    }
    solid_angle / (4.0 * std::f64::consts::PI)
}

/// Checks the level set of `mesh` at `resolution` against the exact distances.
fn check(name: &str, mesh: &Mesh, resolution: u32) {
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
    let h = t.voxel_size;
    let grid = level_set(mesh, t, BAND, InsideRule::Parity, &Progress::none())
        .unwrap()
        .1
        .band;
    let active: Vec<([i64; 3], f32)> = grid
        .leaves()
        .iter()
        .flat_map(|l| {
            let values = l.value.as_ref().unwrap();
            l.offsets().map(move |n| {
                let c = [
                    l.origin[0] + (n / 64) as i64,
                    l.origin[1] + (n / 8 % 8) as i64,
                    l.origin[2] + (n % 8) as i64,
                ];
                (c, values[n])
            })
        })
        .collect();
    let mut rng = SplitMix64(resolution as u64);
    // Values: exact distance, sign by the winding number (skipping centres on the surface).
    for _ in 0..400 {
        let (c, value) = active[(rng.next_u64() % active.len() as u64) as usize];
        let p = t.index_to_world(c);
        let d = distance(mesh, p);
        let expected = if winding(mesh, p).abs() > 0.5 { -d } else { d };
        assert!(
            (f64::from(value) - expected).abs() <= 0.01 * h,
            "{name}: voxel {c:?} holds {value}, the exact signed distance is {expected}"
        );
    }
    // Completeness: around random triangles, every voxel within band - 1 is active.
    let on: std::collections::HashSet<[i64; 3]> = active.iter().map(|a| a.0).collect();
    let triangles: Vec<[u32; 3]> = mesh.triangles().map(|(_, t)| t).collect();
    for _ in 0..8 {
        let [a, b, c] = triangles[(rng.next_u64() % triangles.len() as u64) as usize];
        let centre = (mesh.p(a) + mesh.p(b) + mesh.p(c)) / 3.0;
        let v = t.world_to_voxel(centre);
        for dx in -2..=2 {
            for dy in -2..=2 {
                for dz in -2..=2 {
                    let q = [v[0] + dx, v[1] + dy, v[2] + dz];
                    let d = distance(mesh, t.index_to_world(q));
                    if d <= (BAND - 1.0) * h {
                        assert!(on.contains(&q), "{name}: voxel {q:?} at {d} is not active");
                    }
                }
            }
        }
    }
}

#[test]
fn values_are_exact_signed_distances_and_the_band_is_complete() {
    check(
        "icosphere",
        &generate::icosphere(DVec3::new(0.3, -0.2, 0.1), 1.0, 4),
        96,
    );
    check(
        "torus",
        &generate::torus(DVec3::ZERO, 1.0, 0.35, 48, 24),
        128,
    );
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap();
        check(name, &mesh, 128);
    }
}

#[test]
fn openvdb_reads_a_negative_interior_and_measures_the_volume() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    // Wound inwards on purpose: the sign must not depend on the orientation.
    let mut torus = generate::torus(DVec3::ZERO, 1.0, 0.35, 96, 48);
    generate::reverse_faces(&mut torus);
    torus.write_obj(&obj).unwrap();
    let out = dir.path().join("torus.vdb");
    let run = voxelkit(&[
        "--json",
        "mesh",
        obj.to_str().unwrap(),
        "--sdf",
        "-r",
        "128",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", text(&run));
    let exact_volume = torus.signed_volume().abs();
    let openvdb = voxelkit_openvdb::level_set_volume(out.to_str().unwrap(), "surface").unwrap();
    assert!(
        (openvdb - exact_volume).abs() < 0.01 * exact_volume,
        "OpenVDB's levelSetVolume {openvdb} against the mesh's {exact_volume}"
    );
    // voxelkit's reader takes the band, the fog and their inactive values as OpenVDB does.
    common::assert_read_as_openvdb_reads(&out, "surface");
    common::assert_read_as_openvdb_reads(&out, "density");
    let band = read_vdb_grid(&out, Some("surface")).unwrap();
    assert!(band.voxel_count() > 0);
    // pyopenvdb, an independent reader: class, the value deep in the tube (inactive, a tile
    // or a leaf value) is -background, far outside +background.
    let t = band.transform;
    let inside = t.world_to_voxel(DVec3::new(1.0, 0.0, 0.0));
    let outside = t.world_to_voxel(DVec3::new(0.0, 0.0, 0.0));
    let tuple = |c: [i64; 3]| format!("({}, {}, {})", c[0], c[1], c[2]);
    let (inside, outside) = (tuple(inside), tuple(outside));
    let script = format!(
        "import sys, pyopenvdb as vdb\n\
         g = vdb.read(sys.argv[1], 'surface')\n\
         a = g.getConstAccessor()\n\
         print(g.gridClass, g.background, a.getValue({inside}), a.isValueOn({inside}), a.getValue({outside}))\n"
    );
    let Some(out_text) = run_pyopenvdb(&script, &out, "the level-set read-back") else {
        return;
    };
    let f: Vec<&str> = out_text.split_whitespace().collect();
    assert_eq!(f[0], "level", "{out_text}");
    let background: f64 = f[2].parse().unwrap();
    let deep: f64 = f[3].parse().unwrap();
    let far: f64 = f[5].parse().unwrap();
    assert_eq!(
        f[4], "False",
        "the tube's centre is not in the band: {out_text}"
    );
    assert!((deep + background).abs() < 1e-6, "{out_text}");
    assert!((far - background).abs() < 1e-6, "{out_text}");
}

#[test]
fn open_meshes_are_signed_by_winding_refused_by_parity_and_unsigned_by_udf() {
    let dir = tempfile::tempdir().unwrap();
    let open = dir.path().join("open.obj");
    let mut cube = generate::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    cube.face_starts.pop();
    cube.write_obj(&open).unwrap();
    let out = dir.path().join("open.vdb");
    let (o, v) = (open.to_str().unwrap(), out.to_str().unwrap());
    let refused = voxelkit(&[
        "mesh", o, "--sdf", "--inside", "parity", "-r", "32", "-o", v,
    ]);
    let msg = text(&refused);
    assert!(
        !refused.status.success() && msg.contains("--udf") && msg.contains("--inside"),
        "{msg}"
    );
    assert!(!out.exists());
    let signed = voxelkit(&["mesh", o, "--sdf", "-r", "32", "-o", v]);
    let msg = text(&signed);
    assert!(
        signed.status.success() && msg.contains("inside: winding"),
        "{msg}"
    );
    std::fs::remove_file(&out).unwrap();
    let unsigned = voxelkit(&["mesh", o, "--udf", "-r", "32", "-o", v]);
    assert!(unsigned.status.success(), "{}", text(&unsigned));
    let grid = read_vdb_grid(Path::new(&out), Some("distance")).unwrap();
    assert!(grid.voxel_count() > 0);
    for leaf in grid.leaves() {
        let values = leaf.value.as_ref().unwrap();
        assert!(leaf.offsets().all(|n| values[n] >= 0.0));
    }
}
