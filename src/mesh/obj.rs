//! OBJ input: `v` (with an optional `r g b` colour), `f` and `l` (polyline) statements,
//! polygons kept, vertices numbered exactly as in the file (so errors can name the file's
//! vertex, and unused vertices stay visible to the checks that refuse them). Texture and
//! normal indices of corners are read past; other statements (groups, materials, points)
//! are ignored.

use super::Mesh;
use crate::error::{Error, Result};
use crate::huge_pages::vec_to_fill;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::path::Path;

pub(super) fn load_obj(path: &Path) -> Result<Mesh> {
    let text = read_text(path)?;
    // A byte-order mark is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let parsed = parse_obj(text).map_err(|(line, message)| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    })?;
    let unread = [
        (parsed.texture_coordinates, "texture coordinates (vt)"),
        (parsed.normals, "normals (vn)"),
    ]
    .into_iter()
    .filter(|&(count, _)| count > 0)
    .map(|(_, what)| what.to_string())
    .collect();
    Ok(Mesh {
        positions: parsed.positions,
        indices: parsed.indices,
        face_starts: parsed.face_starts,
        colors: parsed.colors,
        polylines: parsed.polylines,
        source: path.to_path_buf(),
        unread,
        ..Default::default()
    })
}

/// The whole file as text (UTF-8), read into one buffer of its size.
fn read_text(path: &Path) -> Result<String> {
    use std::io::Read;
    let io_error = |e| Error::io(path, e);
    let mut file = std::fs::File::open(path).map_err(io_error)?;
    let size = file.metadata().map_err(io_error)?.len() as usize;
    let mut bytes = vec_to_fill(size + 1);
    file.read_to_end(&mut bytes).map_err(io_error)?;
    String::from_utf8(bytes).map_err(|e| {
        io_error(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text: {}", e.utf8_error()),
        ))
    })
}

/// What an OBJ file holds (0-based indices): polygons as `Mesh` keeps them, their corners
/// in one list (a few hundred thousand small lists cost more to allocate than to parse).
#[derive(Debug)]
struct Parsed {
    positions: Vec<DVec3>,
    /// One colour per vertex, or none at all.
    colors: Vec<Vec3>,
    indices: Vec<u32>,
    /// Where each polygon starts in `indices`, and where the last ends.
    face_starts: Vec<u32>,
    polylines: Vec<Vec<u32>>,
    /// Texture coordinate (`vt`) and normal (`vn`) lines.
    texture_coordinates: usize,
    normals: usize,
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

/// Appends the 0-based vertex indices of an `f` or `l` statement's corners to `out`.
fn corners<'a>(
    words: impl Iterator<Item = &'a str>,
    vertices: i64,
    what: &str,
    line: usize,
    out: &mut Vec<u32>,
) -> std::result::Result<(), LineError> {
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
    Ok(())
}

/// Bytes per piece of text parsed on one thread (whole lines, so a little more).
const PIECE_BYTES: usize = 1 << 20;

/// Parses OBJ text, or names the first bad line: `(1-based line, message)`. The text is
/// parsed in pieces of whole lines on all threads, each told how many lines and vertices
/// come before it (negative indices count back from there), and the pieces joined in order.
fn parse_obj(text: &str) -> std::result::Result<Parsed, LineError> {
    parse_in_pieces(text, PIECE_BYTES)
}

/// `parse_obj` with pieces of about `piece_bytes`.
fn parse_in_pieces(text: &str, piece_bytes: usize) -> std::result::Result<Parsed, LineError> {
    let pieces = whole_line_pieces(text, piece_bytes);
    let counts: Vec<(usize, usize)> = pieces.par_iter().map(|p| line_counts(p)).collect();
    let mut before = Vec::with_capacity(pieces.len());
    let (mut lines, mut vertices) = (0, 0);
    for &(l, v) in &counts {
        before.push((lines, vertices));
        lines += l;
        vertices += v;
    }
    let parsed: Vec<Piece> = pieces
        .par_iter()
        .zip(before)
        .map(|(text, (lines, vertices))| parse_piece(text, lines, vertices))
        .collect();
    join_pieces(parsed)
}

/// `text` cut after newlines into pieces of about `piece_bytes`.
fn whole_line_pieces(text: &str, piece_bytes: usize) -> Vec<&str> {
    let mut pieces = Vec::new();
    let mut rest = text;
    while rest.len() > piece_bytes {
        let cut = match rest.as_bytes()[piece_bytes..]
            .iter()
            .position(|&b| b == b'\n')
        {
            Some(at) => piece_bytes + at + 1,
            None => rest.len(),
        };
        let (piece, after) = rest.split_at(cut);
        pieces.push(piece);
        rest = after;
    }
    if !rest.is_empty() {
        pieces.push(rest);
    }
    pieces
}

/// The lines of `text` and how many of them are `v` statements.
fn line_counts(text: &str) -> (usize, usize) {
    let (mut lines, mut vertices) = (0, 0);
    for line in text.lines() {
        lines += 1;
        let b = line.as_bytes();
        let vertex = match b {
            // The common forms, decided without splitting the line.
            [b'v', next, ..] if next.is_ascii_whitespace() => true,
            [first, ..] if first.is_ascii_graphic() => false,
            _ => line.split_whitespace().next() == Some("v"),
        };
        vertices += usize::from(vertex);
    }
    (lines, vertices)
}

/// A piece of a file parsed: what it holds, the first colour and plain vertex lines, and
/// the first bad line, where parsing stopped.
struct Piece {
    parsed: Parsed,
    first_colored: Option<usize>,
    first_plain: Option<usize>,
    error: Option<LineError>,
}

