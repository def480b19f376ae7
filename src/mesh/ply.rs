//! PLY input, ASCII and binary (either byte order), through `ply-rs-bw`: the `vertex`
//! element's `x y z` (any numeric type) and, when present, `red green blue` (0..255 integers
//! or 0..1 floats) as the mesh's vertex colours (`Cd`), `nx ny nz` as `vertex_normal`, `u v`
//! (or `s t`, `texture_u texture_v`) as `uv`, every other numeric property as a scalar
//! attribute of its own name, and the `face` element's `vertex_indices` (or `vertex_index`)
//! lists. Vertices are numbered from 0, as PLY numbers them; errors name the file and the
//! element.

use super::Mesh;
use super::attributes::{AttributeKind, VertexAttribute};
use crate::error::{Error, Result};
use glam::{DVec3, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::io::Read;
use std::path::Path;

fn parse_error(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.to_path_buf(),
        line: 0,
        message,
    }
}

/// A scalar property as f64.
fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A list property as integers (`None` when it is not a list of integers).
fn indices(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&i| i as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&i| i as i64).collect(),
        _ => return None,
    })
}

/// Refuses a header that declares an element twice, or a property twice in one element: the
/// parser keeps one declaration of each name, so the file would be read as neither.
fn check_header_names(path: &Path, reader: &mut impl std::io::BufRead) -> Result<()> {
    let mut elements: Vec<(String, Vec<String>)> = Vec::new();
    let mut line = Vec::new();
    for number in 1.. {
        line.clear();
        let read = reader
            .read_until(b'\n', &mut line)
            .map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8_lossy(&line);
        let words: Vec<&str> = text.split_whitespace().collect();
        let at = |message: String| Error::Parse {
            path: path.to_path_buf(),
            line: number,
            message,
        };
        match words.as_slice() {
            _ if read == 0 => break,
            ["end_header", ..] => break,
            ["element", name, ..] => {
                if elements.iter().any(|(e, _)| e == name) {
                    return Err(at(format!("the element `{name}` is declared twice")));
                }
                elements.push((name.to_string(), Vec::new()));
            }
            ["property", .., name] => {
                if let Some((element, properties)) = elements.last_mut() {
                    if properties.iter().any(|p| p == name) {
                        return Err(at(format!(
                            "the property `{name}` of element `{element}` is declared twice"
                        )));
                    }
                    properties.push(name.to_string());
                }
            }
            _ => {}
        }
    }
    Ok(())
}

pub(super) fn load_ply(path: &Path) -> Result<Mesh> {
    let open = || std::fs::File::open(path).map_err(|e| Error::io(path, e));
    // A header is text of a few lines: what follows a megabyte of it is left to the parser.
    check_header_names(path, &mut std::io::BufReader::new(open()?.take(1 << 20)))?;
    let mut reader = std::io::BufReader::new(open()?);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        .map_err(|e| parse_error(path, format!("not a PLY file, or a damaged one: {e}")))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| parse_error(path, "the file has no `vertex` element".into()))?;
    let mut positions = Vec::with_capacity(vertices.len());
    for (k, v) in vertices.iter().enumerate() {
        let coordinate = |name: &str| {
            v.get(name).and_then(scalar).ok_or_else(|| {
                parse_error(path, format!("vertex {k} has no numeric `{name}` property"))
            })
        };
        positions.push(DVec3::new(
            coordinate("x")?,
            coordinate("y")?,
            coordinate("z")?,
        ));
    }
    let colored = vertices.first().is_some_and(|v| v.contains_key("red"));
    let mut colors = Vec::new();
    if colored {
        for (k, v) in vertices.iter().enumerate() {
            let channel = |name: &str| {
                match v.get(name) {
                    Some(Property::UChar(c)) => Ok(*c as f32 / 255.0),
                    Some(p) => scalar(p).map(|c| c as f32).ok_or(()),
                    None => Err(()),
                }
                .map_err(|()| {
                    parse_error(path, format!("vertex {k} has no numeric `{name}` colour"))
                })
            };
            colors.push(Vec3::new(
                channel("red")?,
                channel("green")?,
                channel("blue")?,
            ));
        }
    }
    let faces = ply.payload.get("face").map_or(&[][..], |f| &f[..]);
    let mut polygons = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(indices)
            .ok_or_else(|| {
                parse_error(
                    path,
                    format!("face {f} has no `vertex_indices` list of integers"),
                )
            })?;
        let polygon = list
            .iter()
            .map(|&i| {
                u32::try_from(i)
                    .ok()
                    .filter(|&i| (i as usize) < positions.len())
                    .ok_or_else(|| {
                        parse_error(
                            path,
                            format!(
                                "face {f} uses vertex {i}, but the file has vertices 0..{}",
                                positions.len().saturating_sub(1)
                            ),
                        )
                    })
            })
            .collect::<Result<Vec<u32>>>()?;
        polygons.push(polygon);
    }
    let mut mesh = Mesh::from_polygons(path, positions, &polygons);
    mesh.colors = colors;
    mesh.numbered_from_zero = true;
    let names: Vec<String> = ply
        .header
        .elements
        .get("vertex")
        .map(|element| element.properties.keys().cloned().collect())
        .unwrap_or_default();
    (mesh.attributes, mesh.unread) = vertex_attributes(path, &names, vertices)?;
    Ok(mesh)
}

