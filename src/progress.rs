//! Progress and cancellation without unwinding: an observer hears how much work is done and
//! answers whether to go on; the algorithms skip their remaining work once told to stop and
//! return `Error::Cancelled`.

use crate::error::{Error, Result};
use serde::Serialize;
use std::ops::ControlFlow;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Watches a job: the CLI draws progress bars, the C API calls the caller's callback.
pub trait Observer: Sync {
    /// A stage of the work begins with `total` items (an estimate for some methods).
    fn stage(&self, _name: &str, _total: u64) {}
    /// `n` more items of the current stage are done; `Break` asks the work to stop.
    fn advance(&self, n: u64) -> ControlFlow<()>;
}

/// Watches nothing and never stops the work.
pub struct Unobserved;

impl Observer for Unobserved {
    fn advance(&self, _n: u64) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// An observer adaptor from a plain function (tests, simple callers).
pub struct Counting<F: Fn(u64) -> ControlFlow<()> + Sync>(pub F);

impl<F: Fn(u64) -> ControlFlow<()> + Sync> Observer for Counting<F> {
    fn advance(&self, n: u64) -> ControlFlow<()> {
        (self.0)(n)
    }
}

/// Where a run's time went: one stage, its wall-clock seconds and the threads busy in it on
/// average (CPU seconds of the whole process over wall-clock seconds).
#[derive(Clone, Debug, Serialize)]
pub struct StageTime {
    pub stage: String,
    pub seconds: f64,
    pub threads_busy: f64,
}

impl StageTime {
    /// The stage `name` between two moments, each with the process's CPU seconds then.
    fn between(
        name: &str,
        (start, cpu): (Instant, f64),
        (end, cpu_end): (Instant, f64),
    ) -> StageTime {
        StageTime::of(name, end.duration_since(start).as_secs_f64(), cpu_end - cpu)
    }

    /// The stage `name` of `seconds` in which the process used `cpu` CPU seconds.
    fn of(name: &str, seconds: f64, cpu: f64) -> StageTime {
        // The kernel brings other running threads' CPU time up to date only at its ticks, so a
        // stage shorter than a tick can seem to use more threads than the process may run on.
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
        StageTime {
            stage: name.to_string(),
            seconds,
            threads_busy: if seconds > 0.0 {
                (cpu / seconds).clamp(0.0, cores)
            } else {
                0.0
            },
        }
    }

    /// The stage `name` from `start` (the moment and the CPU seconds then, `StageTime::now`)
    /// until now.
    pub fn since(name: &str, start: (Instant, f64)) -> StageTime {
        StageTime::between(name, start, StageTime::now())
    }

    /// This moment and the process's CPU seconds.
    pub fn now() -> (Instant, f64) {
        (Instant::now(), cpu_seconds())
    }
}

/// One stage's time summed over several spans (a write encodes and writes grid by grid).
pub struct StageClock {
    name: &'static str,
    seconds: f64,
    cpu: f64,
}

impl StageClock {
    pub fn new(name: &'static str) -> StageClock {
        StageClock {
            name,
            seconds: 0.0,
            cpu: 0.0,
        }
    }

    /// Runs `work`, adding its time to the stage's.
    pub fn time<T>(&mut self, work: impl FnOnce() -> T) -> T {
        let (start, cpu) = StageTime::now();
        let done = work();
        let (end, cpu_end) = StageTime::now();
        self.seconds += end.duration_since(start).as_secs_f64();
        self.cpu += cpu_end - cpu;
        done
    }

    /// The time summed so far.
    pub fn stage(&self) -> StageTime {
        StageTime::of(self.name, self.seconds, self.cpu)
    }
}

/// CPU time this process has used so far, every thread, in seconds (the scheduler's own
/// nanosecond count rather than getrusage's tick-sampled split into user and system).
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given.
    if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) } != 0 {
        return 0.0;
    }
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// The algorithms' side: count finished items and learn whether to stop.
pub struct Progress<'a> {
    observer: &'a dyn Observer,
    stopped: AtomicBool,
    /// Each stage begun: its name, when, and the process's CPU seconds then.
    begun: Mutex<Vec<(String, Instant, f64)>>,
}

impl<'a> Progress<'a> {
    pub fn new(observer: &'a dyn Observer) -> Self {
        Progress {
            observer,
            stopped: AtomicBool::new(false),
            begun: Mutex::new(Vec::new()),
        }
    }

    /// Progress nobody watches.
    pub fn none() -> Progress<'static> {
        Progress::new(&Unobserved)
    }

    /// Starts a stage of `total` items.
    pub fn stage(&self, name: &str, total: u64) {
        let (at, cpu) = StageTime::now();
        self.begun
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((name.to_string(), at, cpu));
        self.observer.stage(name, total);
    }

    /// The time of every stage begun, each until the next began, the last until now.
    pub fn profile(&self) -> Vec<StageTime> {
        let begun = self.begun.lock().unwrap_or_else(|e| e.into_inner());
        let ends = begun
            .iter()
            .skip(1)
            .map(|(_, at, cpu)| (*at, *cpu))
            .chain([StageTime::now()]);
        begun
            .iter()
            .zip(ends)
            .map(|((name, at, cpu), end)| StageTime::between(name, (*at, *cpu), end))
            .collect()
    }

    /// `n` more items are done; remembers a request to stop.
    pub fn advance(&self, n: u64) {
        if !self.stopped() && self.observer.advance(n).is_break() {
            self.stopped.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the observer asked to stop: the work should skip what is left.
    pub fn stopped(&self) -> bool {
        self.stopped.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once the observer asked to stop: what was built is incomplete.
    pub fn check(&self) -> Result<()> {
        if self.stopped() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }
}