/// Parses the lines of a piece, after `lines_before` lines and `vertices_before` vertices.
fn parse_piece(text: &str, lines_before: usize, vertices_before: usize) -> Piece {
    let mut piece = Piece {
        parsed: Parsed {
            positions: Vec::new(),
            colors: Vec::new(),
            indices: Vec::new(),
            face_starts: Vec::new(),
            polylines: Vec::new(),
            texture_coordinates: 0,
            normals: 0,
        },
        first_colored: None,
        first_plain: None,
        error: None,
    };
    for (n, raw) in text.lines().enumerate() {
        let line = lines_before + n + 1;
        if let Err(e) = parse_line(raw, line, vertices_before, &mut piece) {
            piece.error = Some(e);
            break;
        }
    }
    piece
}

/// Parses one line into `piece`.
fn parse_line(
    raw: &str,
    line: usize,
    vertices_before: usize,
    piece: &mut Piece,
) -> std::result::Result<(), LineError> {
    let out = &mut piece.parsed;
    let mut words = raw.split_whitespace();
    match words.next() {
        Some("v") => {
            out.positions
                .push(DVec3::from_array(numbers::<3>(&mut words, "vertex", line)?));
            let rest = [words.next(), words.next(), words.next()];
            if let [Some(r), Some(g), Some(b)] = rest {
                let c = numbers::<3>(&mut [r, g, b].into_iter(), "vertex colour", line)?;
                out.colors.push(DVec3::from_array(c).as_vec3());
                piece.first_colored.get_or_insert(line);
            } else {
                piece.first_plain.get_or_insert(line);
            }
        }
        Some("f") => {
            let vertices = (vertices_before + out.positions.len()) as i64;
            corners(words, vertices, "face", line, &mut out.indices)?;
            out.face_starts.push(out.indices.len() as u32);
        }
        Some("l") => {
            let mut polyline = Vec::new();
            let vertices = (vertices_before + out.positions.len()) as i64;
            corners(words, vertices, "line", line, &mut polyline)?;
            if polyline.len() < 2 {
                return Err((line, "a line needs 2 or more vertices".into()));
            }
            out.polylines.push(polyline);
        }
        Some("vt") => out.texture_coordinates += 1,
        Some("vn") => out.normals += 1,
        _ => {}
    }
    Ok(())
}

/// The pieces in file order as one file, or its first bad line. A file must not mix vertices
/// with and without colours: the first line where both kinds have been seen is bad.
fn join_pieces(pieces: Vec<Piece>) -> std::result::Result<Parsed, LineError> {
    let colored = pieces.iter().find_map(|p| p.first_colored);
    let plain = pieces.iter().find_map(|p| p.first_plain);
    let mixed = colored.zip(plain).map(|(c, p)| {
        (
            c.max(p),
            format!(
                "vertices mix colours (line {c} has `r g b`) and no colours (line {p}); give every vertex a colour or none"
            ),
        )
    });
    let error = pieces.iter().find_map(|p| p.error.clone());
    match (error, mixed) {
        (Some(e), Some(m)) => return Err(if m.0 < e.0 { m } else { e }),
        (Some(e), None) | (None, Some(e)) => return Err(e),
        (None, None) => {}
    }
    let total = |f: fn(&Parsed) -> usize| pieces.iter().map(|p| f(&p.parsed)).sum::<usize>();
    let mut out = Parsed {
        positions: vec_to_fill(total(|p| p.positions.len())),
        colors: vec_to_fill(total(|p| p.colors.len())),
        indices: vec_to_fill(total(|p| p.indices.len())),
        face_starts: vec_to_fill(total(|p| p.face_starts.len()) + 1),
        polylines: Vec::new(),
        texture_coordinates: total(|p| p.texture_coordinates),
        normals: total(|p| p.normals),
    };
    out.face_starts.push(0);
    for piece in pieces {
        let p = piece.parsed;
        let shift = out.indices.len() as u32;
        out.positions.extend(p.positions);
        out.colors.extend(p.colors);
        out.indices.extend(p.indices);
        out.face_starts
            .extend(p.face_starts.iter().map(|s| s + shift));
        out.polylines.extend(p.polylines);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bad_line(text: &str) -> Option<usize> {
        parse_obj(text).err().map(|(line, _)| line)
    }

    /// Cut into pieces of every small size, a text parses as it does whole.
    fn same_in_pieces(text: &str) {
        let whole = format!("{:?}", parse_in_pieces(text, usize::MAX));
        for piece_bytes in 1..12 {
            let cut = format!("{:?}", parse_in_pieces(text, piece_bytes));
            assert_eq!(cut, whole, "pieces of {piece_bytes} bytes: {text:?}");
        }
    }

    #[test]
    fn pieces_parse_as_the_whole() {
        for text in [
            "v 0 0 0\nv 1 0 0\r\nv 0 1 0\n  v 0 0 1\nf 1 2 3\nf -1 -2 -3\nf 4/1 -3/2 2//1\nl 1 -1\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\nv 0 0 1\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1 1 0 0\nf 1 2 3\nv 1 1 1 x\n",
            "v 0 0 0 1 0 0\n# comment\nv 1 0 0 0 1 0\nvt 0 0\nv 0 1 0\nf 1 2 3\n",
            "v 0 0 0\nv 1 nan 0\nv 0 0 0 1 1 1\n",
            "\u{a0}v 0 0 0\nv\t1 0 0\nv 0 1 0\nf 1 2 3",
        ] {
            same_in_pieces(text);
        }
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
        assert_eq!(parsed.indices, vec![0, 2, 3]);
        assert_eq!(parsed.face_starts, vec![0, 3]);
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
