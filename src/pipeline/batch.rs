//! Several mesh files in one call: frame patterns (`f_####.obj`, `#` standing for the
//! zero-padded frame number as Houdini and Blender write it) over a frame range, and one
//! grid placement shared by every file, fitted to the union of their bounding boxes, so that
//! the frames of an animation share one voxel size and one origin and the volume does not
//! jitter from frame to frame.

use crate::error::{Error, Result};
use crate::mesh::{Aabb, GridFit, Mesh, UpAxis, fit_transform};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A file name with one run of `#`: the frame number, zero-padded to the run's length.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    before: String,
    width: usize,
    after: String,
}

impl FramePattern {
    /// The pattern in `path`, or `None` when it has no `#`; more than one run is refused.
    pub fn of(path: &Path) -> Result<Option<FramePattern>> {
        let text = path.to_string_lossy();
        let Some(start) = text.find('#') else {
            return Ok(None);
        };
        let width = text[start..].chars().take_while(|&c| c == '#').count();
        let after = &text[start + width..];
        if after.contains('#') {
            return Err(Error::InvalidArgument(format!(
                "`{text}` has more than one run of `#`; the frame number takes one"
            )));
        }
        Ok(Some(FramePattern {
            before: text[..start].to_string(),
            width,
            after: after.to_string(),
        }))
    }

    /// The file of `frame`: `f_####.obj` and 7 give `f_0007.obj` (wider numbers are kept
    /// whole).
    pub fn path(&self, frame: u32) -> PathBuf {
        PathBuf::from(format!(
            "{}{frame:0width$}{}",
            self.before,
            self.after,
            width = self.width
        ))
    }
}

/// Frames `first..=last` every `step`: `1-240`, `1-240:2` or one frame, `12`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    pub first: u32,
    pub last: u32,
    pub step: u32,
}

impl FrameRange {
    pub fn frames(&self) -> impl Iterator<Item = u32> {
        (self.first..=self.last).step_by(self.step as usize)
    }
}

impl FromStr for FrameRange {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || format!("expected frames as FIRST-LAST, FIRST-LAST:STEP or FRAME, got `{s}`");
        let number = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
        let (range, step) = match s.split_once(':') {
            Some((r, step)) => (r, number(step)?),
            None => (s, 1),
        };
        let (first, last) = match range.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => (number(range)?, number(range)?),
        };
        if step == 0 || last < first {
            return Err(format!(
                "frames `{s}`: the last frame must not come before the first, and the step must be at least 1"
            ));
        }
        Ok(FrameRange { first, last, step })
    }
}

/// The placement every file shares: `fit` (a resolution along the longest axis of the
/// union, or a voxel size) on the union of the files' bounding boxes, the lower corner on a
/// voxel's lower face as for one file. Files that cannot be read are left out here (they
/// fail again, and are reported, when their job runs); an error only when none can be read.
pub fn shared_placement(files: &[PathBuf], fit: GridFit, up: UpAxis) -> Result<GridFit> {
    let boxes: Vec<Result<Aabb>> = files
        .par_iter()
        .map(|f| Mesh::load(f).map(|m| m.with_up_axis(up).bbox()))
        .collect();
    let mut union: Option<Aabb> = None;
    let mut first_error = None;
    for b in boxes {
        match (b, &mut union) {
            (Ok(b), None) => union = Some(b),
            (Ok(b), Some(u)) => {
                u.min = u.min.min(b.min);
                u.max = u.max.max(b.max);
            }
            (Err(e), _) => {
                first_error.get_or_insert(e);
            }
        }
    }
    match (union, first_error) {
        (Some(union), _) => Ok(GridFit::Placed(fit_transform(&union, fit)?)),
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::InvalidArgument("no input files".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_pad_the_frame_number() {
        let p = FramePattern::of(Path::new("out/f_####.vdb"))
            .unwrap()
            .unwrap();
        assert_eq!(p.path(7), PathBuf::from("out/f_0007.vdb"));
        assert_eq!(p.path(123456), PathBuf::from("out/f_123456.vdb"));
        assert_eq!(FramePattern::of(Path::new("plain.obj")).unwrap(), None);
        assert!(FramePattern::of(Path::new("a_##_b_##.obj")).is_err());
    }

    #[test]
    fn ranges_parse_with_steps() {
        let r: FrameRange = "1-9:4".parse().unwrap();
        assert_eq!(r.frames().collect::<Vec<_>>(), [1, 5, 9]);
        let one: FrameRange = "12".parse().unwrap();
        assert_eq!(one.frames().collect::<Vec<_>>(), [12]);
        for bad in ["", "5-1", "1-4:0", "a-b", "-3", "1-2-3"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad}");
        }
    }
}
