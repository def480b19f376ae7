//! Meshes of results: a `.vdb` file's grid, or a job's outcome, read as a field, contoured
//! and written, timed by stage and reported.

use super::Outcome;
use super::request::ToMeshRequest;
use super::{Limits, Merged, MeshWritten, on_threads};
use crate::contour::{ExactSurface, Meaning, ScalarField, TriangleMesh, contour};
use crate::error::{Error, Result};
use crate::io::atomic::check_output;
use crate::io::mesh_out::{MeshFormat, write_mesh};
use crate::io::vdb::read_vdb_field;
use crate::mesh::Mesh;
use crate::mesh::simplify::simplify;
use crate::mesh::surface_distance::two_sided_distance;
use crate::progress::{StageClock, StageTime};
use glam::DVec3;
use serde::Serialize;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// What a mesh run did.
#[derive(Clone, Debug, Serialize)]
pub struct MeshReport {
    pub input: PathBuf,
    #[serde(flatten)]
    pub mesh: MeshWritten,
    /// The grid's meaning: level set, fog volume or voxels.
    pub meaning: &'static str,
    pub iso: f64,
    /// Read, contour and write, with their seconds and threads busy.
    pub stages: Vec<StageTime>,
    /// The whole run's seconds and the process's peak memory.
    pub seconds: f64,
    pub peak_mib: f64,
}

impl MeshReport {
    pub fn summary(&self) -> String {
        format!(
            "{} from the {} of {} at iso {}\n{:.2} s, peak {:.0} MiB: {}",
            self.mesh.describe(),
            self.meaning,
            self.input.display(),
            self.iso,
            self.seconds,
            self.peak_mib,
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
    check_adaptivity(request.adaptivity)?;
    check_output(output, &[input])?;
    let start = std::time::Instant::now();
    on_threads(limits.threads, || {
        let mut read = StageClock::new("read");
        let field = read.time(|| read_vdb_field(input, request.grid.as_deref(), request.iso))?;
        let (_, mesh, mut stages) =
            contour_to_file(&field, None, request.adaptivity, output, input)?;
        stages.insert(0, read.stage());
        Ok(MeshReport {
            input: input.to_path_buf(),
            mesh,
            meaning: match field.meaning {
                Meaning::LevelSet { .. } => "level set",
                Meaning::Fog => "fog volume",
                Meaning::Voxels => "voxels",
            },
            iso: field.iso as f64,
            stages,
            seconds: start.elapsed().as_secs_f64(),
            peak_mib: crate::system::peak_memory_mib(),
        })
    })
}

/// Refuses an adaptivity that is not a finite number of voxels, 0 or more.
pub fn check_adaptivity(adaptivity: f64) -> Result<()> {
    if adaptivity.is_finite() && adaptivity >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "adaptivity must be 0 or a positive number of voxels, not {adaptivity}"
        )))
    }
}

impl ToMeshRequest {
    /// The adaptivity of a mesh drawn from a result in memory, checked: `grid` and `iso`
    /// choose a `.vdb` file's grid and are refused.
    pub fn result_adaptivity(&self) -> Result<f64> {
        if self.grid.is_some() || self.iso.is_some() {
            return Err(Error::InvalidArgument(
                "grid and iso choose a .vdb file's grid: a result's mesh takes adaptivity".into(),
            ));
        }
        check_adaptivity(self.adaptivity)?;
        Ok(self.adaptivity)
    }
}

/// Checks before a job runs that its mesh can be written to `output`.
pub fn check_mesh_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    MeshFormat::of(output)?;
    check_output(output, inputs)
}

