//! glTF 2.0 input (`.gltf` with its buffers, embedded or beside it, and `.glb`), through the
//! `gltf` crate: every triangle primitive of the default scene (else the first), placed by
//! its nodes' transforms, with `COLOR_0` as the mesh's vertex colours (`Cd`), `NORMAL` (turned
//! with the nodes) as the attribute `vertex_normal` and `TEXCOORD_0` as `uv`, per triangle
//! corner so that the values on both sides of a seam stay apart.
//!
//! glTF splits vertices wherever an attribute changes (UV seams, hard normals), so a closed
//! model arrives as open patches; positions equal after placement are joined into one vertex,
//! which is what makes such a model a closed solid again. Every accessor is checked against
//! its buffer before it is read: the crate trusts the file's offsets and strides.

use super::Mesh;
use super::attributes::{AttributeKind, VertexAttribute};
use crate::error::{Error, Result};
use crate::io::references::read_referenced;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::Source;
use ::gltf::mesh::Mode;
use ::gltf::{Accessor, Document, Gltf, Node, Primitive};
use base64::Engine as _;
use glam::{DMat4, DVec3, Mat4, Vec3};
use rustc_hash::FxHashMap;
use std::path::Path;

fn parse_error(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.to_path_buf(),
        line: 0,
        message,
    }
}

/// The bytes of every buffer: the `.glb`'s binary chunk, a `data:` URI or a file in the
/// model's folder (no further than the buffer's declared length); each at least as long as
/// the file declares.
fn load_buffers(path: &Path, document: &Document, blob: Option<Vec<u8>>) -> Result<Vec<Vec<u8>>> {
    let mut blob = blob;
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let at = |m: String| parse_error(path, format!("buffer {}: {m}", buffer.index()));
        let data = match buffer.source() {
            Source::Bin => blob
                .take()
                .ok_or_else(|| at("the file has no binary chunk for it".into()))?,
            Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, encoded) = uri
                    .split_once(";base64,")
                    .ok_or_else(|| at("a data URI that is not base64".into()))?;
                base64::engine::general_purpose::STANDARD
                    .decode(encoded)
                    .map_err(|e| at(format!("bad base64 data: {e}")))?
            }
            Source::Uri(uri) => {
                let reference = percent_decoded(uri).map_err(at)?;
                read_referenced(path, &reference, buffer.length() as u64).map_err(at)?
            }
        };
        if data.len() < buffer.length() {
            return Err(at(format!(
                "holds {} bytes, but the file declares {}",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// A relative URI as a file name (`%20` and the like decoded).
fn percent_decoded(uri: &str) -> std::result::Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = uri
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("the URI `{uri}` has a bad %-escape"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("the URI `{uri}` is not UTF-8"))
}

/// Checks that `accessor` is dense, of one of the `types` and `dims`, and lies inside its
/// view and buffer, so that reading it cannot run past the data.
fn check_accessor(
    accessor: &Accessor,
    what: &str,
    types: &[DataType],
    dims: &[Dimensions],
    buffers: &[Vec<u8>],
) -> std::result::Result<(), String> {
    let name = format!("{what} accessor {}", accessor.index());
    if accessor.sparse().is_some() {
        return Err(format!("{name} is sparse, which is not supported"));
    }
    if !types.contains(&accessor.data_type()) || !dims.contains(&accessor.dimensions()) {
        return Err(format!(
            "{name} holds {:?} {:?}, expected one of {types:?} as {dims:?}",
            accessor.data_type(),
            accessor.dimensions()
        ));
    }
    let view = accessor
        .view()
        .ok_or_else(|| format!("{name} has no buffer view"))?;
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|end| end > buffer_len) {
        return Err(format!(
            "buffer view {} reaches past the end of buffer {} ({buffer_len} bytes)",
            view.index(),
            view.buffer().index()
        ));
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "buffer view {} has a stride of {stride} bytes, less than the {size}-byte items of {name}",
            view.index()
        ));
    }
    let end = accessor.count().checked_sub(1).and_then(|last| {
        last.checked_mul(stride)
            .and_then(|b| b.checked_add(size))
            .and_then(|b| b.checked_add(accessor.offset()))
    });
    match end {
        None if accessor.count() == 0 => Err(format!("{name} is empty")),
        Some(end) if end <= view.length() => Ok(()),
        _ => Err(format!(
            "{name} ({} items of {size} bytes every {stride}) runs past the end of buffer view {}",
            accessor.count(),
            view.index()
        )),
    }
}

