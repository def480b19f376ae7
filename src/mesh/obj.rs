//! OBJ input: `v` (with an optional `r g b` colour), `f` and `l` (polyline) statements,
//! polygons kept, vertices numbered exactly as in the file (so errors can name the file's
//! vertex, and unused vertices stay visible to the checks that refuse them). Texture
//! coordinates (`vt`) and normals (`vn`) become the attributes `uv` and `vertex_normal` when
//! every face corner names one (`f v/vt/vn`); otherwise they are reported unread, with the
//! first line that lacks one. Other statements (groups, materials, points) are ignored.

use super::Mesh;
use super::attributes::{AttributeKind, VertexAttribute};
use crate::error::{Error, Result};
use crate::huge_pages::vec_to_fill;
use crate::parallel_concat::{concat, concat_with};
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
    let mut attributes = Vec::new();
    let mut unread = Vec::new();
    for (stream, name, kind) in [
        (parsed.texture, "uv", AttributeKind::TextureCoordinates),
        (parsed.normals, "vertex_normal", AttributeKind::Normal),
    ] {
        let every_corner = stream.corners.len() == parsed.indices.len();
        match stream.trouble {
            _ if stream.values.is_empty() || parsed.indices.is_empty() => {}
            None if every_corner => attributes.push(VertexAttribute {
                name: name.into(),
                kind,
                values: stream.values,
                corners: stream.corners,
            }),
            Some((line, why)) => unread.push(format!("{} (line {line}: {why})", stream.what)),
            None => unread.push(stream.what.to_string()),
        }
    }
    Ok(Mesh {
        positions: parsed.positions,
        indices: parsed.indices,
        face_starts: parsed.face_starts,
        colors: parsed.colors,
        polylines: parsed.polylines,
        source: path.to_path_buf(),
        attributes,
        unread,
        ..Default::default()
    })
}

/// The whole file as text (UTF-8), read into one buffer of its size in pieces on all threads:
/// a fresh buffer's pages are made as they are first written, which on one thread took
/// longer than the copy (igea's 11 MB: about 10 ms before the parse could start).
fn read_text(path: &Path) -> Result<String> {
    use std::io::{Read, Seek, SeekFrom};
    use std::os::unix::fs::FileExt;
    const PIECE: usize = 1 << 20;
    let io_error = |e| Error::io(path, e);
    let mut file = std::fs::File::open(path).map_err(io_error)?;
    let size = file.metadata().map_err(io_error)?.len() as usize;
    let mut bytes = vec_to_fill(size + 1);
    if size > 0 {
        bytes.par_extend(rayon::iter::repeat_n(0u8, size));
        bytes
            .par_chunks_mut(PIECE)
            .enumerate()
            .try_for_each(|(k, piece)| file.read_exact_at(piece, (k * PIECE) as u64))
            .map_err(io_error)?;
        file.seek(SeekFrom::Start(size as u64)).map_err(io_error)?;
    }
    // Whatever the file grew by since its size was taken (all of a pipe's).
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
    /// `vt` and `vn` values and the face corners' indices into them.
    texture: CornerValues,
    normals: CornerValues,
}

/// Values a face corner may name after its vertex (`f v/vt/vn`): `vt` or `vn` lines.
#[derive(Debug, Default)]
struct CornerValues {
    /// What the statements are, for messages.
    what: &'static str,
    values: Vec<Vec3>,
    /// One index per face corner while every corner names one.
    corners: Vec<u32>,
    /// The first line where a face corner names none or a bad one, and why: the values are
    /// then not read.
    trouble: Option<(usize, String)>,
}

impl CornerValues {
    fn new(what: &'static str) -> Self {
        CornerValues {
            what,
            ..Default::default()
        }
    }

    /// Takes a face corner's index `text` (empty: none) into values of which `defined` are
    /// defined so far.
    fn take(&mut self, text: Option<&str>, defined: i64, line: usize) {
        if self.trouble.is_some() {
            return;
        }
        match text
            .filter(|t| !t.is_empty())
            .map(|t| resolve(t, defined, self.what))
        {
            Some(Ok(i)) => self.corners.push(i),
            Some(Err(why)) => self.trouble = Some((line, why)),
            None => self.trouble = Some((line, "a face corner names none".into())),
        }
    }

