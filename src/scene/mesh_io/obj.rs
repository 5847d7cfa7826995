//! OBJ reading with `tobj`, tolerant of everything the renderer does not use.
//!
//! The renderer needs positions and faces only, so a pre-pass over the bytes hands `tobj` just
//! those, one output line per input line (so every line number in an error is the file's):
//! - the text is decoded first: UTF-16 (LE or BE) with a byte-order mark becomes UTF-8, a UTF-8
//!   byte-order mark is skipped (UTF-16 without a mark is not recognised);
//! - `v` lines keep `x y z` and an optional `w` (tobj divides by it); vertex colours
//!   (`v x y z r g b`) are dropped, since tobj fails on files where only some vertices have
//!   colours; each position is checked finite here, so the error names the vertex (1-based, as
//!   faces count) and its line;
//! - `f` lines keep each corner's position index (`7/3/2` → `7`): texture and normal indices are
//!   not checked, since nothing uses them; indices are checked here against the file's vertex
//!   count (positive: any vertex of the file; negative, relative: the vertices so far; 0 is no
//!   index), so the error names its line;
//! - faces with fewer than three corners (points, lines) and every other line — comments,
//!   `vt`, `vn`, `o`, `g`, `s`, `usemtl` (empty or not), `mtllib`, `l`, `p`, curves, unknown
//!   keywords — become empty lines: they may hold any bytes, UTF-8 or not (latin-1 material
//!   names are common). A `#` inside a `v` or `f` line starts a comment.
//!
//! The pre-pass runs on a thread of its own and hands its output on in chunks of whole lines
//! while `tobj` parses them (a million-triangle model parses in about half the time); the
//! result is the same as running one after the other: the same text reaches `tobj`, and an
//! error of the pre-pass is the one reported.
//!
//! `tobj` then parses the numbers and triangulates (`triangulate = true`: a polygon becomes a
//! fan from its first corner; [`RawMesh::polygons_triangulated`] counts the faces with more than
//! three corners); since groups and materials are blanked it sees one model. Positions come out
//! compacted to the vertices faces use, in order of first use. Materials are never loaded
//! (colour comes from the scene file). Positions are not welded here (mesh repair welds them,
//! [`crate::scene::repair`]).

use super::{non_finite_vertex, MeshFormat, RawMesh};
use crate::error::InputError;
use glam::Vec3;
use std::borrow::Cow;
use std::io::{BufRead, Read};
use std::sync::mpsc::{self, Receiver, Sender};

/// The pre-pass hands `tobj` its output in chunks of whole lines of about this many bytes.
const CHUNK: usize = 1 << 16;

/// Reads OBJ bytes into a [`RawMesh`]; errors name `display_name` and the line.
pub(super) fn parse(bytes: &[u8], display_name: &str) -> Result<RawMesh, InputError> {
    let text = decode(bytes);
    let err = |line: usize, cause: String| {
        InputError::new(
            display_name,
            format!(
                "OBJ parse error at line {line}: {cause} ({})",
                quoted_line(&text, line)
            ),
        )
    };
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // The pre-pass runs on its own thread while tobj parses what it has handed on (the two
    // take about the same time); its error, if any, is the one reported, as if it had run
    // first: it stops there, and tobj's result is then not looked at.
    let total_vertices = count_vertices(&text);
    let (loaded, polygons, tobj_line) = std::thread::scope(|scope| {
        let (send, chunks) = mpsc::channel();
        let text = &text;
        let prepass = scope.spawn(move || keep_positions_and_faces(text, total_vertices, send));
        let mut reader = KeptReader::new(chunks);
        let loaded = tobj::load_obj_buf(&mut reader, &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        });
        // tobj stops at the line it cannot use: the last line the reader handed out.
        let line = reader.newlines + usize::from(!reader.at_line_start);
        drop(reader);
        let polygons = prepass
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (loaded, polygons, line)
    });
    let polygons = polygons.map_err(|(line, cause)| err(line, cause))?;
    let (models, _materials) = loaded.map_err(|e| err(tobj_line, load_error_cause(&e)))?;

    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as u32;
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        // tobj's indices point into its own positions (it checks them).
        triangles.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    Ok(RawMesh {
        positions,
        triangles,
        format: MeshFormat::Obj,
        polygons_triangulated: polygons,
    })
}

