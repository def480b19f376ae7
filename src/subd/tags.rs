//! OpenSubdiv's shape tags for a control mesh: `t` lines in the OBJ itself (as OpenSubdiv's
//! shape files write them) and in a `NAME.tags` sidecar next to `NAME.obj`.
//!
//! `t crease 2n/m/0 a0 b0 a1 b1 … s…` makes the edges (a_i, b_i) sharp (one sharpness for all,
//! or one per edge), `t corner n/m/0 v… s…` the vertices; vertex indices count from 0 in file
//! order. `interpolateboundary` and `smoothtriangles` are read for their default values only;
//! tags that would change the surface in ways voxelkit does not evaluate (hierarchical edits,
//! holes, Chaikin creasing, other boundary rules on open meshes) are refused by name, so that
//! a surface is never silently different from OpenSubdiv's.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The creases and corners of a control mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tags {
    /// Sharp edges as (vertex, vertex, sharpness); 10 and above is infinitely sharp.
    pub creases: Vec<(u32, u32, f32)>,
    /// Sharp vertices as (vertex, sharpness).
    pub corners: Vec<(u32, f32)>,
    /// Boundary rule asked for other than OpenSubdiv's default, with where it was asked.
    pub(crate) boundary_rule: Option<(String, Place)>,
    /// The files the tags came from.
    pub sources: Vec<PathBuf>,
}

/// A tag's line in its file, for errors found once the mesh is known.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Place {
    pub path: PathBuf,
    pub line: usize,
}

/// The biggest sidecar read (its lines are short tags; anything larger is not one).
const MOST_SIDECAR_BYTES: u64 = 64 << 20;

impl Tags {
    /// The tags of the control mesh in `path`: its own `t` lines when it is an OBJ, then
    /// those of `NAME.tags` beside it when that file exists.
    pub fn read(path: &Path) -> Result<Tags> {
        let mut tags = Tags::default();
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if is_obj {
            let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
            tags.parse(path, &text, true)?;
        }
        let sidecar = path.with_extension("tags");
        if let Ok(meta) = std::fs::metadata(&sidecar) {
            if meta.len() > MOST_SIDECAR_BYTES {
                return Err(Error::Parse {
                    path: sidecar,
                    line: 0,
                    message: format!(
                        "is {} bytes; a tags file of at most {MOST_SIDECAR_BYTES} bytes is read",
                        meta.len()
                    ),
                });
            }
            let text = std::fs::read_to_string(&sidecar).map_err(|e| Error::io(&sidecar, e))?;
            tags.parse(&sidecar, &text, false)?;
        }
        Ok(tags)
    }

    pub fn is_empty(&self) -> bool {
        self.creases.is_empty() && self.corners.is_empty()
    }

    /// Reads the `t` lines of `text`; in an OBJ every other line is the mesh's, in a sidecar
    /// only comments and blank lines may stand beside them.
    fn parse(&mut self, path: &Path, text: &str, in_obj: bool) -> Result<()> {
        let mut found = false;
        for (index, line) in text.lines().enumerate() {
            let place = Place {
                path: path.to_path_buf(),
                line: index + 1,
            };
            let mut words = line.split_whitespace();
            match words.next() {
                Some("t") => {
                    found = true;
                    self.parse_tag(&place, words.collect())?;
                }
                None => {}
                Some(w) if w.starts_with('#') || in_obj => {}
                Some(w) => {
                    return Err(parse_error(
                        &place,
                        format!("`{w}` is not a tag line (a tags file holds `t` lines)"),
                    ));
                }
            }
        }
        if found {
            self.sources.push(path.to_path_buf());
        }
        Ok(())
    }

