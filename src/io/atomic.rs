//! Atomic file output: write beside the target under a short temporary name, check and
//! fsync it, then rename, so a failure (a full disk included) never leaves a partial file
//! where the user expects a result, nor replaces a good one with a damaged one.
//!
//! The target is resolved first: a symbolic link is followed (its target is replaced, the
//! link stays), and anything that exists but is not a regular file (a FIFO, a device, a
//! directory) is refused, since a rename would silently turn it into a regular file.
//! `check_output` also refuses an output that is one of the inputs.
//!
//! A process that installs `remove_temporaries_on_signals` (the CLI does) also removes the
//! temporary files of writes in progress when SIGINT, SIGTERM or SIGHUP ends it.

use crate::error::{Error, Result};
use crate::progress::StageClock;
use std::ffi::CString;
use std::io::ErrorKind;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, Ordering};

/// Runs `write(temp)`, checks and syncs `temp`, and renames it to the resolved `path`;
/// removes `temp` on any failure.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    write_atomic_timed(path, &mut StageClock::new("fsync"), write)
}

/// `write_atomic`, timing the sync on `fsync`.
pub fn write_atomic_timed(
    path: &Path,
    fsync: &mut StageClock,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    let target = resolve_target(path)?;
    let temp = Temporary::new(&target)?;
    write(&temp.path)?;
    fsync
        .time(|| sync_file(&temp.path))
        .map_err(|e| Error::io(path, e))?;
    std::fs::rename(&temp.path, &target).map_err(|e| Error::io(path, e))?;
    temp.disarm();
    // Make the rename itself durable; a file system that cannot sync a directory still
    // has the complete file under its final name.
    if let Ok(dir) = std::fs::File::open(parent_dir(&target)) {
        let _ = dir.sync_all();
    }
    Ok(())
}

/// Refuses `output` when it names the same file as one of `inputs` (through any path or
/// link), or a file that is not a regular one, before any work is done.
pub fn check_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::metadata(output) else {
        return resolve_target(output).map(|_| ());
    };
    use std::os::unix::fs::MetadataExt;
    for input in inputs {
        if let Ok(inp) = std::fs::metadata(input)
            && (inp.dev(), inp.ino()) == (out.dev(), out.ino())
        {
            return Err(refused(
                output,
                format!(
                    "is the input {}: writing it would replace the input (choose another output name)",
                    input.display()
                ),
            ));
        }
    }
    resolve_target(output).map(|_| ())
}

fn refused(path: &Path, message: String) -> Error {
    Error::io(path, std::io::Error::new(ErrorKind::InvalidInput, message))
}

/// The regular file a write to `path` replaces or creates: links followed, other kinds of
/// file refused.
fn resolve_target(path: &Path) -> Result<PathBuf> {
    // Follow links one step at a time: the last one may point to a file not made yet.
    let mut target = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&target).map_err(|e| Error::io(path, e))?;
                target = parent_dir(&target).join(link);
            }
            _ => break,
        }
    }
    if std::fs::symlink_metadata(&target).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(refused(path, "is a loop of symbolic links".into()));
    }
    match std::fs::metadata(&target) {
        Ok(m) if !m.is_file() => {
            use std::os::unix::fs::FileTypeExt;
            let t = m.file_type();
            let kind = if t.is_dir() {
                "a directory"
            } else if t.is_fifo() {
                "a FIFO"
            } else if t.is_char_device() || t.is_block_device() {
                "a device"
            } else if t.is_socket() {
                "a socket"
            } else {
                "not a regular file"
            };
            Err(refused(
                path,
                format!("is {kind}; voxelkit writes regular files only"),
            ))
        }
        _ => Ok(target),
    }
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// fsync: a full disk or an I/O error that the writer's buffered stream did not see
/// surfaces here, before the rename.
fn sync_file(path: &Path) -> std::io::Result<()> {
    std::fs::OpenOptions::new()
        .write(true)
        .open(path)?
        .sync_all()
}

/// A temporary file name beside the target, removed on drop unless disarmed.
struct Temporary {
    path: PathBuf,
    slot: Option<usize>,
    armed: bool,
}

