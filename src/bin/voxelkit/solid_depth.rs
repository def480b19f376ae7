//! The options of `voxelkit solid --method depth-layers` (Passalis et al.'s depth buffers).

use clap::Args;
use voxelkit::pipeline::request::{Directions, SolidRequest};
use voxelkit::solids::depth_layers::{Layers, Unclassified};

fn parse_layers(s: &str) -> Result<Layers, String> {
    s.parse()
}

fn parse_unclassified(s: &str) -> Result<Unclassified, String> {
    s.parse()
}

/// `--directions`: a count of the built-in directions, or `x,y,z;x,y,z;...`, checked.
fn parse_directions(s: &str) -> Result<Directions, String> {
    let directions = parse_direction_list(s)?;
    directions.set().map_err(|e| e.to_string())?;
    Ok(directions)
}

fn parse_direction_list(s: &str) -> Result<Directions, String> {
    if let Ok(n) = s.trim().parse::<usize>() {
        return Ok(Directions::Count(n));
    }
    let list = s
        .split(';')
        .map(|d| {
            let v: Vec<i64> = d
                .split(',')
                .map(|c| c.trim().parse::<i64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("`{d}` is not an integer vector x,y,z"))?;
            <[i64; 3]>::try_from(v).map_err(|_| format!("`{d}` is not an integer vector x,y,z"))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Directions::Given(list))
}

/// Options of --method depth-layers.
#[derive(Args, Clone)]
pub struct DepthArgs {
    /// Depth-layer view directions: a count N takes the first N of 16 (3 are the axes,
    /// Karabassi's six z-buffers; more add face and body diagonals, deciding more voxels of
    /// closed meshes but, on open meshes, meeting holes more often); or your own, `x,y,z`
    /// integer vectors separated by `;` (each with a component of 1 or -1, none parallel),
    /// e.g. `0,0,1;1,1,0;2,1,1`.
    #[arg(long, default_value_t = SolidRequest::default().directions, value_parser = parse_directions, allow_hyphen_values = true)]
    pub directions: Directions,
    /// double: two layers per side and a stencil count of crossings (Passalis et al.);
    /// single: one layer per side (Karabassi et al.), which fills concavities no direction
    /// sees.
    #[arg(long, default_value_t = SolidRequest::default().layers, value_parser = parse_layers)]
    pub layers: Layers,
    /// Which voxels double layers leave unclassified: no-direction (only those no direction
    /// decides: at most four crossings on one of its rays decide, and exact crossings make
    /// deciding directions agree) or paper (Passalis et al.'s rule: those on a ray of any
    /// direction counting more than four crossings).
    #[arg(long, default_value_t = SolidRequest::default().unclassified, value_parser = parse_unclassified)]
    pub unclassified: Unclassified,
}
