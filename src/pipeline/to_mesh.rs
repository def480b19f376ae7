//! A mesh from a `.vdb` file: its grid read as a field, contoured and written, timed by stage
//! and reported.

use super::request::ToMeshRequest;
use super::{Limits, on_threads};
use crate::contour::{Meaning, contour};
use crate::error::{Error, Result};
use crate::io::atomic::check_output;
use crate::io::mesh_out::{MeshFormat, write_mesh};
use crate::io::vdb::read_vdb_field;
use crate::progress::{StageClock, StageTime};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What a mesh run did.
#[derive(Clone, Debug, Serialize)]
pub struct MeshReport {
    pub input: PathBuf,
    pub output: PathBuf,
    /// The grid's meaning: level set, fog volume or voxels.
    pub meaning: &'static str,
    pub iso: f64,
    pub vertices: u64,
    pub triangles: u64,
    /// Read, contour and write, with their seconds and threads busy.
    pub stages: Vec<StageTime>,
}

impl MeshReport {
    pub fn summary(&self) -> String {
        format!(
            "{}: {} vertices, {} triangles (closed, manifold) from {} of {} at iso {}\n\
             {}",
            self.output.display(),
            self.vertices,
            self.triangles,
            self.meaning,
            self.input.display(),
            self.iso,
            self.stages
                .iter()
                .map(|s| format!("{} {:.3} s", s.stage, s.seconds))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

/// Reads `input`'s grid as `request` says, and writes its surface to `output` (.obj, .ply,
/// .stl or .glb).
pub fn vdb_to_mesh(
    input: &Path,
    output: &Path,
    request: &ToMeshRequest,
    limits: &Limits,
) -> Result<MeshReport> {
    MeshFormat::of(output)?;
    check_output(output, &[input])?;
    on_threads(limits.threads, || {
        let mut read = StageClock::new("read");
        let field = read.time(|| read_vdb_field(input, request.grid.as_deref(), request.iso))?;
        let mut contouring = StageClock::new("contour");
        let mesh = contouring.time(|| contour(&field));
        if mesh.triangles.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "{}: the grid has no surface at iso {} (its values never cross it)",
                input.display(),
                field.iso
            )));
        }
        let mut writing = StageClock::new("write");
        writing.time(|| write_mesh(output, &mesh))?;
        Ok(MeshReport {
            input: input.to_path_buf(),
            output: output.to_path_buf(),
            meaning: match field.meaning {
                Meaning::LevelSet { .. } => "level set",
                Meaning::Fog => "fog volume",
                Meaning::Voxels => "voxels",
            },
            iso: field.iso as f64,
            vertices: mesh.positions.len() as u64,
            triangles: mesh.triangles.len() as u64,
            stages: vec![read.stage(), contouring.stage(), writing.stage()],
        })
    })
}
