//! Where the mesh commands write, and running several inputs in one call: a list of files
//! into `--out-dir`, or a frame pattern over `--frames`. Files run at once as far as the
//! memory limit allows (each job's planned estimate is held until it ends); one failing
//! file is reported and the others are still written, and the exit status says so at the end.

use crate::run::{Global, finish_job, plan_job, run_and_report, with_flags};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxelkit::mesh::GridFit;
use voxelkit::pipeline::batch::{FramePattern, FrameRange, MemoryGate, run_pool, shared_placement};
use voxelkit::pipeline::{Job, MeshSource, Outcome, Task};
use voxelkit::progress::Unobserved;
use voxelkit::{Error, Result};

/// The output formats `--format` names for `--out-dir`.
#[derive(clap::ValueEnum, Clone, Copy)]
pub enum OutputFormat {
    Vdb,
    Nvdb,
    Binvox,
    Vox,
}

impl OutputFormat {
    fn extension(self) -> &'static str {
        match self {
            OutputFormat::Vdb => "vdb",
            OutputFormat::Nvdb => "nvdb",
            OutputFormat::Binvox => "binvox",
            OutputFormat::Vox => "vox",
        }
    }
}

/// Where the results go, for one input or many.
#[derive(Args)]
pub struct OutputArgs {
    /// Output file: .vdb, .nvdb (NanoVDB), .binvox or .vox, chosen by extension (`-`: a .vdb on standard
    /// output). Under --frames, a pattern with `#` for the frame number
    /// (`out/f_####.vdb`).
    #[arg(short, long, required_unless_present = "out_dir")]
    output: Option<PathBuf>,
    /// Write each input's result into this folder (created when missing), named after the
    /// input: `bunny.obj` gives `bunny.vdb` (or --format).
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// The format written into --out-dir.
    #[arg(long, value_enum, default_value = "vdb", requires = "out_dir")]
    format: OutputFormat,
    /// Frames of an input pattern with `#` for the zero-padded frame number
    /// (`f_####.obj`): FIRST-LAST, FIRST-LAST:STEP or one FRAME. Every frame shares one
    /// voxel size and origin, fitted to the union of all frames' bounding boxes (with
    /// --resolution: that many voxels along the union's longest axis), so that the
    /// animated volume does not jitter.
    #[arg(long, value_name = "RANGE")]
    frames: Option<FrameRange>,
    /// Give several inputs one grid, fitted to the union of their bounding boxes, as
    /// --frames does (otherwise each input is fitted on its own).
    #[arg(long)]
    shared_grid: bool,
    /// Inputs run at once, at most [default: the cores; fewer when the memory limit
    /// cannot hold them all].
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
}

/// Runs `task` on each input (and frame), writing where `out` says.
pub fn run(
    inputs: &[PathBuf],
    out: &OutputArgs,
    fit: GridFit,
    global: &Global,
    task: impl Fn(MeshSource) -> Result<Task> + Sync,
) -> Result<()> {
    let pairs = pairs(inputs, out)?;
    // The folders of --out-dir and of an output pattern are made as needed.
    if out.out_dir.is_some() || out.frames.is_some() {
        for (_, output) in &pairs {
            if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
            }
        }
    }
    if let ([(input, output)], None, false) = (&pairs[..], out.frames, out.shared_grid) {
        let job = Job::new(task(MeshSource::File(input.clone()))?, fit);
        return run_and_report(job, output, global);
    }
    if global.mesh_out.is_some() {
        return Err(Error::InvalidArgument(
            "--mesh-out names one mesh file: it takes one input, not a batch".into(),
        ));
    }
    let fit = if out.frames.is_some() || out.shared_grid {
        let files: Vec<PathBuf> = pairs.iter().map(|(i, _)| i.clone()).collect();
        shared_placement(&files, fit, global.up_axis)?
    } else {
        fit
    };
    run_all(&pairs, out.jobs, fit, global, &task)
}

/// The (input, output) of every file of the call, refused before any work when they
/// cannot be told apart.
fn pairs(inputs: &[PathBuf], out: &OutputArgs) -> Result<Vec<(PathBuf, PathBuf)>> {
    let named = |input: &Path| -> Result<PathBuf> {
        match (&out.out_dir, &out.output) {
            (Some(dir), _) => {
                let stem = input.file_stem().ok_or_else(|| {
                    Error::InvalidArgument(format!("`{}` names no file", input.display()))
                })?;
                Ok(dir.join(stem).with_extension(out.format.extension()))
            }
            (None, Some(o)) => Ok(o.clone()),
            (None, None) => unreachable!("clap requires -o or --out-dir"),
        }
    };
    let pairs = match out.frames {
        Some(range) => {
            let [input] = inputs else {
                return Err(Error::InvalidArgument(
                    "--frames takes one input pattern (`f_####.obj`)".into(),
                ));
            };
            let pattern = FramePattern::of(input)?.ok_or_else(|| {
                Error::InvalidArgument(format!(
                    "--frames needs `#` in the input for the frame number, as in `f_####.obj`; got `{}`",
                    input.display()
                ))
            })?;
            let output_pattern = match &out.output {
                Some(o) if out.out_dir.is_none() => Some(FramePattern::of(o)?.ok_or_else(|| {
                    Error::InvalidArgument(format!(
                        "with --frames, -o needs `#` for the frame number, as in `out/f_####.vdb`; got `{}`",
                        o.display()
                    ))
                })?),
                _ => None,
            };
            range
                .frames()
                .map(|f| {
                    let input = pattern.path(f);
                    let output = match &output_pattern {
                        Some(p) => p.path(f),
                        None => named(&input)?,
                    };
                    Ok((input, output))
                })
                .collect::<Result<Vec<_>>>()?
        }
        None => {
            if let Some(p) = inputs.iter().find(|p| p.to_string_lossy().contains('#')) {
                return Err(Error::InvalidArgument(format!(
                    "`{}` is a frame pattern: give --frames FIRST-LAST",
                    p.display()
                )));
            }
            if inputs.len() > 1 && out.out_dir.is_none() {
                return Err(Error::InvalidArgument(format!(
                    "-o names one file, but {} inputs were given: use --out-dir DIR",
                    inputs.len()
                )));
            }
            inputs
                .iter()
                .map(|i| Ok((i.clone(), named(i)?)))
                .collect::<Result<Vec<_>>>()?
        }
    };
    let mut outputs: Vec<&PathBuf> = pairs.iter().map(|(_, o)| o).collect();
    outputs.sort();
    if let Some(w) = outputs.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::InvalidArgument(format!(
            "two inputs would both be written to {}; rename one or run them apart",
            w[0].display()
        )));
    }
    Ok(pairs)
}

