//! The project's own closed test and demo meshes, generated so every test and the demo run
//! in a clean clone: spheres, tori, boxes, a G-shaped slab, a G between plates, spheres in a
//! hollow box, a trefoil-knot tube and random closed meshes. All are closed, manifold and
//! oriented outward.

use super::Mesh;
use glam::DVec3;
use std::f64::consts::TAU;

/// An icosphere: the icosahedron subdivided `levels` times, projected onto the sphere.
pub fn icosphere(center: DVec3, radius: f64, levels: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from(*p).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = rustc_hash::FxHashMap::default();
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalize());
                pos.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    let positions = pos.iter().map(|p| center + radius * *p).collect();
    let polys: Vec<Vec<u32>> = tris.iter().map(|t| t.to_vec()).collect();
    Mesh::from_polygons(format!("icosphere(r={radius})"), positions, &polys)
}

/// A closed tube of quads around a closed centre curve sampled at `n` points, `m` around.
fn tube(
    name: String,
    n: usize,
    m: usize,
    point: impl Fn(usize) -> (DVec3, DVec3, DVec3, f64),
) -> Mesh {
    let mut positions = Vec::with_capacity(n * m);
    for i in 0..n {
        // centre, two unit axes spanning the cross-section plane, radius
        let (c, u, v, r) = point(i);
        for j in 0..m {
            let a = TAU * j as f64 / m as f64;
            positions.push(c + r * (a.cos() * u + a.sin() * v));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
    let polys: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    let mut mesh = Mesh::from_polygons(name, positions, &polys);
    if mesh.signed_volume() < 0.0 {
        reverse_faces(&mut mesh);
    }
    mesh
}

/// A torus around the z axis: major radius `big_r`, minor radius `r`, as quads.
pub fn torus(center: DVec3, big_r: f64, r: f64, n: usize, m: usize) -> Mesh {
    tube(format!("torus(R={big_r},r={r})"), n, m, |i| {
        let a = TAU * i as f64 / n as f64;
        let radial = DVec3::new(a.cos(), a.sin(), 0.0);
        (center + big_r * radial, radial, DVec3::Z, r)
    })
}

/// A tube of radius `r` around the trefoil knot `(sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t)`.
pub fn trefoil(scale: f64, r: f64, n: usize, m: usize) -> Mesh {
    let curve = |t: f64| {
        DVec3::new(
            t.sin() + 2.0 * (2.0 * t).sin(),
            t.cos() - 2.0 * (2.0 * t).cos(),
            -(3.0 * t).sin(),
        ) * scale
    };
    tube(format!("trefoil(scale={scale},r={r})"), n, m, |i| {
        let t = TAU * i as f64 / n as f64;
        let tangent = (curve(t + 1e-4) - curve(t - 1e-4)).normalize();
        // The knot's tangent is never parallel to z, so this frame is smooth and periodic.
        let u = tangent.cross(DVec3::Z).normalize();
        let v = tangent.cross(u);
        (curve(t), u, v, r)
    })
}

/// An axis-aligned box as six quads.
pub fn cuboid(min: DVec3, max: DVec3) -> Mesh {
    let p = |x: bool, y: bool, z: bool| {
        DVec3::new(
            if x { max.x } else { min.x },
            if y { max.y } else { min.y },
            if z { max.z } else { min.z },
        )
    };
    let positions: Vec<DVec3> = (0..8)
        .map(|i| p(i & 1 != 0, i & 2 != 0, i & 4 != 0))
        .collect();
    let polys = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    Mesh::from_polygons("box", positions, &polys)
}

/// A slab of height `height` in z whose cross-section is a band of width `2 * half_width`
/// around the 2D polyline `path` (mitred at the corners), closed by caps and end quads.
pub fn extruded_band(name: &str, path: &[[f64; 2]], half_width: f64, height: f64) -> Mesh {
    let n = path.len();
    let pt = |i: usize| DVec3::new(path[i][0], path[i][1], 0.0);
    let mut ribs = Vec::with_capacity(n);
    for i in 0..n {
        let d_in = if i > 0 {
            (pt(i) - pt(i - 1)).normalize()
        } else {
            (pt(1) - pt(0)).normalize()
        };
        let d_out = if i + 1 < n {
            (pt(i + 1) - pt(i)).normalize()
        } else {
            d_in
        };
        let tangent = (d_in + d_out).normalize();
        let left = DVec3::new(-tangent.y, tangent.x, 0.0);
        // Mitre: keep the band's width constant on both straight sides of a corner.
        let miter = half_width / left.dot(DVec3::new(-d_in.y, d_in.x, 0.0));
        ribs.push((pt(i) + miter * left, pt(i) - miter * left));
    }
    let z = DVec3::new(0.0, 0.0, height);
    let mut positions = Vec::with_capacity(4 * n);
    for (l, r) in &ribs {
        positions.extend([*l, *r, *l + z, *r + z]);
    }
    let v = |i: usize, k: u32| 4 * i as u32 + k; // k: 0 left-bottom, 1 right-bottom, 2 left-top, 3 right-top
    let mut polys = Vec::new();
    for i in 0..n - 1 {
        let j = i + 1;
        polys.push(vec![v(i, 0), v(i, 1), v(j, 1), v(j, 0)]); // bottom
        polys.push(vec![v(i, 2), v(j, 2), v(j, 3), v(i, 3)]); // top
        polys.push(vec![v(i, 0), v(j, 0), v(j, 2), v(i, 2)]); // left side
        polys.push(vec![v(i, 1), v(i, 3), v(j, 3), v(j, 1)]); // right side
    }
    polys.push(vec![v(0, 0), v(0, 2), v(0, 3), v(0, 1)]);
    polys.push(vec![v(n - 1, 0), v(n - 1, 1), v(n - 1, 3), v(n - 1, 2)]);
    let mut mesh = Mesh::from_polygons(name, positions, &polys);
    if mesh.signed_volume() < 0.0 {
        reverse_faces(&mut mesh);
    }
    mesh
}

/// The letter G: a thick arc from 45 degrees round to 0 degrees, then a bar inward.
pub fn g_shape() -> Mesh {
    let mut path: Vec<[f64; 2]> = (0..=40)
        .map(|i| {
            let a = (45.0 + 315.0 * i as f64 / 40.0).to_radians();
            [a.cos(), a.sin()]
        })
        .collect();
    path.push([0.35, 0.0]);
    extruded_band("G", &path, 0.18, 0.5)
}

/// The closed boundary of a set of unit cubes (`cells`, lattice corners scaled by `size`):
/// one quad per cube face not shared with another cube, oriented outward. The cells must not
/// touch only along an edge or at a corner, or the boundary would not be manifold there.
pub fn polycube(name: &str, cells: &[[i64; 3]], size: f64) -> Mesh {
    let filled: std::collections::HashSet<[i64; 3]> = cells.iter().copied().collect();
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |p: [i64; 3]| -> u32 {
        *index.entry(p).or_insert_with(|| {
            positions.push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * size);
            positions.len() as u32 - 1
        })
    };
    let mut polys = Vec::new();
    for &c in cells {
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for side in [0, 1] {
                let mut n = c;
                n[axis] += 2 * side - 1;
                if filled.contains(&n) {
                    continue;
                }
                let corner = |du: i64, dv: i64| {
                    let mut p = c;
                    p[axis] += side;
                    p[u] += du;
                    p[v] += dv;
                    p
                };
                // (e_u, e_v) turn counter-clockwise about +axis.
                let mut quad: Vec<u32> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                    .iter()
                    .map(|&(du, dv)| vertex(corner(du, dv)))
                    .collect();
                if side == 0 {
                    quad.reverse();
                }
                polys.push(quad);
            }
        }
    }
    Mesh::from_polygons(name, positions, &polys)
}

