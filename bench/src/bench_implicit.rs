//! `voxelkit bench implicit`: the paper's Fig. 5 — sin(nθ) sin(mφ) - r by interval octree at
//! growing resolutions, as the paper computes it (θ in [0, 2π), the substitution
//! [G]² - r² = 0, so every lobe of the surface), with the time ratio per doubling (the paper: close to 4, not 8) — and
//! the naive reference in the same process: F at every voxel corner, voxels with a sign change.
//! Then the paper's Fig. 7 parts (the gear, the crank) at 512^3 beside its times.

use crate::bench::best_of;
use crate::json::Json;
use clap::Args;
use glam::DVec3;
use voxelkit::implicit::examples::example;
use voxelkit::implicit::{Coordinates, Formula};
use voxelkit::voxelize::interval_octree::{OctreeOptions, voxelize_implicit};
use voxelkit::voxelize::sign_change::voxelize_sign_change;
use voxelkit::{Error, Result};

#[derive(Args)]
pub struct ImplicitBenchArgs {
    /// (n, m) pairs for sin(n θ) sin(m φ) - r, as `n:m` separated by commas.
    #[arg(long, value_delimiter = ',', default_value = "3:4,5:6,9:10,9:18")]
    nm: Vec<String>,
    #[arg(long, value_delimiter = ',', default_value = "128,256,512,1024")]
    resolutions: Vec<u32>,
    /// Resolutions at which the naive corner-sign method also runs.
    #[arg(long, value_delimiter = ',', default_value = "256,512")]
    naive: Vec<u32>,
    /// Also negative r (both signs).
    #[arg(long)]
    negative_r: bool,
    /// r = G as typed (G >= 0: half the lobes) instead of the paper's [G]^2 - r^2 = 0.
    #[arg(long)]
    typed: bool,
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Runs per measurement; the fastest is reported.
    #[arg(long, default_value_t = 1)]
    repeat: usize,
    /// Named examples timed as the paper's Fig. 7 (none: skip them).
    #[arg(long, value_delimiter = ',', default_value = "gear,crankshaft")]
    examples: Vec<String>,
    /// The resolution of the Fig. 7 rows (the paper's: 512).
    #[arg(long, default_value_t = 512)]
    example_resolution: u32,
}

fn parse_nm(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::InvalidArgument(format!("--nm `{s}`: expected n:m"));
    let (n, m) = s.split_once(':').ok_or_else(bad)?;
    Ok((
        n.trim().parse().map_err(|_| bad())?,
        m.trim().parse().map_err(|_| bad())?,
    ))
}

