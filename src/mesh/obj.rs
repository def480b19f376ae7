//! OBJ input through tobj, polygons kept. tobj reports what went wrong but not where, so
//! on any problem a line scan finds the offending line for the error message.

use super::Mesh;
use crate::error::{Error, Result};
use glam::DVec3;
use std::path::Path;

pub(super) fn load_obj(path: &Path) -> Result<Mesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(e) => {
            let (line, message) =
                find_bad_line(&text).unwrap_or((0, format!("tobj could not read the file: {e}")));
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line,
                message,
            });
        }
    };

    let mut positions = Vec::new();
    let mut polygons = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2])),
        );
        let mut at = 0usize;
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&a| a as usize).collect()
        };
        for arity in arities {
            polygons.push(
                m.indices[at..at + arity]
                    .iter()
                    .map(|&i| i + base)
                    .collect(),
            );
            at += arity;
        }
    }
    if positions.iter().any(|p: &DVec3| !p.is_finite()) {
        let (line, message) =
            find_bad_line(&text).unwrap_or((0, "a vertex has a non-finite coordinate".to_string()));
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line,
            message,
        });
    }
    Ok(Mesh::from_polygons(path, positions, &polygons))
}

/// The first `v` line with a missing or non-finite coordinate, or `f` line with an index
/// that is zero, unparsable or out of range: `(1-based line, message)`.
fn find_bad_line(text: &str) -> Option<(usize, String)> {
    let mut vertices = 0i64;
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                vertices += 1;
                let coords: Vec<&str> = words.take(3).collect();
                if coords.len() < 3 {
                    return Some((line, "vertex has fewer than 3 coordinates".into()));
                }
                for c in coords {
                    match c.parse::<f64>() {
                        Ok(x) if x.is_finite() => {}
                        Ok(_) => {
                            return Some((line, format!("non-finite vertex coordinate `{c}`")));
                        }
                        Err(_) => return Some((line, format!("cannot read coordinate `{c}`"))),
                    }
                }
            }
            Some("f") => {
                for corner in words {
                    let index = corner.split('/').next().unwrap_or("");
                    match index.parse::<i64>() {
                        Ok(0) => {
                            return Some((line, "face index 0 (OBJ indices start at 1)".into()));
                        }
                        Ok(i) if i > vertices || -i > vertices => {
                            return Some((
                                line,
                                format!(
                                    "face index {i} is out of range: {vertices} vertices are defined before this line"
                                ),
                            ));
                        }
                        Ok(_) => {}
                        Err(_) => {
                            return Some((line, format!("cannot read face corner `{corner}`")));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_lines_are_found() {
        assert_eq!(find_bad_line("v 0 0 0\nv 1 nan 0\n").unwrap().0, 2);
        assert_eq!(find_bad_line("v 0 0 0\nv 1 inf 0\n").unwrap().0, 2);
        assert_eq!(find_bad_line("v 0 0 0\n\nf 1 2 3\n").unwrap().0, 3);
        assert_eq!(find_bad_line("v 0 0 0\nf 1 -2 1\n").unwrap().0, 2);
        assert!(find_bad_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 -1/3\n").is_none());
    }
}
