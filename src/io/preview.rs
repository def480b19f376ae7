//! Preview pictures of voxel sets, written as PNG: every voxel drawn as the cube it is, in an
//! orthographic view, lit by its `normal` when the grid carries normals (else by the cube's
//! own faces) and coloured by its `Cd` when it carries colours.
//!
//! Each cube (and each tile, as one box) is drawn by intersecting the view ray of every
//! pixel of its footprint with the box; the nearest hit wins in a depth buffer. Voxels hidden
//! inside their leaf on all six sides are skipped, so a solid costs about its surface. Threads
//! draw into their own buffers, merged by depth; a last pass darkens silhouettes and creases
//! where the depth jumps, which keeps small voxels readable.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::grid::UpAxis;
use crate::grid::{Coord, Leaf, SparseGrid};
use glam::Vec3;
use rayon::prelude::*;
use std::path::Path;
use std::str::FromStr;

/// Where the picture looks from (Z up, as in Blender).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum View {
    /// From the front, right and above.
    #[default]
    Iso,
    /// From +x (Blender's right view).
    X,
    /// From -y (Blender's front view).
    Y,
    /// From +z, looking down (Blender's top view).
    Z,
}

impl FromStr for View {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "iso" => Ok(View::Iso),
            "x" => Ok(View::X),
            "y" => Ok(View::Y),
            "z" => Ok(View::Z),
            _ => Err(format!("expected a view iso, x, y or z, got `{s}`")),
        }
    }
}

/// The camera: `toward` points from the scene to the viewer; `right` and `up` span the
/// picture.
struct Camera {
    toward: Vec3,
    right: Vec3,
    up: Vec3,
}

impl View {
    /// The camera over a grid whose up axis is `up`: a Y-up grid is seen as if turned Z-up
    /// (x, y, z) -> (x, -z, y), the camera turned back the other way.
    fn camera(self, up: UpAxis) -> Camera {
        let (toward, right) = match self {
            View::Iso => (Vec3::new(1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, 0.0)),
            View::X => (Vec3::X, Vec3::Y),
            View::Y => (Vec3::NEG_Y, Vec3::X),
            View::Z => (Vec3::Z, Vec3::X),
        };
        let into_grid = |v: Vec3| match up {
            UpAxis::Y => Vec3::new(v.x, v.z, -v.y),
            UpAxis::Z => v,
        };
        let (toward, right) = (into_grid(toward).normalize(), into_grid(right).normalize());
        Camera {
            toward,
            right,
            up: toward.cross(right),
        }
    }
}

/// An RGB picture, 8 bits per channel, rows from the top.
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

/// Largest picture side, so that a typo cannot ask for gigabytes.
pub const MAX_PICTURE_SIDE: u32 = 16384;

/// What the picture is of, and what it is lit and coloured by.
pub struct Scene<'a> {
    pub voxels: &'a SparseGrid,
    /// Unit normals per voxel (the `normal` channel), when the grid has them.
    pub normals: Option<&'a SparseGrid>,
    /// Colours per voxel (the `Cd` channel), when the grid has them.
    pub colors: Option<&'a SparseGrid>,
}

impl<'a> Scene<'a> {
    /// A grid lit and coloured by its own normal and colour channels, where it has them.
    pub fn of(grid: &'a SparseGrid) -> Scene<'a> {
        let channels = grid.channels();
        Scene {
            voxels: grid,
            normals: channels.normal.then_some(grid),
            colors: channels.color.then_some(grid),
        }
    }
}

/// What the nearest hit of a pixel is: its depth (toward the viewer; larger is nearer),
/// colour, and normal (the voxel's own, or the face of its cube).
#[derive(Clone, Copy)]
struct Hit {
    depth: f32,
    albedo: Vec3,
    normal: Vec3,
    /// The normal is the voxel's own (from the grid), not its cube's face.
    smooth: bool,
}

const NO_HIT: Hit = Hit {
    depth: f32::NEG_INFINITY,
    albedo: Vec3::ZERO,
    normal: Vec3::ZERO,
    smooth: false,
};

#[derive(Clone)]
struct Buffer {
    hits: Vec<Hit>,
}

impl Buffer {
    fn new(pixels: usize) -> Buffer {
        Buffer {
            hits: vec![NO_HIT; pixels],
        }
    }

