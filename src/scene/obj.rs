//! OBJ loading with `tobj`: one file becomes one closed [`Mesh`].
//!
//! Choices, and why:
//! - `triangulate = true` (polygons become fans), `single_index = false` (only position
//!   indices matter: normals and texture coordinates are ignored), points and lines ignored,
//!   materials never loaded (`mtllib` is skipped; colour comes from the scene file).
//! - All models (`o`/`g`/`usemtl` groups) of the file are concatenated into one mesh. `tobj`
//!   compacts positions per model, so a vertex shared by two groups arrives twice; vertices with
//!   bit-identical coordinates (−0 = +0) are therefore welded into one, which restores the
//!   file's shared vertices and also closes meshes written with per-face vertex copies.
//! - Non-finite coordinates are rejected before anything else is computed.
//! - The optional transform must be affine (last row 0,0,0,1), finite and non-singular; it is
//!   applied to each point (w = 1) in f64 and rounded once to f32. A negative determinant
//!   (reflection) flips every triangle's winding so the mesh stays outward-facing.
//!
//! Closedness is checked later by [`super::validate`], which names the mesh and the edge.

use super::input_file::read_input_file;
use super::procedural::transform_point;
use super::Mesh;
use crate::error::InputError;
use glam::{Mat4, Vec3, Vec4};
use std::collections::HashMap;
use std::io::{BufRead, Cursor, Read};
use std::path::Path;

/// Loads the OBJ file at `path` as one mesh named `display_name` (also the file named in
/// errors), optionally transformed, with albedo `color`.
///
/// Errors (each naming `display_name`): unreadable file (not a regular file, too large: the
/// rule of [`read_input_file`]), OBJ parse error (with the line and its cause), a non-finite
/// coordinate, no triangles, a non-affine, non-finite or singular transform.
pub fn load_obj(
    path: &Path,
    display_name: &str,
    transform: Option<Mat4>,
    color: [f32; 3],
) -> Result<Mesh, InputError> {
    let bytes = read_input_file(path)
        .map_err(|m| InputError::new(display_name, format!("cannot read OBJ file: {m}")))?;
    parse_obj(&bytes, display_name, transform, color)
}

/// Parses OBJ text already in memory; see [`load_obj`] (used by it and by fuzzing).
pub fn parse_obj(
    bytes: &[u8],
    display_name: &str,
    transform: Option<Mat4>,
    color: [f32; 3],
) -> Result<Mesh, InputError> {
    let err = |m: String| InputError::new(display_name, m);
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = LineCountingReader {
        inner: Cursor::new(bytes),
        newlines: 0,
        at_line_start: true,
    };
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| {
        // tobj stops at the line it cannot use: the last line the reader handed out.
        let line = reader.newlines + usize::from(!reader.at_line_start);
        err(format!(
            "OBJ parse error at line {line}: {} ({})",
            load_error_cause(&e),
            quoted_line(bytes, line)
        ))
    })?;

    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    for model in &models {
        let mesh = &model.mesh;
        let mut local = Vec::with_capacity(mesh.positions.len() / 3);
        for p in mesh.positions.chunks_exact(3) {
            let v = Vec3::new(p[0], p[1], p[2]);
            if !v.is_finite() {
                let object = match model.name.as_str() {
                    "unnamed_object" | "" => String::new(),
                    name => format!(" in object \"{name}\""),
                };
                return Err(err(format!(
                    "vertex ({}, {}, {}){object} is not finite",
                    v.x, v.y, v.z
                )));
            }
            // +0.0 turns −0.0 into +0.0, so both weld together.
            let key = (v + Vec3::ZERO).to_array().map(f32::to_bits);
            let next = positions.len();
            let idx = *weld.entry(key).or_insert_with(|| {
                positions.push(v + Vec3::ZERO);
                next as u32
            });
            local.push(idx);
        }
        for t in mesh.indices.chunks_exact(3) {
            let get = |i: u32| local.get(i as usize).copied();
            match (get(t[0]), get(t[1]), get(t[2])) {
                (Some(a), Some(b), Some(c)) => triangles.push([a, b, c]),
                _ => {
                    return Err(err(
                        "OBJ parse error: face vertex index out of bounds".into()
                    ))
                }
            }
        }
    }
    if triangles.is_empty() {
        return Err(err("the OBJ file has no triangles".into()));
    }

    if let Some(m) = transform {
        check_transform(&m).map_err(|e| err(format!("transform {e}")))?;
        let md = m.as_dmat4();
        for p in &mut positions {
            *p = transform_point(&md, *p);
        }
        if md.determinant() < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(err(format!(
                "transformed vertex ({}, {}, {}) overflows f32",
                p.x, p.y, p.z
            )));
        }
    }
    Ok(Mesh {
        name: display_name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    })
}

