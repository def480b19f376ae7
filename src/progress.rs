//! Progress and cancellation without unwinding: an observer hears how much work is done and
//! answers whether to go on; the algorithms skip their remaining work once told to stop and
//! return `Error::Cancelled`.

use crate::error::{Error, Result};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};

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

/// The algorithms' side: count finished items and learn whether to stop.
pub struct Progress<'a> {
    observer: &'a dyn Observer,
    stopped: AtomicBool,
}

impl<'a> Progress<'a> {
    pub fn new(observer: &'a dyn Observer) -> Self {
        Progress {
            observer,
            stopped: AtomicBool::new(false),
        }
    }

    /// Progress nobody watches.
    pub fn none() -> Progress<'static> {
        Progress::new(&Unobserved)
    }

    /// Starts a stage of `total` items.
    pub fn stage(&self, name: &str, total: u64) {
        self.observer.stage(name, total);
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
