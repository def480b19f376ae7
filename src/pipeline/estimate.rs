//! Pricing: place the grid of a loaded task and estimate the peak memory and the work
//! items of every task, so that a job that cannot fit is refused before it allocates.
//!
//! Peak memory is counted in 8^3 leaves. Mesh surfaces and mesh solids have their own
//! calibration (below); the other tasks are calibrated on the shared meshes (bunny-closed at
//! 512..4096, spot, the sphere and torus formulas): a leaf of a voxel set costs about 3.5 KB
//! at the peak (the thread-local grids before their merge, OpenVDB's bool and float leaves
//! and the flat arrays when writing), one with a normal or colour channel about 20 KB more.
//! A surface of area A (in voxels) crosses about A/32 leaves; a solid is assumed to fill half
//! its box.

use super::attribute_grids::Carry;
use super::load::Work;
use super::{
    BrickStage, BrickTask, Fill, Plan, Shape, ShapeTask, SubdivisionOutput, SurfaceMethod,
};
use crate::error::{Error, Result};
use crate::grid::{CoordBox, MAX_DENSE_VOXELS, SparseGrid, Transform};
use crate::implicit::Formula;
use crate::io::brick_set::brick_voxels;
use crate::io::vdb::check_voxel_size;
use crate::mesh::attributes::AttributeChoice;
use crate::mesh::{Aabb, GridFit, Mesh, fit_transform, index_box};
use crate::ops::csg::same_transform;
use crate::ops::flood::padded;
use crate::solids::cavities::cavity_bytes;
use crate::solids::csg_exact::ExactTree;
use crate::solids::csg_tree::CsgNode;
use crate::solids::exterior_flood::FloodMethod;
use crate::solids::inside_rule::InsideRule;
use crate::subd::ControlMesh;
use crate::voxelize::distance_band;
use crate::voxelize::projective::{self, Coloring};
use crate::voxelize::separating;
use glam::DVec3;
use std::path::Path;

/// Peak bytes per leaf of a voxel set, and per leaf of a normal or colour channel.
const LEAF_BYTES: f64 = 3500.0;
const VECTOR_LEAF_BYTES: f64 = 20000.0;
/// Voxels of surface area per leaf they cross.
const AREA_PER_LEAF: f64 = 32.0;
/// The share of its box a solid is assumed to fill (a ball fills 52%).
const SOLID_FILL: f64 = 0.5;
/// The process itself: code and the allocator's own memory (9 MiB measured for a surface of
/// 211 leaves; 39 MiB while OpenVDB was loaded).
pub const BASE_BYTES: f64 = 10.0 * (1 << 20) as f64;

/// What reading a `.vdb` costs besides the leaves it keeps: per leaf of a voxel set, and per
/// leaf whose values are read too.
const READ_LEAF_BYTES: f64 = 300.0;
const READ_VALUE_LEAF_BYTES: f64 = 4300.0;

/// Bytes a grid read back holds, leaves and tiles, with the reader's cost a leaf: what
/// merging it with others into one voxel set costs.
pub fn merged_bytes(grid: &SparseGrid) -> u64 {
    let leaves = grid.leaf_count() as f64;
    (leaf_bytes(leaves, 0) + leaves * READ_LEAF_BYTES + tile_bytes(grid)) as u64
}

/// Peak bytes of a set of `leaves` leaves with `vector_channels` normal or colour channels.
fn leaf_bytes(leaves: f64, vector_channels: u32) -> f64 {
    (leaves + 1.0) * (LEAF_BYTES + f64::from(vector_channels) * VECTOR_LEAF_BYTES)
}

/// How many leaves with `vector_channels` channels fit in `limit` (default: the memory
/// available), for work whose size is only known as it runs.
pub(super) fn leaf_budget(limit: Option<u64>, vector_channels: u32) -> u64 {
    let per_leaf = LEAF_BYTES + f64::from(vector_channels) * VECTOR_LEAF_BYTES;
    (memory_budget(limit) as f64 / per_leaf) as u64
}

/// Bytes that work whose size is only known as it runs may take under `limit` (default: the
/// memory available).
pub(super) fn memory_budget(limit: Option<u64>) -> u64 {
    let available = limit
        .or_else(crate::system::available_memory_bytes)
        .unwrap_or(u64::MAX) as f64;
    (available - BASE_BYTES).max(0.0) as u64
}

/// Peak bytes of a surface of `area` voxels^2.
fn surface_bytes(area: f64, vector_channels: u32) -> f64 {
    leaf_bytes(area / AREA_PER_LEAF, vector_channels)
}

/// A mesh's area in voxels^2.
fn area_in_voxels(mesh: &Mesh, t: &Transform) -> f64 {
    mesh.area() / (t.voxel_size * t.voxel_size)
}

/// Mesh surfaces and solids, calibrated on the whole process (bunny-closed, igea, armadillo,
/// skull and horse at 1024, estimate/peak 0.94-1.10): a separating or projective surface
/// crosses a leaf per 44 voxels^2 of area and costs 400 bytes per leaf at the peak (the leaf
/// and the encoded buffers on their way to the file, which is written straight from the grid),
/// 8.3 KB more with normals or colours (the channel and its encoded values); each triangle
/// about 330 bytes (reading the file, the voxelizer's tables and bins). The leaf's cost was
/// refitted when the writer began streaming its buffers, and again where the buffers in flight
/// made the same run's peak vary (rocker-arm at 2048: 51-60 MiB over five runs; ogre at 1024:
/// 62-74): estimate/peak 0.92-0.98 on those five, 0.82-1.17 on fandisk, scorpion, rocker-arm,
/// spot and ogre.
const MESH_AREA_PER_LEAF: f64 = 44.0;
const MESH_LEAF_BYTES: f64 = 400.0;
const MESH_VECTOR_LEAF_BYTES: f64 = 8300.0;
const TRIANGLE_BYTES: f64 = 330.0;

