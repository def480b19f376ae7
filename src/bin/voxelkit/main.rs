//! The `voxelkit` command line: a thin shell over the library.

mod batch;
mod commands;
mod implicit;
mod projective;
mod render;
mod run;
mod solid_depth;
mod solids;
mod subdiv;
mod to_mesh;

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use voxelkit::pipeline::request::{
    LimitsRequest, MeshRequest, SurfaceKind, ToMeshRequest, WriteRequest,
};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::Criterion;

#[derive(Parser)]
#[command(
    name = "voxelkit",
    version,
    about = "Voxelize meshes and analytic surfaces into separating voxel surfaces and write OpenVDB files",
    long_about = "Voxelize meshes and analytic surfaces into 6- or 26-separating voxel surfaces \
                  (Huang et al.'s distance criterion) and write OpenVDB .vdb files that Blender, \
                  Houdini and any OpenVDB program open. Each .vdb holds `density` (fog volume) \
                  and, with --normals, `normal` (Vec3); `voxels` (bool) when --grids names it; \
                  with --sdf, `density` and the level set `surface` (float, class LEVEL_SET). \
                  The Python module (pip install .) runs the same jobs.",
    after_long_help = "What a summary (or --json) reports:\n  \
        voxels, leaves: voxels of the main grid (surface or whole solid) and their 8^3 leaves\n  \
        vertex/edge/body voxels: voxels first made by a vertex sphere, edge cylinder, face slab\n  \
        degenerate faces: faces without area, voxelized by their edges (a warning)\n  \
        depth-guard stops (subdiv): sub-patches smaller than the paper's depth guard whose\n    \
        corner voxels were still not adjacent; accepted as they are\n  \
        tolerance voxels (subdiv --enclose): voxels a sub-patch bound within the tolerance\n    \
        touched, where the surface grazes a voxel edge or corner (many also hold a sample)\n  \
        inside/surface voxels, volume inside .. with surface (solids): the true volume lies\n    \
        between them; components (26-connected) and genus (components - Euler characteristic;\n    measure, and solid --topology)\n  \
        unclassified voxels (depth layers): voxels no direction decides, written as\n    \
        `unclassified`\n  \
        voxelize seconds, seconds: the voxelization itself, and the whole run\n  \
        peak, estimated MiB: the process's peak memory, and what planning estimated"
)]
struct Cli {
    /// Worker threads (0 or none: all cores; at most 256).
    #[arg(long, global = true)]
    threads: Option<u32>,
    /// Print one JSON object instead of the human summary (no progress bars); errors too are
    /// one JSON object, on stderr.
    #[arg(long, global = true)]
    json: bool,
    /// Refuse work whose estimated memory exceeds this many MiB, before it starts (0 or
    /// none: the memory available).
    #[arg(long, global = true, value_name = "MIB")]
    max_memory: Option<u64>,
    #[command(subcommand)]
    command: Command,
}

/// How a command writes its .vdb: the options of the commands that write one.
#[derive(Args, Clone)]
pub struct WriteArgs {
    /// Write only these grids of the .vdb, by name (e.g. `density,voxels`) [default: all but
    /// `voxels`, the boolean copy of `density`'s voxels].
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub grids: Vec<String>,
    /// .vdb compression: blosc (OpenVDB's default), zip or none.
    #[arg(long, default_value_t = WriteRequest::default().compression, value_parser = parse_compression)]
    pub compression: voxelkit::io::vdb::Compression,
    /// Write float and vector grids at half precision (16-bit: half the size).
    #[arg(long)]
    pub half: bool,
    /// Also draw each result as a picture beside its output (`out.vdb` gives `out.png`;
    /// `voxelkit render` takes views and sizes).
    #[arg(long)]
    pub preview: bool,
    /// Also write the result's surface as a closed, manifold triangle mesh (.obj, .ply, .stl
    /// or .glb): a level set's zero set (--sdf), a formula's F < 0 within its bounds, a
    /// solid's or a voxel surface's boundary (sharp where the source is known exactly).
    #[arg(long, value_name = "MESH")]
    pub mesh_out: Option<PathBuf>,
    /// With --mesh-out: how far merging its flat regions may move it.
    #[command(flatten)]
    pub adaptivity: to_mesh::AdaptivityArgs,
}

