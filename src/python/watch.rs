//! Running a job from Python: the work runs on its own thread with the GIL released, while
//! the calling thread wakes every few milliseconds to let Python handle signals (Ctrl-C) and
//! to call the caller's progress function; either one raising cancels the work.

use crate::error::Error;
use crate::pipeline::{Job, Outcome};
use crate::progress::Observer;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::ops::ControlFlow;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// How often the calling thread looks at signals and reports progress.
const POLL: Duration = Duration::from_millis(20);

/// The worker thread's stack: as large as a main thread's, for the deepest recursions
/// (octrees, CSG trees).
const WORKER_STACK: usize = 64 << 20;

/// What the work has done so far, shared between the worker and the calling thread.
#[derive(Default)]
struct Watch {
    stage: Mutex<(String, u64)>,
    done: AtomicU64,
    cancelled: AtomicBool,
}

impl Observer for Watch {
    fn stage(&self, name: &str, total: u64) {
        *self.stage.lock().unwrap_or_else(|e| e.into_inner()) = (name.to_string(), total);
        self.done.store(0, Ordering::Relaxed);
    }

    fn advance(&self, n: u64) -> ControlFlow<()> {
        self.done.fetch_add(n, Ordering::Relaxed);
        if self.cancelled.load(Ordering::Relaxed) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

impl Watch {
    /// Lets Python run its signal handlers, then tells `progress` where the work stands.
    fn report(&self, py: Python<'_>, progress: Option<&Py<PyAny>>, finished: bool) -> PyResult<()> {
        py.check_signals()?;
        if let Some(callback) = progress {
            let (stage, total) = self.stage.lock().unwrap_or_else(|e| e.into_inner()).clone();
            // Nothing to tell before the first stage begins.
            if stage.is_empty() {
                return Ok(());
            }
            let done = if finished {
                total
            } else {
                self.done.load(Ordering::Relaxed).min(total)
            };
            callback.call1(py, (stage, done, total))?;
        }
        Ok(())
    }
}

/// Runs `job` without the GIL; a signal's exception (KeyboardInterrupt) or the progress
/// function's exception cancels it and is raised in its place.
pub fn run_job(py: Python<'_>, job: Job, progress: Option<Py<PyAny>>) -> PyResult<Outcome> {
    let watch = Watch::default();
    let mut raised: Option<PyErr> = None;
    let result = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = std::thread::Builder::new()
                .name("voxelkit".into())
                .stack_size(WORKER_STACK)
                .spawn_scoped(scope, || job.run(&watch))
                .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
            while !worker.is_finished() {
                std::thread::sleep(POLL);
                if raised.is_none()
                    && let Err(e) = Python::attach(|py| watch.report(py, progress.as_ref(), false))
                {
                    raised = Some(e);
                    watch.cancelled.store(true, Ordering::Relaxed);
                }
            }
            worker
                .join()
                .map_err(|_| PyRuntimeError::new_err("voxelkit: internal error (a panic)"))
        })
    });
    let outcome = match (result?, raised) {
        (_, Some(e)) => return Err(e),
        (Err(Error::Cancelled), None) => return Err(PyRuntimeError::new_err("cancelled")),
        (Err(e), None) => return Err(super::to_py_err(e)),
        (Ok(outcome), None) => outcome,
    };
    watch.report(py, progress.as_ref(), true)?;
    Ok(outcome)
}