impl Outcome {
    /// The result as a field: a level set's distances (its zero set the surface), the source's
    /// own values around a shell that only envelops it (a formula's), or a voxel set (its
    /// boundary).
    fn field(&self) -> Result<ScalarField<'_>> {
        if self.distances.is_none()
            && let Some(field) = self.exact.as_ref().and_then(|e| e.field_around(&self.grid))
        {
            return Ok(field);
        }
        match &self.distances {
            Some(d) => ScalarField::from_band(&self.grid, d.background, d.interior.as_ref(), 0.0)
                .ok_or_else(|| Error::InvalidArgument("the distance band is empty".into())),
            None => Ok(ScalarField {
                grid: Cow::Borrowed(&self.grid),
                meaning: Meaning::Voxels,
                iso: 0.0,
            }),
        }
    }

    /// The surface of the result as a closed, manifold triangle mesh (empty when the
    /// result is).
    pub fn surface_mesh(&self, adaptivity: f64) -> Result<TriangleMesh> {
        check_adaptivity(adaptivity)?;
        let field = self.field()?;
        on_threads(self.threads, || {
            let mut mesh = contour(&field, self.exact.as_deref())?;
            simplify(&mut mesh, adaptivity, field.grid.transform.voxel_size)?;
            Ok(mesh)
        })
    }

    /// Writes the surface of the result to `output` (.obj, .ply, .stl or .glb), flat regions
    /// merged within `adaptivity` voxels, noted in the report.
    pub fn write_mesh(&mut self, output: &Path, adaptivity: f64) -> Result<()> {
        self.write_mesh_of(output, adaptivity, None)
    }

    /// Writes the surface as `write_mesh` does, and measures how far it lies from `source`,
    /// the mesh the result was made of: a mesh remade closed and manifold.
    pub fn write_remesh(&mut self, output: &Path, adaptivity: f64, source: &Mesh) -> Result<()> {
        self.write_mesh_of(output, adaptivity, Some(source))
    }

    /// Writes the surface of the result to `output` as `write_mesh` does, without noting it
    /// in the report (the result is only borrowed, as the C interface holds it).
    pub fn save_mesh(&self, output: &Path, adaptivity: f64) -> Result<()> {
        self.contour_and_write(output, adaptivity).map(|_| ())
    }

    /// The surface contoured (placed by the exact source where there is one) and written.
    fn contour_and_write(
        &self,
        output: &Path,
        adaptivity: f64,
    ) -> Result<(TriangleMesh, MeshWritten, Vec<StageTime>)> {
        check_adaptivity(adaptivity)?;
        let field = self.field()?;
        let input = PathBuf::from(&self.report.input);
        on_threads(self.threads, || {
            contour_to_file(&field, self.exact.as_deref(), adaptivity, output, &input)
        })
    }

    fn write_mesh_of(
        &mut self,
        output: &Path,
        adaptivity: f64,
        source: Option<&Mesh>,
    ) -> Result<()> {
        let (mesh, mut written, mut stages) = self.contour_and_write(output, adaptivity)?;
        if let Some(source) = source {
            let mut measure = StageClock::new("distance to input");
            let distance = measure.time(|| {
                let corners = |m: &TriangleMesh| -> Vec<[DVec3; 3]> {
                    m.triangles
                        .iter()
                        .map(|t| t.map(|i| m.positions[i as usize]))
                        .collect()
                };
                let source: Vec<[DVec3; 3]> = source
                    .triangles()
                    .map(|(_, t)| t.map(|v| source.p(v)))
                    .collect();
                on_threads(self.threads, || {
                    Ok(two_sided_distance(&corners(&mesh), &source))
                })
            })?;
            written.distance_to_source = Some(distance.a_to_b);
            written.source_to_mesh = Some(distance.b_to_a);
            stages.push(measure.stage());
        }
        self.report.stages.extend(stages);
        self.report.mesh = Some(written);
        Ok(())
    }
}

/// Contours `field` (placed by `exact` where it knows the source), merges flat regions within
/// `adaptivity` voxels and writes the mesh to `output`; refuses a field without a surface,
/// naming `source`.
fn contour_to_file(
    field: &ScalarField,
    exact: Option<&dyn ExactSurface>,
    adaptivity: f64,
    output: &Path,
    source: &Path,
) -> Result<(TriangleMesh, MeshWritten, Vec<StageTime>)> {
    let mut contouring = StageClock::new("contour");
    let mut mesh = contouring.time(|| contour(field, exact))?;
    if mesh.triangles.is_empty() {
        return Err(Error::InvalidArgument(format!(
            "{}: the grid has no surface at iso {} (its values never cross it)",
            source.display(),
            field.iso
        )));
    }
    let mut stages = vec![contouring.stage()];
    let mut merged = None;
    if adaptivity > 0.0 {
        let mut merging = StageClock::new("merge flat regions");
        let simplified =
            merging.time(|| simplify(&mut mesh, adaptivity, field.grid.transform.voxel_size))?;
        merged = Some(Merged {
            triangles_before_merging: simplified.triangles_before as u64,
            adaptivity,
        });
        stages.push(merging.stage());
    }
    let mut writing = StageClock::new("write mesh");
    writing.time(|| write_mesh(output, &mesh))?;
    let written = MeshWritten {
        file: output.display().to_string(),
        vertices: mesh.positions.len() as u64,
        triangles: mesh.triangles.len() as u64,
        merged,
        ..MeshWritten::default()
    };
    stages.push(writing.stage());
    Ok((mesh, written, stages))
}