/// What filling a mesh costs at the peak, besides the process: dense bit volumes over the
/// padded box and over the mesh's inside, bytes per voxel of the box's faces, per leaf of
/// the surface, per 8^3 block of the box and per triangle.
struct FillCost {
    bit_volumes: f64,
    /// Bits per voxel of the mesh's inside (the measure's labelling).
    inside_volumes: f64,
    /// Bytes per voxel of the box's three faces (depth buffers, one per direction).
    face_bytes: f64,
    leaf_bytes: f64,
    block_bytes: f64,
    triangle_bytes: f64,
}

/// A fill's peak comes after the surface's per-triangle tables are gone: each triangle then
/// costs what the mesh keeps of it, 65 bytes.
const FILLED_TRIANGLE_BYTES: f64 = 65.0;
/// The block flood (the default for closed meshes by parity): the surface, the solid's
/// boundary leaves and the grids written (1070 bytes per surface leaf) and the block states
/// (7 bytes per block of the box); the inside's tiles, a bit per 8^3 block, are small beside
/// them; no dense volume. Estimate/peak 0.87-1.04 on bunny-closed, igea, horse, armadillo,
/// skull, scorpion, fandisk, rocker-arm and spot at 1024.
const BLOCK_FLOOD_COST: FillCost = FillCost {
    bit_volumes: 0.0,
    inside_volumes: 0.0,
    face_bytes: 0.0,
    leaf_bytes: 1070.0,
    block_bytes: 7.0,
    triangle_bytes: FILLED_TRIANGLE_BYTES,
};
/// A solid whose inside the winding number decides (no flood): the surface's per-triangle
/// tables, still held while the inside is found beside it (210 bytes a triangle), the list
/// of whole 8^3 blocks (24 bytes each: 0.375 bits per inside voxel), and the surface, the
/// solid's boundary leaves and the grids written (230 bytes per surface leaf); the crossings
/// and columns come on top (`winding_plan`). The leaf's share was 710 bytes while the writers
/// listed every 8^3 tile twice (32 bytes each time), which made the peak of a large inside
/// (bunny-closed's solid at 1024: 107 MiB then, 80-93 MiB since). Estimate/peak 0.88-1.19 on
/// the nine closed meshes above and 0.82-0.85 on the open teapot, ogre and cube_no_bottom, at
/// 1024 and 2 threads (at 300 bytes fandisk's was 1.25-1.31, past the tests' bound once); a closed mesh's inside, read only near its surface
/// (`column_inside`), peaks below an open one's, which every block column decides.
const WINDING_SOLID_COST: FillCost = FillCost {
    bit_volumes: 0.0,
    inside_volumes: 0.375,
    face_bytes: 0.0,
    leaf_bytes: 230.0,
    block_bytes: 0.0,
    triangle_bytes: 210.0,
};
/// The span flood and FloodingXYZ: two dense volumes (surface and reached) and what scales
/// with them, the solid's tiles and the scanline queues, half a volume more; the surface's
/// own leaves are small beside them. Estimate/peak 0.86-1.17 (bunny-closed, igea, armadillo,
/// skull, horse at 512-1024, four of them at 2048; it was 1.24-1.48 at 512-1024).
const DENSE_FLOOD_COST: FillCost = FillCost {
    bit_volumes: 2.5,
    inside_volumes: 0.0,
    face_bytes: 0.0,
    leaf_bytes: 1000.0,
    block_bytes: 0.0,
    triangle_bytes: TRIANGLE_BYTES,
};
/// Depth layers: about one dense volume (the counts) and 266 bytes per voxel of the box's
/// faces (each direction's depth buffer, a few layers deep). Estimate/peak 0.94-1.12
/// (bunny-closed, igea, armadillo, skull, horse at 512-1024, three of them at 2048; it was
/// 0.7-3.2).
const DEPTH_LAYERS_COST: FillCost = FillCost {
    bit_volumes: 0.9,
    inside_volumes: 0.0,
    face_bytes: 266.0,
    leaf_bytes: 0.0,
    block_bytes: 0.0,
    triangle_bytes: TRIANGLE_BYTES,
};
/// `measure` of a mesh: the block flood without writing, then components and genus counted
/// over the solid, whose labels take about 1.5 bits per inside voxel and half a bit per
/// voxel of the box, besides the winding number's crossings and columns. Estimate/peak
/// 0.96-1.07 (bunny-closed, igea, fandisk, skull, armadillo at 1024).
const MEASURE_COST: FillCost = FillCost {
    bit_volumes: 0.6,
    inside_volumes: 1.5,
    face_bytes: 0.0,
    leaf_bytes: 920.0,
    block_bytes: 0.0,
    triangle_bytes: FILLED_TRIANGLE_BYTES,
};
/// The beam fill: two dense volumes and the projective surface, whose per-triangle tables
/// are smaller than the separating voxelizer's. Estimate/peak 0.82-1.21 (five meshes at
/// 512-1024, four of them at 2048; was 1.14-1.82).
const BEAM_COST: FillCost = FillCost {
    bit_volumes: 2.2,
    inside_volumes: 0.0,
    face_bytes: 0.0,
    leaf_bytes: 800.0,
    block_bytes: 0.0,
    triangle_bytes: 100.0,
};

/// A Catmull-Clark surface costs 4.75 KB per leaf of its control polygons' area (a leaf per
/// 44 voxels^2; the limit surface is smaller than its control polygons), normals included
/// (fitted on spot and catmark_torus at 1024).
const SUBDIV_LEAF_BYTES: f64 = 4750.0;
/// Per patch: its evaluation tables and the voxelizer's working set (6 KB; beast's 32k
/// patches at 1024).
const PATCH_BYTES: f64 = 6000.0;
/// Per quadtree node added by semi-sharp creases (`ControlMesh::crease_nodes`): its local
/// mesh and children, 1.6 KB measured on catmark_pawn, rook, car, bishop and helmet at 1024
/// (54, 412, 127, 92 and 32 MB more than without their tags).
const CREASE_NODE_BYTES: f64 = 1800.0;

