//! Voxelizing in bricks, so that one job can spread over processes or machines (the Python
//! module's Dask front end). Index space is cut into cubes of `size` voxels aligned on
//! multiples of `size` (a multiple of 8, so leaves never straddle two bricks). A brick
//! receives only the faces whose box, grown by one voxel, reaches it: the separating
//! criterion is local to a face's neighbourhood, so the brick's part of the surface is
//! exactly the part of the whole surface inside it.
//!
//! Solids by the winding number (option `inside` auto or winding, as a single run chooses it):
//! each brick receives the whole mesh besides its faces and keeps its surface and the centres
//! whose winding number is at least 1/2, exactly as the single run decides them; no brick
//! needs another's answer. Every brick meeting the mesh's box runs, with faces or without (a
//! brick wholly inside comes back as tiles).
//!
//! Solids by parity (the exterior flood, closed meshes): each brick labels its outside
//! components (clear voxels, face-connected, as the exterior flood goes) and hands in the
//! labels on its six faces; `exterior_labels` joins them across bricks and finds those
//! connected to the layout's border, which lies at least one voxel beyond the surface; each
//! brick then keeps the rest as inside.

use super::brick_exterior::face_runs;
use super::request::BricksRequest;
use super::{BrickFaceDetails, BrickStage, BrickTask, Details, MeshSource, Outcome};
use crate::error::{Error, Result};
use crate::grid::{Channels, CoordBox, DenseMask, SparseGrid, Transform};
use crate::io::brick_set::brick_voxels;
use crate::io::vdb::check_voxel_size;
use crate::mesh::boundary_caps::boundary_caps;
use crate::mesh::{GridFit, Mesh, fit_transform, index_box};
use crate::ops::flood::padded;
use crate::ops::labels::{ClearRuns, label_clear_runs};
use crate::progress::Progress;
use crate::solids::flooded_mesh::FLOOD_NEEDS_CLOSED;
use crate::solids::inside_rule::{Inside, choose_inside};
use crate::solids::winding_inside::winding_inside;
use crate::voxelize::Separability;
use crate::voxelize::separating::{SeparatingOptions, voxelize_mesh};
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// A brick's coordinates: brick `b` covers voxels `b * size ..= b * size + size - 1`.
pub type BrickIndex = [i64; 3];

/// The bricks covering a mesh's grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrickLayout {
    pub transform: Transform,
    pub size: i64,
    /// The first and last brick along each axis.
    pub min: BrickIndex,
    pub max: BrickIndex,
}

impl BrickLayout {
    /// The grid `fit` places the mesh on (as a single job would), cut into bricks of `size`
    /// covering the surface and a border of at least one clear voxel around it.
    pub fn new(mesh: &Mesh, fit: GridFit, size: u32) -> Result<BrickLayout> {
        if size < 8 || !size.is_multiple_of(8) {
            return Err(Error::InvalidArgument(format!(
                "the brick size must be a positive multiple of 8 voxels, not {size}"
            )));
        }
        let transform = fit_transform(&mesh.bbox(), fit)?;
        // The surface reaches one voxel beyond the box; one more keeps a clear border.
        let domain = padded(index_box(&mesh.bbox(), &transform), 1);
        let size = i64::from(size);
        Ok(BrickLayout {
            transform,
            size,
            min: domain.min.map(|v| v.div_euclid(size)),
            max: domain.max.map(|v| v.div_euclid(size)),
        })
    }

    /// The voxels of brick `b`.
    pub fn voxels(&self, b: BrickIndex) -> CoordBox {
        brick_voxels(b, self.size)
    }

    /// Every brick of the layout.
    pub fn all(&self) -> impl Iterator<Item = BrickIndex> + '_ {
        (self.min[0]..=self.max[0]).flat_map(move |x| {
            (self.min[1]..=self.max[1])
                .flat_map(move |y| (self.min[2]..=self.max[2]).map(move |z| [x, y, z]))
        })
    }

    /// The faces of `mesh` each brick receives (face numbers, ascending): those whose
    /// index box, grown by one voxel, meets the brick.
    pub fn bin_faces(&self, mesh: &Mesh) -> BTreeMap<BrickIndex, Vec<u32>> {
        let mut bins: BTreeMap<BrickIndex, Vec<u32>> = BTreeMap::new();
        for f in 0..mesh.face_count() {
            let mut lo = [i64::MAX; 3];
            let mut hi = [i64::MIN; 3];
            for &v in mesh.face(f) {
                let p = self.transform.world_to_index(mesh.p(v)).to_array();
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a].floor() as i64 - 1);
                    hi[a] = hi[a].max(p[a].ceil() as i64 + 1);
                }
            }
            let first = lo.map(|v| v.div_euclid(self.size));
            let last = hi.map(|v| v.div_euclid(self.size));
            for x in first[0]..=last[0] {
                for y in first[1]..=last[1] {
                    for z in first[2]..=last[2] {
                        bins.entry([x, y, z]).or_default().push(f as u32);
                    }
                }
            }
        }
        bins
    }
}