    fn merge(mut self, other: Buffer) -> Buffer {
        for (mine, theirs) in self.hits.iter_mut().zip(other.hits) {
            if theirs.depth > mine.depth {
                *mine = theirs;
            }
        }
        self
    }
}

/// Index space placed on the picture.
struct Projection {
    camera: Camera,
    /// Index-space point at the picture's centre.
    centre: Vec3,
    /// Pixels per voxel.
    scale: f32,
    width: u32,
    height: u32,
    light: Vec3,
}

const DEFAULT_ALBEDO: Vec3 = Vec3::new(0.78, 0.80, 0.84);

impl Projection {
    /// Draws the box of half size `half` around `centre` (index space, relative to the
    /// projection's centre), shaded by `normal` (or its face) and `albedo`.
    fn draw_box(
        &self,
        buffer: &mut Buffer,
        centre: Vec3,
        half: f32,
        normal: Option<Vec3>,
        albedo: Vec3,
    ) {
        let Camera { toward, right, up } = &self.camera;
        let (w, h) = (self.width as f32, self.height as f32);
        let sx = 0.5 * w + centre.dot(*right) * self.scale;
        let sy = 0.5 * h - centre.dot(*up) * self.scale;
        let ex = half * self.scale * right.abs().element_sum();
        let ey = half * self.scale * up.abs().element_sum();
        let x0 = (sx - ex).floor().max(0.0) as i64;
        let x1 = (sx + ex).ceil().min(w - 1.0) as i64;
        let y0 = (sy - ey).floor().max(0.0) as i64;
        let y1 = (sy + ey).ceil().min(h - 1.0) as i64;
        let (lo, hi) = (centre - half, centre + half);
        for py in y0..=y1 {
            let v = (0.5 * h - (py as f32 + 0.5)) / self.scale;
            for px in x0..=x1 {
                let u = (px as f32 + 0.5 - 0.5 * w) / self.scale;
                let base = *right * u + *up * v;
                // The ray base + t * toward through the box: the hit nearest the viewer is
                // where it leaves the box going toward the viewer.
                let (mut t_in, mut t_out, mut face) = (f32::NEG_INFINITY, f32::INFINITY, 0);
                for a in 0..3 {
                    let d = toward[a];
                    if d == 0.0 {
                        if base[a] < lo[a] || base[a] > hi[a] {
                            t_in = f32::INFINITY;
                        }
                        continue;
                    }
                    let (t1, t2) = ((lo[a] - base[a]) / d, (hi[a] - base[a]) / d);
                    t_in = t_in.max(t1.min(t2));
                    if t1.max(t2) < t_out {
                        t_out = t1.max(t2);
                        face = a;
                    }
                }
                if t_in > t_out {
                    continue;
                }
                let k = py as usize * self.width as usize + px as usize;
                if t_out <= buffer.hits[k].depth {
                    continue;
                }
                let mut face_normal = Vec3::ZERO;
                face_normal[face] = toward[face].signum();
                buffer.hits[k] = Hit {
                    depth: t_out,
                    albedo,
                    normal: normal.unwrap_or(face_normal),
                    smooth: normal.is_some(),
                };
            }
        }
    }

    /// Draws the voxels of `leaf` that are not hidden inside it.
    fn draw_leaf(&self, buffer: &mut Buffer, leaf: &Leaf, scene: &Scene) {
        let normals = scene
            .normals
            .and_then(|g| g.leaf(leaf.origin))
            .and_then(|l| l.normal.as_ref());
        let colors = scene
            .colors
            .and_then(|g| g.leaf(leaf.origin))
            .and_then(|l| l.color.as_ref());
        let origin = coord_f32(leaf.origin) - self.centre;
        let visible = visible_bits(&leaf.mask);
        for (x, &word) in visible.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let n = x * 64 + b;
                let at = origin + Vec3::new(x as f32, (b >> 3) as f32, (b & 7) as f32);
                let normal = normals
                    .map(|v| Vec3::from(v[n]))
                    .filter(|v| v.length_squared() > 0.5);
                let albedo = colors.map_or(DEFAULT_ALBEDO, |c| Vec3::from(c[n]));
                self.draw_box(buffer, at, 0.5, normal, albedo);
            }
        }
    }
}

/// The voxels of a leaf mask (x-major words of 8 x 8 (y, z) bits) that have an empty face
/// neighbour inside the leaf, or lie on its border.
fn visible_bits(mask: &[u64; 8]) -> [u64; 8] {
    const Z_FIRST: u64 = 0x0101_0101_0101_0101;
    const Z_LAST: u64 = 0x8080_8080_8080_8080;
    let mut visible = [0u64; 8];
    for x in 0..8 {
        let m = mask[x];
        let below = if x > 0 { mask[x - 1] } else { 0 };
        let above = if x < 7 { mask[x + 1] } else { 0 };
        let inside =
            m & ((m << 1) & !Z_FIRST) & ((m >> 1) & !Z_LAST) & (m << 8) & (m >> 8) & below & above;
        visible[x] = m & !inside;
    }
    visible
}