/// The OBJ text as UTF-8 bytes (or bytes that are not text, left as they are): UTF-16 with a
/// byte-order mark decoded (an unpaired surrogate or an odd last byte becomes U+FFFD), a UTF-8
/// byte-order mark skipped.
fn decode(bytes: &[u8]) -> Cow<'_, [u8]> {
    let utf16 = |body: &[u8], unit: fn([u8; 2]) -> u16| {
        let units = body.chunks(2).map(|c| match c {
            [a, b] => unit([*a, *b]),
            _ => 0xFFFD,
        });
        let text: String = char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect();
        Cow::Owned(text.into_bytes())
    };
    match bytes {
        [0xFF, 0xFE, body @ ..] => utf16(body, u16::from_le_bytes),
        [0xFE, 0xFF, body @ ..] => utf16(body, u16::from_be_bytes),
        [0xEF, 0xBB, 0xBF, body @ ..] => Cow::Borrowed(body),
        _ => Cow::Borrowed(bytes),
    }
}

/// The first whitespace-separated word of `line` and the words after it, up to a word starting
/// with `#` (a comment).
fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> + Clone {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .take_while(|w| w[0] != b'#')
}

/// The number of `v` lines of `text`.
fn count_vertices(text: &[u8]) -> usize {
    text.split(|b| *b == b'\n')
        .filter(|line| words(line).next() == Some(b"v".as_slice()))
        .count()
}

/// The pre-pass of the module doc: `v` and `f` lines reduced to what `tobj` needs, everything
/// else blanked, positions checked finite and face indices checked in range (against the
/// file's `total_vertices`), sent on in chunks of whole lines (one output line per input
/// line) until the end or an error. Returns the faces with more than three corners, or the
/// 1-based line of the error and its cause. A line whose numbers do not parse is handed on
/// unchanged, for `tobj` to report. No allocation per line (a model of a million triangles
/// has 1.5 million lines).
fn keep_positions_and_faces(
    text: &[u8],
    total_vertices: usize,
    send: Sender<Vec<u8>>,
) -> Result<usize, (usize, String)> {
    let mut out = Vec::with_capacity(2 * CHUNK);
    let mut vertices = 0usize;
    let mut polygons = 0usize;
    for (i, line) in text.split(|b| *b == b'\n').enumerate() {
        let number = i + 1;
        let mut w = words(line);
        match w.next() {
            Some(b"v") => {
                vertices += 1;
                // Up to 7 values: more is not a position form (finite_position says None).
                let mut buf: [&[u8]; 7] = [&[]; 7];
                let mut count = 0;
                for (slot, v) in buf.iter_mut().zip(w) {
                    *slot = v;
                    count += 1;
                }
                let values = &buf[..count];
                match finite_position(values) {
                    Some(Ok(())) => {
                        out.push(b'v');
                        // x y z [w]: colours (six values) dropped.
                        let n = if values.len() == 4 { 4 } else { 3 };
                        for v in &values[..n] {
                            out.push(b' ');
                            out.extend_from_slice(v);
                        }
                    }
                    Some(Err(p)) => return Err((number, non_finite_vertex(vertices, None, p))),
                    None => out.extend_from_slice(line),
                }
            }
            Some(b"f") => {
                let corners = w.map(|c| c.split(|b| *b == b'/').next().unwrap_or_default());
                let count = corners.clone().count();
                if count >= 3 {
                    out.push(b'f');
                    for c in corners {
                        check_index(c, vertices, total_vertices).map_err(|e| (number, e))?;
                        out.push(b' ');
                        out.extend_from_slice(c);
                    }
                    polygons += usize::from(count > 3);
                }
            }
            _ => {}
        }
        out.push(b'\n');
        if out.len() >= CHUNK {
            // A closed channel (tobj stopped reading) leaves only the checks to finish.
            let _ = send.send(std::mem::replace(&mut out, Vec::with_capacity(2 * CHUNK)));
        }
    }
    let _ = send.send(out);
    Ok(polygons)
}

/// For a `v` line's values: `None` if they are not `x y z`, `x y z w` or `x y z r g b` with
/// parsable numbers (and w ≠ 0) — `tobj` reports those —, else whether the position (x/w, y/w,
/// z/w in f32, as `tobj` computes it) is finite, and if not, the position.
fn finite_position(values: &[&[u8]]) -> Option<Result<(), [f32; 3]>> {
    if ![3, 4, 6].contains(&values.len()) {
        return None;
    }
    let num = |v: &[u8]| std::str::from_utf8(v).ok()?.parse::<f32>().ok();
    let mut p = [num(values[0])?, num(values[1])?, num(values[2])?];
    if values.len() == 4 {
        let w = num(values[3])?;
        if w == 0.0 {
            return None;
        }
        p = p.map(|c| c / w);
    }
    Some(if p.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(p)
    })
}

