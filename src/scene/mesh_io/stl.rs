//! STL reading, ASCII and binary, written here.
//!
//! Why not a crate: `stl_io` 0.11 (the maintained candidate) reads one `solid` only (it stops
//! at the first `endsolid`), tells ASCII from binary by a leading `"solid "` alone (binary files
//! whose 80-byte header starts with "solid" are common and would be misread), takes keywords
//! in lower case only, and its errors carry no line or byte offset. Both formats are small
//! enough to read exactly:
//!
//! - **Binary** (chosen first, by the size rule): an 80-byte header (ignored, it may start with
//!   "solid"), a little-endian u32 triangle count n, then n records of 50 bytes (normal, three
//!   corners, a 2-byte attribute; normal and attribute are ignored). A file of exactly 84 + 50·n
//!   bytes is binary whatever its header says; a file that does not start with `solid` and is
//!   at least 84 bytes long is binary too, a shorter one than 84 + 50·n is an error naming the
//!   first triangle cut off and its byte offset, bytes after the last triangle are ignored.
//! - **ASCII**: `solid name` … `endsolid name`, any number of solids one after another
//!   (concatenated; an empty one is fine), each holding facets
//!   `facet normal nx ny nz / outer loop / vertex x y z (three or more) / endloop / endfacet`.
//!   Keywords in any case, tokens split by any whitespace (line breaks anywhere), names any
//!   bytes. The normal is not read (the winding gives the orientation). A loop of more than
//!   three vertices is fan-triangulated and counted. Errors name the line.
//!
//! Every facet's corners are its own: 3·n positions, unwelded (mesh repair welds them,
//! [`crate::scene::repair`]). A non-finite corner is an error naming the vertex (its index among the
//! positions) and its line or byte offset.

use super::{non_finite_vertex, push_fan, MeshFormat, RawMesh};
use crate::error::InputError;
use glam::Vec3;

/// Bytes of the binary header before the triangle count.
const HEADER_BYTES: usize = 80;
/// Bytes of one binary triangle record.
const RECORD_BYTES: usize = 50;

/// Reads STL bytes into a [`RawMesh`]; errors name `display_name` and the line or byte offset.
pub(super) fn parse(bytes: &[u8], display_name: &str) -> Result<RawMesh, InputError> {
    let err = |m: String| InputError::new(display_name, m);
    let count = bytes
        .get(HEADER_BYTES..HEADER_BYTES + 4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize);
    let binary_size = count.map(|n| (HEADER_BYTES + 4) as u64 + (RECORD_BYTES * n) as u64);
    let starts_solid = bytes
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"));
    match (count, binary_size) {
        (Some(n), Some(size)) if size == bytes.len() as u64 || !starts_solid => {
            binary(bytes, n).map_err(err)
        }
        _ if starts_solid => {
            ascii(bytes).map_err(|(line, m)| err(format!("STL parse error at line {line}: {m}")))
        }
        _ => Err(err(format!(
            "neither ASCII STL (which starts with `solid`) nor binary STL (at least 84 bytes), \
             {} bytes",
            bytes.len()
        ))),
    }
}

/// Binary STL of `n` triangles.
fn binary(bytes: &[u8], n: usize) -> Result<RawMesh, String> {
    let records = &bytes[HEADER_BYTES + 4..];
    let whole = records.len() / RECORD_BYTES;
    if whole < n {
        return Err(format!(
            "binary STL of {n} triangles ({} bytes) ends at byte {}, inside triangle {whole} \
             (which starts at byte offset {})",
            (HEADER_BYTES + 4) as u64 + (RECORD_BYTES * n) as u64,
            bytes.len(),
            HEADER_BYTES + 4 + RECORD_BYTES * whole
        ));
    }
    let mut positions = Vec::with_capacity(3 * n);
    for (t, record) in records.chunks_exact(RECORD_BYTES).take(n).enumerate() {
        for corner in 0..3 {
            let at = 12 + 12 * corner;
            let c = |k: usize| {
                let b = &record[at + 4 * k..at + 4 * k + 4];
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            };
            let p = [c(0), c(1), c(2)];
            if !p.iter().all(|x| x.is_finite()) {
                let offset = HEADER_BYTES + 4 + RECORD_BYTES * t + at;
                let place = format!("triangle {t}, byte offset {offset}");
                return Err(non_finite_vertex(3 * t + corner, Some(&place), p));
            }
            positions.push(Vec3::from_array(p));
        }
    }
    let triangles = (0..n as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    Ok(RawMesh {
        positions,
        triangles,
        format: MeshFormat::Stl,
        polygons_triangulated: 0,
    })
}

/// The lines of a file, numbered from 0.
type NumberedLines<'a> = std::iter::Enumerate<std::slice::Split<'a, u8, fn(&u8) -> bool>>;

/// The whitespace-separated words of ASCII STL with their 1-based lines.
struct Words<'a> {
    lines: NumberedLines<'a>,
    current: Vec<&'a [u8]>,
    next: usize,
    line: usize,
}