/// Draws `scene` (its up axis `up`) from `view` on a `width` x `height` picture.
pub fn render(
    scene: &Scene,
    view: View,
    up: UpAxis,
    width: u32,
    height: u32,
    limit: Option<u64>,
) -> Result<Picture> {
    if !(1..=MAX_PICTURE_SIDE).contains(&width) || !(1..=MAX_PICTURE_SIDE).contains(&height) {
        return Err(Error::InvalidArgument(format!(
            "the picture must be 1 to {MAX_PICTURE_SIDE} pixels on a side, got {width}x{height}"
        )));
    }
    crate::system::check_fits(
        picture_bytes(width, height),
        limit,
        &format!("a picture of {width}x{height} pixels"),
    )?;
    let grid = scene.voxels;
    let mut buffer = Buffer::new(width as usize * height as usize);
    if let Some(b) = grid.bbox() {
        let camera = view.camera(up);
        let (lo, hi) = (coord_f32(b.min) - 0.5, coord_f32(b.max) + 0.5);
        let middle = 0.5 * (lo + hi);
        // The picture frames what is there: the extent of the leaves and tiles on it.
        let boxes = grid
            .leaves()
            .iter()
            .map(|l| (l.origin, 8))
            .chain(grid.tiles().with_edges());
        let (mut u0, mut u1, mut v0, mut v1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
        for (origin, edge) in boxes {
            let half = 0.5 * edge as f32;
            let at = coord_f32(origin) - 0.5 + half - middle;
            let (u, v) = (at.dot(camera.right), at.dot(camera.up));
            let (ru, rv) = (
                half * camera.right.abs().element_sum(),
                half * camera.up.abs().element_sum(),
            );
            (u0, u1, v0, v1) = (
                u0.min(u - ru),
                u1.max(u + ru),
                v0.min(v - rv),
                v1.max(v + rv),
            );
        }
        let offset = middle + camera.right * 0.5 * (u0 + u1) + camera.up * 0.5 * (v0 + v1);
        let scale = 0.92 * (width as f32 / (u1 - u0)).min(height as f32 / (v1 - v0));
        let light = (camera.toward * 0.75 + camera.up * 0.55 + camera.right * 0.35).normalize();
        let projection = Projection {
            camera,
            centre: offset,
            scale,
            width,
            height,
            light,
        };
        let leaves = grid.leaves();
        let pixels = buffer.hits.len();
        buffer = leaves
            .par_chunks(256)
            .fold(
                || Buffer::new(pixels),
                |mut buf, chunk| {
                    for leaf in chunk {
                        projection.draw_leaf(&mut buf, leaf, scene);
                    }
                    buf
                },
            )
            .reduce(|| Buffer::new(pixels), Buffer::merge);
        for (origin, edge) in grid.tiles().with_edges() {
            let at = coord_f32(origin) + 0.5 * (edge as f32 - 1.0) - projection.centre;
            projection.draw_box(&mut buffer, at, 0.5 * edge as f32, None, DEFAULT_ALBEDO);
        }
        let rgb = projection.shade(&buffer);
        return Ok(Picture { width, height, rgb });
    }
    Ok(Picture {
        width,
        height,
        rgb: background(width as usize, height as usize),
    })
}

fn coord_f32(c: Coord) -> Vec3 {
    Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)
}