/// The limit surface's patches with their lazily refined quadtrees.
fn patch_bytes(control: &ControlMesh, t: &Transform) -> f64 {
    control.patch_count() as f64 * PATCH_BYTES
        + control.crease_nodes(t.voxel_size) * CREASE_NODE_BYTES
}
/// A Catmull-Clark solid, measured on the limit surface's size (the polygons of one
/// subdivision step at their limit points; the control hull can be far larger): 7.8 KB per
/// leaf of that area (the enclosed surface with its normals, the seeds, the solid's
/// boundary); four dense volumes over that box (blocked, inside, outside, one seed's
/// region); and the exact volume's quadrature, which refines each patch 30 levels deep
/// towards every extraordinary corner and keeps the refinements (95 KB per corner: beast's
/// 5,832 corners take about 550 MB). Estimate/peak 0.94-1.07 on spot, catmark_torus,
/// catmark_cube, beast, fish and penguin at 256 and 1024 (was up to 5.6).
const SOLID_SUBDIV_LEAF_BYTES: f64 = 7800.0;
const SOLID_SUBDIV_VOLUMES: f64 = 4.0;
const IRREGULAR_CORNER_BYTES: f64 = 95_000.0;
/// The analytic voxelizer's state per 8^3 block of the shape's box (fitted on the sphere,
/// cylinder and quadric at 1024).
const SHAPE_BLOCK_BYTES: f64 = 20.0;

/// Leaves crossed by a surface of `area` voxels^2.
fn surface_leaves(area: f64) -> f64 {
    area / MESH_AREA_PER_LEAF + 1.0
}

/// Depth buffers per ray (count and four depths) and the crossings found on it while its
/// direction renders (a list each).
const FORMULA_RAY_BYTES: f64 = 18.0 + 120.0;

/// A formula's depth-layer solid: the inside and unclassified masks (a bit per voxel each) and
/// the three directions' rays, about a face of the box each.
fn formula_depth_layer_bytes(min: DVec3, max: DVec3, t: &Transform) -> f64 {
    let n = ((max - min) / t.voxel_size).ceil() + 2.0;
    let cells = n.x * n.y * n.z;
    let rays = n.x * n.y + n.y * n.z + n.x * n.z;
    cells / 4.0 + rays * FORMULA_RAY_BYTES
}

/// A tree over the triangles with their corner places, per triangle, for attributes carried
/// from the nearest point.
const NEAREST_TRIANGLE_BYTES: f64 = 180.0;

/// The attributes `chosen` writes of `mesh`: each a grid with a value and a vector channel.
fn attribute_count(mesh: &Mesh, chosen: &AttributeChoice, carry: Carry) -> u32 {
    chosen
        .select(mesh, carry.carries_colours())
        .map_or(0, |a| a.len() as u32)
}

/// Peak bytes per surface leaf of one attribute grid (a value and a vector channel): the
/// projective scan's thread-local grids and their merge add a third (spot's `uv` at 1024:
/// estimate/peak 1.04, was 0.80 counted as a vector channel).
fn attribute_leaf_bytes(carry: Carry) -> f64 {
    match carry {
        Carry::Interpolated => 11_000.0,
        Carry::Nearest => MESH_VECTOR_LEAF_BYTES,
    }
}

/// The nearest-point tree of `mesh` when `carried` attributes are taken from it.
fn nearest_tree_bytes(mesh: &Mesh, carried: u32, by_nearest: bool) -> f64 {
    if carried == 0 || !by_nearest {
        return 0.0;
    }
    mesh.triangle_count() as f64 * NEAREST_TRIANGLE_BYTES
}

/// Peak bytes of `leaves` surface leaves with `vector_channels` normal or colour channels.
fn surface_leaf_bytes(leaves: f64, vector_channels: u32) -> f64 {
    leaves * (MESH_LEAF_BYTES + f64::from(vector_channels) * MESH_VECTOR_LEAF_BYTES)
}

/// Lines: a leaf per 6 voxels of length (a line crosses a leaf in 5-8 voxels), and a mesh's
/// triangles read but not voxelized (85 bytes each). Calibrated on the edges of nine shared
/// meshes at 512-2048: estimate/peak 0.89-1.16 (was up to 1.8).
const LINE_LENGTH_PER_LEAF: f64 = 6.0;
const LINE_TRIANGLE_BYTES: f64 = 85.0;

/// Leaves crossed by a mesh's edges: `along` their length alone, but edges on a surface
/// share its leaves: where they are dense (coarse grids) the surface's `surface` leaves
/// bound them. The two blend as 1/n^2 = 1/along^2 + 1/surface^2 (within 15% of the
/// measured leaves on the nine meshes).
fn edge_leaves(along: f64, surface: f64) -> f64 {
    (along.powi(-2) + surface.powi(-2)).powf(-0.5)
}

/// Peak bytes of the separating or projective surface of `mesh`.
fn mesh_surface_bytes(mesh: &Mesh, t: &Transform, vector_channels: u32) -> f64 {
    let leaves = surface_leaves(area_in_voxels(mesh, t));
    surface_leaf_bytes(leaves, vector_channels) + mesh.triangle_count() as f64 * TRIANGLE_BYTES
}

/// Peak bytes of filling `mesh` over the box `b` at `cost`.
fn mesh_solid_bytes(mesh: &Mesh, t: &Transform, b: &CoordBox, cost: &FillCost) -> f64 {
    let leaves = surface_leaves(area_in_voxels(mesh, t));
    let box_cells = cells(b);
    let inside_cells = mesh.signed_volume().abs() / t.voxel_size.powi(3);
    (cost.bit_volumes * box_cells + cost.inside_volumes * inside_cells) / 8.0
        + face_cells(b) * cost.face_bytes
        + leaves * cost.leaf_bytes
        + box_cells / 512.0 * cost.block_bytes
        + mesh.triangle_count() as f64 * cost.triangle_bytes
}