impl<'a> Words<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        let newline: fn(&u8) -> bool = |b| *b == b'\n';
        Words {
            lines: bytes.split(newline).enumerate(),
            current: Vec::new(),
            next: 0,
            line: 0,
        }
    }

    /// The next word and its line, or `None` at the end.
    fn next_word(&mut self) -> Option<(&'a [u8], usize)> {
        while self.next == self.current.len() {
            let (i, line) = self.lines.next()?;
            self.line = i + 1;
            self.current = line
                .split(u8::is_ascii_whitespace)
                .filter(|w| !w.is_empty())
                .collect();
            self.next = 0;
        }
        self.next += 1;
        Some((self.current[self.next - 1], self.line))
    }

    /// Skips the rest of the current line (a solid's name).
    fn skip_line(&mut self) {
        self.next = self.current.len();
    }

    /// The next word, which must be `keyword` (in any case).
    fn expect(&mut self, keyword: &str) -> Result<usize, (usize, String)> {
        match self.next_word() {
            Some((w, line)) if w.eq_ignore_ascii_case(keyword.as_bytes()) => Ok(line),
            Some((w, line)) => Err((line, format!("expected `{keyword}`, found {}", shown(w)))),
            None => Err((
                self.line,
                format!("the file ends where `{keyword}` should be"),
            )),
        }
    }

    /// The next word as an f32 number.
    fn number(&mut self) -> Result<(f32, usize), (usize, String)> {
        match self.next_word() {
            Some((w, line)) => std::str::from_utf8(w)
                .ok()
                .and_then(|s| s.parse::<f32>().ok())
                .map(|x| (x, line))
                .ok_or_else(|| (line, format!("expected a number, found {}", shown(w)))),
            None => Err((self.line, "the file ends where a number should be".into())),
        }
    }
}

/// A word quoted for a message (lossy UTF-8, at most 40 characters).
fn shown(word: &[u8]) -> String {
    let text = String::from_utf8_lossy(word);
    let mut s: String = text.chars().take(40).collect();
    if s.len() < text.len() {
        s.push('…');
    }
    format!("{s:?}")
}

/// ASCII STL: one or more solids; an error is its line and cause.
fn ascii(bytes: &[u8]) -> Result<RawMesh, (usize, String)> {
    let mut words = Words::new(bytes);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles = Vec::new();
    let mut polygons = 0;
    let mut corners: Vec<u32> = Vec::new();
    while let Some((w, line)) = words.next_word() {
        if !w.eq_ignore_ascii_case(b"solid") {
            return Err((line, format!("expected `solid`, found {}", shown(w))));
        }
        words.skip_line();
        loop {
            let (w, line) = words.next_word().ok_or((
                words.line,
                "the file ends inside a solid (no `endsolid`)".to_string(),
            ))?;
            if w.eq_ignore_ascii_case(b"endsolid") {
                words.skip_line();
                break;
            }
            if !w.eq_ignore_ascii_case(b"facet") {
                return Err((
                    line,
                    format!("expected `facet` or `endsolid`, found {}", shown(w)),
                ));
            }
            words.expect("normal")?;
            for _ in 0..3 {
                words.number()?;
            }
            words.expect("outer")?;
            words.expect("loop")?;
            corners.clear();
            loop {
                let (w, line) = words
                    .next_word()
                    .ok_or((words.line, "the file ends inside a facet".to_string()))?;
                if w.eq_ignore_ascii_case(b"endloop") {
                    if corners.len() < 3 {
                        return Err((
                            line,
                            format!("a facet has {} vertices, needs 3", corners.len()),
                        ));
                    }
                    break;
                }
                if !w.eq_ignore_ascii_case(b"vertex") {
                    return Err((
                        line,
                        format!("expected `vertex` or `endloop`, found {}", shown(w)),
                    ));
                }
                let p = [words.number()?.0, words.number()?.0, words.number()?.0];
                if !p.iter().all(|x| x.is_finite()) {
                    return Err((line, non_finite_vertex(positions.len(), None, p)));
                }
                corners.push(positions.len() as u32);
                positions.push(Vec3::from_array(p));
            }
            words.expect("endfacet")?;
            polygons += usize::from(push_fan(&mut triangles, &corners));
        }
    }
    Ok(RawMesh {
        positions,
        triangles,
        format: MeshFormat::Stl,
        polygons_triangulated: polygons,
    })
}