/// What the scene adds up to: joined positions, their colours, the triangles and the corner
/// attributes.
#[derive(Default)]
struct Collected {
    positions: Vec<DVec3>,
    colors: Vec<Vec3>,
    triangles: Vec<Vec<u32>>,
    joined: FxHashMap<[u64; 3], u32>,
    colored: bool,
    normals: CornerAttribute,
    texture: CornerAttribute,
    /// Attributes besides POSITION, COLOR_0, NORMAL and TEXCOORD_0, by name, and those some
    /// primitives lack.
    unread: std::collections::BTreeSet<String>,
}

/// A glTF vertex attribute gathered per triangle corner over the primitives.
#[derive(Default)]
struct CornerAttribute {
    values: Vec<Vec3>,
    corners: Vec<u32>,
    /// A primitive lacked it: it is not read.
    incomplete: bool,
}

impl CornerAttribute {
    /// Takes a primitive's `values` (one per vertex; none when it lacks them), returning where
    /// they start.
    fn add(&mut self, values: Option<Vec<Vec3>>) -> u32 {
        let start = self.values.len() as u32;
        match values {
            Some(v) => self.values.extend(v),
            None => self.incomplete = true,
        }
        start
    }

    /// The attribute over `corner_count` corners, when every primitive carried it.
    fn finish(
        self,
        name: &str,
        kind: AttributeKind,
        corner_count: usize,
    ) -> Option<VertexAttribute> {
        (!self.incomplete && !self.values.is_empty() && self.corners.len() == corner_count).then(
            || VertexAttribute {
                name: name.into(),
                kind,
                values: self.values,
                corners: self.corners,
            },
        )
    }
}

impl Collected {
    /// The vertex at `p`, shared with any earlier one at exactly the same place.
    fn vertex(&mut self, p: DVec3, color: Option<Vec3>) -> u32 {
        let key = p.to_array().map(|c| (c + 0.0).to_bits());
        let next = self.positions.len() as u32;
        let index = *self.joined.entry(key).or_insert(next);
        if index == next {
            self.positions.push(p);
            self.colors.push(color.unwrap_or(Vec3::ONE));
        }
        index
    }

    /// Adds one primitive placed by `to_world`.
    fn add(
        &mut self,
        primitive: &Primitive,
        to_world: &DMat4,
        buffers: &[Vec<u8>],
    ) -> std::result::Result<(), String> {
        let corners = match primitive.mode() {
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => primitive.mode(),
            // Points and lines bound no surface.
            _ => return Ok(()),
        };
        let positions = primitive
            .get(&::gltf::Semantic::Positions)
            .ok_or("it has no POSITION attribute")?;
        check_accessor(
            &positions,
            "POSITION",
            &[DataType::F32],
            &[Dimensions::Vec3],
            buffers,
        )?;
        for (semantic, _) in primitive.attributes() {
            if !matches!(
                semantic,
                ::gltf::Semantic::Positions
                    | ::gltf::Semantic::Colors(0)
                    | ::gltf::Semantic::Normals
                    | ::gltf::Semantic::TexCoords(0)
            ) {
                self.unread.insert(semantic.to_string());
            }
        }
        for (semantic, name, types, dims) in [
            (
                ::gltf::Semantic::Normals,
                "NORMAL",
                &[DataType::F32][..],
                &[Dimensions::Vec3][..],
            ),
            (
                ::gltf::Semantic::TexCoords(0),
                "TEXCOORD_0",
                &[DataType::F32, DataType::U8, DataType::U16][..],
                &[Dimensions::Vec2][..],
            ),
        ] {
            if let Some(a) = primitive.get(&semantic) {
                check_accessor(&a, name, types, dims, buffers)?;
                if a.count() != positions.count() {
                    return Err(format!(
                        "{name} has {} items for {} positions",
                        a.count(),
                        positions.count()
                    ));
                }
            }
        }
        let colors = primitive.get(&::gltf::Semantic::Colors(0));
        if let Some(c) = &colors {
            check_accessor(
                c,
                "COLOR_0",
                &[DataType::U8, DataType::U16, DataType::F32],
                &[Dimensions::Vec3, Dimensions::Vec4],
                buffers,
            )?;
            if c.count() != positions.count() {
                return Err(format!(
                    "COLOR_0 has {} items for {} positions",
                    c.count(),
                    positions.count()
                ));
            }
        }
        if let Some(indices) = primitive.indices() {
            check_accessor(
                &indices,
                "index",
                &[DataType::U8, DataType::U16, DataType::U32],
                &[Dimensions::Scalar],
                buffers,
            )?;
        }
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        // Normals turn with the inverse transpose of the placement.
        let turn = to_world.inverse().transpose();
        let normals = reader.read_normals().map(|n| {
            n.map(|n| {
                turn.transform_vector3(Vec3::from(n).as_dvec3())
                    .normalize_or_zero()
                    .as_vec3()
            })
            .collect()
        });
        let texture = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(|[u, v]| Vec3::new(u, v, 0.0)).collect());
        let (normals_from, texture_from) = (self.normals.add(normals), self.texture.add(texture));
        let mut read_colors = reader.read_colors(0).map(|c| c.into_rgb_f32());
        self.colored |= read_colors.is_some();
        let placed: Vec<u32> = reader
            .read_positions()
            .ok_or("its positions cannot be read")?
            .map(|p| {
                let p = to_world.transform_point3(Vec3::from(p).as_dvec3());
                let color = read_colors
                    .as_mut()
                    .and_then(Iterator::next)
                    .map(Vec3::from);
                self.vertex(p, color)
            })
            .collect();
        let order: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
            None => (0..placed.len() as u32).collect(),
        };
        if let Some(&bad) = order.iter().find(|&&i| i as usize >= placed.len()) {
            return Err(format!(
                "index {bad} is out of range (the primitive has {} vertices)",
                placed.len()
            ));
        }
        // A mirroring transform turns the faces inside out; keep them facing outward.
        let mirrored = to_world.determinant() < 0.0;
        let mut push = |a: u32, b: u32, c: u32| {
            let corners = if mirrored { [a, c, b] } else { [a, b, c] };
            self.triangles
                .push(corners.map(|i| placed[i as usize]).to_vec());
            for (attribute, from) in [
                (&mut self.normals, normals_from),
                (&mut self.texture, texture_from),
            ] {
                attribute.corners.extend(corners.map(|i| from + i));
            }
        };
        match corners {
            Mode::Triangles => order.chunks_exact(3).for_each(|t| push(t[0], t[1], t[2])),
            Mode::TriangleStrip => order.windows(3).enumerate().for_each(|(k, t)| {
                if k % 2 == 0 {
                    push(t[0], t[1], t[2])
                } else {
                    push(t[1], t[0], t[2])
                }
            }),
            _ => (1..order.len().saturating_sub(1))
                .for_each(|k| push(order[0], order[k], order[k + 1])),
        }
        Ok(())
    }
}