/// A `BufRead` over the OBJ bytes that counts the lines handed out, so that a `tobj` error,
/// which carries no position, can name its line.
struct LineCountingReader<'a> {
    inner: Cursor<&'a [u8]>,
    /// Newlines consumed so far.
    newlines: usize,
    /// Whether the last byte consumed was a newline (or nothing was consumed).
    at_line_start: bool,
}

impl Read for LineCountingReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count(&buf[..n]);
        Ok(n)
    }
}

impl BufRead for LineCountingReader<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        let start = self.inner.position() as usize;
        let data = *self.inner.get_ref();
        let end = (start + amt).min(data.len());
        self.count(&data[start..end]);
        self.inner.consume(amt);
    }
}

impl LineCountingReader<'_> {
    fn count(&mut self, consumed: &[u8]) {
        if let Some(last) = consumed.last() {
            self.newlines += consumed.iter().filter(|b| **b == b'\n').count();
            self.at_line_start = *last == b'\n';
        }
    }
}

/// What a `tobj` error means, in words that say what the line should have been.
fn load_error_cause(e: &tobj::LoadError) -> String {
    use tobj::LoadError as E;
    match e {
        E::ReadError => "not UTF-8 text".into(),
        E::PositionParseError => "a vertex position needs three numbers: v x y z".into(),
        E::FaceParseError => "a face needs three or more vertex indices: f i j k".into(),
        E::NormalParseError => "a normal needs three numbers: vn x y z".into(),
        E::TexcoordParseError => "a texture coordinate needs one to three numbers: vt u v".into(),
        E::FaceVertexOutOfBounds => "face vertex index out of bounds (no such vertex)".into(),
        other => other.to_string(),
    }
}

/// Line `line` (1-based) of `bytes`, quoted and shortened to 80 characters, as text.
fn quoted_line(bytes: &[u8], line: usize) -> String {
    let text = bytes
        .split(|b| *b == b'\n')
        .nth(line.saturating_sub(1))
        .unwrap_or_default();
    let text = String::from_utf8_lossy(text);
    let text = text.trim_end_matches('\r');
    let mut shown: String = text.chars().take(80).collect();
    if shown.len() < text.len() {
        shown.push('…');
    }
    format!("line reads {shown:?}")
}

