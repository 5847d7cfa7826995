//! PLY reading with `ply-rs-bw`: ASCII, `binary_little_endian` and `binary_big_endian`.
//!
//! Crate: `ply-rs-bw` 4, the maintained fork of `ply-rs` (whose last release, 0.1.3, is from
//! 2020 and which depends on the vulnerable `linked-hash-map`, CVE-2020-25573). It parses the
//! header (the grammar, every scalar and list type) and decodes one element at a time into our
//! own types ([`ply_rs_bw::ply::PropertyAccess`]), so no property map is built per vertex.
//! This module drives the element loop itself, which lets every error name the element, its
//! index and its line (ASCII) or byte offset (binary), which the crate's whole-payload reader
//! cannot.
//!
//! Accepted: a `vertex` element with scalar properties `x`, `y`, `z` of any numeric type (read
//! as f64, rounded once to f32); a `face` element with a list property `vertex_indices` or
//! `vertex_index` of any integer type, any list length type, any number of corners (polygons
//! are fan-triangulated from their first corner and counted); elements in any order; other
//! properties (normals, colours, texture coordinates, confidence...) and other elements
//! (edges, materials...) are read past and ignored; blank lines in an ASCII payload are
//! skipped; bytes after the last element are ignored.
//!
//! Refused, with a message: a face with fewer than 3 corners (chosen: an error rather than a
//! silent drop, since repairs are reported and a reader does not repair), a negative or
//! out-of-range vertex index, a non-finite or (after rounding to f32) overflowing coordinate, a
//! float list as face indices, a file with no `face` element (a point cloud).

use super::{non_finite_vertex, push_fan, MeshFormat, RawMesh};
use crate::error::InputError;
use glam::Vec3;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding, PropertyAccess, PropertyAccessResult, PropertyType};
use std::io::Cursor;

/// Where an element is: its line (ASCII) or its byte offset (binary).
#[derive(Clone, Copy)]
enum Place {
    Line(usize),
    Offset(usize),
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Place::Line(l) => write!(f, "line {l}"),
            Place::Offset(o) => write!(f, "byte offset {o}"),
        }
    }
}

/// Reads PLY bytes into a [`RawMesh`]; errors name `display_name` and the element and its
/// place.
pub(super) fn parse(bytes: &[u8], display_name: &str) -> Result<RawMesh, InputError> {
    let err = |m: String| InputError::new(display_name, m);
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = Parser::<Ignored>::new()
        .read_header(&mut reader)
        .map_err(|e| err(format!("PLY header error: {}", crate_message(&e))))?;
    let vertex_def = header.elements.get("vertex");
    if let Some(def) = vertex_def {
        for axis in ["x", "y", "z"] {
            match def.properties.get(axis).map(|p| &p.data_type) {
                Some(PropertyType::Scalar(_)) => {}
                Some(PropertyType::List(..)) => {
                    return Err(err(format!(
                        "PLY header: vertex property `{axis}` is a list, must be a number"
                    )))
                }
                None => {
                    return Err(err(format!(
                        "PLY header: the vertex element has no property `{axis}`"
                    )))
                }
            }
        }
    }
    let Some(face_def) = header.elements.get("face") else {
        return Err(err(
            "the PLY file has no `face` element (a point cloud has no triangles)".into(),
        ));
    };
    if !face_def
        .properties
        .keys()
        .any(|k| k == "vertex_indices" || k == "vertex_index")
    {
        return Err(err(
            "PLY header: the face element has no list property `vertex_indices` or \
             `vertex_index`"
                .into(),
        ));
    }

    let start = reader.get_ref().position() as usize;
    let mut payload = Payload {
        bytes,
        at: start,
        line: bytes[..start].iter().filter(|b| **b == b'\n').count() + 1,
        encoding: header.encoding,
    };
    let mut positions = Vec::new();
    let mut faces: Vec<u32> = Vec::new();
    let mut face_ends: Vec<usize> = Vec::new();
    for def in header.elements.values() {
        // At least one byte per element: a count beyond the file's size is not preallocated.
        let cap = def.count.min(bytes.len());
        let at_element = |i: usize, place: Place, m: String| {
            err(format!("PLY element {} {i} at {place}: {m}", def.name))
        };
        match def.name.as_str() {
            "vertex" => {
                positions.reserve(cap);
                for i in 0..def.count {
                    let (v, place) = payload
                        .element::<Vertex>(def)
                        .map_err(|(p, m)| at_element(i, p, m))?;
                    let p = v.xyz.map(|c| c as f32);
                    if !p.iter().all(|c| c.is_finite()) {
                        let at = place.to_string();
                        return Err(err(non_finite_vertex(i, Some(&at), p)));
                    }
                    positions.push(Vec3::from_array(p));
                }
            }
            "face" => {
                face_ends.reserve(cap);
                for i in 0..def.count {
                    let (f, place) = payload
                        .element::<Face>(def)
                        .map_err(|(p, m)| at_element(i, p, m))?;
                    let corners = f.corners.map_err(|m| at_element(i, place, m))?;
                    if corners.len() < 3 {
                        return Err(at_element(
                            i,
                            place,
                            format!("has {} corners, a face needs at least 3", corners.len()),
                        ));
                    }
                    faces.extend(corners);
                    face_ends.push(faces.len());
                }
            }
            _ => {
                for i in 0..def.count {
                    payload
                        .element::<Ignored>(def)
                        .map_err(|(p, m)| at_element(i, p, m))?;
                }
            }
        }
    }

    let mut triangles = Vec::with_capacity(faces.len().saturating_sub(2 * face_ends.len()));
    let mut polygons = 0;
    let mut begin = 0;
    for (i, &end) in face_ends.iter().enumerate() {
        let corners = &faces[begin..end];
        if let Some(&bad) = corners.iter().find(|&&c| c as usize >= positions.len()) {
            return Err(err(format!(
                "PLY face {i} refers to vertex {bad}, the file has {} vertices",
                positions.len()
            )));
        }
        polygons += usize::from(push_fan(&mut triangles, corners));
        begin = end;
    }
    Ok(RawMesh {
        positions,
        triangles,
        format: MeshFormat::Ply,
        polygons_triangulated: polygons,
    })
}

