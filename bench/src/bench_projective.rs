//! `voxelkit bench projective`: the projective voxelizer in triangles/s and lines/s next to
//! our separating voxelizer on the same mesh, grid and threads, in the same process; with
//! `--leaks`, voxel counts and the inside voxels an exterior 6- or 26-flood reaches through
//! each surface.

use crate::bench::{best_of, data_folder, resolve, thread_pool};
use crate::json::Json;
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::grid::{Adjacency, SparseGrid, Transform};
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::subd::{ControlMesh, LimitSurface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::projective::{
    Coloring, LineSource, line_segments, voxelize_lines, voxelize_triangles,
};
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions, voxelize_mesh};

/// Segments per patch side when `beast` is tessellated: 6x6 quads per patch, about 2.3M
/// triangles from the 32k-face control mesh.
const BEAST_SEGMENTS: usize = 6;

#[derive(Args)]
pub struct ProjectiveBenchArgs {
    /// Meshes: names in DATA/meshes (without .obj), paths to .obj/.stl files, or `beast`, the
    /// limit surface of DATA/subd/beast.obj tessellated 6x6 per patch (about 2.3M triangles)
    /// [default: igea,skull,beast; with --leaks every closed mesh in DATA/meshes].
    #[arg(long, value_delimiter = ',')]
    meshes: Option<Vec<String>>,
    /// Data folder holding meshes/ and subd/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    /// [default: 512; with --leaks 128,256]
    #[arg(long, value_delimiter = ',')]
    resolutions: Option<Vec<u32>>,
    #[arg(long = "thread-counts", value_delimiter = ',', default_value = "2")]
    thread_counts: Vec<usize>,
    /// Runs per measurement; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
    /// Compare voxel counts and flood leaks with the separating surfaces instead of speed.
    #[arg(long)]
    leaks: bool,
    /// Count lines as Jegathese et al.'s Table 1 does: three per triangle, each voxelized
    /// (edges shared by two triangles twice), instead of each edge once.
    #[arg(long)]
    paper_lines: bool,
}

/// The mesh's triangles as closed three-segment polylines: the lines Table 1 counts.
fn triangle_outlines(mesh: &Mesh) -> Mesh {
    let mut outlines = mesh.clone();
    outlines.polylines = mesh
        .triangles()
        .map(|(_, [a, b, c])| vec![a, b, c, a])
        .collect();
    outlines
}

/// The closed meshes of the data folder.
const CLOSED_MESHES: &str = "bunny-closed,armadillo,cow,fandisk,horse,igea,rocker-arm,scorpion,skull,sphere,spot_triangulated,spot_quadrangulated,torus";

fn load(name: &str, data: &std::path::Path) -> Result<Mesh> {
    if name == "beast" {
        let control = ControlMesh::load(&data.join("subd").join("beast.obj"))?;
        let mut mesh = LimitSurface::new(control).tessellate(|_| BEAST_SEGMENTS);
        mesh.source =
            format!("beast (limit surface, {BEAST_SEGMENTS}x{BEAST_SEGMENTS} per patch)").into();
        return Ok(mesh);
    }
    Mesh::load(&resolve(name, data, "meshes"))
}

pub fn run(args: &ProjectiveBenchArgs, json: bool) -> Result<()> {
    if args.leaks {
        return leaks(args, json);
    }
    let data = data_folder(&args.data);
    let meshes = args
        .meshes
        .clone()
        .unwrap_or_else(|| vec!["igea".into(), "skull".into(), "beast".into()]);
    let resolutions = args.resolutions.clone().unwrap_or_else(|| vec![512]);
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<12} {:>9} {:>5} {:>3} {:>9} {:>10} {:>9} {:>10} {:>9} {:>9} {:>8} {:>10} {:>10}",
            "mesh",
            "triangles",
            "res",
            "thr",
            "proj s",
            "Mtris/s",
            "lines s",
            "Mlines/s",
            "sep6 s",
            "sep26 s",
            "vs sep6",
            "proj vox",
            "sep6 vox"
        );
    }
    for name in &meshes {
        let mesh = load(name, &data)?;
        let triangles = mesh.triangle_count() as u64;
        // The lines: each edge once, or (--paper-lines) each triangle's three.
        let (line_mesh, edges) = if args.paper_lines {
            let lines = LineSource {
                polylines: true,
                edges: false,
            };
            (triangle_outlines(&mesh), lines)
        } else {
            let lines = LineSource {
                polylines: true,
                edges: true,
            };
            (mesh.clone(), lines)
        };
        for &res in &resolutions {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res))?;
            for &threads in &args.thread_counts {
                let pool = thread_pool(threads)?;
                let time = |f: &(dyn Fn() -> Result<SparseGrid> + Sync)| {
                    pool.install(|| best_of(args.repeat, f))
                };
                let (tri_s, tri_grid) = time(&|| {
                    Ok(voxelize_triangles(
                        &mesh,
                        t,
                        Coloring::None,
                        &voxelkit::progress::Progress::none(),
                    )?
                    .0)
                })?;
                let (line_s, line_grid) = time(&|| {
                    Ok(voxelize_lines(
                        &line_mesh,
                        t,
                        edges,
                        Coloring::None,
                        &voxelkit::progress::Progress::none(),
                    )?
                    .0)
                })?;
                let segments = line_segments(&line_mesh, edges).len() as u64;
                let (sep6_s, sep6) = time(&|| separating(&mesh, t, Separability::Six))?;
                let (sep26_s, _) = time(&|| separating(&mesh, t, Separability::TwentySix))?;
                let (tri_rate, line_rate) = (triangles as f64 / tri_s, segments as f64 / line_s);
                if json {
                    rows.push(
                        Json::default()
                            .str("mesh", name.clone())
                            .int("triangles", triangles)
                            .int("segments", segments)
                            .int("resolution", res as u64)
                            .int("threads", threads as u64)
                            .num("projective_seconds", tri_s)
                            .num("triangles_per_second", tri_rate)
                            .num("lines_seconds", line_s)
                            .num("lines_per_second", line_rate)
                            .int("line_voxels", line_grid.voxel_count())
                            .num("separating6_seconds", sep6_s)
                            .num("separating26_seconds", sep26_s)
                            .int("projective_voxels", tri_grid.voxel_count())
                            .int("separating6_voxels", sep6.voxel_count()),
                    );
                } else {
                    println!(
                        "{:<12} {:>9} {:>5} {:>3} {:>9.4} {:>10.2} {:>9.4} {:>10.2} {:>9.4} {:>9.4} {:>7.2}x {:>10} {:>10}",
                        name,
                        triangles,
                        res,
                        threads,
                        tri_s,
                        tri_rate / 1e6,
                        line_s,
                        line_rate / 1e6,
                        sep6_s,
                        sep26_s,
                        sep6_s / tri_s,
                        tri_grid.voxel_count(),
                        sep6.voxel_count()
                    );
                }
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        println!(
            "Jegathese et al., Tables 1-2 (SGI O2, R10K): 0.311-0.942M lines/s (Dragon, 2.6M lines: 0.942M/s; \
             their lines are three per triangle: --paper-lines, e.g. --meshes stanford-bunny for the \
             paper's 69,451-triangle bunny); 0.018-0.139M triangles/s (Dragon, 871k triangles: 0.139M/s)"
        );
    }
    Ok(())
}