/// The faces `faces` of `mesh` as a mesh of their own, with only the vertices they use.
pub fn sub_mesh(mesh: &Mesh, faces: &[u32]) -> Mesh {
    let mut renumber = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let mut polygons = Vec::with_capacity(faces.len());
    for &f in faces {
        let polygon: Vec<u32> = mesh
            .face(f as usize)
            .iter()
            .map(|&v| {
                if renumber[v as usize] == u32::MAX {
                    renumber[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                renumber[v as usize]
            })
            .collect();
        polygons.push(polygon);
    }
    let mut sub = Mesh::from_polygons(mesh.source.clone(), positions, &polygons);
    sub.numbered_from_zero = true;
    sub
}

/// The part of the separating surface of the brick's faces that lies in `brick`.
pub fn brick_surface(
    faces: &Mesh,
    transform: Transform,
    brick: CoordBox,
    options: &SeparatingOptions,
    progress: &Progress,
) -> Result<SparseGrid> {
    let (mut surface, _) = voxelize_mesh(faces, transform, options, progress)?;
    surface.retain_leaves(|origin| brick.contains(origin));
    Ok(surface)
}

/// A brick's outside components.
pub struct BrickOutside {
    /// The brick's surface voxels.
    pub blocked: DenseMask,
    /// The clear voxels as runs along z, labelled by component.
    pub runs: ClearRuns,
}

/// The six faces of a brick, in the order -x, +x, -y, +y, -z, +z.
pub const FACES: usize = 6;

impl BrickOutside {
    pub fn label(surface: &SparseGrid, brick: CoordBox) -> Result<BrickOutside> {
        let blocked = DenseMask::from_grid(surface, brick)?;
        let runs = label_clear_runs(&blocked)?;
        Ok(BrickOutside { blocked, runs })
    }

    /// The labels on face `face` (see `FACES`): `size^2` of them, indexed `u * size + v` by
    /// the other two axes in order (y, z for an x face); 0 on the surface.
    pub fn face(&self, face: usize) -> Vec<u32> {
        let (axis, high) = (face / 2, face % 2 == 1);
        let [nx, ny, nz] = self.blocked.dims();
        let mut out = vec![0u32; nx * ny];
        let at = |n: usize| if high { n - 1 } else { 0 };
        match axis {
            // Whole rows: fill each run's span.
            0 | 1 => {
                let rows: Vec<(usize, usize)> = if axis == 0 {
                    (0..ny).map(|y| (at(nx), y)).collect()
                } else {
                    (0..nx).map(|x| (x, at(ny))).collect()
                };
                for (u, (x, y)) in rows.into_iter().enumerate() {
                    let row = x * ny + y;
                    for k in self.runs.row_starts[row]..self.runs.row_starts[row + 1] {
                        let (z0, z1) = self.runs.runs[k];
                        out[u * nz + z0 as usize..=u * nz + z1 as usize].fill(self.runs.labels[k]);
                    }
                }
            }
            // One voxel per row: its end.
            _ => {
                for x in 0..nx {
                    for y in 0..ny {
                        out[x * ny + y] = self.runs.label_at(ny, x, y, at(nz) as u32);
                    }
                }
            }
        }
        out
    }

    /// The surface and every clear run whose component is not in `exterior` (ascending).
    pub fn solid(&self, surface: &SparseGrid, exterior: &[u32]) -> SparseGrid {
        let mut inside = DenseMask::new(self.blocked.bbox).expect("the brick's box was allocated");
        let nz = self.blocked.dims()[2];
        for (row, pair) in self.runs.row_starts.windows(2).enumerate() {
            for k in pair[0]..pair[1] {
                if exterior.binary_search(&self.runs.labels[k]).is_err() {
                    let (z0, z1) = self.runs.runs[k];
                    inside.set_index_range(row * nz + z0 as usize, row * nz + z1 as usize);
                }
            }
        }
        let mut whole = inside.to_grid(surface.transform);
        whole.union(surface);
        whole
    }
}

/// The brick sizes a run chooses from when none is given, largest first: multiples of 128,
/// so that the merge splices the bricks' nodes (`brick_splice`), and 2048 at most, where a
/// worker's peak is a few hundred MiB on a dense mesh's surface (igea at 6144: 167-182 MiB).
const CHOSEN_SIZES: [u32; 5] = [2048, 1024, 512, 256, 128];

/// The sizes a surface run (or a solid run, `solid`) chooses from, largest first: a solid's
/// brick holds masks and leaves over all its voxels, eight times as much at 2048 as at 1024
/// (a surface's grows with its area), so a solid's start at 1024.
fn chosen_sizes(solid: bool) -> &'static [u32] {
    if solid {
        &CHOSEN_SIZES[1..]
    } else {
        &CHOSEN_SIZES
    }
}

/// Bricks with faces each worker thread is given when the size is chosen: bricks differ in
/// cost, and a few per thread let the ones that finish early take more. igea's surface at
/// 6144 on two one-thread workers: bricks of 2048 (29 bricks) took 3.29-3.32 s, of 1024 (121)
/// 3.52-3.55 s.
const BRICKS_PER_THREAD: usize = 8;

/// A distributed run's plan: the mesh read as the CLI reads it (for a solid, its inside rule
/// chosen as a single run chooses it), placed on the grid one run would use, its voxel size
/// one a `.vdb` holds, and cut into bricks with the faces each receives.
pub struct BrickRun {
    pub mesh: Mesh,
    pub layout: BrickLayout,
    pub bins: BTreeMap<BrickIndex, Vec<u32>>,
    /// Whether the run makes a solid (else a surface).
    pub solid: bool,
    /// A solid's inside rule: winding (true) or the exterior flood, and why.
    pub winding: bool,
    pub inside_reason: Option<String>,
}

impl BrickRun {
    /// The plan of `request` on `source`; `output` names the run in errors.
    pub fn plan(
        source: &MeshSource,
        request: &BricksRequest,
        solid: bool,
        output: &Path,
    ) -> Result<BrickRun> {
        let mesh = source.load(false, request.up_axis)?;
        let (winding, inside_reason) = if solid {
            let choice = choose_inside(request.inside, &mesh, FLOOD_NEEDS_CLOSED)?;
            (
                matches!(choice.inside, Inside::Winding(_)),
                Some(choice.reason),
            )
        } else {
            (false, None)
        };
        // Without a size, the largest for now: `fit_to_threads` chooses once the cluster is known.
        let size = request.brick.unwrap_or(chosen_sizes(solid)[0]);
        let layout = BrickLayout::new(&mesh, request.fit()?, size)?;
        check_voxel_size(output, layout.transform.voxel_size)?;
        let bins = layout.bin_faces(&mesh);
        Ok(BrickRun {
            mesh,
            layout,
            bins,
            solid,
            winding,
            inside_reason,
        })
    }

    /// For a `request` that gives no brick size, cuts the grid into the largest bricks of
    /// `chosen_sizes` that give each of `threads` worker threads at least `BRICKS_PER_THREAD`
    /// bricks with faces (the smallest where none does); its size.
    pub fn fit_to_threads(&mut self, request: &BricksRequest, threads: usize) -> Result<i64> {
        if request.brick.is_some() {
            return Ok(self.layout.size);
        }
        let wanted = threads.max(1) * BRICKS_PER_THREAD;
        for &size in chosen_sizes(self.solid) {
            if i64::from(size) != self.layout.size {
                self.layout = BrickLayout::new(&self.mesh, request.fit()?, size)?;
                self.bins = self.layout.bin_faces(&self.mesh);
            }
            if self.bins.len() >= wanted {
                break;
            }
        }
        Ok(self.layout.size)
    }

    /// The bricks a winding solid runs: those with faces and those meeting the mesh's box
    /// (where centres can wind at least 1/2), ascending.
    pub fn winding_bricks(&self) -> Vec<BrickIndex> {
        let region = index_box(&self.mesh.bbox(), &self.layout.transform);
        let mut bricks: Vec<BrickIndex> = self
            .layout
            .all()
            .filter(|&b| {
                self.bins.contains_key(&b) || self.layout.voxels(b).intersection(&region).is_some()
            })
            .collect();
        bricks.sort_unstable();
        bricks
    }
}

/// A brick's job (see `Task::Brick`): its part of the surface, its outside labels or its
/// part of the solid.
pub(super) fn run_brick(task: &BrickTask, t: Transform, progress: &Progress) -> Result<Outcome> {
    // A process that runs bricks runs many, one after another.
    crate::system::keep_freed_memory();
    let start = Instant::now();
    let voxels = brick_voxels(task.brick, task.size);
    let surface = |separability| {
        let options = SeparatingOptions {
            separability,
            ..Default::default()
        };
        brick_surface(&task.faces, t, voxels, &options, progress)
    };
    let (grid, details) = match &task.stage {
        BrickStage::Surface(separability) => (surface(*separability)?, Details::None),
        BrickStage::FaceLabels => {
            let surface = surface(Separability::TwentySix)?;
            let outside = BrickOutside::label(&surface, voxels)?;
            let details = BrickFaceDetails {
                outside_components: outside.runs.components,
                labels: (0..FACES).map(|f| face_runs(&outside.face(f))).collect(),
            };
            (surface, Details::BrickFaces(details))
        }
        BrickStage::Solid { exterior } => {
            let mut exterior = exterior.clone();
            exterior.sort_unstable();
            let surface = surface(Separability::TwentySix)?;
            let outside = BrickOutside::label(&surface, voxels)?;
            (outside.solid(&surface, &exterior), Details::None)
        }
        BrickStage::Winding { mesh } => {
            let surface = if task.faces.face_count() == 0 {
                SparseGrid::new(t, Channels::NONE)
            } else {
                surface(Separability::TwentySix)?
            };
            let region = index_box(&mesh.bbox(), &t).intersection(&voxels);
            let mut whole = match region {
                Some(region) => {
                    winding_inside(mesh, &boundary_caps(mesh), t, region, progress)?
                        .into_grids(t)
                        .0
                }
                None => SparseGrid::new(t, surface.channels()),
            };
            whole.union(&surface);
            (whole, Details::None)
        }
    };
    let meta = vec![("method", "voxelkit brick".into())];
    Ok(Outcome::new(grid, meta, details).timed(start))
}
