//! Triangle meshes written as files, the format chosen by the extension: OBJ (text),
//! binary little-endian PLY, binary STL or binary glTF (`.glb`). Coordinates are written as
//! 32-bit floats (OBJ's text too: the shortest text that reads back to the same float), which
//! every reader of these formats expects. Writes are atomic.

use super::atomic::write_atomic;
use super::direct_file::DirectFile;
use crate::contour::TriangleMesh;
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::path::Path;

/// The mesh formats written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
    Stl,
    Glb,
}

impl MeshFormat {
    /// The format named by `path`'s extension, or an error naming the ones written.
    pub fn of(path: &Path) -> Result<MeshFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("stl") => Ok(MeshFormat::Stl),
            Some("glb") => Ok(MeshFormat::Glb),
            _ => Err(Error::InvalidArgument(format!(
                "{}: a mesh is written as .obj, .ply, .stl or .glb (named by the extension)",
                path.display()
            ))),
        }
    }
}

/// Writes `mesh` to `path` in the format its extension names.
pub fn write_mesh(path: &Path, mesh: &TriangleMesh) -> Result<()> {
    let format = MeshFormat::of(path)?;
    // Binary glTF counts its bytes in 32 bits; STL its triangles.
    let glb_bytes = 12 * (mesh.positions.len() as u64 + mesh.triangles.len() as u64) + 4096;
    if format == MeshFormat::Glb && glb_bytes > u32::MAX as u64 {
        return Err(Error::InvalidArgument(format!(
            "{}: {} triangles do not fit a .glb (4 GiB at most): write .ply instead",
            path.display(),
            mesh.triangles.len()
        )));
    }
    write_atomic(path, |tmp| {
        let io_error = |e| Error::io(tmp, e);
        let mut file = DirectFile::create(tmp).map_err(io_error)?;
        let mut put = |bytes: &[u8]| file.write_all(bytes);
        match format {
            MeshFormat::Obj => put(&obj(mesh)),
            MeshFormat::Ply => ply(mesh, &mut put),
            MeshFormat::Stl => stl(mesh, &mut put),
            MeshFormat::Glb => put(&glb(mesh)),
        }
        .map_err(io_error)?;
        file.finish().map(drop).map_err(io_error)
    })
}

/// Rows per piece of a binary file handed to the file: the large binary formats are written
/// piece by piece from one reused buffer rather than built whole in fresh memory first.
const ROWS_PER_PIECE: usize = 1 << 16;

/// Hands `put` the bytes `row` appends for each of `rows`, a piece of `ROWS_PER_PIECE` rows
/// at a time.
fn put_rows<T>(
    rows: &[T],
    put: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
    row: impl Fn(&mut Vec<u8>, &T),
) -> std::io::Result<()> {
    let mut piece = Vec::new();
    for chunk in rows.chunks(ROWS_PER_PIECE) {
        piece.clear();
        chunk.iter().for_each(|r| row(&mut piece, r));
        put(&piece)?;
    }
    Ok(())
}

fn point(mesh: &TriangleMesh, i: u32) -> [f32; 3] {
    mesh.positions[i as usize].as_vec3().to_array()
}

/// Rows formatted in parallel chunks, joined in order.
fn text_rows<T: Sync>(rows: &[T], row: impl Fn(&mut String, &T) + Sync) -> Vec<u8> {
    let chunks: Vec<String> = rows
        .par_chunks(1 << 14)
        .map(|chunk| {
            let mut s = String::with_capacity(chunk.len() * 32);
            for r in chunk {
                row(&mut s, r);
            }
            s
        })
        .collect();
    chunks.concat().into_bytes()
}

fn obj(mesh: &TriangleMesh) -> Vec<u8> {
    use std::fmt::Write as _;
    let mut out = format!(
        "# written by voxelkit {}: {} vertices, {} triangles\n",
        env!("CARGO_PKG_VERSION"),
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    out.extend(text_rows(&mesh.positions, |s, p| {
        let p = p.as_vec3();
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }));
    out.extend(text_rows(&mesh.triangles, |s, t| {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }));
    out
}

fn ply(
    mesh: &TriangleMesh,
    put: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by voxelkit {}\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        env!("CARGO_PKG_VERSION"),
        mesh.positions.len(),
        mesh.triangles.len()
    );
    put(header.as_bytes())?;
    put_rows(&mesh.positions, put, |out, p| {
        for v in p.as_vec3().to_array() {
            out.extend_from_slice(&v.to_le_bytes());
        }
    })?;
    put_rows(&mesh.triangles, put, |out, t| {
        out.push(3);
        for v in t {
            out.extend_from_slice(&(*v as i32).to_le_bytes());
        }
    })
}

fn stl(
    mesh: &TriangleMesh,
    put: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut header = format!(
        "binary STL written by voxelkit {}",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes();
    header.resize(80, b' ');
    header.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    put(&header)?;
    put_rows(&mesh.triangles, put, |out, t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let normal = (b - a)
            .cross(c - a)
            .normalize_or_zero()
            .as_vec3()
            .to_array();
        out.extend(normal.iter().flat_map(|v| v.to_le_bytes()));
        for &i in t {
            out.extend(point(mesh, i).iter().flat_map(|v| v.to_le_bytes()));
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    })
}

/// One buffer (positions, then indices), two accessors, one mesh, one node.
fn glb(mesh: &TriangleMesh) -> Vec<u8> {
    let mut bin = Vec::with_capacity(12 * mesh.positions.len() + 12 * mesh.triangles.len());
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        for (a, v) in p.as_vec3().to_array().into_iter().enumerate() {
            lo[a] = lo[a].min(v);
            hi[a] = hi[a].max(v);
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let positions_len = bin.len();
    for t in &mesh.triangles {
        for v in t {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": format!("voxelkit {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions_len, "target": 34962},
            {"buffer": 0, "byteOffset": positions_len, "byteLength": bin.len() - positions_len, "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": mesh.positions.len(), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * mesh.triangles.len(), "type": "SCALAR"},
        ],
    });
    glb_container(json.to_string().into_bytes(), &bin)
}

/// A binary glTF file: its header, the JSON chunk (padded with spaces to four bytes) and the
/// binary chunk `bin` (already a multiple of four bytes).
pub fn glb_container(mut json: Vec<u8>, bin: &[u8]) -> Vec<u8> {
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}
