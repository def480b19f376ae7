//! The limit surface of a control mesh as a set of quad patches, addressed the way OpenSubdiv
//! addresses it (`Bfr::Parameterization`):
//! - a quad face is one patch; corner k at (0,0), (1,0), (1,1), (0,1);
//! - an n-gon (n != 4) is split by one subdivision step into n sub-faces; sub-face s is the
//!   quad [corner s, midpoint of edge s, centre, midpoint of edge s-1], placed in tile
//!   (s mod D, s div D) with D = 2 for triangles, 3 for n = 5..9, 1 + floor(sqrt(n-1)) above,
//!   at half size: face u = tile_u + s_u / 2, v = tile_v + s_v / 2.

use super::control_mesh::ControlMesh;
use super::patch::{LimitSample, PatchNode};
use super::subdivide::subdivide;
use crate::error::{Error, Result};
use rayon::prelude::*;

pub struct LimitSurface {
    control: ControlMesh,
    patches: Vec<PatchNode>,
    /// `first_patch[f]..first_patch[f + 1]` are the patches of face f.
    first_patch: Vec<u32>,
    /// Face of every patch.
    patch_face: Vec<u32>,
}

/// Where a patch sits in its face's parameter domain: face (u, v) = origin + scale * (s, t).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchDomain {
    pub face: usize,
    pub origin: (f64, f64),
    pub scale: f64,
}

/// Tiles per row of an n-gon's sub-faces.
pub fn subface_tiles(n: usize) -> usize {
    match n {
        3 => 2,
        5..=9 => 3,
        _ => 1 + ((n - 1) as f64).sqrt().floor() as usize,
    }
}

impl LimitSurface {
    /// Builds every patch (in parallel; irregular patches refine lazily on first use).
    pub fn new(control: ControlMesh) -> LimitSurface {
        let mesh = &control.mesh;
        let per_face: Vec<Vec<PatchNode>> = (0..mesh.face_count())
            .into_par_iter()
            .map(|f| {
                let faces = mesh.one_ring_faces(f, &control.outgoing);
                let net = mesh.extract_rotated(&faces, 0);
                if mesh.face_len(f) == 4 {
                    return vec![PatchNode::new(net)];
                }
                let complete: Vec<bool> = (0..net.points.len() as u32)
                    .map(|v| net.face(0).contains(&v))
                    .collect();
                let child = subdivide(&net, &complete);
                let outgoing = child.outgoing();
                (0..mesh.face_len(f))
                    .map(|s| {
                        let faces = child.one_ring_faces(s, &outgoing);
                        PatchNode::new(child.extract_rotated(&faces, 0))
                    })
                    .collect()
            })
            .collect();
        let mut first_patch = vec![0u32];
        let mut patch_face = Vec::new();
        let mut patches = Vec::new();
        for (f, face_patches) in per_face.into_iter().enumerate() {
            patch_face.extend(std::iter::repeat_n(f as u32, face_patches.len()));
            patches.extend(face_patches);
            first_patch.push(patches.len() as u32);
        }
        LimitSurface {
            control,
            patches,
            first_patch,
            patch_face,
        }
    }

    pub fn control(&self) -> &ControlMesh {
        &self.control
    }

    pub fn patch_count(&self) -> usize {
        self.patches.len()
    }

    /// Evaluates patch `pid` at its own `(s, t)` in `[0,1]²` (derivatives per unit of s, t).
    pub fn eval_patch(&self, pid: usize, s: f64, t: f64) -> LimitSample {
        self.patches[pid].eval(s, t)
    }

    /// A box containing patch `pid` over `[s0,s1] x [t0,t1]`.
    pub fn bound_patch(
        &self,
        pid: usize,
        s0: f64,
        s1: f64,
        t0: f64,
        t1: f64,
    ) -> (glam::DVec3, glam::DVec3) {
        self.patches[pid].bound(s0, s1, t0, t1)
    }

    /// See `PatchNode::within_tolerance`.
    pub fn within_tolerance(&self, pid: usize, [s0, s1, t0, t1]: [f64; 4], tolerance: f64) -> bool {
        self.patches[pid].within_tolerance(s0, s1, t0, t1, tolerance)
    }

    /// The face patch `pid` belongs to, and its place among the face's patches (an n-gon's
    /// sub-face number; 0 for a quad).
    pub fn patch_of_face(&self, pid: usize) -> (usize, usize) {
        let face = self.patch_face[pid] as usize;
        (face, pid - self.first_patch[face] as usize)
    }

    /// Whether patch `pid` is one polynomial over `[s0,s1] x [t0,t1]` (see
    /// `PatchNode::polynomial_on`).
    pub fn polynomial_on(&self, pid: usize, s0: f64, s1: f64, t0: f64, t1: f64) -> bool {
        self.patches[pid].polynomial_on(s0, s1, t0, t1)
    }

