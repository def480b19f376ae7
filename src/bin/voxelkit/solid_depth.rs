//! `voxelkit solid --method depth-layers`: Passalis et al.'s depth-buffer solid, written with
//! its unclassifiable voxels and summarised direction by direction.

use crate::report::{Json, peak_mib};
use crate::solids::{SolidArgs, write_centre_solid};
use clap::Args;
use std::time::Instant;
use voxelkit::Result;
use voxelkit::mesh::{Mesh, fit_transform, index_box};
use voxelkit::voxelize::depth_layers::{DIRECTIONS, DepthLayerOptions, Layers, depth_layer_solid};

#[derive(clap::ValueEnum, Clone, Copy)]
enum LayersKind {
    /// Two layers per side and a stencil count of crossings (Passalis et al.).
    Double,
    /// One layer per side (Karabassi et al.): fills concavities no direction sees.
    Single,
}

/// Options of --method depth-layers.
#[derive(Args, Clone, Copy)]
pub struct DepthArgs {
    /// Depth-layer view directions: 3 are the axes (Karabassi's six z-buffers); up to 16 add
    /// face and body diagonals, deciding more voxels of closed meshes (but, on open meshes,
    /// meeting holes more often).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(3..=16))]
    directions: u32,
    #[arg(long, value_enum, default_value = "double")]
    layers: LayersKind,
}

fn direction_name(d: [i64; 3]) -> String {
    format!("({},{},{})", d[0], d[1], d[2])
}

pub fn run(args: &SolidArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let mesh = Mesh::load(&args.input)?;
    let edges = mesh.edge_counts();
    let transform = fit_transform(&mesh.bbox(), args.fill.fit.grid_fit())?;
    let bbox = index_box(&mesh.bbox(), &transform);
    let layers = match args.depth.layers {
        LayersKind::Double => Layers::Double,
        LayersKind::Single => Layers::Single,
    };
    let options = DepthLayerOptions {
        directions: args.depth.directions as usize,
        layers,
    };
    let solid = depth_layer_solid(&mesh, &transform, bbox, &options)?;
    let classify_seconds = start.elapsed().as_secs_f64();
    let method = format!(
        "depth-layers ({}, {} directions)",
        match layers {
            Layers::Double => "double layers + stencil",
            Layers::Single => "single layer",
        },
        options.directions
    );
    let meta = vec![
        ("method", method.clone()),
        ("source_file", args.input.display().to_string()),
        ("resolution", args.fill.fit.describe()),
    ];
    write_centre_solid(
        &args.output,
        &solid.inside,
        transform,
        &[("unclassified", &solid.unclassified.to_grid(transform))],
        &meta,
    )?;
    let s = &solid.stats;
    let cell = transform.voxel_size.powi(3);
    let volume = s.inside_voxels as f64 * cell;
    let volume_max = (s.inside_voxels + s.unclassified_voxels) as f64 * cell;
    let density = args.fill.density;
    let seconds = start.elapsed().as_secs_f64();
    if json {
        let directions = s
            .per_direction
            .iter()
            .map(|c| {
                Json::default()
                    .str("direction", direction_name(c.direction))
                    .int("rays", c.rays)
                    .int("crossed_0", c.none)
                    .int("crossed_2", c.two)
                    .int("crossed_4", c.four)
                    .int("crossed_more", c.more)
                    .int("crossed_odd", c.odd)
            })
            .collect();
        let j = Json::default()
            .str("output", args.output.display().to_string())
            .str("method", method)
            .int("voxels", s.voxels)
            .int("inside_voxels", s.inside_voxels)
            .int("unclassified_voxels", s.unclassified_voxels)
            .int("unclassified_on_odd_rays", s.open_voxels)
            .int("odd_rays", s.odd_rays())
            .int("boundary_edges", edges.boundary)
            .int("non_manifold_edges", edges.non_manifold)
            .num("volume", volume)
            .num("volume_with_unclassified", volume_max)
            .num("mass", volume * density)
            .num("mesh_signed_volume", mesh.signed_volume())
            .arr("directions", directions)
            .num("classify_seconds", classify_seconds)
            .num("seconds", seconds)
            .num("peak_mib", peak_mib());
        println!("{}", j.render());
        return Ok(());
    }
    println!(
        "{}: {method}: {} inside, {} unclassifiable of {} voxels; volume {volume:.6} (inside centres){}; mass {:.6} at density {density}; mesh signed volume {:.6}",
        args.output.display(),
        s.inside_voxels,
        s.unclassified_voxels,
        s.voxels,
        if s.unclassified_voxels > 0 {
            format!(", {volume_max:.6} with the unclassifiable voxels")
        } else {
            String::new()
        },
        volume * density,
        mesh.signed_volume()
    );
    println!("  rays by crossings     0          2          4         >4        odd");
    for c in &s.per_direction {
        println!(
            "  {:<12} {:>10} {:>10} {:>10} {:>10} {:>10}",
            direction_name(c.direction),
            c.none,
            c.two,
            c.four,
            c.more,
            c.odd
        );
    }
    if s.odd_rays() > 0 {
        println!(
            "  the input is not closed ({} boundary and {} non-manifold edges): {} rays cross it an odd number of times, and the {} voxels on them are unclassifiable (written as `unclassified`, neither filled nor left empty)",
            edges.boundary,
            edges.non_manifold,
            s.odd_rays(),
            s.open_voxels
        );
    } else if s.unclassified_voxels > 0 {
        println!(
            "  {} voxels are crossed more than four times along every direction and are written as `unclassified`{}",
            s.unclassified_voxels,
            if options.directions < DIRECTIONS.len() {
                format!("; up to {} --directions may decide some", DIRECTIONS.len())
            } else {
                String::new()
            }
        );
    }
    println!(
        "  {seconds:.2} s ({classify_seconds:.2} s classifying), peak {:.0} MiB",
        peak_mib()
    );
    Ok(())
}
