//! `voxelkit csg --tree tree.json`: evaluate a CSG tree and write the solid.

use crate::report::{Json, peak_mib};
use std::path::Path;
use std::time::Instant;
use voxelkit::Result;
use voxelkit::ops::csg_tree::read_csg_tree;

pub fn run(tree_path: &Path, output: &Path, json: bool) -> Result<()> {
    let start = Instant::now();
    let tree = read_csg_tree(tree_path)?;
    let (transform, solid, leaves) = tree.evaluate()?;
    let meta = vec![
        ("method", "csg-tree (voxel centres)".to_string()),
        ("source_file", tree_path.display().to_string()),
    ];
    let voxels = crate::solids::write_centre_solid(output, &solid, transform, &[], &meta)?;
    let volume = voxels as f64 * transform.voxel_size.powi(3);
    let seconds = start.elapsed().as_secs_f64();
    if json {
        let leaves = leaves
            .iter()
            .map(|l| Json::default().str("leaf", &l.what).int("voxels", l.voxels))
            .collect();
        let j = Json::default()
            .str("output", output.display().to_string())
            .int("voxels", voxels)
            .num("voxel_size", transform.voxel_size)
            .num("volume", volume)
            .arr("leaves", leaves)
            .num("seconds", seconds)
            .num("peak_mib", peak_mib());
        println!("{}", j.render());
    } else {
        println!(
            "{}: {voxels} voxels (volume {volume:.6}) at voxel size {:.6} from {} leaves of {}; {seconds:.2} s, peak {:.0} MiB",
            output.display(),
            transform.voxel_size,
            leaves.len(),
            tree_path.display(),
            peak_mib()
        );
        for l in &leaves {
            println!("  {:>12} voxels  {}", l.voxels, l.what);
        }
    }
    Ok(())
}
