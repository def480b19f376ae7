//! Pictures of results: `voxelkit render IN.vdb -o preview.png`, and `--preview` on the
//! voxelizing commands, which draws the result beside its output.

use crate::run::Global;
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxelkit::grid::SparseGrid;
use voxelkit::io::preview::{Scene, View, check_picture_output, render, write_png};
use voxelkit::io::vdb::{COLOR_GRID, NORMAL_GRID, read_vdb_grid, read_vdb_info};
use voxelkit::mesh::UpAxis;
use voxelkit::pipeline::on_threads;
use voxelkit::{Error, Result};

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("expected a size WIDTHxHEIGHT such as 800x600, got `{s}`");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

fn parse_view(s: &str) -> std::result::Result<View, String> {
    s.parse()
}

/// How a picture is taken.
#[derive(Args, Clone, Copy)]
pub struct PictureArgs {
    /// Where it looks from: iso (front, right, above), x (from +x), y (from -y, the front)
    /// or z (from above); Z is up.
    #[arg(long, default_value = "iso", value_parser = parse_view)]
    view: View,
    /// Picture size in pixels.
    #[arg(long, default_value = "800x600", value_parser = parse_size, value_name = "WxH")]
    size: (u32, u32),
    /// The grid's up axis: `y` stands a grid upright that was voxelized from a Y-up mesh (most
    /// OBJ, every glTF) without --up-axis y; `z` as Blender shows it.
    #[arg(long, default_value_t = UpAxis::Z, value_name = "AXIS")]
    up_axis: UpAxis,
}

impl Default for PictureArgs {
    fn default() -> Self {
        PictureArgs {
            view: View::Iso,
            size: (800, 600),
            up_axis: UpAxis::Z,
        }
    }
}

#[derive(Args)]
pub struct RenderArgs {
    /// A .vdb file.
    input: PathBuf,
    /// The grid drawn [default: `voxels`, else `density`, else the first bool, mask or float
    /// grid]; the file's `normal` and `Cd` grids light and colour it.
    #[arg(long)]
    grid: Option<String>,
    #[command(flatten)]
    picture: PictureArgs,
    /// Light each voxel by the faces of its cube, even when the file has a `normal` grid.
    #[arg(long)]
    faces: bool,
    /// Output .png.
    #[arg(short, long)]
    output: PathBuf,
}

/// Draws `scene` into `output` and says so.
fn draw(scene: &Scene, picture: PictureArgs, output: &Path, limit: Option<u64>) -> Result<String> {
    let start = Instant::now();
    let (w, h) = picture.size;
    let image = render(scene, picture.view, picture.up_axis, w, h, limit)?;
    write_png(output, &image)?;
    Ok(format!(
        "{}: {w}x{h} picture of {} voxels, {:.2} s",
        output.display(),
        scene.voxels.voxel_count(),
        start.elapsed().as_secs_f64()
    ))
}

pub fn run(args: &RenderArgs, global: &Global) -> Result<()> {
    check_picture_output(&args.output, &[&args.input])?;
    let infos = read_vdb_info(&args.input)?;
    let has = |name: &str| {
        infos
            .iter()
            .any(|i| i.name == name && i.value_type == "vec3s")
    };
    let voxels = read_vdb_grid(&args.input, args.grid.as_deref())?;
    let channel = |name: &str| -> Result<Option<SparseGrid>> {
        if has(name) {
            read_vdb_grid(&args.input, Some(name)).map(Some)
        } else {
            Ok(None)
        }
    };
    let normals = if args.faces {
        None
    } else {
        channel(NORMAL_GRID)?
    };
    let colors = channel(COLOR_GRID)?;
    let scene = Scene {
        voxels: &voxels,
        normals: normals.as_ref(),
        colors: colors.as_ref(),
    };
    let said = on_threads(global.limits().threads, || {
        draw(
            &scene,
            args.picture,
            &args.output,
            global.limits().max_memory,
        )
    })?;
    if global.json {
        println!(
            "{}",
            serde_json::json!({
                "output": args.output.display().to_string(),
                "voxels": voxels.voxel_count(),
                "size": [args.picture.size.0, args.picture.size.1],
            })
        );
    } else {
        println!("{said}");
    }
    Ok(())
}

/// `--preview`: the picture beside `output` (`out.vdb` gives `out.png`), drawn from the
/// result in memory.
pub fn beside(
    scene: &Scene,
    output: &Path,
    picture: PictureArgs,
    limit: Option<u64>,
) -> Result<PathBuf> {
    if output == Path::new("-") {
        return Err(Error::InvalidArgument(
            "--preview needs an output file to write the picture beside".into(),
        ));
    }
    let png = output.with_extension("png");
    check_picture_output(&png, &[output])?;
    draw(scene, picture, &png, limit)?;
    Ok(png)
}