    /// Appends a later piece's values and corners.
    fn join(&mut self, later: CornerValues) {
        self.values.extend(later.values);
        self.corners.extend(later.corners);
        self.trouble = self.trouble.take().or(later.trouble);
    }
}

/// How many lines, and of each vertex statement, come before a piece of text.
#[derive(Clone, Copy, Debug, Default)]
struct Counts {
    lines: usize,
    positions: usize,
    texture: usize,
    normals: usize,
}

impl std::ops::Add for Counts {
    type Output = Counts;
    fn add(self, o: Counts) -> Counts {
        Counts {
            lines: self.lines + o.lines,
            positions: self.positions + o.positions,
            texture: self.texture + o.texture,
            normals: self.normals + o.normals,
        }
    }
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

/// The 0-based index an OBJ index `text` names among `defined` values (`noun`): 1-based,
/// negative counting back from the last.
fn resolve(text: &str, defined: i64, noun: &str) -> std::result::Result<u32, String> {
    let i = match text.parse::<i64>() {
        Ok(0) => return Err("index 0 (OBJ indices start at 1)".into()),
        Ok(i) if i < 0 => defined + i,
        Ok(i) => i - 1,
        Err(_) => return Err(format!("cannot read index `{text}`")),
    };
    if i < 0 || i >= defined {
        return Err(format!(
            "index {text} is out of range: {defined} {noun} are defined before this line"
        ));
    }
    Ok(i as u32)
}

/// Appends the 0-based vertex indices of an `f` or `l` statement's corners to `out`, and a
/// face's texture and normal indices to `corner_values`.
fn corners<'a>(
    words: impl Iterator<Item = &'a str>,
    defined: Counts,
    what: &str,
    line: usize,
    out: &mut Vec<u32>,
    mut corner_values: Option<(&mut CornerValues, &mut CornerValues)>,
) -> std::result::Result<(), LineError> {
    for corner in words {
        let mut parts = corner.split('/');
        let index = parts.next().unwrap_or("");
        let i = resolve(index, defined.positions as i64, "vertices").map_err(|why| {
            if index.parse::<i64>().is_err() {
                (line, format!("cannot read {what} corner `{corner}`"))
            } else {
                (line, format!("{what} {why}"))
            }
        })?;
        out.push(i);
        if let Some((texture, normals)) = corner_values.as_mut() {
            texture.take(parts.next(), defined.texture as i64, line);
            normals.take(parts.next(), defined.normals as i64, line);
        }
    }
    Ok(())
}

/// Bytes per piece of text parsed on one thread (whole lines, so a little more).
const PIECE_BYTES: usize = 1 << 20;

/// Parses OBJ text, or names the first bad line: `(1-based line, message)`. The text is
/// parsed in pieces of whole lines on all threads, each told how many lines and vertex
/// statements come before it (negative indices count back from there), and the pieces
/// joined in order.
fn parse_obj(text: &str) -> std::result::Result<Parsed, LineError> {
    parse_in_pieces(text, PIECE_BYTES)
}

