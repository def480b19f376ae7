//! The files a model file names (a glTF buffer, the bricks of a brick set's index): a model
//! must not make voxelkit read beyond its own folder, nor read special files (a FIFO that
//! never answers, `/dev/zero` that never ends), nor read more than the model declares. Every
//! such reference goes through `referenced_file`, and its bytes through `read_referenced`.

use std::io::Read;
use std::path::{Path, PathBuf};

/// The folder a model's references are found in: the model's own.
fn model_folder(model: &Path) -> &Path {
    match model.parent() {
        Some(f) if !f.as_os_str().is_empty() => f,
        _ => Path::new("."),
    }
}

/// The file the model at `model` names `reference` by: a relative path that stays inside the
/// model's folder once links are resolved, naming a regular file. The error says why not,
/// naming the reference as the model wrote it (never the bytes of what it points to).
pub fn referenced_file(model: &Path, reference: &str) -> Result<PathBuf, String> {
    let named = Path::new(reference);
    if named.is_absolute() {
        return Err(format!(
            "names `{reference}`, an absolute path: a model's files must lie in its own folder"
        ));
    }
    let folder = model_folder(model);
    let root = folder
        .canonicalize()
        .map_err(|e| format!("cannot resolve the model's folder: {e}"))?;
    let real = folder
        .join(named)
        .canonicalize()
        .map_err(|e| format!("cannot read `{reference}`: {e}"))?;
    if !real.starts_with(&root) {
        return Err(format!(
            "names `{reference}`, outside the model's folder: a model's files must lie in its own folder"
        ));
    }
    let kind = std::fs::metadata(&real).map_err(|e| format!("cannot read `{reference}`: {e}"))?;
    if !kind.is_file() {
        return Err(format!("names `{reference}`, which is not a regular file"));
    }
    Ok(real)
}

/// The first `len` bytes of the file the model names `reference` by (see `referenced_file`),
/// refused when the file holds fewer; never more is read.
pub fn read_referenced(model: &Path, reference: &str, len: u64) -> Result<Vec<u8>, String> {
    let file = referenced_file(model, reference)?;
    let cannot = |e: std::io::Error| format!("cannot read `{reference}`: {e}");
    let opened = std::fs::File::open(&file).map_err(cannot)?;
    let size = opened.metadata().map_err(cannot)?.len();
    if size < len {
        return Err(format!(
            "`{reference}` holds {size} bytes, but the model declares {len}"
        ));
    }
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(len as usize)
        .map_err(|_| format!("`{reference}`: {len} bytes do not fit in memory"))?;
    opened.take(len).read_to_end(&mut bytes).map_err(cannot)?;
    if (bytes.len() as u64) < len {
        return Err(format!(
            "`{reference}` ended after {} bytes, but the model declares {len}",
            bytes.len()
        ));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_stay_in_the_folder_and_name_regular_files() {
        let dir = tempfile::tempdir().unwrap();
        let inner = dir.path().join("model");
        std::fs::create_dir(&inner).unwrap();
        let model = inner.join("m.gltf");
        std::fs::write(inner.join("b.bin"), [1u8, 2, 3, 4]).unwrap();
        std::fs::write(dir.path().join("outside.bin"), [9u8; 4]).unwrap();
        std::os::unix::fs::symlink("../outside.bin", inner.join("link.bin")).unwrap();
        std::fs::create_dir(inner.join("sub")).unwrap();
        assert_eq!(read_referenced(&model, "b.bin", 3).unwrap(), vec![1, 2, 3]);
        let refused = |r: &str, why: &str| {
            let e = read_referenced(&model, r, 1).unwrap_err();
            assert!(e.contains(why), "{r}: {e}");
        };
        refused("../outside.bin", "outside the model's folder");
        refused("link.bin", "outside the model's folder");
        refused("/etc/passwd", "an absolute path");
        refused("sub", "not a regular file");
        refused("missing.bin", "cannot read");
        let e = read_referenced(&model, "b.bin", 5).unwrap_err();
        assert!(e.contains("holds 4 bytes, but the model declares 5"), "{e}");
    }
}
