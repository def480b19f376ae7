//! OBJ input: `v` (with an optional `r g b` colour), `f` and `l` (polyline) statements,
//! polygons kept, vertices numbered exactly as in the file (so errors can name the file's
//! vertex, and unused vertices stay visible to the checks that refuse them). Texture and
//! normal indices of corners are read past; other statements (groups, materials, points)
//! are ignored.

use super::Mesh;
use crate::error::{Error, Result};
use glam::{DVec3, Vec3};
use std::path::Path;

pub(super) fn load_obj(path: &Path) -> Result<Mesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    // A byte-order mark is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let parsed = parse_obj(text).map_err(|(line, message)| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    })?;
    let mut mesh = Mesh::from_polygons(path, parsed.positions, &parsed.polygons);
    mesh.colors = parsed.colors;
    mesh.polylines = parsed.polylines;
    Ok(mesh)
}

/// What an OBJ file holds (0-based indices).
#[derive(Debug, Default)]
struct Parsed {
    positions: Vec<DVec3>,
    /// One colour per vertex, or none at all.
    colors: Vec<Vec3>,
    polygons: Vec<Vec<u32>>,
    polylines: Vec<Vec<u32>>,
}

type LineError = (usize, String);

/// Reads `N` finite numbers from `words`.
fn numbers<'a, const N: usize>(
    words: &mut impl Iterator<Item = &'a str>,
    what: &str,
    line: usize,
) -> std::result::Result<[f64; N], LineError> {
    let mut out = [0.0; N];
    for x in out.iter_mut() {
        let c = words
            .next()
            .ok_or_else(|| (line, format!("{what} has fewer than {N} numbers")))?;
        *x = match c.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            Ok(_) => return Err((line, format!("non-finite {what} value `{c}`"))),
            Err(_) => return Err((line, format!("cannot read {what} value `{c}`"))),
        };
    }
    Ok(out)
}

/// The 0-based vertex indices of an `f` or `l` statement's corners.
fn corners<'a>(
    words: impl Iterator<Item = &'a str>,
    vertices: i64,
    what: &str,
    line: usize,
) -> std::result::Result<Vec<u32>, LineError> {
    let mut out = Vec::new();
    for corner in words {
        let index = corner.split('/').next().unwrap_or("");
        let i = match index.parse::<i64>() {
            Ok(0) => return Err((line, format!("{what} index 0 (OBJ indices start at 1)"))),
            // Negative indices count back from the last vertex read so far.
            Ok(i) if i < 0 => vertices + i,
            Ok(i) => i - 1,
            Err(_) => return Err((line, format!("cannot read {what} corner `{corner}`"))),
        };
        if i < 0 || i >= vertices {
            return Err((
                line,
                format!(
                    "{what} index {index} is out of range: {vertices} vertices are defined before this line"
                ),
            ));
        }
        out.push(i as u32);
    }
    Ok(out)
}

/// Parses OBJ text, or names the first bad line: `(1-based line, message)`.
fn parse_obj(text: &str) -> std::result::Result<Parsed, LineError> {
    let mut out = Parsed::default();
    // The first vertex line with a colour and the first without: a file must not mix them.
    let (mut colored, mut plain) = (None, None);
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                out.positions
                    .push(DVec3::from_array(numbers::<3>(&mut words, "vertex", line)?));
                let rest: Vec<&str> = words.collect();
                if rest.len() >= 3 {
                    let c = numbers::<3>(&mut rest.into_iter(), "vertex colour", line)?;
                    out.colors.push(DVec3::from_array(c).as_vec3());
                    colored.get_or_insert(line);
                } else {
                    plain.get_or_insert(line);
                }
                if let (Some(c), Some(p)) = (colored, plain) {
                    return Err((
                        line,
                        format!(
                            "vertices mix colours (line {c} has `r g b`) and no colours (line {p}); give every vertex a colour or none"
                        ),
                    ));
                }
            }
            Some("f") => {
                let polygon = corners(words, out.positions.len() as i64, "face", line)?;
                out.polygons.push(polygon);
            }
            Some("l") => {
                let polyline = corners(words, out.positions.len() as i64, "line", line)?;
                if polyline.len() < 2 {
                    return Err((line, "a line needs 2 or more vertices".into()));
                }
                out.polylines.push(polyline);
            }
            _ => {}
        }
    }
    Ok(out)
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
        let parsed =
            parse_obj("v 0 0 0\nv 9 9 9\nv 1 0 0\nvt 0 0\nv 0 1 0\nf 1/1 3/1 -1/1\n").unwrap();
        assert_eq!(parsed.positions.len(), 4);
        assert_eq!(parsed.polygons, vec![vec![0, 2, 3]]);
        assert!(parsed.colors.is_empty());
    }

    #[test]
    fn colours_and_polylines_are_read() {
        let parsed =
            parse_obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nl 1 2 3 1\nl 3/1 -3\n")
                .unwrap();
        assert_eq!(parsed.colors[1], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(parsed.polylines, vec![vec![0, 1, 2, 0], vec![2, 0]]);
        assert_eq!(bad_line("v 0 0 0 1 1 1\nv 1 1 1\n"), Some(2));
        assert_eq!(bad_line("v 0 0 0\nl 1\n"), Some(2));
        assert_eq!(bad_line("v 0 0 0\nv 1 0 0\nl 1 3\n"), Some(3));
        assert_eq!(bad_line("v 0 0 0 1 x 1\n"), Some(1));
    }
}