/// CSG trees evaluate node by node on dense masks over the tree's box, whose pages are
/// touched only where solids are (1.2 volumes of the box at the peak), and the result's
/// boundary leaves cost 3 KB each; a result crosses about one leaf per 92 voxels^2 of its
/// box's faces. Mesh leaves add their fill (13 KB per leaf of their surface, and their
/// triangles), Catmull-Clark leaves their solid, grid leaves their leaves. Estimate/peak
/// 0.89-1.15 on the flange, a union of shapes and a mesh minus a slab at 256-1024 (was
/// 1.2-9.5). A tree of shapes and formulas also keeps its shell's normals: 512 of them and a
/// mask per shell leaf, 15.5 KB per leaf the faces' estimate counts (the shell crosses about
/// 2.5 leaves for each of those; flange 256-1024: estimate/peak 1.01-1.12, 0.38 at 1024
/// without them).
const CSG_VOLUMES: f64 = 1.2;
const CSG_FACE_AREA_PER_LEAF: f64 = 92.0;
const CSG_LEAF_BYTES: f64 = 3000.0;
const CSG_MESH_LEAF_BYTES: f64 = 13000.0;
const CSG_NORMAL_LEAF_BYTES: f64 = 15500.0;

/// Peak bytes of evaluating the CSG tree `root` over the box `b`.
fn csg_tree_bytes(root: &CsgNode, t: &Transform, b: &CoordBox) -> f64 {
    fn leaves_bytes(node: &CsgNode, t: &Transform) -> f64 {
        match node {
            CsgNode::Boolean { operands, .. } => operands.iter().map(|n| leaves_bytes(n, t)).sum(),
            CsgNode::Mesh(mesh) => {
                surface_leaves(area_in_voxels(mesh, t)) * CSG_MESH_LEAF_BYTES
                    + mesh.triangle_count() as f64 * TRIANGLE_BYTES
            }
            CsgNode::Subdivision(control) => {
                subdivision_solid_bytes(control, t) + patch_bytes(control, t)
            }
            CsgNode::Grid { grid, .. } => grid.leaf_count() as f64 * LEAF_BYTES,
            CsgNode::Primitive { .. } | CsgNode::Formula { .. } => 0.0,
        }
    }
    CSG_VOLUMES * cells(b) / 8.0
        + 2.0 * face_cells(b) / CSG_FACE_AREA_PER_LEAF * CSG_LEAF_BYTES
        + leaves_bytes(root, t)
}

/// Peak bytes of a Catmull-Clark solid besides its patches (see `SOLID_SUBDIV_LEAF_BYTES`),
/// sized on the limit surface.
fn subdivision_solid_bytes(control: &ControlMesh, t: &Transform) -> f64 {
    let limit = control.limit_polygons();
    let limit_box = index_box(&limit.bbox(), t);
    surface_leaves(area_in_voxels(&limit, t)) * SOLID_SUBDIV_LEAF_BYTES
        + SOLID_SUBDIV_VOLUMES * cells(&padded(limit_box, 1)) / 8.0
        + control.irregular_corner_count() as f64 * IRREGULAR_CORNER_BYTES
}

/// Triangles per leaf of a certified tessellation at most: two, or a fan where finer leaves
/// meet it (2.0-3.2 on the shared control meshes at 64-1024).
const TESSELLATION_TRIANGLES_PER_LEAF: f64 = 3.5;

/// The certified tessellation depth layers run on: its leaves are counted exactly (the
/// split alone, a fraction of a second), each triangle at its cost while built and rendered.
fn tessellation_bytes(control: &ControlMesh, t: &Transform) -> f64 {
    let surface = crate::subd::LimitSurface::new(control.clone());
    let tolerance = crate::solids::subdivision::TESSELLATION_TOLERANCE * t.voxel_size;
    crate::subd::certified_leaf_count(&surface, tolerance) as f64
        * TESSELLATION_TRIANGLES_PER_LEAF
        * crate::subd::TESSELLATION_TRIANGLE_BYTES as f64
}

/// A distance band's leaf with its values and encoded buffers: 2.4 KB; a level set's also
/// holds its interior's leaf and the fog volume's buffers, 2.45 KB. Each triangle 150 bytes
/// (its corners, the bins). Fitted on bunny-closed (`--sdf`) and igea (`--udf`) at 1024; the
/// unsigned leaf refitted by `voxelkit-bench calibrate` on the five meshes (factor 1.15), the
/// signed one when the writer began streaming its buffers (factor 0.87) and when it stopped
/// listing the interior's 8^3 tiles one by one (2600 -> 2450 bytes), and when the inside's
/// whole blocks were kept as node masks rather than listed (2450 -> 2300 bytes; estimate/peak
/// 1.05 on bunny-closed, 0.98 on igea, 1.03-1.26 on scorpion, rocker-arm, spot and fandisk).
const UNSIGNED_BAND_LEAF_BYTES: f64 = 2400.0;
const SIGNED_BAND_LEAF_BYTES: f64 = 2300.0;
const BAND_TRIANGLE_BYTES: f64 = 150.0;

/// `check`: the surface and its word-wise span floods, about 2.2 dense volumes over the box
/// at the peak, 900 bytes per surface leaf (normals at the surface's cost). Estimate/peak
/// 0.92-1.17 (bunny-closed, igea, armadillo, horse at 512-2048; it was up to 2.3).
const CHECK_VOLUMES: f64 = 2.2;
const CHECK_LEAF_BYTES: f64 = 900.0;

/// Bytes per labelled run of clear voxels: its span, label and union-find parent.
const RUN_BYTES: f64 = 16.0;

/// Peak bytes of one brick's work (see `bricks`): the surface of its faces; for a solid by
/// the exterior flood the two bit masks over its `size^3` voxels, the labelled runs (a few per
/// row) and the solid's leaves; for a solid by the winding number the whole mesh it holds, the
/// crossings of its columns (at most those of every triangle over them) and the solid's leaves.
fn brick_bytes(brick: &BrickTask, t: &Transform) -> f64 {
    let edge = brick.size as f64;
    let leaves = || leaf_bytes(edge.powi(3) * SOLID_FILL / 512.0, 0);
    let fill = match &brick.stage {
        BrickStage::Surface(_) => 0.0,
        BrickStage::FaceLabels | BrickStage::Solid { .. } => {
            let runs = 4.0 * edge * edge;
            edge.powi(3) / 4.0 + runs * RUN_BYTES + leaves()
        }
        BrickStage::Winding { mesh } => {
            // The triangles whose projection's box meets the brick's columns.
            let columns = brick_voxels(brick.brick, brick.size);
            let over = |tri: &[DVec3; 3]| {
                let [a, b, c] = tri.map(|v| t.world_to_index(v));
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                (0..2).all(|i| {
                    hi[i] >= columns.min[i] as f64 - 1.0 && lo[i] <= columns.max[i] as f64 + 1.0
                })
            };
            let near = mesh
                .triangles()
                .map(|(_, tri)| tri.map(|v| mesh.p(v)))
                .filter(over);
            mesh.triangle_count() as f64 * BAND_TRIANGLE_BYTES
                + winding_bytes(crossings_in_voxels(near, t), edge * edge)
                + leaves()
        }
    };
    surface_bytes(area_in_voxels(&brick.faces, t), 0) + fill
}