    /// Every patch `pid` sampled on an `(n+1) x (n+1)` grid, `n = segments(pid)`, and split
    /// into quads: a closed polygon approximation of the limit surface of a closed control
    /// mesh. Points shared by patches are evaluated once per patch (equal to rounding) and
    /// welded on a 1e-9 lattice.
    pub fn tessellate(&self, segments: impl Fn(usize) -> usize + Sync) -> crate::mesh::Mesh {
        let per_patch: Vec<(usize, Vec<glam::DVec3>)> = (0..self.patch_count())
            .into_par_iter()
            .map(|pid| {
                let n = segments(pid).max(1);
                let points = (0..=n)
                    .flat_map(|j| (0..=n).map(move |i| (i, j)))
                    .map(|(i, j)| {
                        self.eval_patch(pid, i as f64 / n as f64, j as f64 / n as f64)
                            .position
                    })
                    .collect();
                (n, points)
            })
            .collect();
        let b = self.control.bbox();
        let lattice = (b.max - b.min).length().max(f64::MIN_POSITIVE) * 1e-9;
        let mut index = rustc_hash::FxHashMap::default();
        let mut positions = Vec::new();
        let mut quads = Vec::new();
        for (n, points) in per_patch {
            let ids: Vec<u32> = points
                .iter()
                .map(|&p| {
                    let key = ((p - b.min) / lattice).round().as_i64vec3().to_array();
                    *index.entry(key).or_insert_with(|| {
                        positions.push(p);
                        positions.len() as u32 - 1
                    })
                })
                .collect();
            let at = |i: usize, j: usize| ids[j * (n + 1) + i];
            for j in 0..n {
                for i in 0..n {
                    quads.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        crate::mesh::Mesh::from_polygons(self.control.source.clone(), positions, &quads)
    }

    pub fn patch_domain(&self, pid: usize) -> PatchDomain {
        let face = self.patch_face[pid] as usize;
        let n = self.control.face_len(face);
        if n == 4 {
            return PatchDomain {
                face,
                origin: (0.0, 0.0),
                scale: 1.0,
            };
        }
        let s = pid - self.first_patch[face] as usize;
        let d = subface_tiles(n);
        PatchDomain {
            face,
            origin: ((s % d) as f64, (s / d) as f64),
            scale: 0.5,
        }
    }

    /// `per_patch` uniformly random points on every patch, as face `(face, u, v)`.
    pub fn random_parameters(&self, per_patch: usize, seed: u64) -> Vec<(usize, f64, f64)> {
        let mut rng = crate::random::SplitMix64(seed);
        let mut out = Vec::with_capacity(per_patch * self.patch_count());
        for pid in 0..self.patch_count() {
            let d = self.patch_domain(pid);
            for _ in 0..per_patch {
                let (s, t) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
                out.push((d.face, d.origin.0 + d.scale * s, d.origin.1 + d.scale * t));
            }
        }
        out
    }

    /// Evaluates face `face` at OpenSubdiv's `(u, v)`; derivatives are per unit of u and v.
    pub fn evaluate(&self, face: usize, u: f64, v: f64) -> Result<LimitSample> {
        let (pid, s, t, scale) = self.locate(face, u, v)?;
        let mut sample = self.patches[pid].eval(s, t);
        sample.du /= scale;
        sample.dv /= scale;
        Ok(sample)
    }

    /// The patch holding face coordinates `(u, v)`, the patch coordinates and the scale.
    fn locate(&self, face: usize, u: f64, v: f64) -> Result<(usize, f64, f64, f64)> {
        let faces = self.control.face_count();
        if face >= faces {
            return Err(Error::InvalidArgument(format!(
                "face {face} does not exist: {} has {faces} faces (0-based)",
                self.control.source.display()
            )));
        }
        let n = self.control.face_len(face);
        let first = self.first_patch[face] as usize;
        let out_of_range = || {
            Error::InvalidArgument(format!(
                "(u, v) = ({u}, {v}) is outside face {face} ({n} corners) of {}",
                self.control.source.display()
            ))
        };
        if !(u.is_finite() && v.is_finite()) {
            return Err(out_of_range());
        }
        if n == 4 {
            if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
                return Err(out_of_range());
            }
            return Ok((first, u, v, 1.0));
        }
        let d = subface_tiles(n);
        let (tu, tv) = (u.floor().max(0.0), v.floor().max(0.0));
        // A point on the far edge of a half-size tile belongs to that tile.
        let mut sub = None;
        for (cu, cv) in [
            (tu, tv),
            (tu - 1.0, tv),
            (tu, tv - 1.0),
            (tu - 1.0, tv - 1.0),
        ] {
            if cu < 0.0 || cv < 0.0 {
                continue;
            }
            let (su, sv) = (2.0 * (u - cu), 2.0 * (v - cv));
            let s = cv as usize * d + cu as usize;
            if (cu as usize) < d && s < n && (0.0..=1.0).contains(&su) && (0.0..=1.0).contains(&sv)
            {
                sub = Some((s, su, sv));
                break;
            }
        }
        let (s, su, sv) = sub.ok_or_else(out_of_range)?;
        Ok((first + s, su, sv, 0.5))
    }
}