/// The payload being read, element by element.
struct Payload<'a> {
    bytes: &'a [u8],
    /// Byte offset of the next element.
    at: usize,
    /// 1-based line of the next element (ASCII).
    line: usize,
    encoding: Encoding,
}

impl Payload<'_> {
    /// The next element of `def`, decoded into `E`, and where it was; or where it failed and why.
    fn element<E: PropertyAccess>(
        &mut self,
        def: &ElementDef,
    ) -> Result<(E, Place), (Place, String)> {
        let parser = Parser::<E>::new();
        if self.encoding == Encoding::Ascii {
            // One element per line; blank lines are skipped.
            loop {
                let rest = &self.bytes[self.at.min(self.bytes.len())..];
                let place = Place::Line(self.line);
                if rest.is_empty() {
                    return Err((place, "the file ends before this element".into()));
                }
                let len = rest
                    .iter()
                    .position(|b| *b == b'\n')
                    .map_or(rest.len(), |n| n + 1);
                let line = &rest[..len];
                self.at += len;
                self.line += 1;
                if line.iter().all(u8::is_ascii_whitespace) {
                    continue;
                }
                let text =
                    std::str::from_utf8(line).map_err(|_| (place, "not ASCII text".to_string()))?;
                return parser
                    .read_ascii_element(text, def)
                    .map(|e| (e, place))
                    .map_err(|e| (place, crate_message(&e)));
            }
        }
        let place = Place::Offset(self.at);
        let mut cursor = Cursor::new(self.bytes);
        cursor.set_position(self.at as u64);
        let element = if self.encoding == Encoding::BinaryLittleEndian {
            parser.read_little_endian_element(&mut cursor, def)
        } else {
            parser.read_big_endian_element(&mut cursor, def)
        };
        self.at = cursor.position() as usize;
        element
            .map(|e| (e, place))
            .map_err(|e| (place, crate_message(&e)))
    }
}

/// The first line of a `ply-rs-bw` error, without its "Line N: " prefix (this module names the
/// place itself) or, for a header error, with "line N: ".
fn crate_message(e: &ParseError) -> String {
    let text = e.to_string();
    let text = match e.line() {
        Some(line) => {
            let body = text
                .strip_prefix(&format!("Line {line}: "))
                .unwrap_or(&text);
            format!("line {line}: {body}")
        }
        None => text,
    };
    let first = text.lines().next().unwrap_or_default().trim_end();
    if first.contains("failed to fill whole buffer") {
        return "the file ends inside this element".into();
    }
    first.to_string()
}

/// An element whose properties are all read past.
struct Ignored;