/// A brick on its run's grid, which only `GridFit::Placed` gives.
fn brick_plan(brick: &BrickTask, fit: GridFit) -> Result<Plan> {
    let GridFit::Placed(t) = fit else {
        return Err(Error::InvalidArgument(
            "a brick is placed on its run's grid (GridFit::Placed)".into(),
        ));
    };
    check_voxel_size(Path::new("the brick"), t.voxel_size)?;
    let voxels = brick_voxels(brick.brick, brick.size);
    let bbox = Aabb {
        min: t.index_to_world(voxels.min),
        max: t.index_to_world(voxels.max),
    };
    let bytes = brick_bytes(brick, &t);
    Ok(plan_of(
        t,
        &bbox,
        bytes,
        separating::work_items(&brick.faces),
    ))
}

/// Voxels of a box, as a float (boxes past 2^64 voxels must still be refused, not wrap).
fn cells(b: &CoordBox) -> f64 {
    box_edges(b).iter().product()
}

/// Voxels of three of a box's faces, one of each orientation.
fn face_cells(b: &CoordBox) -> f64 {
    let [x, y, z] = box_edges(b);
    x * y + y * z + z * x
}

fn box_edges(b: &CoordBox) -> [f64; 3] {
    std::array::from_fn(|a| (b.max[a] - b.min[a] + 1) as f64)
}

fn extent(bbox: &Aabb, t: &Transform) -> [f64; 3] {
    (bbox.extent() / t.voxel_size).to_array()
}

/// The index box of `bbox`, refused before any arithmetic overflows i64.
fn checked_box(bbox: &Aabb, t: &Transform) -> Result<CoordBox> {
    let e = extent(bbox, t);
    let far = (bbox.min.abs().max(bbox.max.abs()) / t.voxel_size).max_element();
    // Coordinates this many voxels from the origin keep a thousandth of a voxel in f64.
    const PRECISE: f64 = 1e-3 * (1u64 << 52) as f64;
    if e.iter().all(|v| v.is_finite() && *v < 1e15) && far.is_finite() && far > PRECISE {
        return Err(Error::InvalidArgument(format!(
            "coordinates up to {:.3e} lie {far:.3e} voxels from the origin: double precision \
             cannot place them to a thousandth of a voxel of size {:.3e}; move the model nearer \
             the origin or raise the voxel size",
            bbox.min.abs().max(bbox.max.abs()).max_element(),
            t.voxel_size
        )));
    }
    if !(e.iter().all(|v| v.is_finite() && *v < 1e15) && far < 1e15) {
        // At least a bit per voxel of the box.
        let bits: f64 = e.iter().map(|v| v.max(1.0)).product();
        return Err(Error::TooLarge {
            estimated_mib: (bits / 8.0 / (1u64 << 20) as f64).min(u64::MAX as f64) as u64,
            available_mib: crate::system::available_memory_bytes().unwrap_or(0) >> 20,
            detail: format!(
                "{:.3e} x {:.3e} x {:.3e} voxels cannot be indexed; raise the voxel size",
                e[0], e[1], e[2]
            ),
        });
    }
    Ok(index_box(bbox, t))
}

/// An implicit surface's size is only known by voxelizing it: a pass at `COARSE_OCTREE`
/// voxels along the bounds counts its voxels, scaled by the square of the resolution ratio (a
/// surface's voxels grow fourfold per doubling) in leaves of about 64 voxels; where the coarse
/// pass fills more than a quarter of its box (`0*x`), by the cube, in full leaves. A leaf costs
/// 6.5 KB at the peak, normals included (fitted on the sphere and `0*x` at 256, the gear
/// and sinsin examples at 1024).
const COARSE_OCTREE: u32 = 64;
const IMPLICIT_VOXELS_PER_LEAF: f64 = 64.0;
const IMPLICIT_LEAF_BYTES: f64 = 6500.0;

/// The leaves the surface of `formula` in `[min, max]` will fill at `resolution`.
fn implicit_leaves(
    formula: &Formula,
    min: DVec3,
    max: DVec3,
    resolution: u32,
    both_signs: bool,
) -> Result<f64> {
    use crate::voxelize::interval_octree::{OctreeOptions, voxelize_implicit};
    let coarse = resolution.clamp(1, COARSE_OCTREE);
    let options = OctreeOptions {
        resolution: coarse,
        both_signs,
        ..Default::default()
    };
    let out = voxelize_implicit(
        formula,
        min,
        max,
        &options,
        &crate::progress::Progress::none(),
    )?;
    let (voxels, ratio) = (
        out.stats.voxels as f64,
        f64::from(resolution) / f64::from(coarse),
    );
    let filled = voxels / (f64::from(coarse).powi(3));
    Ok(if filled > 0.25 {
        voxels * ratio.powi(3) / 512.0
    } else {
        voxels * ratio.powi(2) / IMPLICIT_VOXELS_PER_LEAF
    })
}

