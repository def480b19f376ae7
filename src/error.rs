//! The one error type of voxelkit. Every variant carries enough context (file, line, face)
//! for a user to find the problem without a debugger.

use std::path::PathBuf;

/// Everything that can go wrong in voxelkit.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}{}: {message}", line_suffix(*line))]
    Parse {
        path: PathBuf,
        /// 1-based line number; 0 when the format has no lines (binary STL: see message).
        line: usize,
        message: String,
    },
    #[error("{path}: face {face}: {message}")]
    BadFace {
        path: PathBuf,
        /// 0-based face index in file order.
        face: usize,
        message: String,
    },
    #[error("{path}: the mesh is empty ({message})")]
    EmptyMesh { path: PathBuf, message: String },
    #[error("{path}: unsupported file type (expected .obj, .stl, .ply, .off, .gltf or .glb)")]
    UnsupportedFormat { path: PathBuf },
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// A mesh whose shape rules out what was asked (open where an inside is needed); the
    /// message names the file and the first offending edge.
    #[error("{0}")]
    BadMesh(String),
    #[error(
        "resolution too large: an estimated {} MiB is needed but only {available_mib} MiB is available ({detail})",
        short_number(*estimated_mib)
    )]
    TooLarge {
        estimated_mib: u64,
        available_mib: u64,
        detail: String,
    },
    #[error("{path}: OpenVDB: {message}")]
    Vdb { path: PathBuf, message: String },
    #[error(
        "formula, column {column}: {message}\n  {text}\n  {caret:>column$}",
        caret = "^"
    )]
    Formula {
        text: String,
        /// 1-based column (in characters) where the problem starts.
        column: usize,
        message: String,
    },
    #[error("{0}")]
    Unsupported(String),
    /// Some inputs of a batch failed (each reported on its own); the others were written.
    #[error("{failed} of {total} inputs failed (each is named above)")]
    Batch { failed: usize, total: usize },
    /// The observer asked the work to stop; nothing was kept.
    #[error("cancelled")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, Error>;

/// `:12` for line 12; nothing for formats without lines (line 0).
fn line_suffix(line: usize) -> String {
    if line > 0 {
        format!(":{line}")
    } else {
        String::new()
    }
}

/// A count as people read it: digits up to a billion, then scientific notation.
fn short_number(n: u64) -> String {
    if n < 1_000_000_000 {
        n.to_string()
    } else {
        format!("{:.2e}", n as f64)
    }
}

impl Error {
    /// The file and the line (or face) the error is about, where it has them.
    pub fn location(&self) -> (Option<&std::path::Path>, Option<usize>) {
        match self {
            Error::Io { path, .. } | Error::Vdb { path, .. } => (Some(path), None),
            Error::EmptyMesh { path, .. } | Error::UnsupportedFormat { path } => (Some(path), None),
            Error::Parse { path, line, .. } => (Some(path), (*line > 0).then_some(*line)),
            Error::BadFace { path, .. } => (Some(path), None),
            _ => (None, None),
        }
    }

    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}