/// Vertex properties read as vectors: each is a name and its properties' names.
const VECTORS: [(&str, AttributeKind, [&str; 3]); 4] = [
    ("vertex_normal", AttributeKind::Normal, ["nx", "ny", "nz"]),
    ("uv", AttributeKind::TextureCoordinates, ["u", "v", ""]),
    ("uv", AttributeKind::TextureCoordinates, ["s", "t", ""]),
    (
        "uv",
        AttributeKind::TextureCoordinates,
        ["texture_u", "texture_v", ""],
    ),
];

/// The vertex properties besides position and colour, named `names` in the header's order:
/// vectors (normals, texture coordinates) where all their parts are present, scalars
/// otherwise; list properties are reported unread.
fn vertex_attributes(
    path: &Path,
    names: &[String],
    vertices: &[DefaultElement],
) -> Result<(Vec<VertexAttribute>, Vec<String>)> {
    let has = |n: &str| names.iter().any(|m| m == n);
    let mut taken: Vec<&str> = vec!["x", "y", "z", "red", "green", "blue"];
    let mut attributes: Vec<VertexAttribute> = Vec::new();
    let mut unread = Vec::new();
    let component = |k: usize, v: &DefaultElement, name: &str| {
        v.get(name).and_then(scalar).ok_or_else(|| {
            parse_error(path, format!("vertex {k} has no numeric `{name}` property"))
        })
    };
    for (name, kind, parts) in VECTORS {
        let parts: Vec<&str> = parts.into_iter().filter(|p| !p.is_empty()).collect();
        let named_already = attributes.iter().any(|a| a.name == name);
        if named_already || !parts.iter().all(|p| has(p)) {
            continue;
        }
        let values = vertices
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let mut x = [0.0f32; 3];
                for (i, p) in parts.iter().enumerate() {
                    x[i] = component(k, v, p)? as f32;
                }
                Ok(Vec3::from_array(x))
            })
            .collect::<Result<Vec<Vec3>>>()?;
        taken.extend(parts);
        attributes.push(VertexAttribute {
            name: name.into(),
            kind,
            values,
            corners: Vec::new(),
        });
    }
    for name in names.iter().filter(|n| !taken.contains(&n.as_str())) {
        let numeric = vertices
            .first()
            .is_some_and(|v| v.get(name).and_then(scalar).is_some());
        if !numeric {
            unread.push(name.clone());
            continue;
        }
        let values = vertices
            .iter()
            .enumerate()
            .map(|(k, v)| Ok(Vec3::new(component(k, v, name)? as f32, 0.0, 0.0)))
            .collect::<Result<Vec<Vec3>>>()?;
        attributes.push(VertexAttribute {
            name: name.clone(),
            kind: AttributeKind::Scalar,
            values,
            corners: Vec::new(),
        });
    }
    Ok((attributes, unread))
}

impl Mesh {
    /// Writes the mesh as PLY, ASCII or binary little-endian, atomically: coordinates as
    /// doubles (exact), faces as lists of uint, colours as uchar when the mesh has them.
    pub fn write_ply(&self, path: &Path, binary: bool) -> Result<()> {
        use ply_rs_bw::ply::{
            Addable, ElementDef, Encoding, Ply, PropertyDef, PropertyType, ScalarType,
        };
        let mut ply = Ply::<DefaultElement>::new();
        ply.header.encoding = if binary {
            Encoding::BinaryLittleEndian
        } else {
            Encoding::Ascii
        };
        let colored = !self.colors.is_empty();
        let mut vertex = ElementDef::new("vertex".into());
        for n in ["x", "y", "z"] {
            vertex.properties.add(PropertyDef::new(
                n.into(),
                PropertyType::Scalar(ScalarType::Double),
            ));
        }
        if colored {
            for n in ["red", "green", "blue"] {
                vertex.properties.add(PropertyDef::new(
                    n.into(),
                    PropertyType::Scalar(ScalarType::UChar),
                ));
            }
        }
        ply.header.elements.add(vertex);
        let mut face = ElementDef::new("face".into());
        face.properties.add(PropertyDef::new(
            "vertex_indices".into(),
            PropertyType::List(ScalarType::UInt, ScalarType::UInt),
        ));
        ply.header.elements.add(face);
        let vertices = self
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mut e = DefaultElement::new();
                for (a, name) in ["x", "y", "z"].iter().enumerate() {
                    e.insert(name.to_string(), Property::Double(p[a]));
                }
                if let Some(c) = self.colors.get(i).filter(|_| colored) {
                    for (a, name) in ["red", "green", "blue"].iter().enumerate() {
                        let byte = (c[a].clamp(0.0, 1.0) * 255.0).round() as u8;
                        e.insert(name.to_string(), Property::UChar(byte));
                    }
                }
                e
            })
            .collect();
        let faces = (0..self.face_count())
            .map(|f| {
                let mut e = DefaultElement::new();
                e.insert(
                    "vertex_indices".into(),
                    Property::ListUInt(self.face(f).to_vec()),
                );
                e
            })
            .collect();
        ply.payload.insert("vertex".into(), vertices);
        ply.payload.insert("face".into(), faces);
        let mut bytes = Vec::new();
        ply_rs_bw::writer::Writer::<DefaultElement>::new()
            .write_ply(&mut bytes, &mut ply)
            .map_err(|e| Error::io(path, e))?;
        crate::io::atomic::write_atomic(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| Error::io(tmp, e))
        })
    }
}