pub fn run(args: &ImplicitBenchArgs, json: bool) -> Result<()> {
    let pool = crate::bench::thread_pool(args.threads)?;
    let (min, max) = (DVec3::splat(-1.0), DVec3::ONE);
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:>2} {:>2} {:>5} {:>9} {:>7} {:>10} {:>12} {:>9} {:>9} {:>10} {:>8} {:>8}",
            "n",
            "m",
            "res",
            "octree s",
            "x prev",
            "voxels",
            "cells",
            "grid MiB",
            "naive s",
            "naive/oct",
            "missed",
            "extra"
        );
    }
    for nm in &args.nm {
        let (n, m) = parse_nm(nm)?;
        let text = format!("sin({n}*theta)*sin({m}*phi) - r");
        let formula = Formula {
            squared: !args.typed,
            ..Formula::parse(&text, Coordinates::Spherical)?
        };
        let mut previous: Option<f64> = None;
        for &res in &args.resolutions {
            let options = OctreeOptions {
                resolution: res,
                both_signs: args.negative_r,
                levels: false,
                ..Default::default()
            };
            let (seconds, out) = pool.install(|| {
                best_of(args.repeat, || {
                    voxelize_implicit(
                        &formula,
                        min,
                        max,
                        &options,
                        &voxelkit::progress::Progress::none(),
                    )
                })
            })?;
            let growth = previous.map(|p| seconds / p);
            previous = Some(seconds);
            // Leaves with a normal channel: mask, origin and 512 normals.
            let grid_mib = out.surface.leaf_count() as f64 * (64.0 + 24.0 + 512.0 * 12.0)
                / (1u64 << 20) as f64;
            let naive = if args.naive.contains(&res) {
                let (naive_s, grid) = pool.install(|| {
                    best_of(args.repeat, || {
                        Ok(voxelize_sign_change(
                            &formula,
                            min,
                            max,
                            res,
                            options.both_signs,
                        ))
                    })
                })?;
                let missed = out.surface.voxels().filter(|&c| !grid.contains(c)).count();
                let extra = grid.voxels().filter(|&c| !out.surface.contains(c)).count();
                Some((naive_s, missed, extra))
            } else {
                None
            };
            if json {
                let mut j = Json::default()
                    .int("n", n as u64)
                    .int("m", m as u64)
                    .int("resolution", res as u64)
                    .num("octree_seconds", seconds)
                    .int("voxels", out.stats.voxels)
                    .int("cells_tested", out.stats.cells_tested)
                    .num("grid_mib", grid_mib);
                if let Some(g) = growth {
                    j = j.num("growth", g);
                }
                if let Some((s, missed, extra)) = naive {
                    j = j
                        .num("naive_seconds", s)
                        .int("naive_missed", missed as u64)
                        .int("naive_extra", extra as u64);
                }
                rows.push(j);
            } else {
                let (ns, ratio, missed, extra) = match naive {
                    Some((s, missed, extra)) => (
                        format!("{s:.3}"),
                        format!("{:.1}x", s / seconds),
                        missed.to_string(),
                        extra.to_string(),
                    ),
                    None => ("-".into(), "-".into(), "-".into(), "-".into()),
                };
                println!(
                    "{n:>2} {m:>2} {res:>5} {seconds:>9.3} {:>7} {:>10} {:>12} {grid_mib:>9.1} {ns:>9} {ratio:>10} {missed:>8} {extra:>8}",
                    growth.map_or("-".into(), |g| format!("{g:.2}")),
                    out.stats.voxels,
                    out.stats.cells_tested,
                );
            }
        }
    }
    let examples = figure_seven(args, &pool, json)?;
    if json {
        println!(
            "{}",
            Json::default()
                .arr("runs", rows)
                .arr("examples", examples)
                .render()
        );
    }
    Ok(())
}

/// The paper's Fig. 7 parts by interval octree (with normals, as the paper times them), one
/// row each, beside the paper's seconds.
fn figure_seven(
    args: &ImplicitBenchArgs,
    pool: &rayon::ThreadPool,
    json: bool,
) -> Result<Vec<Json>> {
    let mut rows = Vec::new();
    let res = args.example_resolution;
    if !json && !args.examples.is_empty() {
        println!(
            "\nThe paper's Fig. 7 at {res}^3, {} thread(s)\n{:<12} {:>10} {:>10} {:>12} {:>14}",
            args.threads, "example", "octree s", "voxels", "cells", "paper's s"
        );
    }
    for name in args.examples.iter().filter(|n| !n.is_empty()) {
        let e = example(name)?;
        let formula = Formula::parse(e.formula, e.coordinates)?;
        let options = OctreeOptions {
            resolution: res,
            ..Default::default()
        };
        let (seconds, out) = pool.install(|| {
            best_of(args.repeat, || {
                voxelize_implicit(
                    &formula,
                    DVec3::splat(-1.0),
                    DVec3::ONE,
                    &options,
                    &voxelkit::progress::Progress::none(),
                )
            })
        })?;
        let paper = e
            .paper_seconds_at_512
            .filter(|_| res == 512)
            .map_or("-".to_string(), |s| format!("{s}"));
        if json {
            rows.push(
                Json::default()
                    .str("example", e.name)
                    .int("resolution", res as u64)
                    .num("octree_seconds", seconds)
                    .int("voxels", out.stats.voxels)
                    .int("cells_tested", out.stats.cells_tested),
            );
        } else {
            println!(
                "{:<12} {seconds:>10.3} {:>10} {:>12} {paper:>14}",
                e.name, out.stats.voxels, out.stats.cells_tested
            );
        }
    }
    Ok(rows)
}