pub(super) fn load_gltf(path: &Path) -> Result<Mesh> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let damaged =
        |e: String| parse_error(path, format!("not a glTF 2.0 file, or a damaged one: {e}"));
    let Gltf { document, blob } =
        Gltf::from_slice_without_validation(&bytes).map_err(|e| damaged(e.to_string()))?;
    let json = document.into_json();
    // The crate's validation indexes the POSITION accessor before checking it: check first.
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = ::gltf::json::validation::Checked::Valid(::gltf::Semantic::Positions);
            if let Some(a) = primitive.attributes.get(&position)
                && a.value() >= json.accessors.len()
            {
                return Err(damaged(format!(
                    "mesh {m}, primitive {p}: POSITION names accessor {}, but there are {}",
                    a.value(),
                    json.accessors.len()
                )));
            }
        }
    }
    let document = Document::from_json(json).map_err(|e| damaged(e.to_string()))?;
    let buffers = load_buffers(path, &document, blob)?;
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| parse_error(path, "the file has no scene".into()))?;
    let mut collected = Collected::default();
    let mut visited = vec![false; document.nodes().len()];
    // Depth first with an explicit stack: hostile files may nest nodes deeply.
    let mut stack: Vec<(Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(parse_error(
                path,
                format!(
                    "node {} is reached twice (glTF nodes form trees)",
                    node.index()
                ),
            ));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let to_world = parent * local;
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                collected
                    .add(&primitive, &to_world, &buffers)
                    .map_err(|m| {
                        let name = mesh.name().map(|n| format!(" ({n:?})")).unwrap_or_default();
                        parse_error(
                            path,
                            format!(
                                "mesh {}{name}, primitive {}: {m}",
                                mesh.index(),
                                primitive.index()
                            ),
                        )
                    })?;
            }
        }
        stack.extend(node.children().map(|c| (c, to_world)));
    }
    let Collected {
        positions,
        colors,
        triangles,
        colored,
        normals,
        texture,
        mut unread,
        ..
    } = collected;
    let mut mesh = Mesh::from_polygons(path, positions, &triangles);
    if colored {
        mesh.colors = colors;
    }
    mesh.numbered_from_zero = true;
    let corner_count = mesh.indices.len();
    for (attribute, semantic, name, kind) in [
        (normals, "NORMAL", "vertex_normal", AttributeKind::Normal),
        (
            texture,
            "TEXCOORD_0",
            "uv",
            AttributeKind::TextureCoordinates,
        ),
    ] {
        let lacking = attribute.incomplete && !attribute.values.is_empty();
        match attribute.finish(name, kind, corner_count) {
            Some(a) => mesh.attributes.push(a),
            None if lacking => {
                unread.insert(format!("{semantic} (some primitives lack it)"));
            }
            None => {}
        }
    }
    mesh.unread = unread.into_iter().collect();
    Ok(mesh)
}