/// The up axis of input mesh files: an option of the commands that read meshes.
#[derive(Args, Clone, Copy)]
pub struct UpAxisArgs {
    /// The up axis of the input mesh files: `y` turns a Y-up file (most OBJ) to Z-up as
    /// Blender's OBJ importer does, (x, y, z) -> (x, -z, y), so the volume stands where the
    /// imported mesh stands; `z` keeps the coordinates.
    #[arg(long, default_value_t = MeshRequest::default().up_axis, value_name = "AXIS")]
    pub up_axis: voxelkit::mesh::UpAxis,
}

#[derive(Args, Clone, Copy)]
pub struct FitArgs {
    /// Voxels along the longest bounding-box axis [default: 256].
    #[arg(short, long, conflicts_with = "voxel_size")]
    resolution: Option<u32>,
    /// Voxel edge length in world units (instead of --resolution).
    #[arg(long)]
    voxel_size: Option<f64>,
    /// World position `x,y,z` of the centre of voxel (0,0,0) [default: half a voxel inside the
    /// low corner of the mesh's box]: 0,0,0 puts every centre on a multiple of the voxel size
    /// (as trimesh does), the mesh's low corner gives Open3D's VoxelGrid centres.
    #[arg(long, value_parser = commands::parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
    origin: Option<glam::DVec3>,
    /// The world box the grid covers, `lo,hi` (a cube) or `x0,y0,z0,x1,y1,z1` [default: the
    /// mesh's box]: --resolution counts voxels along its longest side and voxels whose
    /// centres lie outside it are left out.
    #[arg(long, value_parser = implicit::parse_bounds, allow_hyphen_values = true, value_name = "LO,HI")]
    pub bounds: Option<voxelkit::pipeline::request::Bounds>,
}

#[derive(Args, Clone, Copy)]
pub struct SurfaceArgs {
    /// 6: thin surface blocking face-connected paths; 26: thicker, blocks every path.
    #[arg(short, long, default_value_t = MeshRequest::default().separability, value_parser = parse_separability)]
    separability: Separability,
    /// huang: the paper's full vertex spheres and edge cylinders; clipped: the same clipped
    /// to the face slabs (still separating, far fewer redundant voxels). Meshes only.
    #[arg(long, default_value_t = MeshRequest::default().criterion, value_parser = parse_criterion)]
    criterion: Criterion,
    /// Also write a `normal` grid (nearest face/edge/vertex normal per voxel).
    #[arg(long)]
    normals: bool,
    /// Analytic shapes: the paper's plain rule, slabs of half thickness t without the margin
    /// for the surface's curvature (which can leave holes on curved surfaces; for comparison).
    #[arg(long)]
    no_curvature_margin: bool,
}

fn parse_separability(s: &str) -> Result<Separability, String> {
    s.parse()
}

fn parse_compression(s: &str) -> Result<voxelkit::io::vdb::Compression, String> {
    s.parse()
}

pub fn parse_criterion(s: &str) -> Result<Criterion, String> {
    s.parse()
}

fn parse_surface_kind(s: &str) -> Result<SurfaceKind, String> {
    s.parse()
}

