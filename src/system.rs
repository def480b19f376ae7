//! What the machine offers: available and peak memory (Linux `/proc`), the check that
//! refuses work that cannot fit before anything is allocated, and how a process that runs
//! many jobs keeps the memory they free.

use crate::error::{Error, Result};

fn proc_kib(file: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// Memory this process may still allocate, in bytes: the least of what the kernel says is
/// available, what the process's cgroup (v2 or v1) still allows, and what its address-space
/// limit (`ulimit -v`) leaves.
pub fn available_memory_bytes() -> Option<u64> {
    let kernel = proc_kib("/proc/meminfo", "MemAvailable:").map(|k| k * 1024);
    [kernel, cgroup_headroom(), address_space_headroom()]
        .into_iter()
        .flatten()
        .min()
}

fn read_u64(path: &str) -> Option<u64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// The cgroup's limit minus its usage (no limit: `None`).
fn cgroup_headroom() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let (limit, usage) = if controllers.is_empty() {
            let dir = format!("/sys/fs/cgroup{path}");
            (
                read_u64(&format!("{dir}/memory.max")),
                read_u64(&format!("{dir}/memory.current")),
            )
        } else if controllers.split(',').any(|c| c == "memory") {
            let dir = format!("/sys/fs/cgroup/memory{path}");
            (
                read_u64(&format!("{dir}/memory.limit_in_bytes")),
                read_u64(&format!("{dir}/memory.usage_in_bytes")),
            )
        } else {
            continue;
        };
        // "max" (v2) does not parse; v1 reports no limit as a huge number.
        if let Some(limit) = limit.filter(|&l| l < 1 << 60) {
            return Some(limit.saturating_sub(usage.unwrap_or(0)));
        }
    }
    None
}

/// `RLIMIT_AS` minus the address space in use.
fn address_space_headroom() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0
        || limit.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let used = proc_kib("/proc/self/status", "VmSize:").map_or(0, |k| k * 1024);
    Some(limit.rlim_cur.saturating_sub(used))
}

/// Peak resident memory of this process so far, in bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    proc_kib("/proc/self/status", "VmHWM:").map(|k| k * 1024)
}

/// Peak resident memory of this process so far, in MiB (0 where unknown), as reports give it.
pub fn peak_memory_mib() -> f64 {
    peak_memory_bytes().unwrap_or(0) as f64 / (1 << 20) as f64
}

/// The limit a front end gives for the whole process (0: none), which every check without a
/// limit of its own (reading a file, drawing a picture) honours.
static PROCESS_LIMIT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Sets the process's limit in bytes (`--max-memory`); none: the memory available.
pub fn set_process_limit(limit: Option<u64>) {
    PROCESS_LIMIT.store(limit.unwrap_or(0), std::sync::atomic::Ordering::Relaxed);
}

fn process_limit() -> Option<u64> {
    Some(PROCESS_LIMIT.load(std::sync::atomic::Ordering::Relaxed)).filter(|&l| l > 0)
}

/// Refuses `estimated` bytes when more than `limit` (or the process's limit, or the
/// available memory) allows.
pub fn check_fits(estimated: u64, limit: Option<u64>, detail: &str) -> Result<()> {
    let available = limit
        .or_else(process_limit)
        .or_else(available_memory_bytes)
        .unwrap_or(u64::MAX);
    if estimated > available {
        return Err(Error::TooLarge {
            estimated_mib: estimated >> 20,
            available_mib: available >> 20,
            detail: detail.to_string(),
        });
    }
    Ok(())
}

/// Keeps the memory a job frees inside the process for the next job, in a process that runs
/// many (a distributed worker's bricks): glibc otherwise hands every block above a few
/// megabytes back to the kernel, and the next job faults in and zeroes fresh pages again (on
/// the virtual machine measured, two workers' bricks of igea at 6144 took 2.5 s instead of
/// 2.9 s). A worker's peak then rises a little above one job's, as freed blocks of one size
/// serve the next job's other sizes only in part (bricks of 1024: 86 -> 100 MiB; of 2048: 128
/// -> 170-181 MiB); blocks above 32 MiB (glibc's largest threshold) still go back.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        ONCE.call_once(|| {
            // SAFETY: mallopt changes glibc's thresholds under its own lock; the values are
            // within the ranges it accepts.
            unsafe {
                libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
                libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
            }
        });
    }
}