/// A transform must be finite, affine (last row 0,0,0,1) and invertible.
pub(crate) fn check_transform(m: &Mat4) -> Result<(), String> {
    if !m.is_finite() {
        return Err("contains a non-finite number".into());
    }
    if m.row(3) != Vec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(format!(
            "is not affine: its last row (elements 3, 7, 11, 15 in column-major order) is {:?}, \
             must be [0, 0, 0, 1]",
            m.row(3).to_array()
        ));
    }
    let det = m.as_dmat4().determinant();
    if det == 0.0 || !det.is_finite() {
        return Err("is singular (determinant 0): it flattens the mesh".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;
    use crate::scene::procedural::signed_volume6;

    /// A unit cube written as 6 quads in three groups sharing vertices.
    const CUBE: &str = "# cube\nmtllib nowhere.mtl\n\
        v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
        o a\nf 1 3 4 2\nf 5 6 8 7\n\
        g b\nusemtl red\nf 1 2 6 5\nf 3 7 8 4\n\
        o c\nf 1 5 7 3\nf 2/1/1 4/1/1 8/1/1 6/1/1\nvt 0 0\nvn 0 0 1\nl 1 2\np 3\n";

    fn parse(text: &str, t: Option<Mat4>) -> Result<Mesh, InputError> {
        parse_obj(text.as_bytes(), "test.obj", t, [0.5; 3])
    }

    #[test]
    fn cube_groups_are_welded() {
        let m = parse(CUBE, None).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.triangles.len(), 12);
        adjacency::build(&m).unwrap();
        assert!((signed_volume6(&m) - 6.0).abs() < 1e-9);
        assert_eq!(m.name, "test.obj");
    }

    #[test]
    fn transform_and_reflection() {
        let t =
            Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * Mat4::from_scale(Vec3::splat(2.0));
        let m = parse(CUBE, Some(t)).unwrap();
        assert!((signed_volume6(&m) - 48.0).abs() < 1e-9);
        assert!(m.positions.contains(&Vec3::new(3.0, 4.0, 5.0)));
        let mirror = parse(CUBE, Some(Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0)))).unwrap();
        assert!((signed_volume6(&mirror) - 6.0).abs() < 1e-9);
        adjacency::build(&mirror).unwrap();
    }

    #[test]
    fn bad_transforms() {
        let e = parse(CUBE, Some(Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)))).unwrap_err();
        assert!(
            e.to_string().starts_with("test.obj: transform is singular"),
            "{e}"
        );
        let mut p = Mat4::IDENTITY;
        p.x_axis.w = 0.5;
        assert!(parse(CUBE, Some(p))
            .unwrap_err()
            .message
            .contains("not affine"));
        let mut n = Mat4::IDENTITY;
        n.w_axis.x = f32::NAN;
        assert!(parse(CUBE, Some(n))
            .unwrap_err()
            .message
            .contains("non-finite"));
        let big = Mat4::from_translation(Vec3::X * 3e38) * Mat4::from_scale(Vec3::splat(3e38));
        assert!(parse(CUBE, Some(big))
            .unwrap_err()
            .message
            .contains("overflows"));
    }

    #[test]
    fn nan_vertex() {
        let e = parse("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", None).unwrap_err();
        assert_eq!(e.to_string(), "test.obj: vertex (NaN, 0, 0) is not finite");
        let e = parse("v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", None).unwrap_err();
        assert!(e.message.contains("(inf, 0, 0)"), "{e}");
    }

    #[test]
    fn parse_errors() {
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "test.obj: OBJ parse error at line 4: a face needs three or more vertex indices: \
             f i j k (line reads \"f 1 2 x\")"
        );
        let e = parse("# c\nv 0 0 0\nv 0 zero 0\nv 0 1 0\n", None).unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 3: a vertex position needs three numbers: v x y z \
             (line reads \"v 0 zero 0\")"
        );
        let e = parse_obj(b"v 0 0 0\nv 1 \xff 0", "x.obj", None, [0.5; 3]).unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 2: not UTF-8 text (line reads \"v 1 \u{fffd} 0\")"
        );
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", None).unwrap_err();
        assert!(e.message.contains("out of bounds"), "{e}");
        let e = parse("v 0 zero 0\n", None).unwrap_err();
        assert!(e.message.contains("OBJ parse error"), "{e}");
        let e = parse("v 0 0 0\nv 1 0 0\nl 1 2\n", None).unwrap_err();
        assert_eq!(e.message, "the OBJ file has no triangles");
        assert!(parse_obj(&[0xff, 0xfe, 0x00], "x.obj", None, [0.5; 3]).is_err());
    }

    #[test]
    fn missing_file() {
        let e = load_obj(
            Path::new("/nonexistent/dir/none.obj"),
            "none.obj",
            None,
            [0.5; 3],
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("none.obj: cannot read OBJ file: "),
            "{e}"
        );
    }
}
