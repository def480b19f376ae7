//! A frame sequence's plan for the Dask front end: each frame's input and output file, and the
//! one placement they all share (`pipeline::batch`, as the command line's `--frames` has it),
//! so that every worker voxelizes its frames on the same grid.

use super::keywords::Keywords;
use super::to_py_err;
use crate::error::Error;
use crate::mesh::GridFit;
use crate::pipeline::batch::{FramePattern, FrameRange, shared_placement};
use crate::pipeline::request::BricksRequest;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// The pattern of `path` (one run of `#` for the frame number), refused without one.
fn pattern(path: &Path, what: &str) -> PyResult<FramePattern> {
    FramePattern::of(path).map_err(to_py_err)?.ok_or_else(|| {
        PyValueError::new_err(format!(
            "the {what} needs `#` for the frame number, as in `f_####.obj`; got `{}`",
            path.display()
        ))
    })
}

/// The frames `frames` (`FIRST-LAST`, `FIRST-LAST:STEP` or one frame) of the input pattern
/// `inputs` and the output pattern `outputs`: `(frame, input, output)` each, with the voxel
/// size and the world position of voxel (0, 0, 0) fitted to the union of the frames' boxes by
/// the placement of `options` (the distributed table's: `resolution` along the union's
/// longest axis, or `voxel_size`, `origin`, `up_axis`).
#[pyfunction]
#[pyo3(signature = (inputs, frames, outputs, **options))]
#[allow(clippy::type_complexity)]
pub fn frame_plan(
    py: Python<'_>,
    inputs: PathBuf,
    frames: &str,
    outputs: PathBuf,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Vec<(u32, PathBuf, PathBuf)>, f64, [f64; 3])> {
    let call = Keywords::<BricksRequest>::new(options)?;
    let range: FrameRange = frames.parse().map_err(PyValueError::new_err)?;
    let (input, output) = (pattern(&inputs, "input")?, pattern(&outputs, "output")?);
    let plan: Vec<(u32, PathBuf, PathBuf)> = range
        .frames()
        .map(|f| (f, input.path(f), output.path(f)))
        .collect();
    let fit = call.request.fit().map_err(to_py_err)?;
    let files: Vec<PathBuf> = plan.iter().map(|(_, i, _)| i.clone()).collect();
    let up = call.request.up_axis;
    let placed = py
        .detach(|| shared_placement(&files, fit, up))
        .map_err(to_py_err)?;
    match placed {
        GridFit::Placed(t) => Ok((plan, t.voxel_size, t.origin.to_array())),
        other => Err(to_py_err(Error::InvalidArgument(format!(
            "frames share one placement, not {other:?}"
        )))),
    }
}