#[cfg(test)]
mod tests {
    use super::super::parse_mesh;
    use super::*;

    fn parse_bytes(bytes: &[u8]) -> Result<RawMesh, InputError> {
        parse_mesh(bytes, MeshFormat::Stl, "t.stl", None)
    }

    /// Binary STL of `tris` with a header starting "solid".
    fn binary_file(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = b"solid but binary".to_vec();
        b.resize(80, b' ');
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0u8; 12]);
            for c in t.iter().flatten() {
                b.extend(c.to_le_bytes());
            }
            b.extend([0u8; 2]);
        }
        b
    }

    const TRI_A: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    const TRI_B: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    #[test]
    fn binary_starting_with_solid() {
        let m = parse_bytes(&binary_file(&[TRI_A, TRI_B])).unwrap();
        assert_eq!(m.positions.len(), 6);
        assert_eq!(m.positions[4], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
    }

    #[test]
    fn binary_errors() {
        let b = binary_file(&[TRI_A, TRI_B]);
        // Cut: the header still says 2, the file holds 1.5 triangles; a header not starting
        // with "solid" makes it binary.
        let mut cut = b[..84 + 75].to_vec();
        cut[..5].copy_from_slice(b"model");
        assert_eq!(
            parse_bytes(&cut).unwrap_err().to_string(),
            "t.stl: binary STL of 2 triangles (184 bytes) ends at byte 159, inside triangle 1 \
             (which starts at byte offset 134)"
        );
        let mut nan = b.clone();
        nan[84 + 50 + 24 + 8..84 + 50 + 24 + 12].copy_from_slice(&f32::INFINITY.to_le_bytes());
        assert_eq!(
            parse_bytes(&nan).unwrap_err().message,
            "vertex 4 (triangle 1, byte offset 158) is not finite: (0, 1, inf)"
        );
        assert_eq!(
            parse_bytes(b"abc").unwrap_err().message,
            "neither ASCII STL (which starts with `solid`) nor binary STL (at least 84 bytes), \
             3 bytes"
        );
    }

    const TWO_SOLIDS: &str = "solid first É\n\
        facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n\
        endsolid first\nSOLID empty\nENDSOLID\n\
        solid second\n facet normal 0 0 0 outer loop vertex 0 0 0 vertex 0 1 0 vertex 0 0 1\n\
        vertex 0 2 2 endloop endfacet\nendsolid\n";

    #[test]
    fn ascii_two_solids() {
        let m = parse_bytes(TWO_SOLIDS.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 7);
        assert_eq!(m.positions[6], Vec3::new(0.0, 2.0, 2.0));
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5], [3, 5, 6]]);
        assert_eq!(m.polygons_triangulated, 1);
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let e = parse_bytes(
            TWO_SOLIDS
                .replace("vertex 1 0 0", "vertex 1 x 0")
                .as_bytes(),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.stl: STL parse error at line 5: expected a number, found \"x\""
        );
        let e = parse_bytes(
            TWO_SOLIDS
                .replace("vertex 1 0 0", "vertex 1 nan 0")
                .as_bytes(),
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "STL parse error at line 5: vertex 1 is not finite: (1, NaN, 0)"
        );
        let e = parse_bytes(b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nendloop\n")
            .unwrap_err();
        assert_eq!(
            e.message,
            "STL parse error at line 5: a facet has 1 vertices, needs 3"
        );
        let e = parse_bytes(b"solid a\nfacet normal 0 0 1\n").unwrap_err();
        assert_eq!(
            e.message,
            "STL parse error at line 3: the file ends where `outer` should be"
        );
        let e = parse_bytes(b"solid a\nendsolid a\njunk\n").unwrap_err();
        assert_eq!(
            e.message,
            "STL parse error at line 3: expected `solid`, found \"junk\""
        );
        let e = parse_bytes(b"solid a\nendsolid a\n").unwrap_err();
        assert_eq!(e.message, "the STL file has no triangles");
    }
}