/// One input's job: planned (its output checked against every input of the batch), run
/// once its memory fits, written.
fn run_one(
    (input, output): &(PathBuf, PathBuf),
    batch_inputs: &[&Path],
    fit: GridFit,
    global: &Global,
    gate: &MemoryGate,
    task: &(impl Fn(MeshSource) -> Result<Task> + Sync),
) -> Result<Outcome> {
    let start = Instant::now();
    let job = Job::new(task(MeshSource::File(input.clone()))?, fit);
    let planned = plan_job(job, Some(output), batch_inputs, global)?;
    let bytes = planned.plan().estimated_bytes;
    gate.admit(bytes, || {
        finish_job(planned, Some(output), &Unobserved, global, start)
    })
}

fn run_all(
    pairs: &[(PathBuf, PathBuf)],
    jobs: Option<usize>,
    fit: GridFit,
    global: &Global,
    task: &(impl Fn(MeshSource) -> Result<Task> + Sync),
) -> Result<()> {
    let start = Instant::now();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let workers = jobs.unwrap_or(cores).clamp(1, pairs.len());
    let gate = MemoryGate::new(global.limits().max_memory);
    let batch_inputs: Vec<&Path> = pairs.iter().map(|(i, _)| i.as_path()).collect();
    let bar = if global.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(pairs.len() as u64).with_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {elapsed_precise}")
                .expect("valid template")
                .progress_chars("=> "),
        )
    };
    bar.set_message("files");
    let results = run_pool(
        pairs.len(),
        workers,
        |k| run_one(&pairs[k], &batch_inputs, fit, global, &gate, task),
        |k, result| {
            let (input, output) = &pairs[k];
            if !global.json {
                bar.suspend(|| match result {
                    Ok(o) => println!(
                        "wrote {}: {} voxels, {:.2} s",
                        output.display(),
                        o.report.voxels,
                        o.report.seconds
                    ),
                    // Most errors name their file already.
                    Err(e) if e.to_string().contains(&*input.to_string_lossy()) => {
                        eprintln!("error: {}", with_flags(&e.to_string()))
                    }
                    Err(e) => {
                        eprintln!("error: {}: {}", input.display(), with_flags(&e.to_string()))
                    }
                });
            }
            bar.inc(1);
        },
    );
    bar.finish_and_clear();
    let failed = results.iter().filter(|r| r.is_err()).count();
    let seconds = start.elapsed().as_secs_f64();
    if global.json {
        let items: Vec<serde_json::Value> = pairs
            .iter()
            .zip(&results)
            .map(|((input, output), r)| match r {
                Ok(o) => serde_json::to_value(&o.report).expect("a report serializes"),
                Err(e) => serde_json::json!({
                    "input": input.display().to_string(),
                    "output": output.display().to_string(),
                    "error": e.to_string(),
                }),
            })
            .collect();
        let summary = serde_json::json!({
            "inputs": items,
            "written": pairs.len() - failed,
            "failed": failed,
            "grid": placement_json(fit),
            "seconds": seconds,
        });
        println!("{summary}");
    } else {
        let grid = match fit {
            GridFit::Placed(t) => format!(
                " on one grid (voxel size {:.6}, voxel (0,0,0) at {:.6},{:.6},{:.6})",
                t.voxel_size, t.origin.x, t.origin.y, t.origin.z
            ),
            _ => String::new(),
        };
        println!(
            "{} of {} inputs written{grid} in {seconds:.2} s ({workers} at a time at most)",
            pairs.len() - failed,
            pairs.len()
        );
    }
    if failed > 0 {
        return Err(Error::Batch {
            failed,
            total: pairs.len(),
        });
    }
    Ok(())
}

fn placement_json(fit: GridFit) -> serde_json::Value {
    match fit {
        GridFit::Placed(t) => serde_json::json!({
            "voxel_size": t.voxel_size,
            "origin": t.origin.to_array(),
        }),
        _ => serde_json::Value::Null,
    }
}