impl Projection {
    /// The index-space point a pixel's hit lies on.
    fn point(&self, k: usize, depth: f32) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let (x, y) = (
            (k % self.width as usize) as f32,
            (k / self.width as usize) as f32,
        );
        let u = (x + 0.5 - 0.5 * w) / self.scale;
        let v = (0.5 * h - (y + 0.5)) / self.scale;
        self.camera.right * u + self.camera.up * v + self.camera.toward * depth
    }

    /// The surface normal at pixel `k` from the depths around it, `reach` pixels away on
    /// each side (one side where the other jumps or is empty); `None` where neither side
    /// has a neighbour on the same surface.
    fn depth_normal(&self, hits: &[Hit], k: usize, reach: usize, jump: f32) -> Option<Vec3> {
        let (w, h) = (self.width as usize, self.height as usize);
        let (x, y) = (k % w, k / w);
        let d = hits[k].depth;
        let same = |n: usize| (hits[n].depth - d).abs() <= jump;
        let span = |back: Option<usize>, ahead: Option<usize>| -> Option<Vec3> {
            let back = back.filter(|&n| same(n)).unwrap_or(k);
            let ahead = ahead.filter(|&n| same(n)).unwrap_or(k);
            (back != ahead)
                .then(|| self.point(ahead, hits[ahead].depth) - self.point(back, hits[back].depth))
        };
        let dx = span(
            x.checked_sub(reach).map(|x| y * w + x),
            (x + reach < w).then(|| k + reach),
        )?;
        let dy = span(
            y.checked_sub(reach).map(|y| y * w + x),
            (y + reach < h).then(|| k + reach * w),
        )?;
        let n = dy.cross(dx).normalize_or_zero();
        (n != Vec3::ZERO).then_some(n)
    }

    /// The picture: each hit lit by its voxel's normal, or, where voxels are small on the
    /// picture, by the normal of the depths around it (smoother than the cubes' faces), with
    /// silhouettes and creases darkened where the depth jumps; the background elsewhere.
    fn shade(&self, buffer: &Buffer) -> Vec<u8> {
        let (w, h) = (self.width as usize, self.height as usize);
        let hits = &buffer.hits;
        let jump = 2.0 + 2.0 / self.scale;
        let reach = ((2.5 / self.scale).ceil() as usize).max(1);
        let back = background(w, h);
        let pixels: Vec<[u8; 3]> = (0..hits.len())
            .into_par_iter()
            .map(|k| {
                let hit = hits[k];
                if hit.depth == f32::NEG_INFINITY {
                    return [back[3 * k], back[3 * k + 1], back[3 * k + 2]];
                }
                let normal = if hit.smooth || self.scale >= 1.5 {
                    hit.normal
                } else {
                    self.depth_normal(hits, k, reach, jump * reach as f32)
                        .unwrap_or(hit.normal)
                };
                // Mesh normals may face either way: turn them toward the viewer.
                let normal = normal * normal.dot(self.camera.toward).signum();
                let mut lit = 0.35 + 0.65 * normal.dot(self.light).max(0.0);
                let (x, y) = (k % w, k / w);
                let near = [
                    (x > 0).then(|| k - 1),
                    (x + 1 < w).then_some(k + 1),
                    (y > 0).then(|| k - w),
                    (y + 1 < h).then_some(k + w),
                ];
                if near
                    .into_iter()
                    .flatten()
                    .any(|n| hits[n].depth < hit.depth - jump)
                {
                    lit *= 0.55;
                }
                let c = (hit.albedo * lit).clamp(Vec3::ZERO, Vec3::ONE) * 255.0;
                [c.x as u8, c.y as u8, c.z as u8]
            })
            .collect();
        pixels.concat()
    }
}

/// What drawing a picture holds: a depth buffer per worker's share of the leaves (rayon's
/// fold makes about two per thread) and the main one, then the picture and its PNG.
fn picture_bytes(width: u32, height: u32) -> u64 {
    let pixels = u64::from(width) * u64::from(height);
    let buffers = 2 * rayon::current_num_threads() as u64 + 2;
    pixels * (buffers * std::mem::size_of::<Hit>() as u64 + 2 * 3)
}

/// A vertical grey gradient.
fn background(width: usize, height: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        let t = y as f32 / height.max(2) as f32;
        let c = [62.0 - 30.0 * t, 65.0 - 31.0 * t, 72.0 - 34.0 * t].map(|c| c as u8);
        for _ in 0..width {
            rgb.extend_from_slice(&c);
        }
    }
    rgb
}

/// Refuses a picture output that is not a `.png`, or cannot be written, or is an input,
/// before any drawing.
pub fn check_picture_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    if !output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(Error::InvalidArgument(format!(
            "{}: a picture is written as .png",
            output.display()
        )));
    }
    super::atomic::check_output(output, inputs)
}

/// Writes `picture` to `path` as PNG, atomically.
pub fn write_png(path: &Path, picture: &Picture) -> Result<()> {
    write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::io(path, e))?;
        let mut encoder =
            png::Encoder::new(std::io::BufWriter::new(file), picture.width, picture.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let failed = |e: png::EncodingError| Error::io(path, std::io::Error::other(e));
        let mut writer = encoder.write_header().map_err(failed)?;
        writer.write_image_data(&picture.rgb).map_err(failed)?;
        writer.finish().map_err(failed)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_voxels_with_an_empty_neighbour_in_the_leaf_are_visible() {
        let full = [u64::MAX; 8];
        let visible = visible_bits(&full);
        // The 6^3 inner voxels of a full leaf are hidden; its 296 border voxels are not.
        let count: u32 = visible.iter().map(|w| w.count_ones()).sum();
        assert_eq!(count, 512 - 216);
        let mut one = [0u64; 8];
        one[3] = 1 << (3 * 8 + 3);
        assert_eq!(visible_bits(&one), one);
    }
}
