//! Several mesh files in one call: frame patterns (`f_####.obj`, `#` standing for the
//! zero-padded frame number as Houdini and Blender write it) over a frame range, one grid
//! placement shared by every file, fitted to the union of their bounding boxes, so that the
//! frames of an animation share one voxel size and one origin and the volume does not
//! jitter from frame to frame; and the scheduler that runs the files' jobs at once as far as
//! the memory limit allows (each job's planned estimate held until it ends).

use crate::error::{Error, Result};
use crate::mesh::{Aabb, GridFit, Mesh, UpAxis, fit_transform};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};

/// Memory held by the jobs of a batch that run now, against the limit.
pub struct MemoryGate {
    held: Mutex<u64>,
    freed: Condvar,
    limit: u64,
}

impl MemoryGate {
    /// A gate at `limit` bytes (none: the memory available).
    pub fn new(limit: Option<u64>) -> MemoryGate {
        MemoryGate {
            held: Mutex::new(0),
            freed: Condvar::new(),
            limit: limit
                .or_else(crate::system::available_memory_bytes)
                .unwrap_or(u64::MAX),
        }
    }

    /// Runs `work` once `bytes` fit beside what runs (or nothing runs: planning has already
    /// refused a job that cannot fit alone).
    pub fn admit<T>(&self, bytes: u64, work: impl FnOnce() -> T) -> T {
        {
            let mut held = self.held.lock().unwrap_or_else(|e| e.into_inner());
            while *held > 0 && held.saturating_add(bytes) > self.limit {
                held = self.freed.wait(held).unwrap_or_else(|e| e.into_inner());
            }
            *held += bytes;
        }
        let result = work();
        *self.held.lock().unwrap_or_else(|e| e.into_inner()) -= bytes;
        self.freed.notify_all();
        result
    }
}

/// Runs `work(k)` for every `k` below `count` on up to `workers` threads, each taking the
/// next item when it is free; `done(k, &result)` hears of each as it ends. The results come
/// back in the order of `k`.
pub fn run_pool<T: Send>(
    count: usize,
    workers: usize,
    work: impl Fn(usize) -> T + Sync,
    done: impl Fn(usize, &T) + Sync,
) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<T>>> = Mutex::new((0..count).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, count.max(1)) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= count {
                        break;
                    }
                    let result = work(k);
                    done(k, &result);
                    results.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(result);
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .flatten()
        .collect()
}

/// A file name with one run of `#`: the frame number, zero-padded to the run's length.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    before: String,
    width: usize,
    after: String,
}

impl FramePattern {
    /// The pattern in `path`, or `None` when it has no `#`; more than one run is refused.
    pub fn of(path: &Path) -> Result<Option<FramePattern>> {
        let text = path.to_string_lossy();
        let Some(start) = text.find('#') else {
            return Ok(None);
        };
        let width = text[start..].chars().take_while(|&c| c == '#').count();
        let after = &text[start + width..];
        if after.contains('#') {
            return Err(Error::InvalidArgument(format!(
                "`{text}` has more than one run of `#`; the frame number takes one"
            )));
        }
        Ok(Some(FramePattern {
            before: text[..start].to_string(),
            width,
            after: after.to_string(),
        }))
    }

    /// The file of `frame`: `f_####.obj` and 7 give `f_0007.obj` (wider numbers are kept
    /// whole).
    pub fn path(&self, frame: u32) -> PathBuf {
        PathBuf::from(format!(
            "{}{frame:0width$}{}",
            self.before,
            self.after,
            width = self.width
        ))
    }
}

/// Frames `first..=last` every `step`: `1-240`, `1-240:2` or one frame, `12`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    pub first: u32,
    pub last: u32,
    pub step: u32,
}

impl FrameRange {
    pub fn frames(&self) -> impl Iterator<Item = u32> {
        (self.first..=self.last).step_by(self.step as usize)
    }
}