/// The octree's resolution: voxels along the longest side of the bounds.
pub(super) fn octree_resolution(fit: GridFit, min: DVec3, max: DVec3) -> Result<u32> {
    let fit = match fit {
        GridFit::Placed(t) | GridFit::Within(t, _) => GridFit::VoxelSize(t.voxel_size),
        other => other,
    };
    match fit {
        GridFit::Resolution(r) | GridFit::ResolutionAt(r, _) => Ok(r),
        GridFit::VoxelSize(h) if h.is_finite() && h > 0.0 => {
            let r = ((max - min).max_element() / h).ceil();
            if r > f64::from(1u32 << 16) {
                Err(Error::InvalidArgument(format!(
                    "voxel size {h:?} gives {r:.3e} voxels along the bounds; the octree takes at most 65536"
                )))
            } else {
                Ok(r.max(1.0) as u32)
            }
        }
        GridFit::VoxelSize(h)
        | GridFit::Placed(Transform { voxel_size: h, .. })
        | GridFit::Within(Transform { voxel_size: h, .. }, _) => Err(Error::InvalidArgument(
            format!("voxel size must be a positive number, got {h:?}"),
        )),
    }
}

/// The plan of a surface of `mesh`.
fn mesh_plan(mesh: &Mesh, fit: GridFit) -> Result<(Transform, CoordBox)> {
    let t = fit_transform(&mesh.bbox(), fit)?;
    let b = checked_box(&mesh.bbox(), &t)?;
    Ok((t, b))
}

/// Places the grid of `work` and prices it; `what` names the input in errors.
pub(super) fn price(work: &Work, fit: GridFit, what: &str) -> Result<Plan> {
    Ok(match work {
        Work::MeshSurface {
            mesh,
            method,
            attributes,
        } => {
            let (t, _) = mesh_plan(mesh, fit)?;
            let (channels, items) = match method {
                SurfaceMethod::Separating(o) => {
                    (u32::from(o.normals), separating::work_items(mesh))
                }
                SurfaceMethod::Projective(c) => {
                    let colour = c.coloring(mesh) != Coloring::None;
                    (u32::from(colour), mesh.face_count() as u64)
                }
            };
            let carry = Carry::of(method);
            let carried = attribute_count(mesh, attributes, carry);
            let leaves = surface_leaves(area_in_voxels(mesh, &t));
            let bytes = mesh_surface_bytes(mesh, &t, channels)
                + leaves * f64::from(carried) * attribute_leaf_bytes(carry)
                + nearest_tree_bytes(mesh, carried, carry == Carry::Nearest);
            plan_of(t, &mesh.bbox(), bytes, items)
        }
        Work::DistanceBand {
            mesh,
            band,
            signed,
            attributes,
            ..
        } => {
            let (t, _) = mesh_plan(mesh, fit)?;
            // A band 2w+1 voxels thick crosses about that many eighths of each leaf it meets.
            let leaves = surface_leaves(area_in_voxels(mesh, &t)) * (2.0 * band + 1.0) / 4.0;
            let per_leaf = if *signed {
                SIGNED_BAND_LEAF_BYTES
            } else {
                UNSIGNED_BAND_LEAF_BYTES
            };
            let carried = attribute_count(mesh, attributes, Carry::Nearest);
            let bytes = leaves * per_leaf
                + mesh.triangle_count() as f64 * BAND_TRIANGLE_BYTES
                + leaves * f64::from(carried) * MESH_VECTOR_LEAF_BYTES
                + nearest_tree_bytes(mesh, carried, true);
            plan_of(t, &mesh.bbox(), bytes, separating::work_items(mesh))
        }
        Work::SeparationCheck { mesh, options } => {
            let (t, b) = mesh_plan(mesh, fit)?;
            let leaves = surface_leaves(area_in_voxels(mesh, &t));
            let bytes = CHECK_VOLUMES * cells(&padded(b, 3)) / 8.0
                + leaves * CHECK_LEAF_BYTES
                + leaves * f64::from(u32::from(options.normals)) * MESH_VECTOR_LEAF_BYTES
                + mesh.triangle_count() as f64 * TRIANGLE_BYTES;
            plan_of(t, &mesh.bbox(), bytes, separating::work_items(mesh))
        }
        Work::Lines {
            mesh,
            source,
            coloring,
        } => {
            let (t, _) = mesh_plan(mesh, fit)?;
            let segments = projective::line_segments(mesh, *source);
            let length: f64 = segments
                .iter()
                .map(|&[a, b]| mesh.p(a).distance(mesh.p(b)))
                .sum();
            let mut leaves =
                (length / t.voxel_size + mesh.positions.len() as f64) / LINE_LENGTH_PER_LEAF;
            if mesh.face_count() > 0 {
                leaves = edge_leaves(leaves, surface_leaves(area_in_voxels(mesh, &t)));
            }
            let colour = *coloring != Coloring::None;
            let bytes = surface_leaf_bytes(leaves, u32::from(colour))
                + mesh.triangle_count() as f64 * LINE_TRIANGLE_BYTES;
            plan_of(t, &mesh.bbox(), bytes, segments.len() as u64)
        }
        Work::Shape(ShapeTask { shape, normals, .. }) => {
            let bbox = shape.surface().bbox();
            let t = fit_transform(&bbox, fit)?;
            let b = checked_box(&bbox, &t)?;
            let leaves = match shape {
                Shape::Formula(f) => {
                    let resolution = ((bbox.max - bbox.min).max_element() / t.voxel_size).ceil();
                    implicit_leaves(f.formula(), bbox.min, bbox.max, resolution as u32, false)?
                }
                _ => surface_leaves(shape.area() / (t.voxel_size * t.voxel_size)),
            };
            let bytes = surface_leaf_bytes(leaves, u32::from(*normals))
                + cells(&b) / 512.0 * SHAPE_BLOCK_BYTES;
            plan_of(t, &bbox, bytes, (cells(&b) / 512.0).ceil() as u64)
        }
        Work::Subdivision {
            control, output, ..
        } => {
            let bbox = control.bbox();
            let t = fit_transform(&bbox, fit)?;
            checked_box(&bbox, &t)?;
            let leaves = surface_leaves(area_in_voxels(&control.polygon_mesh(), &t));
            let bytes = patch_bytes(control, &t)
                + match output {
                    SubdivisionOutput::Solid(fill) => {
                        subdivision_solid_bytes(control, &t)
                            + if fill.depth_layers {
                                tessellation_bytes(control, &t)
                            } else {
                                0.0
                            }
                    }
                    SubdivisionOutput::Surface => leaves * SUBDIV_LEAF_BYTES,
                    // The tessellation (two triangles a quad) and the flood's volumes.
                    SubdivisionOutput::SeparationCheck => {
                        let segments = super::outcome::check_segments(control, &t) as f64;
                        let b = checked_box(&bbox, &t)?;
                        leaves * (SUBDIV_LEAF_BYTES + CHECK_LEAF_BYTES)
                            + 2.0 * control.patch_count() as f64 * segments.powi(2) * TRIANGLE_BYTES
                            + CHECK_VOLUMES * cells(&padded(b, 3)) / 8.0
                    }
                };
            plan_of(t, &bbox, bytes, control.patch_count() as u64)
        }
        Work::Implicit {
            formula,
            min,
            max,
            levels,
            negative_r,
            depth_layers,
            ..
        } => {
            let resolution = octree_resolution(fit, *min, *max)?;
            let bbox = Aabb {
                min: *min,
                max: *max,
            };
            let longest = (*max - *min).max_element();
            let t = Transform::new(
                *min + 0.5 * longest / f64::from(resolution.max(1)),
                longest / f64::from(resolution.max(1)),
            );
            // Every level holds about a quarter of the one below it.
            let levels = if *levels { 4.0 / 3.0 } else { 1.0 };
            let leaves = implicit_leaves(formula, *min, *max, resolution, *negative_r)?;
            let bytes = if *depth_layers {
                formula_depth_layer_bytes(*min, *max, &t)
            } else {
                (leaves + 1.0) * IMPLICIT_LEAF_BYTES * levels
            };
            let options = crate::voxelize::interval_octree::OctreeOptions {
                resolution,
                ..Default::default()
            };
            let items = crate::voxelize::interval_octree::progress_total(&options);
            plan_of(t, &bbox, bytes, items)
        }
        Work::Solid {
            mesh, fill, inside, ..
        } => match fill {
            // The winding number decides without a flood.
            Fill::Flood(_) if *inside != InsideRule::Parity => {
                winding_plan(mesh, fit, &WINDING_SOLID_COST)?
            }
            _ => solid_plan(mesh, fit, *fill)?,
        },
        // Measuring a mesh fills its flooded surface.
        Work::MeasureMesh {
            mesh,
            flood,
            inside,
            ..
        } => match inside {
            InsideRule::Parity => flood_plan(mesh, fit, flood_cost(*flood, &MEASURE_COST))?,
            _ => winding_plan(mesh, fit, &MEASURE_COST)?,
        },
        Work::MeasureSurface { surface, .. } => grid_plan(surface, what)?,
        Work::CsgTree(tree) => {
            let (t, bounds) = tree.transform()?;
            let b = checked_box(&bounds, &t)?;
            let normals = match ExactTree::of(tree, &t) {
                Some(_) => face_cells(&b) / CSG_FACE_AREA_PER_LEAF * CSG_NORMAL_LEAF_BYTES,
                None => 0.0,
            };
            let bytes = csg_tree_bytes(&tree.root, &t, &b) + normals;
            plan_of(t, &bounds, bytes, tree.node_count() as u64)
        }
        Work::Brick(brick) => brick_plan(brick, fit)?,
        Work::Combine {
            operands,
            normals,
            resample,
            ..
        } => {
            // Resampled onto the first grid (only when the grids differ), each voxel of a
            // later operand becomes (hb/ha)^3.
            let a = &operands[0];
            let later: f64 = operands[1..]
                .iter()
                .map(|b| {
                    let scale = b.transform.voxel_size / a.transform.voxel_size;
                    if *resample && !same_transform(&a.transform, &b.transform) {
                        (b.voxel_count() as f64 * scale.powi(3) / 64.0).max(b.leaf_count() as f64)
                    } else {
                        b.leaf_count() as f64
                    }
                })
                .sum();
            let leaves = a.leaf_count() as f64 + later;
            // The result's copy of the tiles of each, and its set's growth: 1.4 tiles each
            // (a checkerboard of 10^6 tiles in each of two grids: 204 MiB at the peak,
            // estimate 189).
            let tiles = 1.4 * operands.iter().map(tile_bytes).sum::<f64>();
            // The operands' normals, and as many again carried into the result.
            let normal_leaves: f64 = normals
                .iter()
                .flatten()
                .map(|g| g.leaf_count() as f64)
                .sum();
            let normals = 2.0 * normal_leaves * CSG_NORMAL_LEAF_BYTES;
            plan_of(
                a.transform,
                &world_box(a),
                leaf_bytes(leaves, 0) + tiles + normals,
                1,
            )
        }
    })
}