impl PropertyAccess for Ignored {
    fn new() -> Self {
        Ignored
    }
}

/// A vertex: x, y, z of any numeric type, as f64.
struct Vertex {
    xyz: [f64; 3],
}

impl Vertex {
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.xyz[axis] = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex { xyz: [0.0; 3] }
    }
    fn set_char(&mut self, name: &str, v: i8) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_uchar(&mut self, name: &str, v: u8) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_short(&mut self, name: &str, v: i16) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_ushort(&mut self, name: &str, v: u16) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_int(&mut self, name: &str, v: i32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_uint(&mut self, name: &str, v: u32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set(name, v)
    }
}

/// A face: its corners' vertex indices, or why they are not indices.
struct Face {
    corners: Result<Vec<u32>, String>,
}

impl Face {
    /// Stores the list if `name` is the face's index list; `T` is its element type.
    fn set<T: Copy + TryInto<u32> + std::fmt::Display>(
        &mut self,
        name: &str,
        list: Vec<T>,
    ) -> PropertyAccessResult {
        if name != "vertex_indices" && name != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        // Into the list's own allocation where `T` is 4 bytes (int, uint: the common case).
        self.corners = list
            .into_iter()
            .map(|i| {
                i.try_into()
                    .map_err(|_| format!("vertex index {i} is not a vertex"))
            })
            .collect();
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face {
            corners: Ok(Vec::new()),
        }
    }
    fn set_list_char(&mut self, name: &str, v: Vec<i8>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_uchar(&mut self, name: &str, v: Vec<u8>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_short(&mut self, name: &str, v: Vec<i16>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_ushort(&mut self, name: &str, v: Vec<u16>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_int(&mut self, name: &str, v: Vec<i32>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_uint(&mut self, name: &str, v: Vec<u32>) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_list_float(&mut self, name: &str, _: Vec<f32>) -> PropertyAccessResult {
        self.refuse_float(name)
    }
    fn set_list_double(&mut self, name: &str, _: Vec<f64>) -> PropertyAccessResult {
        self.refuse_float(name)
    }
}

impl Face {
    /// Face indices must be integers; other float lists are ignored.
    fn refuse_float(&mut self, name: &str) -> PropertyAccessResult {
        if name == "vertex_indices" || name == "vertex_index" {
            PropertyAccessResult::UnsupportedType
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::parse_mesh;
    use super::*;

    /// A unit cube, ASCII, with normals and colours, as 6 quads.
    pub(in crate::scene::mesh_io) const CUBE_ASCII: &str = "ply\nformat ascii 1.0\n\
        comment a cube\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
        property float nx\nproperty uchar red\nelement face 6\n\
        property list uchar int vertex_indices\nend_header\n\
        0 0 0 0 1\n1 0 0 0 2\n0 1 0 0 3\n1 1 0 0 4\n0 0 1 0 5\n1 0 1 0 6\n0 1 1 0 7\n1 1 1 0 8\n\
        4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";

    fn parse_bytes(bytes: &[u8]) -> Result<RawMesh, InputError> {
        parse_mesh(bytes, MeshFormat::Ply, "t.ply", None)
    }

    /// A binary tetrahedron-ish file: 4 vertices (double x, int y, float z, a uchar
    /// confidence), an `edge` element in between, faces with a ushort list of uint indices
    /// (a triangle and a quad).
    fn binary(big: bool) -> Vec<u8> {
        let order = if big { "big" } else { "little" };
        let mut b = format!(
            "ply\nformat binary_{order}_endian 1.0\nelement vertex 4\nproperty double x\n\
             property int y\nproperty float z\nproperty uchar confidence\nelement edge 1\n\
             property int vertex1\nproperty int vertex2\nelement face 2\n\
             property list ushort uint vertex_index\nend_header\n"
        )
        .into_bytes();
        let put = |bytes: &[u8], b: &mut Vec<u8>| {
            if big {
                b.extend(bytes.iter().rev());
            } else {
                b.extend(bytes);
            }
        };
        for (x, y, z) in [
            (0.5f64, 0i32, 0f32),
            (1.0, 0, 0.0),
            (0.0, 1, 0.0),
            (0.0, 0, 1.0),
        ] {
            put(&x.to_le_bytes(), &mut b);
            put(&y.to_le_bytes(), &mut b);
            put(&z.to_le_bytes(), &mut b);
            b.push(7);
        }
        put(&0i32.to_le_bytes(), &mut b);
        put(&1i32.to_le_bytes(), &mut b);
        for face in [&[0u32, 2, 1][..], &[0, 1, 3, 2]] {
            put(&(face.len() as u16).to_le_bytes(), &mut b);
            for i in face {
                put(&i.to_le_bytes(), &mut b);
            }
        }
        b
    }

    #[test]
    fn ascii_cube() {
        let m = parse_bytes(CUBE_ASCII.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.positions[5], Vec3::new(1.0, 0.0, 1.0));
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.triangles[..2], [[0, 2, 3], [0, 3, 1]]);
        assert_eq!(m.polygons_triangulated, 6);
    }

    #[test]
    fn binary_both_endians() {
        for big in [false, true] {
            let m = parse_bytes(&binary(big)).unwrap();
            assert_eq!(
                m.positions,
                vec![
                    Vec3::new(0.5, 0.0, 0.0),
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(0.0, 1.0, 0.0),
                    Vec3::new(0.0, 0.0, 1.0)
                ]
            );
            assert_eq!(m.triangles, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]]);
            assert_eq!(m.polygons_triangulated, 1);
        }
    }

    #[test]
    fn binary_errors_name_the_byte_offset() {
        let b = binary(false);
        let header_len = b.len() - 4 * 17 - 8 - (2 + 12) - (2 + 16);
        // Cut inside the third vertex.
        let e = parse_bytes(&b[..header_len + 2 * 17 + 5]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "t.ply: PLY element vertex 2 at byte offset {}: the file ends inside this element",
                header_len + 34
            )
        );
        // A NaN x in vertex 1.
        let mut nan = b.clone();
        nan[header_len + 17..header_len + 25].copy_from_slice(&f64::NAN.to_le_bytes());
        assert_eq!(
            parse_bytes(&nan).unwrap_err().message,
            format!(
                "vertex 1 (byte offset {}) is not finite: (NaN, 0, 0)",
                header_len + 17
            )
        );
        // Face 1's last index 9.
        let mut far = b.clone();
        let last = far.len() - 4;
        far[last..].copy_from_slice(&9u32.to_le_bytes());
        assert_eq!(
            parse_bytes(&far).unwrap_err().message,
            "PLY face 1 refers to vertex 9, the file has 4 vertices"
        );
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let bad = CUBE_ASCII.replace("1 1 0 0 4\n", "1 one 0 0 4\n");
        let e = parse_bytes(bad.as_bytes()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("t.ply: PLY element vertex 3 at line 16: "),
            "{e}"
        );
        let two = CUBE_ASCII.replace("4 0 1 5 4\n", "2 0 1\n");
        assert_eq!(
            parse_bytes(two.as_bytes()).unwrap_err().message,
            "PLY element face 2 at line 23: has 2 corners, a face needs at least 3"
        );
        let neg = CUBE_ASCII.replace("4 0 1 5 4\n", "3 0 1 -5\n");
        assert_eq!(
            parse_bytes(neg.as_bytes()).unwrap_err().message,
            "PLY element face 2 at line 23: vertex index -5 is not a vertex"
        );
        let inf = CUBE_ASCII.replace("0 1 1 0 7\n", "0 1e39 1 0 7\n");
        assert_eq!(
            parse_bytes(inf.as_bytes()).unwrap_err().message,
            "vertex 6 (line 19) is not finite: (0, inf, 1)"
        );
        let short = &CUBE_ASCII[..CUBE_ASCII.len() - 10];
        assert_eq!(
            parse_bytes(short.as_bytes()).unwrap_err().message,
            "PLY element face 5 at line 26: the file ends before this element"
        );
    }

    #[test]
    fn header_errors() {
        let e = parse_bytes(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "PLY header: the vertex element has no property `y`"
        );
        let e = parse_bytes(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
            .unwrap_err();
        assert_eq!(
            e.message,
            "the PLY file has no `face` element (a point cloud has no triangles)"
        );
        let e =
            parse_bytes(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\n").unwrap_err();
        assert!(e.message.starts_with("PLY header error: line 4: "), "{e}");
        let e = parse_bytes(b"solid x\n").unwrap_err();
        assert!(e.message.starts_with("PLY header error: line 1: "), "{e}");
        let float_list = CUBE_ASCII.replace("list uchar int", "list uchar float");
        assert!(parse_bytes(float_list.as_bytes())
            .unwrap_err()
            .message
            .starts_with("PLY element face 0 at line 21: "));
    }
}
