//! The Python module `voxelkit._voxelkit` (feature `python`, built by maturin): a thin front
//! end over the pipeline, like the CLI. The package `python/voxelkit` re-exports it.

mod arrays;
mod bricks;
mod frames;
mod grid;
mod jobs;
mod keywords;
mod queries;
mod watch;

use crate::error::Error;
use pyo3::exceptions::{PyFileNotFoundError, PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;

/// voxelkit's errors as Python's: files as OSError (FileNotFoundError when missing), memory
/// as MemoryError, everything the caller gave wrong as ValueError; the CLI's messages.
pub(crate) fn to_py_err(e: Error) -> PyErr {
    let message = e.to_string();
    match e {
        Error::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        Error::Io { .. } | Error::Vdb { .. } => PyOSError::new_err(message),
        Error::TooLarge { .. } => PyMemoryError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

#[pymodule]
fn _voxelkit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_RESOLUTION", crate::mesh::DEFAULT_RESOLUTION)?;
    m.add_class::<grid::Grid>()?;
    m.add_function(wrap_pyfunction!(jobs::mesh, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::solid, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::subdiv, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::implicit, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::lines, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::csg, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::measure, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::combine, m)?)?;
    m.add_function(wrap_pyfunction!(queries::signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(queries::contains, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::read_vdb, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::placement, m)?)?;
    m.add_function(wrap_pyfunction!(frames::frame_plan, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::options, m)?)?;
    bricks::register(m)?;
    Ok(())
}