/// Our separating surface (clipped criterion) of `mesh` on `t`.
fn separating(mesh: &Mesh, t: Transform, separability: Separability) -> Result<SparseGrid> {
    let opts = SeparatingOptions {
        separability,
        criterion: Criterion::Clipped,
        normals: false,
    };
    Ok(voxelize_mesh(mesh, t, &opts, &voxelkit::progress::Progress::none())?.0)
}

/// Inside voxels reached by the exterior flood through `surface`, with 6 and with 26.
fn leaked(surface: &SparseGrid, mesh: &Mesh) -> Result<[u64; 2]> {
    let six = check_mesh_separation(surface, mesh, Adjacency::Six)?.leaked;
    let twenty_six = check_mesh_separation(surface, mesh, Adjacency::TwentySix)?.leaked;
    Ok([six, twenty_six])
}

fn leaks(args: &ProjectiveBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let meshes = args
        .meshes
        .clone()
        .unwrap_or_else(|| CLOSED_MESHES.split(',').map(String::from).collect());
    let resolutions = args.resolutions.clone().unwrap_or_else(|| vec![128, 256]);
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<20} {:>5} {:>10} {:>8} {:>8} {:>10} {:>8} {:>8} {:>10} {:>8}",
            "mesh",
            "res",
            "proj vox",
            "leak6",
            "leak26",
            "sep6 vox",
            "leak6",
            "leak26",
            "sep26 vox",
            "leak26"
        );
    }
    for name in &meshes {
        let mesh = load(name, &data)?;
        for &res in &resolutions {
            let t: Transform = fit_transform(&mesh.bbox(), GridFit::Resolution(res))?;
            let (proj, _) = voxelize_triangles(
                &mesh,
                t,
                Coloring::None,
                &voxelkit::progress::Progress::none(),
            )?;
            let (sep6, sep26) = (
                separating(&mesh, t, Separability::Six)?,
                separating(&mesh, t, Separability::TwentySix)?,
            );
            let (p, s6, s26) = (
                leaked(&proj, &mesh)?,
                leaked(&sep6, &mesh)?,
                leaked(&sep26, &mesh)?,
            );
            if json {
                rows.push(
                    Json::default()
                        .str("mesh", name.clone())
                        .int("resolution", res as u64)
                        .int("projective_voxels", proj.voxel_count())
                        .int("projective_leaks6", p[0])
                        .int("projective_leaks26", p[1])
                        .int("separating6_voxels", sep6.voxel_count())
                        .int("separating6_leaks6", s6[0])
                        .int("separating6_leaks26", s6[1])
                        .int("separating26_voxels", sep26.voxel_count())
                        .int("separating26_leaks26", s26[1]),
                );
            } else {
                println!(
                    "{:<20} {:>5} {:>10} {:>8} {:>8} {:>10} {:>8} {:>8} {:>10} {:>8}",
                    name,
                    res,
                    proj.voxel_count(),
                    p[0],
                    p[1],
                    sep6.voxel_count(),
                    s6[0],
                    s6[1],
                    sep26.voxel_count(),
                    s26[1]
                );
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        println!(
            "leakN: inside voxel centres an exterior N-connected flood reaches through the surface"
        );
    }
    Ok(())
}