impl Temporary {
    /// `dir/.vk-PID-N.tmp`: the same directory (a rename must not cross file systems),
    /// hidden, unique, and short whatever the target's name (names have a length limit).
    fn new(target: &Path) -> Result<Temporary> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        if target.file_name().is_none() {
            return Err(refused(target, "is not a file name".into()));
        }
        let dir = parent_dir(target);
        if !dir.is_dir() {
            return Err(Error::io(
                target,
                std::io::Error::new(ErrorKind::NotFound, "the output directory does not exist"),
            ));
        }
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = dir.join(format!(".vk-{}-{n}.tmp", std::process::id()));
        let slot = register_for_signals(&path);
        Ok(Temporary {
            path,
            slot,
            armed: true,
        })
    }

    /// The file was renamed: nothing to remove any more.
    fn disarm(mut self) {
        self.armed = false;
    }

    fn release_slot(&mut self) {
        if let Some(slot) = self.slot.take() {
            // The string stays allocated: a signal handler may be reading it right now.
            PENDING[slot].store(std::ptr::null_mut(), Ordering::SeqCst);
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        self.release_slot();
        if self.armed {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Temporary files of writes in progress, for the signal handler (only while installed).
const SLOTS: usize = 64;
static PENDING: [AtomicPtr<libc::c_char>; SLOTS] =
    [const { AtomicPtr::new(std::ptr::null_mut()) }; SLOTS];
static CLEANUP_INSTALLED: AtomicBool = AtomicBool::new(false);

fn register_for_signals(path: &Path) -> Option<usize> {
    if !CLEANUP_INSTALLED.load(Ordering::SeqCst) {
        return None;
    }
    let name = CString::new(path.as_os_str().as_bytes()).ok()?.into_raw();
    for (k, slot) in PENDING.iter().enumerate() {
        if slot
            .compare_exchange(
                std::ptr::null_mut(),
                name,
                Ordering::SeqCst,
                Ordering::SeqCst,
            )
            .is_ok()
        {
            return Some(k);
        }
    }
    // SAFETY: `name` came from `into_raw` above and was not stored anywhere.
    drop(unsafe { CString::from_raw(name) });
    None
}

extern "C" fn remove_pending_and_reraise(signal: libc::c_int) {
    for slot in &PENDING {
        let name = slot.load(Ordering::SeqCst);
        if !name.is_null() {
            // SAFETY: a NUL-terminated string that is never freed; unlink is async-signal-safe.
            unsafe { libc::unlink(name) };
        }
    }
    // SAFETY: signal and raise are async-signal-safe; the default action ends the process
    // with the status a shell expects of this signal.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
        libc::raise(signal);
    }
}

/// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary files of
/// writes in progress, then end the process as the signal would have.
pub fn remove_temporaries_on_signals() {
    CLEANUP_INSTALLED.store(true, Ordering::SeqCst);
    for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        // SAFETY: the handler only calls async-signal-safe functions and reads atomics.
        unsafe {
            libc::signal(
                signal,
                remove_pending_and_reraise as extern "C" fn(libc::c_int) as libc::sighandler_t,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failure_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        let r = write_atomic(&target, |tmp| {
            std::fs::write(tmp, b"partial").unwrap();
            Err(Error::InvalidArgument("boom".into()))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&target, |tmp| {
            std::fs::write(tmp, b"ok").map_err(|e| Error::io(tmp, e))
        })
        .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"ok");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn missing_directory_is_an_error_naming_the_path() {
        let e = write_atomic(Path::new("no/such/dir/out.vdb"), |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("no/such/dir/out.vdb"));
    }

    #[test]
    fn longest_file_name_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join(format!("{}.vdb", "n".repeat(251)));
        write_atomic(&target, |tmp| {
            std::fs::write(tmp, b"ok").map_err(|e| Error::io(tmp, e))
        })
        .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"ok");
    }

    #[test]
    fn a_link_is_followed_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.vdb");
        let link = dir.path().join("link.vdb");
        std::fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_atomic(&link, |tmp| {
            std::fs::write(tmp, b"new").map_err(|e| Error::io(tmp, e))
        })
        .unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
    }

    #[test]
    fn special_files_and_inputs_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = write_atomic(dir.path(), |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        let e = write_atomic(Path::new("/dev/null"), |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
        let input = dir.path().join("in.obj");
        std::fs::write(&input, b"v 0 0 0").unwrap();
        let alias = dir.path().join(".").join("in.obj");
        let e = check_output(&alias, &[Path::new("other.obj"), &input]).unwrap_err();
        assert!(e.to_string().contains("replace the input"), "{e}");
        check_output(&dir.path().join("out.vdb"), &[&input]).unwrap();
    }
}
