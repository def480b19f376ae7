//! OFF input (Geomview's Object File Format, written by MeshLab, CGAL and many datasets):
//! `OFF` (or `COFF`, vertices with colours), the counts `vertices faces edges` (on the same
//! line or the next), the vertices `x y z [r g b [a]]`, then the faces `n v1 .. vn [colour]`.
//! Vertices are numbered from 0 as the file numbers them; `#` starts a comment. Colours are
//! 0..1 floats or 0..255 integers, kept as the mesh's vertex colours (`Cd`). Meshes are
//! written back as OFF too.

use super::Mesh;
use crate::error::{Error, Result};
use glam::{DVec3, Vec3};
use std::path::Path;

pub(super) fn load_off(path: &Path) -> Result<Mesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let (positions, colors, polygons) =
        parse_off(text).map_err(|(line, message)| Error::Parse {
            path: path.to_path_buf(),
            line,
            message,
        })?;
    let mut mesh = Mesh::from_polygons(path, positions, &polygons);
    mesh.colors = colors;
    mesh.numbered_from_zero = true;
    Ok(mesh)
}

impl Mesh {
    /// Writes the mesh as OFF (COFF when it has vertex colours), atomically; coordinates
    /// round-trip exactly.
    pub fn write_off(&self, path: &Path) -> Result<()> {
        use std::fmt::Write as _;
        let colored = !self.colors.is_empty();
        let mut s = String::from(if colored { "COFF\n" } else { "OFF\n" });
        let _ = writeln!(s, "{} {} 0", self.positions.len(), self.face_count());
        for (i, p) in self.positions.iter().enumerate() {
            let _ = write!(s, "{} {} {}", p.x, p.y, p.z);
            if let Some(c) = self.colors.get(i).filter(|_| colored) {
                let _ = write!(s, " {} {} {}", c.x, c.y, c.z);
            }
            s.push('\n');
        }
        for f in 0..self.face_count() {
            let face = self.face(f);
            let _ = write!(s, "{}", face.len());
            for &v in face {
                let _ = write!(s, " {v}");
            }
            s.push('\n');
        }
        crate::io::atomic::write_atomic(path, |tmp| {
            std::fs::write(tmp, s.as_bytes()).map_err(|e| Error::io(tmp, e))
        })
    }
}

type Parsed = (Vec<DVec3>, Vec<Vec3>, Vec<Vec<u32>>);

/// The file's tokens line by line, comments and blank lines left out, with 1-based line
/// numbers.
fn lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let words: Vec<&str> = l
            .split('#')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .collect();
        (!words.is_empty()).then_some((i + 1, words))
    })
}

fn number<T: std::str::FromStr>(
    word: &str,
    line: usize,
    what: &str,
) -> std::result::Result<T, (usize, String)> {
    word.parse()
        .map_err(|_| (line, format!("{what} `{word}` is not a number")))
}

fn parse_off(text: &str) -> std::result::Result<Parsed, (usize, String)> {
    let mut lines = lines(text);
    let (first, mut words) = lines.next().ok_or((1, "the file is empty".to_string()))?;
    let colored = match words[0] {
        "OFF" => false,
        "COFF" => true,
        other => {
            return Err((
                first,
                format!("an OFF file starts with OFF or COFF, not `{other}`"),
            ));
        }
    };
    words.remove(0);
    let (count_line, counts) = if words.is_empty() {
        lines
            .next()
            .ok_or((first, "the vertex and face counts are missing".to_string()))?
    } else {
        (first, words)
    };
    if counts.len() < 2 {
        return Err((
            count_line,
            "expected the counts `vertices faces edges`".into(),
        ));
    }
    let nv: usize = number(counts[0], count_line, "the vertex count")?;
    let nf: usize = number(counts[1], count_line, "the face count")?;
    // Each vertex and face takes a line: never reserve more than the text can hold.
    let room = text.len() / 2 + 1;
    let mut positions = Vec::with_capacity(nv.min(room));
    let mut colors = Vec::new();
    for k in 0..nv {
        let (line, w) = lines.next().ok_or((
            count_line,
            format!("the file ends after {k} of its {nv} vertices"),
        ))?;
        if w.len() < 3 {
            return Err((line, format!("vertex {k} needs x y z")));
        }
        let p: Vec<f64> = (0..3)
            .map(|a| number(w[a], line, "a coordinate"))
            .collect::<std::result::Result<_, _>>()?;
        positions.push(DVec3::new(p[0], p[1], p[2]));
        if colored {
            if w.len() < 6 {
                return Err((
                    line,
                    format!("vertex {k} of a COFF file needs a colour r g b"),
                ));
            }
            let c: Vec<f32> = (3..6)
                .map(|a| number(w[a], line, "a colour"))
                .collect::<std::result::Result<_, _>>()?;
            // Integers 0..255 or floats 0..1.
            let integer = w[3..6].iter().all(|s| !s.contains('.')) && c.iter().any(|&v| v > 1.0);
            let scale = if integer { 255.0 } else { 1.0 };
            colors.push(Vec3::new(c[0], c[1], c[2]) / scale);
        }
    }
    let mut polygons = Vec::with_capacity(nf.min(room));
    for f in 0..nf {
        let (line, w) = lines.next().ok_or((
            count_line,
            format!("the file ends after {f} of its {nf} faces"),
        ))?;
        let n: usize = number(w[0], line, "a face's corner count")?;
        if n < 3 || w.len() < 1 + n {
            return Err((
                line,
                format!("face {f} announces {n} corners and lists {}", w.len() - 1),
            ));
        }
        let mut face = Vec::with_capacity(n);
        for word in &w[1..=n] {
            let v: usize = number(word, line, "a vertex index")?;
            if v >= nv {
                return Err((
                    line,
                    format!(
                        "face {f} uses vertex {v}, but the file has vertices 0..{}",
                        nv.saturating_sub(1)
                    ),
                ));
            }
            face.push(v as u32);
        }
        polygons.push(face);
    }
    if let Some((line, _)) = lines.next() {
        return Err((
            line,
            format!("text after the {nv} vertices and {nf} faces the counts announce"),
        ));
    }
    Ok((positions, colors, polygons))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_on_the_header_line_comments_and_colours() {
        let (p, c, f) = parse_off(
            "COFF 4 2 0 # a square\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 255 255 255\n\
             3 0 1 2\n3 0 2 3 10 20 30\n",
        )
        .unwrap();
        assert_eq!(p.len(), 4);
        assert_eq!(c[0], Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(f, vec![vec![0, 1, 2], vec![0, 2, 3]]);
    }

    #[test]
    fn errors_name_the_line() {
        let bad = [
            ("PLY\n", 1, "starts with OFF"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n",
                2,
                "ends after 2 of its 3 vertices",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 x\n3 0 1 2\n",
                5,
                "not a number",
            ),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 6, "vertex 3"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
                6,
                "announces 4 corners",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n",
                7,
                "text after",
            ),
        ];
        for (text, line, words) in bad {
            let (l, message) = parse_off(text).unwrap_err();
            assert_eq!(l, line, "{text:?}: {message}");
            assert!(message.contains(words), "{text:?}: {message}");
        }
    }
}
