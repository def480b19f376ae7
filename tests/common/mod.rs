//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

#[path = "skip.rs"]
mod skip;
pub use skip::skip_or_fail;

/// The shared test data folder: `$VOXELKIT_DATA`, or `../shared/data` beside the crate.
/// `None` (with a loud warning) when it is missing, so a clean clone still passes; CI
/// (`.ci/run`) refuses to run without it.
pub fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("VOXELKIT_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    if dir.join("meshes").is_dir() {
        Some(dir)
    } else {
        skip_or_fail(&format!(
            "VOXELKIT_DATA: the shared test data is not at {} (set VOXELKIT_DATA to the shared data folder)",
            dir.display()
        ));
        None
    }
}

/// Every `.obj` in the data folder's `meshes/`, sorted.
pub fn shared_meshes(data: &std::path::Path) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(data.join("meshes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    paths
}

/// The closed meshes of the data folder used for separability tests.
pub const CLOSED_MESHES: [&str; 10] = [
    "bunny-closed",
    "rocker-arm",
    "spot_triangulated",
    "armadillo",
    "fandisk",
    "torus",
    "sphere",
    "skull",
    "scorpion",
    "horse",
];

/// Voxelizes `mesh` at `resolution` voxels along its longest axis.
pub fn voxelize_at(
    mesh: &voxelkit::mesh::Mesh,
    resolution: u32,
    opts: voxelkit::voxelize::separating::SeparatingOptions,
) -> (
    voxelkit::grid::SparseGrid,
    voxelkit::voxelize::separating::SeparatingStats,
) {
    use voxelkit::mesh::{GridFit, fit_transform};
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
    voxelkit::voxelize::separating::voxelize_mesh(
        mesh,
        t,
        &opts,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap()
}

/// Asserts that the evaluator matches expected limit points: positions to 1e-9 of the bbox
/// diagonal, normals to 1e-6 rad.
pub fn assert_limit_match(what: &str, c: &voxelkit::subd::Comparison) {
    assert!(c.points > 0, "{what}: no points compared");
    assert!(
        c.max_relative_position_error <= 1e-9,
        "{what}: position error {:e} of the diagonal",
        c.max_relative_position_error
    );
    assert!(
        c.max_normal_angle <= 1e-6,
        "{what}: normal off by {:e} rad at {:?}",
        c.max_normal_angle,
        c.worst_normal_at
    );
}