impl FromStr for FrameRange {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || format!("expected frames as FIRST-LAST, FIRST-LAST:STEP or FRAME, got `{s}`");
        let number = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
        let (range, step) = match s.split_once(':') {
            Some((r, step)) => (r, number(step)?),
            None => (s, 1),
        };
        let (first, last) = match range.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => (number(range)?, number(range)?),
        };
        if step == 0 || last < first {
            return Err(format!(
                "frames `{s}`: the last frame must not come before the first, and the step must be at least 1"
            ));
        }
        Ok(FrameRange { first, last, step })
    }
}

/// The placement every file shares: `fit` (a resolution along the longest axis of the
/// union, or a voxel size) on the union of the files' bounding boxes, the lower corner on a
/// voxel's lower face as for one file. Files that cannot be read are left out here (they
/// fail again, and are reported, when their job runs); an error only when none can be read.
/// A fit within bounds is shared as it is.
pub fn shared_placement(files: &[PathBuf], fit: GridFit, up: UpAxis) -> Result<GridFit> {
    if let GridFit::Within(..) = fit {
        return Ok(fit);
    }
    let boxes: Vec<Result<Aabb>> = files
        .par_iter()
        .map(|f| Mesh::load(f).map(|m| m.with_up_axis(up).bbox()))
        .collect();
    let mut union: Option<Aabb> = None;
    let mut first_error = None;
    for b in boxes {
        match (b, &mut union) {
            (Ok(b), None) => union = Some(b),
            (Ok(b), Some(u)) => {
                u.min = u.min.min(b.min);
                u.max = u.max.max(b.max);
            }
            (Err(e), _) => {
                first_error.get_or_insert(e);
            }
        }
    }
    match (union, first_error) {
        (Some(union), _) => Ok(GridFit::Placed(fit_transform(&union, fit)?)),
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::InvalidArgument("no input files".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pool_runs_every_item_once_and_keeps_their_order() {
        let heard = AtomicUsize::new(0);
        let out = run_pool(
            50,
            4,
            |k| k * k,
            |_, _| {
                heard.fetch_add(1, Ordering::Relaxed);
            },
        );
        assert_eq!(out, (0..50).map(|k| k * k).collect::<Vec<_>>());
        assert_eq!(heard.into_inner(), 50);
    }

    #[test]
    fn the_gate_holds_jobs_that_do_not_fit_beside_those_running() {
        let gate = MemoryGate::new(Some(10));
        let running = AtomicUsize::new(0);
        let most = AtomicUsize::new(0);
        run_pool(
            8,
            4,
            |_| {
                gate.admit(6, || {
                    let now = running.fetch_add(1, Ordering::SeqCst) + 1;
                    most.fetch_max(now, Ordering::SeqCst);
                    std::thread::sleep(std::time::Duration::from_millis(5));
                    running.fetch_sub(1, Ordering::SeqCst);
                })
            },
            |_, _| {},
        );
        assert_eq!(
            most.into_inner(),
            1,
            "two jobs of 6 ran under a limit of 10"
        );
    }

    #[test]
    fn patterns_pad_the_frame_number() {
        let p = FramePattern::of(Path::new("out/f_####.vdb"))
            .unwrap()
            .unwrap();
        assert_eq!(p.path(7), PathBuf::from("out/f_0007.vdb"));
        assert_eq!(p.path(123456), PathBuf::from("out/f_123456.vdb"));
        assert_eq!(FramePattern::of(Path::new("plain.obj")).unwrap(), None);
        assert!(FramePattern::of(Path::new("a_##_b_##.obj")).is_err());
    }

    #[test]
    fn ranges_parse_with_steps() {
        let r: FrameRange = "1-9:4".parse().unwrap();
        assert_eq!(r.frames().collect::<Vec<_>>(), [1, 5, 9]);
        let one: FrameRange = "12".parse().unwrap();
        assert_eq!(one.frames().collect::<Vec<_>>(), [12]);
        for bad in ["", "5-1", "1-4:0", "a-b", "-3", "1-2-3"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad}");
        }
    }
}
