//! OBJ input: `v` and `f` lines, polygons kept, vertices numbered exactly as in the file (so
//! errors can name the file's vertex, and unused vertices stay visible to the checks that
//! refuse them). Texture and normal indices of `f` corners are read past; other statements
//! (groups, materials, lines, points) are ignored.

use super::Mesh;
use crate::error::{Error, Result};
use glam::DVec3;
use std::path::Path;

pub(super) fn load_obj(path: &Path) -> Result<Mesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let (positions, polygons) = parse_obj(&text).map_err(|(line, message)| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    })?;
    Ok(Mesh::from_polygons(path, positions, &polygons))
}

/// Positions and polygons (0-based indices).
type Parsed = (Vec<DVec3>, Vec<Vec<u32>>);

/// Parses OBJ text, or names the first bad line: `(1-based line, message)`.
fn parse_obj(text: &str) -> std::result::Result<Parsed, (usize, String)> {
    let mut positions = Vec::new();
    let mut polygons = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.take(3).collect();
                if coords.len() < 3 {
                    return Err((line, "vertex has fewer than 3 coordinates".into()));
                }
                let mut p = [0.0; 3];
                for (x, c) in p.iter_mut().zip(coords) {
                    *x = match c.parse::<f64>() {
                        Ok(x) if x.is_finite() => x,
                        Ok(_) => return Err((line, format!("non-finite vertex coordinate `{c}`"))),
                        Err(_) => return Err((line, format!("cannot read coordinate `{c}`"))),
                    };
                }
                positions.push(DVec3::from_array(p));
            }
            Some("f") => {
                let vertices = positions.len() as i64;
                let mut polygon = Vec::new();
                for corner in words {
                    let index = corner.split('/').next().unwrap_or("");
                    let i = match index.parse::<i64>() {
                        Ok(0) => {
                            return Err((line, "face index 0 (OBJ indices start at 1)".into()));
                        }
                        // Negative indices count back from the last vertex read so far.
                        Ok(i) if i < 0 => vertices + i,
                        Ok(i) => i - 1,
                        Err(_) => {
                            return Err((line, format!("cannot read face corner `{corner}`")));
                        }
                    };
                    if i < 0 || i >= vertices {
                        return Err((
                            line,
                            format!(
                                "face index {index} is out of range: {vertices} vertices are defined before this line"
                            ),
                        ));
                    }
                    polygon.push(i as u32);
                }
                polygons.push(polygon);
            }
            _ => {}
        }
    }
    Ok((positions, polygons))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bad_line(text: &str) -> Option<usize> {
        parse_obj(text).err().map(|(line, _)| line)
    }

    #[test]
    fn bad_lines_are_found() {
        assert_eq!(bad_line("v 0 0 0\nv 1 nan 0\n"), Some(2));
        assert_eq!(bad_line("v 0 0 0\nv 1 inf 0\n"), Some(2));
        assert_eq!(bad_line("v 0 0 0\n\nf 1 2 3\n"), Some(3));
        assert_eq!(bad_line("v 0 0 0\nf 1 -2 1\n"), Some(2));
        assert_eq!(
            bad_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 -1/3\n"),
            None
        );
    }

    #[test]
    fn vertices_keep_file_numbering() {
        let (positions, polygons) =
            parse_obj("v 0 0 0\nv 9 9 9\nv 1 0 0\nvt 0 0\nv 0 1 0\nf 1/1 3/1 -1/1\n").unwrap();
        assert_eq!(positions.len(), 4);
        assert_eq!(polygons, vec![vec![0, 2, 3]]);
    }
}