/// A face corner's position index against the vertices so far (`seen`, for relative indices)
/// and in the file (`total`); an index that does not parse is left to `tobj`.
fn check_index(corner: &[u8], seen: usize, total: usize) -> Result<(), String> {
    let Some(i) = std::str::from_utf8(corner)
        .ok()
        .and_then(|s| s.parse::<i64>().ok())
    else {
        return Ok(());
    };
    let ok = match i {
        0 => return Err("vertex index 0 (OBJ counts vertices from 1)".into()),
        i if i > 0 => i.unsigned_abs() <= total as u64,
        i => i.unsigned_abs() <= seen as u64,
    };
    if ok {
        Ok(())
    } else if i > 0 {
        Err(format!(
            "face vertex index {i} out of bounds (the file has {total} vertices)"
        ))
    } else {
        Err(format!(
            "relative face vertex index {i} out of bounds ({seen} vertices so far)"
        ))
    }
}

/// A `BufRead` over the pre-pass's output as its thread sends it (chunks of whole lines; the
/// end when the pre-pass is done), counting the lines handed out, so that a `tobj` error,
/// which carries no position, can name its line.
struct KeptReader {
    chunks: Receiver<Vec<u8>>,
    /// The chunk being read, and how far.
    chunk: Vec<u8>,
    at: usize,
    /// Newlines consumed so far.
    newlines: usize,
    /// Whether the last byte consumed was a newline (or nothing was consumed).
    at_line_start: bool,
}

impl KeptReader {
    fn new(chunks: Receiver<Vec<u8>>) -> Self {
        KeptReader {
            chunks,
            chunk: Vec::new(),
            at: 0,
            newlines: 0,
            at_line_start: true,
        }
    }
}

impl Read for KeptReader {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for KeptReader {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        while self.at == self.chunk.len() {
            match self.chunks.recv() {
                Ok(next) => (self.chunk, self.at) = (next, 0),
                // The pre-pass is done: the end of the text.
                Err(_) => break,
            }
        }
        Ok(&self.chunk[self.at..])
    }