/// Bytes each worker thread of `work` keeps besides the shared memory `price` counts: the
/// dense scratch of a brick of surface (distances with a level set, nearest distances and
/// normals with a surface's normals, voxel bits alone otherwise), for the works that
/// voxelize a mesh's surface.
pub(super) fn thread_bytes(work: &Work) -> u64 {
    match work {
        Work::MeshSurface {
            method: SurfaceMethod::Separating(o),
            ..
        } => separating::thread_scratch_bytes(o.normals),
        Work::SeparationCheck { options, .. } => separating::thread_scratch_bytes(options.normals),
        Work::DistanceBand { .. } => distance_band::thread_scratch_bytes(),
        Work::Solid { .. } | Work::MeasureMesh { .. } | Work::CsgTree(_) | Work::Brick(_) => {
            separating::thread_scratch_bytes(false)
        }
        _ => 0,
    }
}

/// A plan over `bbox` on `transform` needing `bytes` besides the process itself.
fn plan_of(transform: Transform, bbox: &Aabb, bytes: f64, work_items: u64) -> Plan {
    Plan {
        transform,
        extent: extent(bbox, &transform),
        estimated_bytes: (BASE_BYTES + bytes).min(u64::MAX as f64) as u64,
        work_items,
    }
}

/// Filling `mesh` by `fill`: its surface, the bit volumes over its box and the solid.
fn solid_plan(mesh: &Mesh, fit: GridFit, fill: Fill) -> Result<Plan> {
    match fill {
        Fill::Flood(method) => flood_plan(mesh, fit, flood_cost(method, &BLOCK_FLOOD_COST)),
        Fill::DepthLayers(o) => fill_plan(mesh, fit, &DEPTH_LAYERS_COST, |_, b| {
            o.directions.len() as u64 + (b.max[0] - b.min[0] + 1) as u64
        }),
        Fill::Beam(_) => fill_plan(mesh, fit, &BEAM_COST, |m, _| m.face_count() as u64),
    }
}