/// The letter G standing between two square plates, as one closed solid: the G's inner
/// hollow opens to the outside only through its mouth, sideways, so every axis-parallel line
/// through the hollow meets the solid on both sides (Passalis et al.'s Fig. 2 in 3D). With one
/// depth layer per side no axis sees the hollow; with two layers the z axis does.
pub fn g_between_plates() -> Mesh {
    const G: [&str; 7] = [
        "XXXXXXX", // y = 6
        "X......", "X......", "X..XXXX", "X.....X", "X.....X", "XXXXXXX", // y = 0
    ];
    let mut cells = Vec::new();
    for (row, line) in G.iter().enumerate() {
        let y = 6 - row as i64;
        for (x, ch) in line.chars().enumerate() {
            cells.push([x as i64, y, 0]);
            cells.push([x as i64, y, 2]);
            if ch == 'X' {
                cells.push([x as i64, y, 1]);
            }
        }
    }
    polycube("G between plates", &cells, 1.0 / 7.0)
}

/// The G's hollow: the empty cells of `g_between_plates` (the middle layer's dots), as boxes
/// in the same units, for tests that ask which voxels must stay outside.
pub fn g_hollow_cells() -> Vec<(DVec3, DVec3)> {
    let mut cells = Vec::new();
    for y in 1..6 {
        for x in 1..7 {
            let open = match y {
                4 | 5 => true,
                3 => x < 3,
                _ => x < 6,
            };
            if open {
                let lo = DVec3::new(x as f64, y as f64, 1.0) / 7.0;
                cells.push((lo, lo + DVec3::splat(1.0 / 7.0)));
            }
        }
    }
    cells
}