    fn consume(&mut self, amt: usize) {
        let end = (self.at + amt).min(self.chunk.len());
        let consumed = &self.chunk[self.at..end];
        if let Some(&last) = consumed.last() {
            self.newlines += consumed.iter().filter(|b| **b == b'\n').count();
            self.at_line_start = last == b'\n';
        }
        self.at = end;
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

#[cfg(test)]
pub(super) mod tests {
    use super::super::parse_mesh;
    use super::*;

    /// A unit cube written as 6 quads in groups sharing vertices, with material, texture and
    /// normal lines, a line and a point.
    pub(in crate::scene::mesh_io) const CUBE: &str = "# cube\nmtllib nowhere.mtl\n\
        v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
        o a\nf 1 3 4 2\nf 5 6 8 7\n\
        g b\nusemtl red\nf 1 2 6 5\nf 3 7 8 4\n\
        o c\nf 1 5 7 3\nf 2/1/1 4/1/1 8/1/1 6/1/1\nvt 0 0\nvn 0 0 1\nl 1 2\np 3\n";

    fn parse_str(text: &str) -> Result<RawMesh, InputError> {
        parse_mesh(text.as_bytes(), MeshFormat::Obj, "test.obj", None)
    }

    #[test]
    fn cube_quads_become_fans() {
        let m = parse_str(CUBE).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.polygons_triangulated, 6);
        assert_eq!(m.format, MeshFormat::Obj);
        // Vertices in order of first use: 1 3 4 2 5 6 8 7 (file numbering).
        assert_eq!(
            m.triangles[..4],
            [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
        );
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.positions[1], Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn negative_indices_and_polygons() {
        let m =
            parse_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nf -5 -4 -3 -2 -1\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        assert_eq!(m.polygons_triangulated, 1);
        let e = parse_str("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n").unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 3: relative face vertex index -3 out of bounds \
             (2 vertices so far) (line reads \"f -1 -2 -3\")"
        );
    }

    #[test]
    fn vertex_colours_and_w() {
        // Colours on some vertices only (tobj alone fails on that), w divides.
        let m =
            parse_str("v 0 0 0 1 0 0\nv 2 0 0 2\nv 0 1 0 0.5 0.5 0.5\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
                .unwrap();
        assert_eq!(m.positions[1], Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(m.triangles.len(), 2);
    }

    #[test]
    fn latin1_usemtl_comments_and_empty_usemtl() {
        let text = b"# caf\xe9 model\nmtllib m\xe9.mtl\nusemtl\nusemtl \xc0rouge\no \xe9\ng\ns 1\n\
            v 0 0 0 # c\xf4t\xe9\nv 1 0 0\nv 0 1 0\nf 1 2 3 # fin\n";
        let m = parse(text, "l.obj").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn utf16_with_bom() {
        let text = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n# é\r\nf 1 2 3\r\n";
        let mut be = vec![0xFE, 0xFF];
        be.extend(text.encode_utf16().flat_map(u16::to_be_bytes));
        let m = parse(&be, "be.obj").unwrap();
        assert_eq!(m.positions[1], Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        let mut le = vec![0xFF, 0xFE];
        le.extend(text.encode_utf16().flat_map(u16::to_le_bytes));
        assert_eq!(parse(&le, "le.obj").unwrap(), m);
        let mut utf8 = vec![0xEF, 0xBB, 0xBF];
        utf8.extend(text.as_bytes());
        assert_eq!(parse(&utf8, "u.obj").unwrap(), m);
        // An error in UTF-16 text quotes the decoded line.
        let mut bad = vec![0xFE, 0xFF];
        bad.extend(
            "v 0 0 0\nv 1 x 0\n"
                .encode_utf16()
                .flat_map(u16::to_be_bytes),
        );
        assert_eq!(
            parse(&bad, "be.obj").unwrap_err().message,
            "OBJ parse error at line 2: a vertex position needs three numbers: v x y z \
             (line reads \"v 1 x 0\")"
        );
    }

    #[test]
    fn polyline_of_three_points_is_not_a_triangle() {
        // tobj reads `l` like `f`: a three-point polyline would become a triangle.
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\nf 1 2\np 1\n").unwrap_err();
        assert_eq!(e.message, "the OBJ file has no triangles");
    }

    #[test]
    fn nan_vertex() {
        let e = parse_str("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "test.obj: OBJ parse error at line 2: vertex 2 is not finite: (NaN, 0, 0) \
             (line reads \"v nan 0 0\")"
        );
        let e = parse_str("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert!(
            e.message.contains("vertex 2 is not finite: (inf, 0, 0)"),
            "{e}"
        );
        let e = parse_str("v 1 0 0 1e-45\n").unwrap_err();
        assert!(e.message.contains("vertex 1 is not finite"), "{e}");
    }

    #[test]
    fn parse_errors() {
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "test.obj: OBJ parse error at line 4: a face needs three or more vertex indices: \
             f i j k (line reads \"f 1 2 x\")"
        );
        let e = parse_str("# c\nv 0 0 0\nv 0 zero 0\nv 0 1 0\n").unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 3: a vertex position needs three numbers: v x y z \
             (line reads \"v 0 zero 0\")"
        );
        let e = parse(b"v 0 0 0\nv 1 \xff 0", "x.obj").unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 2: not UTF-8 text (line reads \"v 1 \u{fffd} 0\")"
        );
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            e.message,
            "OBJ parse error at line 4: face vertex index 9 out of bounds (the file has 3 \
             vertices) (line reads \"f 1 2 9\")"
        );
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n").unwrap_err();
        assert!(e.message.contains("line 4: vertex index 0"), "{e}");
        let e = parse_str("v 0 0 0\nv 1 0 0\nl 1 2\n").unwrap_err();
        assert_eq!(e.message, "the OBJ file has no triangles");
        // A UTF-16 byte-order mark and half a character: one line, no face.
        let e = parse_mesh(&[0xff, 0xfe, 0x00], MeshFormat::Obj, "x.obj", None).unwrap_err();
        assert_eq!(e.message, "the OBJ file has no triangles");
    }

    /// A file of many chunks of the pre-pass (each vertex line ~20 bytes): tobj's errors still
    /// name their line across chunks, and a pre-pass error after a line tobj rejects is the
    /// one reported (as when the pre-pass ran to its end before tobj began).
    #[test]
    fn errors_far_into_a_file_of_many_chunks() {
        let n = 20_000; // ~6 chunks of vertices
        let mut text = String::new();
        for i in 0..n {
            text.push_str(&format!("v {i} 0.5 0.25\n"));
        }
        text.push_str("f 1 2 3\n");
        let good = parse_str(&text).unwrap();
        assert_eq!((good.positions.len(), good.triangles.len()), (3, 1));
        let bad_face = format!("{text}f 1 2 x\n");
        let e = parse_str(&bad_face).unwrap_err();
        assert_eq!(
            e.message,
            format!(
                "OBJ parse error at line {}: a face needs three or more vertex indices: f i j k \
                 (line reads \"f 1 2 x\")",
                n + 2
            )
        );
        // Line 2 has only two numbers (for tobj to report), the last line is not finite.
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        lines[1] = "v 1 2".into();
        lines.push("v 0 nan 0".into());
        let e = parse_str(&(lines.join("\n") + "\n")).unwrap_err();
        assert_eq!(
            e.message,
            format!(
                "OBJ parse error at line {}: vertex {} is not finite: (0, NaN, 0) (line reads \
                 \"v 0 nan 0\")",
                n + 2,
                n + 1
            )
        );
    }
}
