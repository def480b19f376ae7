//! Text files of surface points, one per line: `face u v` optionally followed by the expected
//! `x y z nx ny nz` (the format of OpenSubdiv reference files); `#` starts a comment line.

use crate::error::{Error, Result};
use glam::DVec3;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub face: usize,
    pub u: f64,
    pub v: f64,
    /// Expected position and unit normal, when the file gives them.
    pub expected: Option<(DVec3, DVec3)>,
}

pub fn read_points(path: &Path) -> Result<Vec<SurfacePoint>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_points(path, &text)
}

pub fn parse_points(path: &Path, text: &str) -> Result<Vec<SurfacePoint>> {
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |message: String| Error::Parse {
            path: path.to_path_buf(),
            line: i + 1,
            message,
        };
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() != 3 && fields.len() != 9 {
            return Err(bad(format!(
                "expected `face u v` or `face u v x y z nx ny nz`, found {} fields",
                fields.len()
            )));
        }
        let face = fields[0].parse::<usize>().map_err(|_| {
            bad(format!(
                "face index `{}` is not a non-negative integer",
                fields[0]
            ))
        })?;
        let mut numbers = Vec::with_capacity(8);
        for field in &fields[1..] {
            let x = field
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("`{field}` is not a finite number")))?;
            numbers.push(x);
        }
        let expected = (numbers.len() == 8).then(|| {
            (
                DVec3::new(numbers[2], numbers[3], numbers[4]),
                DVec3::new(numbers[5], numbers[6], numbers[7]),
            )
        });
        points.push(SurfacePoint {
            face,
            u: numbers[0],
            v: numbers[1],
            expected,
        });
    }
    Ok(points)
}
