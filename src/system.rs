//! What the machine offers: available and peak memory (Linux `/proc`), and the check that
//! refuses work that cannot fit before anything is allocated.

use crate::error::{Error, Result};

fn proc_kib(file: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// Memory the kernel says is available to new allocations, in bytes.
pub fn available_memory_bytes() -> Option<u64> {
    proc_kib("/proc/meminfo", "MemAvailable:").map(|k| k * 1024)
}

/// Peak resident memory of this process so far, in bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    proc_kib("/proc/self/status", "VmHWM:").map(|k| k * 1024)
}

/// Refuses `estimated` bytes when more than `limit` (or the available memory) allows.
pub fn check_fits(estimated: u64, limit: Option<u64>, detail: &str) -> Result<()> {
    let available = limit.or_else(available_memory_bytes).unwrap_or(u64::MAX);
    if estimated > available {
        return Err(Error::TooLarge {
            estimated_mib: estimated >> 20,
            available_mib: available >> 20,
            detail: detail.to_string(),
        });
    }
    Ok(())
}