#[derive(Subcommand)]
enum Command {
    /// Voxelize a polygon mesh (.obj, .stl, .ply, .off, .gltf or .glb) into a separating surface, or by projective
    /// scan-lines with vertex colours carried into a `Cd` grid; or write its level set
    /// (--sdf) or unsigned distances (--udf).
    Mesh {
        /// Input meshes: .obj (polygons kept; `v x y z r g b` colours read), .stl, .ply,
        /// .off, .gltf or .glb; several with --out-dir, or one pattern with --frames.
        #[arg(required = true, num_args = 1..)]
        inputs: Vec<PathBuf>,
        /// separating: Huang et al.'s 6/26-separating surface; projective: Jegathese et al.'s
        /// scan-lines in each triangle's dominant plane (fast, colours, no separability
        /// guarantee where triangles meet; ignores -s, --criterion and --normals).
        #[arg(long, default_value_t = MeshRequest::default().method, value_parser = parse_surface_kind)]
        method: SurfaceKind,
        #[command(flatten)]
        color: projective::ColorArgs,
        /// The mesh's vertex attributes to write, each as a grid of its name: `all`, `none`
        /// or names, comma-separated (`uv,vertex_normal`): OBJ `vt` as `uv` and `vn` as
        /// `vertex_normal`, PLY normals and texture coordinates the same, other PLY vertex
        /// properties by their names, vertex colours as `Cd` (--method projective writes
        /// those by its colour options). --method projective interpolates them across each
        /// triangle; the separating surface and --sdf/--udf take each voxel's value at the
        /// mesh's nearest point [default: all with --method projective, none otherwise]
        #[arg(long, value_delimiter = ',', value_name = "NAMES")]
        attributes: Option<Vec<String>>,
        #[command(flatten)]
        distance: commands::DistanceArgs,
        #[command(flatten)]
        fit: FitArgs,
        #[command(flatten)]
        surface: SurfaceArgs,
        #[command(flatten)]
        out: batch::OutputArgs,
        #[command(flatten)]
        write: WriteArgs,
        #[command(flatten)]
        up: UpAxisArgs,
    },
    /// Voxelize 3D polylines (OBJ `l`) or the edges of a mesh by marching each segment's
    /// dominant axis (Jegathese et al.), carrying vertex colours into a `Cd` grid.
    Lines(projective::LinesArgs),
    /// Voxelize an analytic surface (Huang et al. §7) by exact point-to-surface distance.
    Shape {
        #[command(subcommand)]
        shape: commands::ShapeKind,
    },
    /// Describe the grids of a .vdb file (types, counts, transform, metadata), or the bricks
    /// of a brick set by its index (`index.json`, from `python -m voxelkit.distributed`).
    Info {
        /// A .vdb file, or a brick set's `index.json`.
        file: PathBuf,
    },
    /// Draw the voxels of a .vdb as a PNG picture: each voxel a cube, lit by the file's
    /// `normal` grid when it has one, coloured by its `Cd` grid.
    Render(render::RenderArgs),
    /// Check a mesh voxelization: separability by flooding and the share of simple voxels.
    Check {
        /// Closed input mesh (with --subdiv, a Catmull-Clark control mesh).
        input: PathBuf,
        #[command(flatten)]
        fit: FitArgs,
        #[command(flatten)]
        surface: SurfaceArgs,
        /// The input is a Catmull-Clark control mesh: check the voxels of its limit surface
        /// (as `subdiv` makes them, by --adjacency, --presplit and --enclose) against a
        /// tessellation far finer than a voxel: 6-paths for the paper's surface, 26-paths for
        /// the enclosed one.
        #[arg(long)]
        subdiv: bool,
        #[command(flatten)]
        subdiv_surface: subdiv::SubdivSurfaceArgs,
        #[command(flatten)]
        up: UpAxisArgs,
    },
    /// Voxelize the bundled example (a trefoil-knot tube) and write .vdb files into a folder.
    Demo {
        /// Folder for the example mesh and the .vdb files (created when missing).
        #[arg(short, long, default_value = "voxelkit-demo")]
        output: PathBuf,
        /// Voxels along the example's longest bounding-box axis.
        #[arg(short, long, default_value_t = voxelkit::mesh::DEFAULT_RESOLUTION)]
        resolution: u32,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// Fill a mesh: its 26-separating surface plus its inside (any mesh, by --inside: the
    /// winding number, or the exterior flood of a closed one), or by depth layers, which report
    /// the voxels they cannot classify; prints volumes and mass (components and genus with
    /// --topology).
    Solid(solids::SolidArgs),
    /// Boolean of two voxel grids (.vdb): union, intersection or difference; or a whole CSG
    /// tree of shapes, formulas, meshes and grids from a JSON file (--tree).
    Csg(solids::CsgArgs),
    /// The intersection curve of voxel surfaces (.vdb grids, or meshes voxelized here on one
    /// grid): the voxels they share.
    Intersect(solids::IntersectArgs),
    /// Volume, mass, components and genus of a mesh (its inside by --inside) or of a closed
    /// .vdb surface.
    Measure(solids::MeasureArgs),
    /// Draw the surface of a grid in a .vdb as a closed, manifold triangle mesh (.obj, .ply,
    /// .stl or .glb): a level set's zero set, a fog volume's iso surface or a voxel set's
    /// boundary.
    ToMesh(to_mesh::ToMeshArgs),
    /// Remake any mesh (open, overlapping, self-intersecting too) as a closed, manifold mesh:
    /// its level set on a grid, signed by --inside, drawn as a mesh; reports the two-sided
    /// distance to the input.
    Remesh(to_mesh::RemeshArgs),
    /// Voxelize an implicit surface F = 0 typed as a formula, by interval octree (Stolte &
    /// Kaufman): every level of the octree envelops the surface.
    Implicit(implicit::ImplicitArgs),
    /// Voxelize a Catmull-Clark control mesh from its exact limit surface (Lai & Cheng), or
    /// check the limit-surface evaluator against OpenSubdiv (`subdiv check`, `subdiv eval`).
    Subdiv(subdiv::SubdivArgs),
}

impl Command {
    /// The command's write options and up axis, where it takes them.
    fn output_options(&self) -> (Option<&WriteArgs>, Option<voxelkit::mesh::UpAxis>) {
        match self {
            Command::Mesh { write, up, .. } => (Some(write), Some(up.up_axis)),
            Command::Lines(a) => (Some(&a.write), Some(a.up.up_axis)),
            Command::Shape { shape } => (Some(&shape.common().write), None),
            Command::Check { up, .. } => (None, Some(up.up_axis)),
            Command::Demo { write, .. } => (Some(write), None),
            Command::Solid(a) => (Some(&a.write), Some(a.up.up_axis)),
            Command::Csg(a) => (Some(&a.write), None),
            Command::Intersect(a) => (Some(&a.write), None),
            Command::Measure(a) => (None, Some(a.up.up_axis)),
            Command::Implicit(a) => (Some(&a.write), None),
            Command::Subdiv(a) => (Some(&a.voxelize.write), Some(a.voxelize.up.up_axis)),
            Command::Remesh(a) => (None, Some(a.up.up_axis)),
            Command::Info { .. } | Command::Render(_) | Command::ToMesh(_) => (None, None),
        }
    }
}

fn main() -> ExitCode {
    // Like other command-line tools, stop quietly when the reader of stdout goes away
    // (`voxelkit info x.vdb | head`) instead of panicking on the broken pipe.
    // SAFETY: restoring the default disposition of a signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // An interrupted run leaves no temporary file behind.
    voxelkit::io::atomic::remove_temporaries_on_signals();
    let cli = Cli::parse();
    let (write, up_axis) = cli.command.output_options();
    let global = run::Global {
        limits: LimitsRequest {
            threads: cli.threads,
            max_memory_mib: cli.max_memory,
        },
        up_axis: up_axis.unwrap_or_default(),
        json: cli.json,
        preview: write.is_some_and(|w| w.preview),
        mesh_out: write.and_then(|w| w.mesh_out.clone()),
        mesh_adaptivity: write.map_or(ToMeshRequest::default().adaptivity, |w| {
            w.adaptivity.adaptivity
        }),
        write: write.map_or_else(Default::default, |w| voxelkit::io::vdb::WriteOptions {
            grids: w.grids.clone(),
            compression: w.compression,
            half: w.half,
        }),
    };
    // Reading a file or drawing a picture is planned against the limit given, too.
    voxelkit::system::set_process_limit(global.limits().max_memory);
    let result = match cli.command {
        Command::Mesh {
            inputs,
            method,
            color,
            attributes,
            distance,
            fit,
            surface,
            out,
            ..
        } => commands::mesh(
            &inputs,
            method == SurfaceKind::Projective,
            &color,
            attributes,
            &distance,
            fit,
            surface,
            &out,
            &global,
        ),
        Command::Lines(args) => projective::lines(&args, &global),
        Command::Shape { shape } => commands::shape(&shape, &global),
        Command::Info { file } => commands::info(&file, &global),
        Command::Render(args) => render::run(&args, &global),
        Command::Check {
            input,
            fit,
            surface,
            subdiv,
            subdiv_surface,
            ..
        } => subdiv
            .then(|| subdiv_surface.request().options())
            .transpose()
            .and_then(|subdiv| commands::check(&input, fit, surface, subdiv, &global)),
        Command::Demo {
            output, resolution, ..
        } => commands::demo(&output, resolution, &global),
        Command::Subdiv(args) => subdiv::run(&args, &global),
        Command::Implicit(args) => implicit::run(&args, &global),
        Command::Solid(args) => solids::solid(&args, &global),
        Command::Csg(args) => solids::csg(&args, &global),
        Command::Intersect(args) => solids::intersect(&args, &global),
        Command::Measure(args) => solids::measure(&args, &global),
        Command::ToMesh(args) => to_mesh::run(&args, &global),
        Command::Remesh(args) => to_mesh::remesh(&args, &global),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if cli.json => {
            let (file, line) = e.location();
            let j = serde_json::json!({
                "error": run::with_flags(&e.to_string()),
                "file": file.map(|f| f.display().to_string()),
                "line": line,
            });
            eprintln!("{j}");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {}", run::with_flags(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}