/// Several meshes as one (faces renumbered, nothing welded).
pub fn combine(name: &str, parts: &[Mesh]) -> Mesh {
    let mut out = Mesh {
        face_starts: vec![0],
        source: name.into(),
        ..Default::default()
    };
    for m in parts {
        let base = out.positions.len() as u32;
        out.positions.extend_from_slice(&m.positions);
        for f in 0..m.face_count() {
            out.indices.extend(m.face(f).iter().map(|&i| i + base));
            out.face_starts.push(out.indices.len() as u32);
        }
    }
    out
}

/// Passalis et al.'s teapots in boxes with spheres for teapots: two spheres inside a hollow box
/// (an outer box and an inward-facing inner box), so every line through a sphere crosses the
/// box's walls on both sides of it: six crossings or more in every direction.
pub fn spheres_in_box() -> Mesh {
    let mut inner = cuboid(DVec3::splat(-0.8), DVec3::splat(0.8));
    reverse_faces(&mut inner);
    combine(
        "spheres in a hollow box",
        &[
            cuboid(DVec3::splat(-1.0), DVec3::splat(1.0)),
            inner,
            icosphere(DVec3::new(-0.35, -0.3, 0.0), 0.3, 3),
            icosphere(DVec3::new(0.35, 0.3, 0.1), 0.3, 3),
        ],
    )
}

/// Flips every face (turns an inward-oriented mesh outward).
pub fn reverse_faces(mesh: &mut Mesh) {
    for f in 0..mesh.face_count() {
        let (a, b) = (
            mesh.face_starts[f] as usize,
            mesh.face_starts[f + 1] as usize,
        );
        mesh.indices[a..b].reverse();
    }
}

pub use crate::random::SplitMix64;

/// A random closed mesh from `seed`: a bumpy star-shaped blob (genus 0) or a bumpy torus
/// (genus 1), randomly stretched, rotated and moved, so triangles meet the grid at every angle.
pub fn random_closed(seed: u64) -> Mesh {
    let mut rng = SplitMix64(seed);
    let bumps: Vec<(DVec3, f64, f64)> = (0..6)
        .map(|_| {
            (
                rng.unit_vector(),
                rng.range(-0.25, 0.25),
                rng.range(1.0, 4.0),
            )
        })
        .collect();
    let bump = |d: DVec3| {
        1.0 + bumps
            .iter()
            .map(|(c, a, k)| a * (k * d.dot(*c)).sin())
            .sum::<f64>()
            * 0.5
    };
    let mut mesh = if rng.next_u64().is_multiple_of(2) {
        let mut m = icosphere(DVec3::ZERO, 1.0, 3);
        for p in &mut m.positions {
            *p *= bump(*p);
        }
        m
    } else {
        let mut m = torus(DVec3::ZERO, 1.0, 0.4, 48, 16);
        for p in &mut m.positions {
            let ring = DVec3::new(p.x, p.y, 0.0).normalize();
            let off = *p - ring;
            *p = ring + off * bump(p.normalize()).clamp(0.6, 1.4);
        }
        m
    };
    let axis = rng.unit_vector();
    let rot = glam::DQuat::from_axis_angle(axis, rng.range(0.0, TAU));
    let stretch = DVec3::new(
        rng.range(0.6, 1.4),
        rng.range(0.6, 1.4),
        rng.range(0.6, 1.4),
    );
    let shift = DVec3::new(
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
    );
    for p in &mut mesh.positions {
        *p = rot * (*p * stretch) + shift;
    }
    mesh.source = format!("random_closed(seed={seed})").into();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_closed_and_outward(m: &Mesh) {
        let mut edges = rustc_hash::FxHashMap::default();
        for f in 0..m.face_count() {
            let face = m.face(f);
            for k in 0..face.len() {
                *edges
                    .entry((face[k], face[(k + 1) % face.len()]))
                    .or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(
                count,
                1,
                "{}: directed edge {a}->{b} used {count} times",
                m.source.display()
            );
            assert_eq!(
                edges.get(&(b, a)),
                Some(&1),
                "{}: edge {a}-{b} open",
                m.source.display()
            );
        }
        assert!(m.signed_volume() > 0.0, "{} is inward", m.source.display());
    }

    #[test]
    fn fixtures_are_closed_and_have_the_right_volume() {
        let s = icosphere(DVec3::ZERO, 2.0, 4);
        assert_closed_and_outward(&s);
        assert!((s.signed_volume() / (4.0 / 3.0 * std::f64::consts::PI * 8.0) - 1.0).abs() < 0.01);
        let t = torus(DVec3::ONE, 1.0, 0.25, 96, 32);
        assert_closed_and_outward(&t);
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 0.25f64.powi(2);
        assert!((t.signed_volume() / exact - 1.0).abs() < 0.01);
        let b = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        assert_closed_and_outward(&b);
        assert!((b.signed_volume() - 6.0).abs() < 1e-12);
        assert_closed_and_outward(&g_shape());
        assert_closed_and_outward(&trefoil(1.0, 0.4, 256, 24));
        for seed in 0..8 {
            assert_closed_and_outward(&random_closed(seed));
        }
    }
}