/// `parse_obj` with pieces of about `piece_bytes`.
fn parse_in_pieces(text: &str, piece_bytes: usize) -> std::result::Result<Parsed, LineError> {
    let pieces = whole_line_pieces(text, piece_bytes);
    let counts: Vec<Counts> = pieces.par_iter().map(|p| line_counts(p)).collect();
    let before = counts.iter().scan(Counts::default(), |sum, &c| {
        let at = *sum;
        *sum = *sum + c;
        Some(at)
    });
    let before: Vec<Counts> = before.collect();
    let parsed: Vec<Piece> = pieces
        .par_iter()
        .zip(before)
        .map(|(text, before)| parse_piece(text, before))
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

/// The lines of `text` and how many of them are `v`, `vt` and `vn` statements.
fn line_counts(text: &str) -> Counts {
    let mut counts = Counts::default();
    for line in text.lines() {
        counts.lines += 1;
        let b = line.as_bytes();
        let statement = match b {
            // The common forms, decided without splitting the line.
            [b'v', next, ..] if next.is_ascii_whitespace() => "v",
            [b'v', b't', next, ..] if next.is_ascii_whitespace() => "vt",
            [b'v', b'n', next, ..] if next.is_ascii_whitespace() => "vn",
            [first, ..] if first.is_ascii_graphic() => "",
            _ => line.split_whitespace().next().unwrap_or(""),
        };
        match statement {
            "v" => counts.positions += 1,
            "vt" => counts.texture += 1,
            "vn" => counts.normals += 1,
            _ => {}
        }
    }
    counts
}

/// A piece of a file parsed: what it holds, the first colour and plain vertex lines, and
/// the first bad line, where parsing stopped.
struct Piece {
    parsed: Parsed,
    first_colored: Option<usize>,
    first_plain: Option<usize>,
    error: Option<LineError>,
}

impl Piece {
    /// What is defined up to `line`, after `before`: what the corners' indices may name.
    fn defined(&self, before: Counts, line: usize) -> Counts {
        Counts {
            lines: line,
            positions: before.positions + self.parsed.positions.len(),
            texture: before.texture + self.parsed.texture.values.len(),
            normals: before.normals + self.parsed.normals.values.len(),
        }
    }

    /// A `v` statement's position and, where it has one, its colour.
    fn push_vertex(&mut self, position: DVec3, colour: Option<DVec3>, line: usize) {
        self.parsed.positions.push(position);
        match colour {
            Some(c) => {
                self.parsed.colors.push(c.as_vec3());
                self.first_colored.get_or_insert(line);
            }
            None => {
                self.first_plain.get_or_insert(line);
            }
        }
    }
}

/// Parses the lines of a piece, after the lines and vertex statements of `before`.
fn parse_piece(text: &str, before: Counts) -> Piece {
    let mut piece = Piece {
        parsed: Parsed {
            positions: Vec::new(),
            colors: Vec::new(),
            indices: Vec::new(),
            face_starts: Vec::new(),
            polylines: Vec::new(),
            texture: CornerValues::new("texture coordinates (vt)"),
            normals: CornerValues::new("normals (vn)"),
        },
        first_colored: None,
        first_plain: None,
        error: None,
    };
    for (n, raw) in text.lines().enumerate() {
        let line = before.lines + n + 1;
        if let Err(e) = parse_line(raw, line, before, &mut piece) {
            piece.error = Some(e);
            break;
        }
    }
    piece
}

/// Parses one line into `piece`: the common forms (`v x y z [r g b]`, and `f` with plain
/// positive vertex numbers) from their bytes, every other line, and any of these that those
/// do not take, word by word (`parse_words`), which also names what is wrong with a line.
fn parse_line(
    raw: &str,
    line: usize,
    before: Counts,
    piece: &mut Piece,
) -> std::result::Result<(), LineError> {
    let taken = match raw.as_bytes() {
        [b'v', b' ' | b'\t', ..] => plain_vertex(raw, line, piece),
        [b'f', b' ' | b'\t', ..] => plain_face(raw, line, before, piece),
        _ => false,
    };
    if taken {
        return Ok(());
    }
    parse_words(raw, line, before, piece)
}

/// The words of `raw` after its statement: runs of bytes between spaces and tabs, when
/// there are at most `N` and every byte is printable ASCII, a space or a tab (any other
/// separator is left to `parse_words`' Unicode whitespace).
fn plain_words<const N: usize>(raw: &str) -> Option<([&str; N], usize)> {
    let mut words = [""; N];
    let mut count = 0;
    let mut start = None;
    for (i, &b) in raw.as_bytes().iter().enumerate().skip(1) {
        match b {
            b' ' | b'\t' => {
                if let Some(s) = start.take() {
                    *words.get_mut(count)? = &raw[s..i];
                    count += 1;
                }
            }
            b'!'..=b'~' => {
                start.get_or_insert(i);
            }
            _ => return None,
        }
    }
    if let Some(s) = start {
        *words.get_mut(count)? = &raw[s..];
        count += 1;
    }
    Some((words, count))
}

/// A `v` line of three or six finite numbers into `piece`; whether it took the line.
fn plain_vertex(raw: &str, line: usize, piece: &mut Piece) -> bool {
    let Some((words, count)) = plain_words::<6>(raw) else {
        return false;
    };
    if count != 3 && count != 6 {
        return false;
    }
    let mut values = [0.0; 6];
    for (value, word) in values.iter_mut().zip(&words[..count]) {
        match word.parse::<f64>() {
            Ok(x) if x.is_finite() => *value = x,
            _ => return false,
        }
    }
    let colour = (count == 6).then(|| DVec3::new(values[3], values[4], values[5]));
    piece.push_vertex(DVec3::new(values[0], values[1], values[2]), colour, line);
    true
}

/// Corners an `f` line may have for `plain_face`; longer faces are read word by word.
const PLAIN_FACE_CORNERS: usize = 8;

/// An `f` line of plain vertex numbers (1 to the vertices defined so far) into `piece`;
/// whether it took the line.
fn plain_face(raw: &str, line: usize, before: Counts, piece: &mut Piece) -> bool {
    let Some((words, count)) = plain_words::<PLAIN_FACE_CORNERS>(raw) else {
        return false;
    };
    let defined = piece.defined(before, line);
    let mut corners = [0u32; PLAIN_FACE_CORNERS];
    for (corner, word) in corners.iter_mut().zip(&words[..count]) {
        // At most 10 digits: no overflow in u64.
        if word.len() > 10 || !word.bytes().all(|b| b.is_ascii_digit()) {
            return false;
        }
        let n = word.bytes().fold(0u64, |n, b| 10 * n + u64::from(b - b'0'));
        if n == 0 || n > defined.positions as u64 {
            return false;
        }
        *corner = (n - 1) as u32;
    }
    if count == 0 {
        return false;
    }
    let out = &mut piece.parsed;
    out.indices.extend_from_slice(&corners[..count]);
    // As a corner naming no `vt` or `vn` would in `corners`.
    out.texture.take(None, defined.texture as i64, line);
    out.normals.take(None, defined.normals as i64, line);
    out.face_starts.push(out.indices.len() as u32);
    true
}

/// Parses one line into `piece` word by word.
fn parse_words(
    raw: &str,
    line: usize,
    before: Counts,
    piece: &mut Piece,
) -> std::result::Result<(), LineError> {
    let defined = piece.defined(before, line);
    let out = &mut piece.parsed;
    let mut words = raw.split_whitespace();
    match words.next() {
        Some("v") => {
            let position = DVec3::from_array(numbers::<3>(&mut words, "vertex", line)?);
            let colour = match [words.next(), words.next(), words.next()] {
                [Some(r), Some(g), Some(b)] => Some(DVec3::from_array(numbers::<3>(
                    &mut [r, g, b].into_iter(),
                    "vertex colour",
                    line,
                )?)),
                _ => None,
            };
            piece.push_vertex(position, colour, line);
        }
        Some("f") => {
            let streams = Some((&mut out.texture, &mut out.normals));
            corners(words, defined, "face", line, &mut out.indices, streams)?;
            out.face_starts.push(out.indices.len() as u32);
        }
        Some("l") => {
            let mut polyline = Vec::new();
            corners(words, defined, "line", line, &mut polyline, None)?;
            if polyline.len() < 2 {
                return Err((line, "a line needs 2 or more vertices".into()));
            }
            out.polylines.push(polyline);
        }
        // `vt u [v [w]]`: v defaults to 0; w is dropped. A bad value spoils the attribute,
        // not the shape.
        Some("vt") => {
            let uv: Vec<f64> = words.take(2).map_while(|w| w.parse().ok()).collect();
            let value = match uv[..] {
                [u] => Vec3::new(u as f32, 0.0, 0.0),
                [u, v] => Vec3::new(u as f32, v as f32, 0.0),
                _ => Vec3::NAN,
            };
            vertex_value(&mut out.texture, value, line);
        }
        Some("vn") => {
            let n = numbers::<3>(&mut words, "normal", line).map_or(Vec3::NAN, |n| {
                DVec3::from_array(n).normalize_or_zero().as_vec3()
            });
            vertex_value(&mut out.normals, n, line);
        }
        _ => {}
    }
    Ok(())
}

/// Adds a `vt` or `vn` value; one that is not finite spoils its attribute.
fn vertex_value(stream: &mut CornerValues, value: Vec3, line: usize) {
    if !value.is_finite() && stream.trouble.is_none() {
        stream.trouble = Some((line, "not a finite value".into()));
    }
    stream.values.push(value);
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
    let (mut positions, mut colors, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let mut polylines = Vec::new();
    let mut texture = CornerValues::new("texture coordinates (vt)");
    let mut normals = CornerValues::new("normals (vn)");
    // The first face starts at 0; a piece's faces end where they end in all the indices,
    // after the pieces before its own.
    let mut face_ends = vec![vec![0u32]];
    let mut shifts = vec![0u32];
    let mut before = 0;
    for piece in pieces {
        let p = piece.parsed;
        shifts.push(before);
        before += p.indices.len() as u32;
        positions.push(p.positions);
        colors.push(p.colors);
        indices.push(p.indices);
        face_ends.push(p.face_starts);
        polylines.extend(p.polylines);
        texture.join(p.texture);
        normals.join(p.normals);
    }
    Ok(Parsed {
        positions: concat(positions),
        colors: concat(colors),
        indices: concat(indices),
        face_starts: concat_with(face_ends, |k, end| end + shifts[k]),
        polylines,
        texture,
        normals,
    })
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
            "v 0 0 0\nv 1 0 0\nvt 0 0\nvt 1 0\nvn 0 0 1\nv 0 1 0\nvt 0 1\nf 1/1/1 2/-2/1 3/-1/-1\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2 3\nf 1/4 2/1 3/1\n",
        ] {
            same_in_pieces(text);
        }
    }

    /// The lines of `text` parsed word by word alone, as a piece.
    fn by_words(text: &str) -> String {
        let mut piece = parse_piece("", Counts::default());
        for (n, raw) in text.lines().enumerate() {
            if let Err(e) = parse_words(raw, n + 1, Counts::default(), &mut piece) {
                piece.error = Some(e);
                break;
            }
        }
        described(piece)
    }

    /// All that a piece holds, to compare.
    fn described(piece: Piece) -> String {
        let Piece {
            parsed,
            first_colored,
            first_plain,
            error,
        } = piece;
        format!("{parsed:?} {first_colored:?} {first_plain:?} {error:?}")
    }

    /// The byte-level readers of `v` and `f` lines take what reading word by word takes, the
    /// same way, and leave the rest to it (their messages included).
    #[test]
    fn plain_lines_read_as_word_by_word() {
        let vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
        for lines in [
            "f 1 2 3\nf\t4 3  2 \nf 1 2 3 4 1 2 3 4\nf 1 2 3 4 1 2 3 4 1\nf 01 0002 3\n",
            "f 1 2 5\n",
            "f 0 1 2\n",
            "f +1 2 3\n",
            "f 1 2 3\u{a0}\n",
            "f 1 2 99999999999\n",
            "f 1/1 2 3\n",
            "f -1 -2 -3\n",
            "f\n",
            "f \n",
            "v 1 2 3 4\nv 1 2 3 4 5\nv 1 2 3 0.5 0.5 0.5\nv 1 2 3 4 5 6 7\n",
            "v 1e3 -2.5 .5\r\nv 1\t2\t3\n",
            "v 1 2\n",
            "v 1 2 nan\n",
            "v 1 2 inf 1 1 1\n",
            "v 1 2 3 1 1 x\n",
            "v 1\u{a0}2 3\n",
            "v 1 2 3\u{0b}\n",
            "v 1 2 3\rv 4 5 6\n",
        ] {
            let text = format!("{vertices}{lines}");
            let fast = described(parse_piece(&text, Counts::default()));
            assert_eq!(fast, by_words(&text), "{lines:?}");
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
    fn corner_texture_coordinates_and_normals_are_read() {
        // A seam: vertex 1 takes uv 1 in the first face and uv 3 in the second.
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0.5 0.5\nvt 0 1\n\
                    vn 0 0 2\nf 1/1/1 2/2/1 3/4/1\nf 2/-2/-1 4/-1/1 3/-1/1\n";
        let parsed = parse_obj(text).unwrap();
        assert_eq!(parsed.texture.values.len(), 4);
        assert_eq!(parsed.texture.corners, vec![0, 1, 3, 2, 3, 3]);
        assert_eq!(parsed.normals.values, vec![Vec3::Z]);
        assert_eq!(parsed.normals.corners, vec![0; 6]);
        assert!(parsed.texture.trouble.is_none() && parsed.normals.trouble.is_none());
        // A face without texture coordinates, or with a bad index, spoils them (not the
        // shape), naming the line.
        let parsed =
            parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2 3\n").unwrap();
        assert_eq!(parsed.texture.trouble.as_ref().map(|t| t.0), Some(6));
        let parsed = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n").unwrap();
        let (line, why) = parsed.texture.trouble.unwrap();
        assert_eq!(line, 5);
        assert!(why.contains("out of range"), "{why}");
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
