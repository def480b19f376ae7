//! Preview pictures: what is drawn covers what the voxels cover from the view (a ball seen
//! from above is a disc, a box a full rectangle), faces of different orientation are lit
//! differently, `Cd` colours the voxels, and the CLI writes PNG files (`render`, `--preview`)
//! that decode to the asked size, refusing other outputs.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;

use cli_support::{text, voxelkit};
use voxelkit::grid::{Channels, SparseGrid, Transform};
use voxelkit::io::preview::{Picture, Scene, View, render};
use voxelkit::mesh::UpAxis;

/// The pixels that differ from the background's gradient (the background is the same
/// across a row).
fn covered(p: &Picture) -> Vec<bool> {
    let w = p.width as usize;
    (0..p.rgb.len() / 3)
        .map(|k| {
            let row_start = (k / w) * w;
            let back = if k % w == 0 {
                row_start + w - 1
            } else {
                row_start
            };
            p.rgb[3 * k..3 * k + 3] != p.rgb[3 * back..3 * back + 3]
        })
        .collect()
}

/// The bounding rectangle of the covered pixels and how many there are.
fn footprint(p: &Picture) -> ([usize; 4], usize) {
    let w = p.width as usize;
    let mask = covered(p);
    let mut r = [usize::MAX, 0, usize::MAX, 0];
    let mut n = 0;
    for (k, &c) in mask.iter().enumerate() {
        if c {
            let (x, y) = (k % w, k / w);
            r = [r[0].min(x), r[1].max(x), r[2].min(y), r[3].max(y)];
            n += 1;
        }
    }
    (r, n)
}

fn ball(radius: i64, channels: Channels) -> SparseGrid {
    let mut g = SparseGrid::new(Transform::default(), channels);
    let mut acc = g.accessor();
    for x in -radius..=radius {
        for y in -radius..=radius {
            for z in -radius..=radius {
                if x * x + y * y + z * z <= radius * radius {
                    let (leaf, n) = acc.leaf_mut([x, y, z]);
                    leaf.set_on(n);
                    if let Some(c) = leaf.color.as_mut() {
                        c[n] = [0.9, 0.1, 0.1];
                    }
                }
            }
        }
    }
    g
}

fn draw(grid: &SparseGrid, view: View, size: u32) -> Picture {
    render(&Scene::of(grid), view, UpAxis::Z, size, size, None).unwrap()
}

/// A Y-up grid (a post standing along y) drawn with its up axis stands upright: from the
/// front it is four times as tall as wide; taken as Z-up it lies on its back, seen end on.
#[test]
fn a_y_up_grid_stands_upright_when_drawn_with_its_up_axis() {
    let mut post = SparseGrid::default();
    for x in 0..16 {
        for y in 0..64 {
            for z in 0..16 {
                post.insert([x, y, z]);
            }
        }
    }
    let aspect = |up: UpAxis| {
        let p = render(&Scene::of(&post), View::Y, up, 400, 400, None).unwrap();
        let ([x0, x1, y0, y1], _) = footprint(&p);
        (y1 - y0 + 1) as f64 / (x1 - x0 + 1) as f64
    };
    let (upright, on_its_back) = (aspect(UpAxis::Y), aspect(UpAxis::Z));
    assert!((upright - 4.0).abs() < 0.2, "{upright}");
    assert!((on_its_back - 1.0).abs() < 0.1, "{on_its_back}");
}

