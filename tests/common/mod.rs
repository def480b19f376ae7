//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

#[path = "skip.rs"]
mod skip;
pub use skip::skip_or_fail;

/// A cube control mesh, [-1, 1]^3 with outward faces: 8 valence-3 extraordinary vertices.
pub const CUBE_OBJ: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

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
            "the shared test data (VOXELKIT_DATA): not at {} (set VOXELKIT_DATA to the shared data folder)",
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

/// Asserts that voxelkit's own reader and OpenVDB read grid `name` of the `.vdb` at `path`
/// alike: the same leaves (origin, mask and all 512 values, inactive ones included), the same
/// tiles, voxel count and transform.
#[cfg(feature = "vdb")]
pub fn assert_read_as_openvdb_reads(path: &std::path::Path, name: &str) {
    use std::collections::{BTreeMap, BTreeSet};
    let ours = voxelkit::io::vdb::read_vdb_grid(path, Some(name)).unwrap();
    let theirs = voxelkit_openvdb::read_grid(path.to_str().unwrap(), name).unwrap();
    let what = format!("{}: grid {name}", path.display());
    let per_leaf = theirs.values.len() / (theirs.origins.len() / 3).max(1);
    let mut leaves = BTreeMap::new();
    for (i, o) in theirs.origins.chunks_exact(3).enumerate() {
        let origin = [o[0] as i64, o[1] as i64, o[2] as i64];
        let mask: [u64; 8] = theirs.masks[8 * i..8 * i + 8].try_into().unwrap();
        let values = theirs
            .values
            .get(i * per_leaf..(i + 1) * per_leaf)
            .unwrap_or(&[]);
        leaves.insert(origin, (mask, values.to_vec()));
    }
    assert_eq!(ours.leaf_count(), leaves.len(), "{what}: leaf count");
    for leaf in ours.leaves() {
        let (mask, values) = leaves
            .get(&leaf.origin)
            .unwrap_or_else(|| panic!("{what}: OpenVDB has no leaf at {:?}", leaf.origin));
        assert_eq!(
            &leaf.mask, mask,
            "{what}: mask of the leaf at {:?}",
            leaf.origin
        );
        let ours_values: Vec<f32> =
            match (&leaf.value, leaf.normal.as_ref().or(leaf.color.as_ref())) {
                (Some(v), _) => v.to_vec(),
                (None, Some(v)) => v.iter().flatten().copied().collect(),
                (None, None) => Vec::new(),
            };
        assert!(
            ours_values
                .iter()
                .zip(values)
                .all(|(a, b)| a.to_bits() == b.to_bits())
                && ours_values.len() == values.len(),
            "{what}: values of the leaf at {:?}",
            leaf.origin
        );
    }
    let their_tiles: BTreeSet<([i64; 3], i64)> = theirs
        .tiles
        .chunks_exact(4)
        .map(|t| ([t[0] as i64, t[1] as i64, t[2] as i64], t[3] as i64))
        .collect();
    let our_tiles: BTreeSet<([i64; 3], i64)> = ours.tiles().with_edges().collect();
    assert_eq!(our_tiles, their_tiles, "{what}: tiles");
    assert_eq!(
        ours.voxel_count(),
        theirs.info.active_voxels,
        "{what}: voxel count"
    );
    assert_eq!(
        ours.transform.voxel_size, theirs.info.voxel_size[0],
        "{what}: voxel size"
    );
    let origin = ours.transform.origin.to_array();
    assert!(
        (0..3)
            .all(|a| (origin[a] - theirs.info.origin[a]).abs() <= 1e-12 * origin[a].abs().max(1.0)),
        "{what}: origin"
    );
}