/// The winding number's inside gathers every crossing of a column's ray with the mesh and its
/// caps (16 bytes each, gathered in batches sized for them, then placed column by column into
/// one array): 32 bytes a crossing at the peak beside the surface and the solid's grids, and
/// 8 bytes a column (where its crossings start, and where the next goes while they are
/// placed). Estimate/peak of the solids: see `WINDING_SOLID_COST`.
const WINDING_CROSSING_BYTES: f64 = 32.0;
const WINDING_COLUMN_BYTES: f64 = 8.0;

/// The winding number's crossings and columns (`WINDING_CROSSING_BYTES`).
fn winding_bytes(crossings: f64, columns: f64) -> f64 {
    crossings * WINDING_CROSSING_BYTES + columns * WINDING_COLUMN_BYTES
}

/// A solid or a measure at `cost` (its grids, no flood) whose inside the winding number
/// decides: the crossings and columns added.
fn winding_plan(mesh: &Mesh, fit: GridFit, cost: &FillCost) -> Result<Plan> {
    let mut plan = fill_plan(mesh, fit, cost, |m, _| separating::work_items(m))?;
    let triangles = mesh.triangles().map(|(_, t)| t.map(|v| mesh.p(v)));
    let [x, y, _] = box_edges(&crate::mesh::index_box(&mesh.bbox(), &plan.transform));
    let bytes = winding_bytes(crossings_in_voxels(triangles, &plan.transform), x * y);
    plan.estimated_bytes = plan.estimated_bytes.saturating_add(bytes as u64);
    Ok(plan)
}

/// The crossings of rays along z through voxel columns with `triangles`: a ray crosses a
/// triangle where its projection covers the ray's column.
fn crossings_in_voxels(triangles: impl Iterator<Item = [DVec3; 3]>, t: &Transform) -> f64 {
    let h2 = t.voxel_size.powi(2);
    triangles
        .map(|[a, b, c]| 0.5 * ((b - a).truncate().perp_dot((c - a).truncate())).abs() / h2)
        .sum()
}

/// The cost of a flood: `blocks` for the block flood (writing a solid or measuring it), the
/// dense volumes' for the others.
fn flood_cost(method: FloodMethod, blocks: &'static FillCost) -> &'static FillCost {
    match method {
        FloodMethod::Blocks => blocks,
        _ => &DENSE_FLOOD_COST,
    }
}

/// Flooding `mesh` at `cost`, and taking its cavities out (see `solids::cavities`).
fn flood_plan(mesh: &Mesh, fit: GridFit, cost: &FillCost) -> Result<Plan> {
    let mut plan = fill_plan(mesh, fit, cost, |m, _| separating::work_items(m))?;
    let cavities = cavity_bytes(mesh, plan.transform.voxel_size);
    plan.estimated_bytes = plan.estimated_bytes.saturating_add(cavities as u64);
    Ok(plan)
}

/// Filling `mesh` at `cost`, with `work_items` for the progress bar.
fn fill_plan(
    mesh: &Mesh,
    fit: GridFit,
    cost: &FillCost,
    work_items: impl Fn(&Mesh, &CoordBox) -> u64,
) -> Result<Plan> {
    let (t, b) = mesh_plan(mesh, fit)?;
    let bytes = mesh_solid_bytes(mesh, &t, &padded(b, 2), cost);
    Ok(plan_of(t, &mesh.bbox(), bytes, work_items(mesh, &b)))
}

/// The tiles of a grid.
fn tile_bytes(grid: &SparseGrid) -> f64 {
    grid.tiles().bytes() as f64
}

/// A grid's index box (the voxel at the origin when it is empty).
fn grid_box(grid: &SparseGrid) -> CoordBox {
    grid.bbox().unwrap_or(CoordBox {
        min: [0; 3],
        max: [0; 3],
    })
}

/// The world box of a grid's voxel centres.
fn world_box(grid: &SparseGrid) -> Aabb {
    let b = grid_box(grid);
    Aabb {
        min: grid.transform.index_to_world(b.min),
        max: grid.transform.index_to_world(b.max),
    }
}

/// Measuring a surface grid: filled and labelled as a mesh's (`MEASURE_COST`, the inside
/// taken as 30% of the box: bunny-closed fills 26%, igea 41%) in a dense volume over the
/// grid's box, allocated whole (it counts against an address-space limit), plus what reading
/// it left: OpenVDB's float leaves and their copied values (4.3 KB per leaf of a grid with
/// values, 300 bytes of a bool grid). Estimate/peak 1.02-1.20 on solids' shells (bunny-closed,
/// igea, skull, armadillo; armadillo's at 1024 1.36) and a surface at 512-1024 (was 5-14). A
/// box past the dense volume's limit is refused here, with the input's name.
fn grid_plan(grid: &SparseGrid, what: &str) -> Result<Plan> {
    let box_cells = cells(&padded(grid_box(grid), 2));
    let read_bytes = if grid.channels().value {
        READ_VALUE_LEAF_BYTES
    } else {
        READ_LEAF_BYTES
    };
    let bytes = (1.0 + 0.3 * MEASURE_COST.inside_volumes) * box_cells / 8.0
        + grid.leaf_count() as f64 * (MEASURE_COST.leaf_bytes + read_bytes)
        + tile_bytes(grid);
    let p = plan_of(grid.transform, &world_box(grid), bytes, 1);
    if box_cells > MAX_DENSE_VOXELS as f64 {
        return Err(Error::TooLarge {
            estimated_mib: p.estimated_bytes >> 20,
            available_mib: (MAX_DENSE_VOXELS / 8) >> 20,
            detail: format!(
                "{what} at {} voxels: measuring fills a dense volume over the grid's box, at \
                 most 2^34 voxels",
                p.describe_extent()
            ),
        });
    }
    Ok(p)
}
