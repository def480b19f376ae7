//! Running a job from the command line: the output checked before any work, progress bars
//! as the observer, the outcome written, and the report printed (summary or `--json`).

use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write as _;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;
use voxelkit::io::vdb::{WriteOptions, check_voxel_size};
use voxelkit::pipeline::request::{LimitsRequest, ToMeshRequest};
use voxelkit::pipeline::to_mesh::{check_adaptivity, check_mesh_output};
use voxelkit::pipeline::{Job, Limits, Outcome, PlannedJob, check_output_path};
use voxelkit::progress::Observer;
use voxelkit::{Error, Result};

/// What every command shares: threads, memory limit, output style.
#[derive(Clone)]
pub struct Global {
    pub limits: LimitsRequest,
    pub up_axis: voxelkit::mesh::UpAxis,
    pub json: bool,
    pub write: WriteOptions,
    /// Draw a picture of each result beside its output (`--preview`).
    pub preview: bool,
    /// Also write the result's surface as a mesh (`--mesh-out`).
    pub mesh_out: Option<std::path::PathBuf>,
    /// How far merging the mesh's flat regions may move it, in voxels (`--adaptivity`).
    pub mesh_adaptivity: f64,
}

impl Global {
    pub fn limits(&self) -> Limits {
        self.limits.limits()
    }
}

/// A progress bar per stage on stderr (none under `--json` or off a terminal).
pub struct Bars {
    bar: Mutex<ProgressBar>,
    quiet: bool,
}

impl Bars {
    pub fn new(quiet: bool) -> Bars {
        Bars {
            bar: Mutex::new(ProgressBar::hidden()),
            quiet,
        }
    }

    pub fn finish(&self) {
        self.bar
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .finish_and_clear();
    }
}

impl Observer for Bars {
    fn stage(&self, name: &str, total: u64) {
        let mut bar = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        bar.finish_and_clear();
        if self.quiet {
            return;
        }
        // No eta: the first items of most methods are not typical of the rest.
        *bar = ProgressBar::new(total).with_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(name.to_string());
    }

    fn advance(&self, n: u64) -> ControlFlow<()> {
        self.bar.lock().unwrap_or_else(|e| e.into_inner()).inc(n);
        ControlFlow::Continue(())
    }
}

/// Plans `job` and refuses, before any work, an `output` that cannot be written or that is
/// one of its inputs or of `also_read` (the other inputs of a batch), links followed.
pub fn plan_job(
    job: Job,
    output: Option<&Path>,
    also_read: &[&Path],
    global: &Global,
) -> Result<PlannedJob> {
    let planned = Job {
        limits: global.limits(),
        up_axis: global.up_axis,
        ..job
    }
    .plan()?;
    if let Some(out) = output {
        let inputs = planned.input_files();
        let mut inputs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
        inputs.extend_from_slice(also_read);
        check_output_path(out, &inputs)?;
        check_voxel_size(out, planned.plan().transform.voxel_size)?;
        match &global.mesh_out {
            Some(mesh) => {
                inputs.push(out);
                check_mesh_output(mesh, &inputs)?;
                check_adaptivity(global.mesh_adaptivity)?;
            }
            None if global.mesh_adaptivity != ToMeshRequest::default().adaptivity => {
                return Err(Error::InvalidArgument(
                    "--adaptivity shapes the mesh of --mesh-out: give --mesh-out too".into(),
                ));
            }
            None => {}
        }
    }
    Ok(planned)
}

/// Runs a planned job under `observer`, writes the outcome to `output` and returns it with
/// the whole run, from `start`, timed.
pub fn finish_job(
    planned: PlannedJob,
    output: Option<&Path>,
    observer: &dyn Observer,
    global: &Global,
    start: Instant,
) -> Result<Outcome> {
    let inputs = planned.input_files();
    let inputs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let mut outcome = planned.run(observer)?;
    if let Some(out) = output {
        outcome.write(out, &inputs, &global.write)?;
        if global.preview {
            let limit = global.limits().max_memory;
            let png = crate::render::beside(&outcome.scene(), out, Default::default(), limit)?;
            outcome.report.preview = Some(png.display().to_string());
        }
        if let Some(mesh) = &global.mesh_out {
            outcome.write_mesh(mesh, global.mesh_adaptivity)?;
        }
    }
    outcome.report.finish(start);
    Ok(outcome)
}

/// Plans `job`, refuses an `output` that cannot be written (or is an input) before any
/// work, runs it with progress bars, writes the outcome to `output` and returns it with the
/// whole run timed.
pub fn run_job(job: Job, output: Option<&Path>, global: &Global) -> Result<Outcome> {
    let start = Instant::now();
    let planned = plan_job(job, output, &[], global)?;
    let bars = Bars::new(global.json);
    let result = finish_job(planned, output, &bars, global, start);
    bars.finish();
    result
}

/// The library names options as the requests do (option `voxel_size`); the command line
/// says its flags instead (`--voxel-size`).
pub fn with_flags(text: &str) -> String {
    const MARK: &str = "option `";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(MARK) {
        out.push_str(&rest[..at]);
        let after = &rest[at + MARK.len()..];
        let Some(end) = after.find('`') else {
            break;
        };
        out.push_str(&format!("--{}", after[..end].replace('_', "-")));
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    out
}

/// Runs `job`, the process's last, and prints its report: on stdout, or on stderr when the
/// `.vdb` goes to stdout.
pub fn run_and_report(job: Job, output: &Path, global: &Global) -> Result<()> {
    let outcome = run_job(job, Some(output), global)?;
    let text = if global.json {
        outcome.report.to_json()
    } else {
        with_flags(&outcome.report.summary())
    };
    if output == Path::new("-") {
        let _ = writeln!(std::io::stderr(), "{text}");
    } else {
        println!("{text}");
    }
    // SAFETY: the process ends after its one job, and no other grid is left to use.
    unsafe { outcome.end_with_process() };
    Ok(())
}
