//! Outputs never destroy data: an output that is an input, a FIFO, a device or a link; a full
//! disk; a signal during the write. Each case ends with a clear error (or the link's target
//! written), the previous file intact and no temporary file left.
#![cfg(feature = "vdb")]

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::Command;
mod cli_support;

use cli_support::{text, voxelkit};

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

/// Temporary (hidden) files left in `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect()
}

fn path_str(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn assert_refused(args: &[&str], expect: &str) {
    let o = voxelkit(args);
    let msg = text(&o);
    assert!(!o.status.success(), "{args:?} succeeded: {msg}");
    assert!(msg.contains(expect), "`{expect}` missing from: {msg}");
    assert!(!msg.contains("panicked"), "{msg}");
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("in.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let o = path_str(&obj);
    // The same file under another spelling is still the input.
    let alias = format!("{}/./in.obj", path_str(dir.path()));
    for args in [
        vec!["mesh", o, "-o", o],
        vec!["mesh", o, "-o", &alias],
        vec!["mesh", o, "--method", "projective", "-o", o],
        vec!["solid", o, "-o", o],
        vec!["solid", o, "--method", "depth-layers", "-o", o],
        vec!["lines", o, "-o", o],
        vec!["subdiv", o, "-o", o],
    ] {
        assert_refused(&args, "replace the input");
        assert_eq!(std::fs::read_to_string(&obj).unwrap(), TETRA, "{args:?}");
    }
    // A CSG tree: neither the tree file nor a mesh it reads may be the output.
    let tree = dir.path().join("t.json");
    let tree_text = r#"{"resolution": 16, "tree": {"union": [{"mesh": "in.obj"}, {"sphere": {"center": [0,0,0], "radius": 0.5}}]}}"#;
    std::fs::write(&tree, tree_text).unwrap();
    let t = path_str(&tree);
    assert_refused(&["csg", "--tree", t, "-o", t], "replace the input");
    assert_refused(&["csg", "--tree", t, "-o", o], "replace the input");
    assert_eq!(std::fs::read_to_string(&tree).unwrap(), tree_text);
    assert_eq!(std::fs::read_to_string(&obj).unwrap(), TETRA);
    assert!(temporaries(dir.path()).is_empty());
}

#[test]
fn special_files_are_refused_and_links_followed() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("in.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let o = path_str(&obj);
    let fifo = dir.path().join("pipe.vdb");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    assert_refused(&["mesh", o, "-r", "8", "-o", path_str(&fifo)], "a FIFO");
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    assert_refused(&["mesh", o, "-r", "8", "-o", "/dev/null"], "a device");
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    assert_refused(
        &["mesh", o, "-r", "8", "-o", path_str(dir.path())],
        "a directory",
    );

    let real = dir.path().join("real.vdb");
    let link = dir.path().join("link.vdb");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let out = voxelkit(&["mesh", o, "-r", "8", "-o", path_str(&link)]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(std::fs::metadata(&real).unwrap().len() > 0);

    let long = dir.path().join(format!("{}.vdb", "x".repeat(250)));
    let out = voxelkit(&["mesh", o, "-r", "8", "-o", path_str(&long)]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(long.is_file());
    assert!(temporaries(dir.path()).is_empty());
}

/// A small tmpfs mounted for one test and unmounted on drop.
struct SmallDisk(tempfile::TempDir);

impl SmallDisk {
    fn mount(size: &str) -> Option<SmallDisk> {
        let dir = tempfile::tempdir().unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir.path())
            .output()
            .is_ok_and(|o| o.status.success());
        ok.then_some(SmallDisk(dir))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.0.path()).status();
    }
}

#[test]
fn a_full_disk_is_an_error_and_keeps_the_previous_file() {
    let Some(disk) = SmallDisk::mount("256k") else {
        // A permission of the machine, not a missing tool: skipped loudly, in CI too.
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "\n!!! mounting a small tmpfs is not allowed here: the full-disk test is SKIPPED\n"
        );
        return;
    };
    let dir = disk.0.path();
    let out = dir.join("sphere.vdb");
    let small = voxelkit(&["shape", "sphere", "-r", "16", "-o", path_str(&out)]);
    assert!(small.status.success(), "{}", text(&small));
    let before = std::fs::read(&out).unwrap();
    // At 256 the file is several MB: it cannot fit in 256 KiB.
    let big = voxelkit(&["shape", "sphere", "-r", "256", "-o", path_str(&out)]);
    let msg = text(&big);
    assert!(
        !big.status.success(),
        "a write to a full disk succeeded: {msg}"
    );
    assert!(msg.contains("sphere.vdb"), "the error names no file: {msg}");
    assert!(
        msg.to_lowercase().contains("space"),
        "the error names no cause: {msg}"
    );
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the previous output was damaged"
    );
    assert!(
        temporaries(dir).is_empty(),
        "temporary file left on the full disk"
    );
}

#[test]
fn a_signal_during_the_run_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sphere.vdb");
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_voxelkit"))
            .args(["shape", "sphere", "-r", "1024", "-o", path_str(&out)])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap()
    };
    // How long a whole run takes here; the signals then land all along it, the write included.
    let start = std::time::Instant::now();
    assert!(run().wait().unwrap().success());
    let whole = start.elapsed();
    std::fs::remove_file(&out).unwrap();
    for (k, signal) in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP]
        .into_iter()
        .cycle()
        .take(12)
        .enumerate()
    {
        let mut child = run();
        std::thread::sleep(whole.mul_f64((k as f64 + 0.5) / 12.0));
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as i32, signal) };
        let status = child.wait().unwrap();
        assert!(
            temporaries(dir.path()).is_empty(),
            "signal {signal} at {k}/12 of the run left a temporary file"
        );
        if status.success() {
            // It finished first: the file is whole.
            assert!(std::fs::metadata(&out).unwrap().len() > 0);
        }
    }
}

#[test]
fn an_output_linked_to_another_input_of_the_batch_is_refused_and_that_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in ["a.obj", "b.obj", "f_0001.obj", "f_0002.obj"] {
        std::fs::write(d.join(name), TETRA).unwrap();
    }
    let od = d.join("od");
    std::fs::create_dir(&od).unwrap();
    std::os::unix::fs::symlink("../b.obj", od.join("a.vdb")).unwrap();
    std::fs::create_dir(d.join("o")).unwrap();
    std::os::unix::fs::symlink("../f_0002.obj", d.join("o/o_0001.vdb")).unwrap();
    let (a, b) = (d.join("a.obj"), d.join("b.obj"));
    let (a, b, od) = (path_str(&a), path_str(&b), path_str(&od));
    let frames = d.join("f_####.obj");
    let pattern = d.join("o/o_####.vdb");
    for args in [
        vec!["mesh", a, b, "--out-dir", od],
        vec!["mesh", a, b, "--out-dir", od, "--shared-grid"],
        vec!["solid", a, b, "--out-dir", od],
        vec![
            "mesh",
            path_str(&frames),
            "--frames",
            "1-2",
            "-o",
            path_str(&pattern),
        ],
    ] {
        assert_refused(&args, "replace the input");
        for input in ["b.obj", "f_0002.obj"] {
            assert_eq!(
                std::fs::read_to_string(d.join(input)).unwrap(),
                TETRA,
                "{args:?}: {input}"
            );
        }
    }
}
