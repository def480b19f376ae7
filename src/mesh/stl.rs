//! STL input, binary and ASCII. Triangles arrive as separate corners; identical positions
//! are welded so edges are shared, which the separating voxelizer needs to treat each
//! edge once.

use super::Mesh;
use crate::error::{Error, Result};
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::path::Path;

pub(super) fn load_stl(path: &Path) -> Result<Mesh> {
    let read = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bytes = match read.strip_prefix(b"\xEF\xBB\xBF") {
        // A byte-order mark: UTF-8 text, never a binary header.
        Some(text) => return Ok(weld(path, &ascii_corners(path, text)?)),
        None => &read,
    };
    let corners = if is_binary(bytes) {
        binary_corners(path, bytes)?
    } else {
        ascii_corners(path, bytes)?
    };
    Ok(weld(path, &corners))
}

/// A binary STL is exactly 84 + 50 n bytes; an ASCII one starts with `solid` (any case).
fn is_binary(bytes: &[u8]) -> bool {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() == 84 + 50 * n {
            return true;
        }
    }
    let start = bytes.trim_ascii_start();
    !(start.len() >= 5 && start[..5].eq_ignore_ascii_case(b"solid"))
}

fn binary_corners(path: &Path, bytes: &[u8]) -> Result<Vec<DVec3>> {
    let parse_error = |message: String| Error::Parse {
        path: path.to_path_buf(),
        line: 0,
        message,
    };
    if bytes.len() < 84 {
        return Err(parse_error(format!(
            "binary STL shorter than its 84-byte header ({} bytes)",
            bytes.len()
        )));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    if bytes.len() != 84 + 50 * n {
        return Err(parse_error(format!(
            "binary STL announces {n} triangles ({} bytes) but has {} bytes",
            84 + 50 * n,
            bytes.len()
        )));
    }
    let mut corners = Vec::with_capacity(3 * n);
    for t in 0..n {
        let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
        for c in 0..3 {
            let f = |k: usize| {
                let o = 12 + 12 * c + 4 * k;
                f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
            };
            let p = DVec3::new(f(0), f(1), f(2));
            if !p.is_finite() {
                return Err(Error::BadFace {
                    path: path.to_path_buf(),
                    face: t,
                    message: format!("corner {} has a non-finite coordinate {p:?}", c + 1),
                });
            }
            corners.push(p);
        }
    }
    Ok(corners)
}

fn ascii_corners(path: &Path, bytes: &[u8]) -> Result<Vec<DVec3>> {
    let text = std::str::from_utf8(bytes).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: 0,
        message: format!("neither binary STL nor UTF-8 text: {e}"),
    })?;
    let mut corners = Vec::new();
    let mut in_facet = 0usize;
    let mut ended = false;
    for (n, line) in text.lines().enumerate() {
        let err = |message: String| Error::Parse {
            path: path.to_path_buf(),
            line: n + 1,
            message,
        };
        let mut words = line.split_whitespace();
        // Keywords in any case (some exporters write `FACET NORMAL`).
        let keyword = words.next().map(str::to_ascii_lowercase);
        if ended && keyword.is_some() {
            return Err(err("text after `endsolid`".into()));
        }
        match keyword.as_deref() {
            Some("vertex") => {
                let mut v = [0.0; 3];
                for (a, slot) in v.iter_mut().enumerate() {
                    let w = words
                        .next()
                        .ok_or_else(|| err(format!("vertex has only {a} coordinates")))?;
                    *slot = w
                        .parse::<f64>()
                        .map_err(|_| err(format!("cannot read coordinate `{w}`")))?;
                    if !slot.is_finite() {
                        return Err(err(format!("non-finite vertex coordinate `{w}`")));
                    }
                }
                corners.push(DVec3::from(v));
                in_facet += 1;
            }
            Some("endfacet") => {
                if in_facet != 3 {
                    return Err(err(format!("facet has {in_facet} vertices, expected 3")));
                }
                in_facet = 0;
            }
            Some("endsolid") => ended = true,
            _ => {}
        }
    }
    if corners.len() % 3 != 0 || !ended {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: text.lines().count(),
            message: if corners.len() % 3 != 0 {
                "file ends inside a facet".into()
            } else {
                "file ends without `endsolid` (truncated?)".into()
            },
        });
    }
    Ok(corners)
}

/// Shares exactly equal positions between triangles.
fn weld(path: &Path, corners: &[DVec3]) -> Mesh {
    let mut ids: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    let mut positions = Vec::new();
    let mut polygons = Vec::with_capacity(corners.len() / 3);
    for tri in corners.chunks_exact(3) {
        let face = tri
            .iter()
            .map(|p| {
                // +0.0 folds -0.0 into one key.
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                *ids.entry(key).or_insert_with(|| {
                    positions.push(*p);
                    positions.len() as u32 - 1
                })
            })
            .collect();
        polygons.push(face);
    }
    Mesh::from_polygons(path, positions, &polygons)
}