    fn parse_tag(&mut self, place: &Place, words: Vec<&str>) -> Result<()> {
        let err = |message: String| Err(parse_error(place, message));
        let [name, counts, args @ ..] = words.as_slice() else {
            return err("a tag needs a name and its argument counts (`t NAME i/f/s ...`)".into());
        };
        let counts: Vec<usize> = counts.split('/').filter_map(|c| c.parse().ok()).collect();
        let [ints, floats, strings] = counts[..] else {
            return err(format!(
                "tag `{name}`: cannot read its argument counts (`integers/floats/strings`)"
            ));
        };
        if args.len() != ints + floats + strings {
            return err(format!(
                "tag `{name}` announces {ints}/{floats}/{strings} arguments but has {}",
                args.len()
            ));
        }
        let mut int_args = Vec::with_capacity(ints);
        for a in &args[..ints] {
            match a.parse::<u32>() {
                Ok(i) => int_args.push(i),
                Err(_) => return err(format!("tag `{name}`: `{a}` is not a vertex index")),
            }
        }
        let mut float_args = Vec::with_capacity(floats);
        for a in &args[ints..ints + floats] {
            match a.parse::<f32>() {
                Ok(s) if s.is_finite() && s >= 0.0 => float_args.push(s),
                _ => {
                    return err(format!(
                        "tag `{name}`: sharpness `{a}` is not a finite number of at least 0"
                    ));
                }
            }
        }
        let string_args = &args[ints + floats..];
        // One sharpness for every element, or one each.
        let sharpness = |elements: usize| -> Result<Vec<f32>> {
            match float_args.len() {
                1 => Ok(vec![float_args[0]; elements]),
                n if n == elements => Ok(float_args.clone()),
                n => Err(parse_error(
                    place,
                    format!(
                        "tag `{name}` has {n} sharpness values for {elements} elements (give \
                         one, or one each)"
                    ),
                )),
            }
        };
        match *name {
            "crease" => {
                if int_args.is_empty() || int_args.len() % 2 != 0 {
                    return err("tag `crease` needs vertex pairs, one per edge".into());
                }
                let s = sharpness(int_args.len() / 2)?;
                for (pair, s) in int_args.chunks(2).zip(s) {
                    self.creases.push((pair[0], pair[1], s));
                }
            }
            "corner" => {
                if int_args.is_empty() {
                    return err("tag `corner` needs vertices".into());
                }
                for (&v, s) in int_args.iter().zip(sharpness(int_args.len())?) {
                    self.corners.push((v, s));
                }
            }
            "interpolateboundary" => match int_args[..] {
                [1] => {}
                [0] => {
                    self.boundary_rule =
                        Some(("0 (no boundary interpolation)".into(), place.clone()))
                }
                [2] => self.boundary_rule = Some(("2 (edges only)".into(), place.clone())),
                _ => return err("tag `interpolateboundary` takes 0, 1 or 2".into()),
            },
            "smoothtriangles" => {
                if string_args != ["catmark"] {
                    return err(format!(
                        "tag `smoothtriangles {}`: only the Catmull-Clark rule for triangles \
                         (`catmark`) is evaluated",
                        string_args.join(" ")
                    ));
                }
            }
            "creasemethod" => {
                if string_args != ["uniform"] && string_args != ["normal"] {
                    return err(format!(
                        "tag `creasemethod {}`: only uniform creasing is evaluated (Chaikin's \
                         is not)",
                        string_args.join(" ")
                    ));
                }
            }
            // Face-varying data (UVs) does not move the surface.
            "facevaryinginterpolateboundary" | "facevaryingpropagatecorners" => {}
            "vertexedit" | "edgeedit" | "faceedit" => {
                return err(format!(
                    "tag `{name}`: hierarchical edits are not evaluated; remove the tag to \
                     subdivide the mesh without its edits"
                ));
            }
            "hole" => {
                return err(
                    "tag `hole`: holes are not evaluated; delete the faces to leave them out"
                        .into(),
                );
            }
            other => return err(format!("tag `{other}` is not known")),
        }
        Ok(())
    }
}

pub(crate) fn parse_error(place: &Place, message: String) -> Error {
    Error::Parse {
        path: place.path.clone(),
        line: place.line,
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Tags> {
        let mut tags = Tags::default();
        tags.parse(Path::new("m.tags"), text, false)?;
        Ok(tags)
    }

    #[test]
    fn creases_and_corners_are_read() {
        let tags = parse(
            "# creased\nt crease 2/1/0 0 1 5.0\nt crease 4/2/0 1 2 2 3 0.5 10\n\
             t corner 2/1/0 4 5 2.5\nt interpolateboundary 1/0/0 1\n",
        )
        .unwrap();
        assert_eq!(tags.creases, vec![(0, 1, 5.0), (1, 2, 0.5), (2, 3, 10.0)]);
        assert_eq!(tags.corners, vec![(4, 2.5), (5, 2.5)]);
        assert_eq!(tags.sources, vec![PathBuf::from("m.tags")]);
    }

    #[test]
    fn bad_tags_are_named_with_their_line() {
        for (text, needle) in [
            ("t crease 2/1/0 0 1\n", "announces"),
            ("t crease 2/1/0 0 x 1.0\n", "not a vertex index"),
            ("t crease 2/1/0 0 1 -1\n", "at least 0"),
            ("t crease 4/3/0 0 1 1 2 1 1 1\n", "3 sharpness values for 2"),
            ("\nt vertexedit 1/0/0 3\n", "hierarchical edits"),
            ("t hole 1/0/0 3\n", "holes"),
            ("t creasemethod 0/0/1 chaikin\n", "Chaikin"),
            ("t wobble 0/0/0\n", "not known"),
            ("v 1 2 3\n", "not a tag line"),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.contains("m.tags") && e.contains(needle), "{text:?}: {e}");
        }
        let e = parse("\nt vertexedit 1/0/0 3\n").unwrap_err().to_string();
        assert!(e.contains(":2") || e.contains("line 2"), "{e}");
    }
}