#[test]
fn a_ball_seen_from_above_is_a_disc_and_a_box_a_rectangle() {
    let p = draw(&ball(40, Channels::NONE), View::Z, 300);
    let ([x0, x1, y0, y1], n) = footprint(&p);
    let (w, h) = ((x1 - x0 + 1) as f64, (y1 - y0 + 1) as f64);
    assert!((w - h).abs() <= 2.0, "{w} x {h}");
    let fill = n as f64 / (w * h);
    assert!((fill - std::f64::consts::FRAC_PI_4).abs() < 0.02, "{fill}");

    // A box of whole 8^3 tiles and leaves: every pixel of its rectangle is covered.
    let mut b = SparseGrid::default();
    for x in 0..6 {
        for y in 0..3 {
            b.fill_leaf_block([8 * x, 8 * y, 0]);
        }
    }
    b.insert([0, 0, 8]);
    let p = draw(&b, View::Z, 240);
    let ([x0, x1, y0, y1], n) = footprint(&p);
    assert_eq!(n, (x1 - x0 + 1) * (y1 - y0 + 1));
    let aspect = (x1 - x0 + 1) as f64 / (y1 - y0 + 1) as f64;
    assert!((aspect - 2.0).abs() < 0.05, "{aspect}");
}

#[test]
fn faces_are_lit_by_their_orientation_and_coloured_by_cd() {
    // A 24^3 cube from the iso view: its top, right and front faces take three shades.
    let mut cube = SparseGrid::default();
    let mut acc = cube.accessor();
    for x in 0..24 {
        for y in 0..24 {
            for z in 0..24 {
                acc.insert([x, y, z]);
            }
        }
    }
    let p = draw(&cube, View::Iso, 200);
    let mask = covered(&p);
    let mut shades: Vec<[u8; 3]> = mask
        .iter()
        .enumerate()
        .filter(|(_, c)| **c)
        .map(|(k, _)| [p.rgb[3 * k], p.rgb[3 * k + 1], p.rgb[3 * k + 2]])
        .collect();
    shades.sort_unstable();
    shades.dedup_by_key(|s| s[0] / 8);
    assert!(shades.len() >= 3, "{shades:?}");

    let red = draw(
        &ball(
            20,
            Channels {
                color: true,
                ..Channels::NONE
            },
        ),
        View::Iso,
        200,
    );
    let mask = covered(&red);
    let (mut reds, mut count) = (0, 0);
    for (k, &c) in mask.iter().enumerate() {
        if c {
            count += 1;
            let [r, g, b] = [red.rgb[3 * k], red.rgb[3 * k + 1], red.rgb[3 * k + 2]];
            reds += usize::from(r > 2 * g.max(b));
        }
    }
    assert!(count > 1000 && reds == count, "{reds} of {count}");
}

#[test]
fn the_cli_draws_vdb_files_and_previews_beside_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    voxelkit::mesh::generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 48, 16)
        .write_obj(&obj)
        .unwrap();
    let vdb = dir.path().join("torus.vdb");
    let o = voxelkit(&[
        "mesh",
        "--preview",
        obj.to_str().unwrap(),
        "--normals",
        "-r",
        "64",
        "-o",
        vdb.to_str().unwrap(),
    ]);
    assert!(
        o.status.success() && text(&o).contains("preview:"),
        "{}",
        text(&o)
    );
    let decode = |path: &std::path::Path| {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let reader = decoder.read_info().unwrap();
        let info = reader.info();
        (info.width, info.height)
    };
    assert_eq!(decode(&dir.path().join("torus.png")), (800, 600));
    let picture = dir.path().join("top.png");
    let o = voxelkit(&[
        "render",
        vdb.to_str().unwrap(),
        "--view",
        "z",
        "--size",
        "320x200",
        "-o",
        picture.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(decode(&picture), (320, 200));
    for (args, expected) in [
        (vec!["--size", "0x10"], "1 to 16384"),
        (vec!["--size", "big"], "WIDTHxHEIGHT"),
        (vec!["--view", "up"], "iso, x, y or z"),
    ] {
        let bad = dir.path().join("bad.png");
        let mut all = vec!["render", vdb.to_str().unwrap(), "-o", bad.to_str().unwrap()];
        all.extend(args);
        let o = voxelkit(&all);
        assert!(
            !o.status.success() && text(&o).contains(expected),
            "{}",
            text(&o)
        );
        assert!(!bad.exists());
    }
    let o = voxelkit(&["render", vdb.to_str().unwrap(), "-o", vdb.to_str().unwrap()]);
    assert!(
        !o.status.success() && text(&o).contains(".png"),
        "{}",
        text(&o)
    );
}