/// How `Mesh::write_gltf` stores the binary data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfLayout {
    /// One `.glb` file.
    Binary,
    /// A `.gltf` with its buffer as a base64 `data:` URI.
    Embedded,
    /// A `.gltf` with its buffer in a `.bin` file beside it.
    SeparateBuffer,
}

/// Little-endian floats, three per vector.
fn float_bytes(v: &[Vec3]) -> Vec<u8> {
    v.iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect()
}

impl Mesh {
    /// Writes the mesh as glTF 2.0 (used by tests): positions as floats (glTF has no
    /// doubles), faces fan-triangulated, colours as `COLOR_0`. The mesh hangs below a chain
    /// of nodes, one per matrix of `placement` (outermost first), so that the file places it
    /// at `placement[0] * placement[1] * ...` applied to its positions.
    pub fn write_gltf(&self, path: &Path, layout: GltfLayout, placement: &[DMat4]) -> Result<()> {
        let mut bin: Vec<u8> = Vec::new();
        let mut views = Vec::new();
        let mut accessors = Vec::new();
        let mut add = |bytes: Vec<u8>, accessor: serde_json::Value| {
            views.push(serde_json::json!({
                "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()
            }));
            bin.extend_from_slice(&bytes);
            bin.resize(bin.len().next_multiple_of(4), 0);
            let mut accessor = accessor;
            accessor["bufferView"] = (views.len() - 1).into();
            accessors.push(accessor);
            accessors.len() - 1
        };
        let points: Vec<Vec3> = self.positions.iter().map(|p| p.as_vec3()).collect();
        let (lo, hi) = points.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let position = add(
            float_bytes(&points),
            serde_json::json!({"componentType": 5126, "count": points.len(), "type": "VEC3",
                               "min": lo.to_array(), "max": hi.to_array()}),
        );
        let corners: Vec<u8> = self
            .triangles()
            .flat_map(|(_, t)| t)
            .flat_map(u32::to_le_bytes)
            .collect();
        let count = corners.len() / 4;
        let indices = add(
            corners,
            serde_json::json!({"componentType": 5125, "count": count, "type": "SCALAR"}),
        );
        let mut attributes = serde_json::json!({ "POSITION": position });
        if !self.colors.is_empty() {
            let c = add(
                float_bytes(&self.colors),
                serde_json::json!({"componentType": 5126, "count": self.colors.len(), "type": "VEC3"}),
            );
            attributes["COLOR_0"] = c.into();
        }
        let mut nodes = Vec::new();
        for (k, m) in placement.iter().enumerate() {
            let matrix: Vec<f64> = m.to_cols_array().to_vec();
            nodes.push(serde_json::json!({"matrix": matrix, "children": [k + 1]}));
        }
        nodes.push(serde_json::json!({"mesh": 0}));
        let uri = match layout {
            GltfLayout::Binary => None,
            GltfLayout::Embedded => Some(format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bin)
            )),
            GltfLayout::SeparateBuffer => Some(
                path.with_extension("bin")
                    .file_name()
                    .map(|n| n.to_string_lossy().replace(' ', "%20"))
                    .unwrap_or_default(),
            ),
        };
        let mut buffer = serde_json::json!({ "byteLength": bin.len() });
        if let Some(uri) = &uri {
            buffer["uri"] = uri.clone().into();
        }
        let json = serde_json::json!({
            "asset": {"version": "2.0", "generator": "voxelkit"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": nodes,
            "meshes": [{"primitives": [{"attributes": attributes, "indices": indices, "mode": 4}]}],
            "buffers": [buffer],
            "bufferViews": views,
            "accessors": accessors,
        });
        let text = json.to_string().into_bytes();
        let bytes = if layout == GltfLayout::Binary {
            crate::io::mesh_out::glb_container(text, &bin)
        } else {
            text
        };
        if layout == GltfLayout::SeparateBuffer {
            let bin_path = path.with_extension("bin");
            crate::io::atomic::write_atomic(&bin_path, |tmp| {
                std::fs::write(tmp, &bin).map_err(|e| Error::io(tmp, e))
            })?;
        }
        crate::io::atomic::write_atomic(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| Error::io(tmp, e))
        })
    }
}
