//! glTF 2.0 reading: `.gltf` (JSON, buffers in `data:` URIs or in files beside it) and `.glb`.
//!
//! Crate: `gltf` for what it does well, the JSON schema (`gltf::json`, serde) and its
//! validation (every index in range, required fields present) and the typed document walk.
//! The bytes are read here instead: the crate's GLB splitter and accessor iterators index and
//! subtract without checks (a GLB whose length is below its header size, an accessor of count 0
//! or past its view panic in `gltf` 1.4), and its `import` feature opens buffer files itself,
//! bypassing the size rule of [`read_input_file`]. So this module splits GLB chunks, decodes
//! `data:` URIs (the `base64` crate), reads buffer files through [`read_input_file`] relative
//! to the `.gltf`'s directory (percent-escapes decoded), and checks every accessor's bytes
//! against its view and buffer with checked arithmetic.
//!
//! What is read, and the choices:
//! - The scene: the `scene` field's scene, else scene 0; a file without scenes gives every
//!   root node (a node that is no node's child); a file without nodes gives every mesh as it
//!   is. Nodes outside the chosen scene are not drawn (as a viewer would not).
//! - At most [`MAX_ELEMENTS`] vertices and as many triangles in all (an error past that). glTF
//!   is the one format whose size does not bound its mesh: one accessor may be drawn by many
//!   primitives, each mesh placed by many nodes, so a few kilobytes of JSON could ask for 10¹⁰
//!   vertices. The bound is what a file of the input size limit could write out (12 bytes per
//!   position), so every mesh such a file really holds is read.
//! - Each node's transform (`matrix`, or `translation`·`rotation`·`scale`) composed down the
//!   hierarchy in f64; each position is transformed once and rounded to f32. A node whose
//!   world transform has a negative determinant flips its triangles' winding (glTF's rule). A
//!   mesh used by several nodes is placed once per node. A node reached twice (a cycle) is an
//!   error.
//! - Primitives of mode TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN, converted to triangles as
//!   the glTF spec numbers them; indexed (u8, u16, u32) or not (consecutive vertices). POINTS
//!   and LINE* primitives are skipped like OBJ's points and lines; a file with no triangle
//!   primitive at all is an error naming the first other primitive and its mode. A primitive
//!   without POSITION is skipped (the spec says such a primitive is not drawn).
//! - Morph targets and skins are ignored: the base positions are used, as with the default
//!   weights of zero and a bind pose.
//! - Refused with a message: sparse accessors, POSITION other than VEC3 FLOAT, the required
//!   extensions that change how geometry is stored (KHR_draco_mesh_compression,
//!   EXT_meshopt_compression, KHR_mesh_quantization); other required extensions (materials,
//!   textures, lights) do not touch positions and are ignored. A file whose required extension
//!   is Draco but which also holds uncompressed fallback accessors is still refused, since the
//!   file says it must not be read without it.

use super::super::input_file::read_input_file;
use super::super::procedural::transform_point;
use super::{MeshFormat, RawMesh};
use crate::error::InputError;
use crate::limits::MAX_INPUT_FILE_BYTES;
use base64::Engine as _;
use glam::{DMat4, DQuat, DVec3, DVec4, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::scene::Transform;
use gltf::{Accessor, Document, Node, Semantic};
use std::borrow::Cow;
use std::path::Path;

/// The GLB magic, "glTF".
const GLB_MAGIC: &[u8; 4] = b"glTF";
/// The GLB chunk type of the JSON chunk ("JSON").
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// The GLB chunk type of the binary chunk ("BIN\0").
const CHUNK_BIN: u32 = 0x004E_4942;

/// Most vertices, and most triangles, one glTF file may place (see the module doc): as many
/// VEC3 FLOAT positions as a file of [`MAX_INPUT_FILE_BYTES`] holds, about 44.7 million.
pub const MAX_ELEMENTS: usize = (MAX_INPUT_FILE_BYTES / 12) as usize;

/// Required extensions this reader refuses, and what they are.
const REFUSED_EXTENSIONS: [(&str, &str); 3] = [
    ("KHR_draco_mesh_compression", "Draco-compressed meshes"),
    ("EXT_meshopt_compression", "meshopt-compressed buffers"),
    ("KHR_mesh_quantization", "quantized (non-float) positions"),
];

/// Reads glTF or GLB bytes into a [`RawMesh`]; errors name `display_name`, and the mesh,
/// primitive, accessor, node or byte offset.
pub(super) fn parse(
    bytes: &[u8],
    display_name: &str,
    base_dir: Option<&Path>,
) -> Result<RawMesh, InputError> {
    let err = |m: String| InputError::new(display_name, m);
    let (json, bin) = if bytes.starts_with(GLB_MAGIC) {
        split_glb(bytes).map_err(|m| err(format!("GLB container: {m}")))?
    } else {
        (bytes, None)
    };
    let mut root: gltf::json::Root = gltf::json::deserialize::from_slice(json)
        .map_err(|e| err(format!("glTF JSON error: {e}")))?;
    for ext in &root.extensions_required {
        if let Some((_, what)) = REFUSED_EXTENSIONS.iter().find(|(name, _)| name == ext) {
            return Err(err(format!(
                "requires the extension {ext} ({what}), which this reader does not support"
            )));
        }
    }
    // The other required extensions do not change geometry (see the module doc); the crate's
    // validation would refuse any it does not know.
    root.extensions_required.clear();
    if let Some(problem) = position_index_out_of_range(&root) {
        return Err(err(format!("glTF validation error at {problem}")));
    }
    let mut problems = Vec::new();
    {
        use gltf::json::validation::Validate;
        root.validate(&root, gltf::json::Path::new, &mut |path, e| {
            problems.push(format!("{}: {e}", path()));
        });
    }
    if let Some(first) = problems.first() {
        let more = match problems.len() {
            1 => String::new(),
            n => format!(" (and {} more problems)", n - 1),
        };
        return Err(err(format!("glTF validation error at {first}{more}")));
    }
    let doc = Document::from_json_without_validation(root);
    let mut reader = MeshReader {
        doc: &doc,
        buffers: vec![None; doc.buffers().len()],
        bin,
        base_dir,
        positions: Vec::new(),
        triangles: Vec::new(),
        skipped: None,
    };
    reader.read_scene().map_err(err)?;
    if reader.triangles.is_empty() {
        if let Some(skipped) = reader.skipped {
            return Err(err(format!(
                "the glTF file has no triangle primitive ({skipped}: only TRIANGLES, \
                 TRIANGLE_STRIP and TRIANGLE_FAN are read)"
            )));
        }
    }
    Ok(RawMesh {
        positions: reader.positions,
        triangles: reader.triangles,
        format: MeshFormat::Gltf,
        polygons_triangulated: 0,
    })
}

/// The first primitive whose POSITION accessor index is past the accessors, named as the
/// crate's validation names a bad index (`meshes[M].primitives[P].attributes["POSITION"]:
/// Index out of bounds`). Checked before that validation: gltf-json 1.4's primitive check
/// reads the POSITION accessor by its index before the index itself is checked, and panics on
/// an index past the end (found by fuzzing, `fuzz/regressions/gltf/`).
fn position_index_out_of_range(root: &gltf::json::Root) -> Option<String> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::{Checked, Error};
    root.meshes.iter().enumerate().find_map(|(m, mesh)| {
        mesh.primitives.iter().enumerate().find_map(|(p, prim)| {
            let index = prim.attributes.get(&Checked::Valid(Semantic::Positions))?;
            (index.value() >= root.accessors.len()).then(|| {
                let path = gltf::json::Path::new()
                    .field("meshes")
                    .index(m)
                    .field("primitives")
                    .index(p)
                    .field("attributes")
                    .key("POSITION");
                format!("{path}: {}", Error::IndexOutOfBounds)
            })
        })
    })
}

/// A little-endian u32 at `at`, if the bytes hold it.
fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// The JSON chunk and the binary chunk (if any) of a GLB file.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let version = u32_at(bytes, 4).ok_or("the file ends inside the 12-byte header")?;
    if version != 2 {
        return Err(format!(
            "version {version} at byte offset 4, only 2 is read"
        ));
    }
    let length = u32_at(bytes, 8).ok_or("the file ends inside the 12-byte header")? as usize;
    if length > bytes.len() {
        return Err(format!(
            "the header (byte offset 8) gives a length of {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..length];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (u32_at(bytes, at), u32_at(bytes, at + 4)) else {
            return Err(format!(
                "the file ends inside the chunk header at byte offset {at}"
            ));
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                format!(
                    "the chunk at byte offset {at} has {len} bytes, past the end of the file \
                     ({} bytes)",
                    bytes.len()
                )
            })?;
        let data = &bytes[start..end];
        match kind {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some(data),
            CHUNK_BIN if bin.is_none() && json.is_some() => bin = Some(data),
            _ if at == 12 => {
                return Err("the first chunk (byte offset 12) is not the JSON chunk".into())
            }
            // Chunks of other types are skipped, as the GLB spec says.
            _ => {}
        }
        // Chunks start on 4-byte boundaries.
        at = end.next_multiple_of(4);
    }
    let json = json.ok_or("no JSON chunk")?;
    Ok((json, bin))
}

/// Walks the scene and collects its triangles.
struct MeshReader<'a> {
    doc: &'a Document,
    /// Each buffer's bytes, loaded when first used.
    buffers: Vec<Option<Cow<'a, [u8]>>>,
    /// The GLB binary chunk.
    bin: Option<&'a [u8]>,
    base_dir: Option<&'a Path>,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// The first primitive skipped for its mode, for the error when nothing is read.
    skipped: Option<String>,
}

impl<'a> MeshReader<'a> {
    /// Every mesh of the chosen scene (see the module doc).
    fn read_scene(&mut self) -> Result<(), String> {
        let doc = self.doc;
        let scene = doc.default_scene().or_else(|| doc.scenes().next());
        let has_scene = scene.is_some();
        let roots: Vec<Node> = match scene {
            Some(s) => s.nodes().collect(),
            None => {
                let mut is_child = vec![false; doc.nodes().len()];
                for n in doc.nodes() {
                    for c in n.children() {
                        is_child[c.index()] = true;
                    }
                }
                doc.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        if doc.nodes().len() == 0 && !has_scene {
            for mesh in doc.meshes() {
                self.read_mesh(&mesh, &DMat4::IDENTITY)?;
            }
            return Ok(());
        }
        let mut reached = vec![false; doc.nodes().len()];
        // Depth first, in the file's order: the stack holds the next node last.
        let mut stack: Vec<(Node, DMat4)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        while let Some((node, parent)) = stack.pop() {
            if std::mem::replace(&mut reached[node.index()], true) {
                return Err(format!(
                    "node {} is reached twice from the scene (a cycle, or a node with two \
                     parents)",
                    node.index()
                ));
            }
            let world = parent * local_transform(&node)?;
            if let Some(mesh) = node.mesh() {
                self.read_mesh(&mesh, &world)?;
            }
            let children: Vec<Node> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }
        Ok(())
    }

    /// The triangle primitives of `mesh`, placed by `world`.
    fn read_mesh(&mut self, mesh: &gltf::Mesh, world: &DMat4) -> Result<(), String> {
        let flip = world.determinant() < 0.0;
        for prim in mesh.primitives() {
            let at = || match mesh.name() {
                Some(name) => format!(
                    "mesh {} ({name:?}) primitive {}",
                    mesh.index(),
                    prim.index()
                ),
                None => format!("mesh {} primitive {}", mesh.index(), prim.index()),
            };
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.skipped
                    .get_or_insert_with(|| format!("{} has mode {mode:?}", at()));
                continue;
            }
            let Some(pos) = prim.get(&Semantic::Positions) else {
                continue;
            };
            let local = self
                .read_positions(&pos)
                .map_err(|m| format!("{}: POSITION {m}", at()))?;
            let corners: Vec<u32> = match prim.indices() {
                Some(acc) => self
                    .read_indices(&acc, local.len())
                    .map_err(|m| format!("{}: indices {m}", at()))?,
                None => (0..local.len() as u32).collect(),
            };
            let triangles = match mode {
                Mode::Triangles => corners.len() / 3,
                _ => corners.len().saturating_sub(2),
            };
            within_limit(
                (self.positions.len(), self.triangles.len()),
                local.len(),
                triangles,
            )
            .map_err(|m| format!("{}: {m}", at()))?;
            let base = self.positions.len() as u32;
            for p in &local {
                let q = transform_point(world, *p);
                if !q.is_finite() {
                    return Err(format!(
                        "{}: a vertex transformed by its nodes, ({}, {}, {}), overflows f32",
                        at(),
                        q.x,
                        q.y,
                        q.z
                    ));
                }
                self.positions.push(q);
            }
            if mode == Mode::Triangles && corners.len() % 3 != 0 {
                return Err(format!(
                    "{}: mode TRIANGLES needs a multiple of 3 vertices, has {}",
                    at(),
                    corners.len()
                ));
            }
            let c = |i: usize| corners[i] + base;
            for i in 0..corners.len().saturating_sub(2) {
                let t = match mode {
                    Mode::Triangles if i % 3 == 0 => [c(i), c(i + 1), c(i + 2)],
                    Mode::Triangles => continue,
                    // glTF 2.0 §3.7.2.1: strips alternate the winding, fans turn about vertex 0.
                    Mode::TriangleStrip if i % 2 == 0 => [c(i), c(i + 1), c(i + 2)],
                    Mode::TriangleStrip => [c(i + 1), c(i), c(i + 2)],
                    _ => [c(i + 1), c(i + 2), c(0)],
                };
                self.triangles
                    .push(if flip { [t[0], t[2], t[1]] } else { t });
            }
        }
        Ok(())
    }

    /// The bytes of buffer `index`, loaded (and checked against its byteLength) once.
    fn buffer(&mut self, index: usize) -> Result<&[u8], String> {
        if self.buffers[index].is_none() {
            let buffer = self.doc.buffers().nth(index).ok_or("no such buffer")?;
            let data: Cow<'a, [u8]> = match buffer.source() {
                gltf::buffer::Source::Bin => Cow::Borrowed(self.bin.ok_or_else(|| {
                    format!("buffer {index} is the GLB binary chunk, which the file does not have")
                })?),
                gltf::buffer::Source::Uri(uri) => Cow::Owned(self.load_uri(index, uri)?),
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {index} holds {} bytes, its byteLength is {}",
                    data.len(),
                    buffer.length()
                ));
            }
            self.buffers[index] = Some(data);
        }
        Ok(self.buffers[index].as_deref().unwrap_or_default())
    }

    /// A buffer URI's bytes: a base64 `data:` URI decoded, else a file relative to the
    /// `.gltf`'s directory.
    fn load_uri(&self, index: usize, uri: &str) -> Result<Vec<u8>, String> {
        if let Some(data) = uri.strip_prefix("data:") {
            let (_, payload) = data.split_once(";base64,").ok_or_else(|| {
                format!("buffer {index}: a data URI must be base64 (`data:...;base64,...`)")
            })?;
            return base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map_err(|e| format!("buffer {index}: bad base64 in its data URI: {e}"));
        }
        let Some(dir) = self.base_dir else {
            return Err(format!(
                "buffer {index} is the file {uri:?}, and there is no directory to read it from"
            ));
        };
        let path = dir.join(percent_decoded(uri));
        read_input_file(&path)
            .map_err(|m| format!("cannot read buffer {index} file {}: {m}", path.display()))
    }

    /// The bytes of `acc`'s elements: the slice from its first element and the stride, or
    /// `None` for an accessor without a buffer view (all zeros). `size` is the element size.
    fn accessor_bytes(
        &mut self,
        acc: &Accessor,
        size: usize,
    ) -> Result<Option<(&[u8], usize)>, String> {
        let i = acc.index();
        if acc.sparse().is_some() {
            return Err(format!(
                "accessor {i} is sparse: sparse accessors are not supported"
            ));
        }
        let Some(view) = acc.view() else {
            return Ok(None);
        };
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(format!(
                "accessor {i}: buffer view {} has a byteStride of {stride}, below the element \
                 size {size}",
                view.index()
            ));
        }
        let count = acc.count();
        let view_end = view.offset().checked_add(view.length());
        let span = count
            .checked_sub(1)
            .map_or(Some(0), |last| last.checked_mul(stride)?.checked_add(size));
        let end = span.and_then(|s| s.checked_add(acc.offset()));
        match (view_end, end) {
            (Some(view_end), Some(end))
                if end <= view.length() && view_end <= view.buffer().length() =>
            {
                let start = view.offset() + acc.offset();
                let data = self
                    .buffer(view.buffer().index())
                    .map_err(|m| format!("accessor {i}: {m}"))?;
                Ok(Some((&data[start..view.offset() + end], stride)))
            }
            _ => Err(format!(
                "accessor {i} ({count} elements of {size} bytes, stride {stride}, offset {}) \
                 does not fit in buffer view {} ({} bytes at offset {} of buffer {}, {} bytes)",
                acc.offset(),
                view.index(),
                view.length(),
                view.offset(),
                view.buffer().index(),
                view.buffer().length()
            )),
        }
    }

    /// A POSITION accessor's points, all finite.
    fn read_positions(&mut self, acc: &Accessor) -> Result<Vec<Vec3>, String> {
        let i = acc.index();
        if acc.data_type() != DataType::F32 || acc.dimensions() != Dimensions::Vec3 {
            return Err(format!(
                "accessor {i} is {:?} of {:?}, must be VEC3 of FLOAT",
                acc.dimensions(),
                acc.data_type()
            ));
        }
        let count = acc.count();
        let Some((data, stride)) = self.accessor_bytes(acc, 12)? else {
            return Ok(vec![Vec3::ZERO; count]);
        };
        let mut out = Vec::with_capacity(count);
        for k in 0..count {
            let f = |c: usize| {
                let at = k * stride + 4 * c;
                f32::from_le_bytes([data[at], data[at + 1], data[at + 2], data[at + 3]])
            };
            let p = Vec3::new(f(0), f(1), f(2));
            if !p.is_finite() {
                return Err(format!(
                    "accessor {i}: vertex {k} is not finite: ({}, {}, {})",
                    p.x, p.y, p.z
                ));
            }
            out.push(p);
        }
        Ok(out)
    }

    /// An index accessor's indices, each checked below `vertices`.
    fn read_indices(&mut self, acc: &Accessor, vertices: usize) -> Result<Vec<u32>, String> {
        let i = acc.index();
        let size = match (acc.data_type(), acc.dimensions()) {
            (DataType::U8, Dimensions::Scalar) => 1,
            (DataType::U16, Dimensions::Scalar) => 2,
            (DataType::U32, Dimensions::Scalar) => 4,
            (t, d) => {
                return Err(format!(
                    "accessor {i} is {d:?} of {t:?}, must be SCALAR of UNSIGNED_BYTE, \
                     UNSIGNED_SHORT or UNSIGNED_INT"
                ))
            }
        };
        let count = acc.count();
        let Some((data, stride)) = self.accessor_bytes(acc, size)? else {
            return Ok(vec![0; count]);
        };
        let mut out = Vec::with_capacity(count);
        for k in 0..count {
            let at = k * stride;
            let v = match size {
                1 => u32::from(data[at]),
                2 => u32::from(u16::from_le_bytes([data[at], data[at + 1]])),
                _ => u32::from_le_bytes([data[at], data[at + 1], data[at + 2], data[at + 3]]),
            };
            if v as usize >= vertices {
                return Err(format!(
                    "accessor {i}: index {k} is {v}, the primitive has {vertices} vertices"
                ));
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// Whether a primitive of `vertices` and `triangles` placed after the `placed` (vertices,
/// triangles) so far keeps the file within [`MAX_ELEMENTS`] of each, else why not.
fn within_limit(placed: (usize, usize), vertices: usize, triangles: usize) -> Result<(), String> {
    if placed.0 + vertices > MAX_ELEMENTS || placed.1 + triangles > MAX_ELEMENTS {
        return Err(format!(
            "the file places more than {MAX_ELEMENTS} vertices or triangles (this primitive \
             adds {vertices} and {triangles} to {} and {})",
            placed.0, placed.1
        ));
    }
    Ok(())
}

/// A node's local transform in f64: its `matrix` (which must be affine and finite), or
/// T · R · S from its parts (the rotation normalized in f64).
fn local_transform(node: &Node) -> Result<DMat4, String> {
    let i = node.index();
    match node.transform() {
        Transform::Matrix { matrix } => {
            let m = DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)));
            if !m.is_finite() || m.row(3) != DVec4::new(0.0, 0.0, 0.0, 1.0) {
                return Err(format!(
                    "node {i}: its matrix is not a finite affine transform (last row {:?})",
                    m.row(3).to_array()
                ));
            }
            Ok(m)
        }
        Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let q = DQuat::from_array(rotation.map(f64::from));
            let t = DVec3::from_array(translation.map(f64::from));
            let s = DVec3::from_array(scale.map(f64::from));
            let len = q.length();
            if !(t.is_finite() && s.is_finite() && len.is_finite() && len > 0.0) {
                return Err(format!(
                    "node {i}: its translation, rotation or scale is not finite, or the \
                     rotation is zero"
                ));
            }
            Ok(DMat4::from_scale_rotation_translation(s, q / len, t))
        }
    }
}

/// `uri` with its %XX escapes decoded (bytes that are not UTF-8 are replaced).
fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).copied().and_then(hex),
            b.get(i + 2).copied().and_then(hex),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::super::{parse_mesh, read_mesh};
    use super::*;

    /// Buffer: 4 positions (1,0,0) (0,1,0) (0,0,0) (0,0,1) as VEC3 FLOAT (48 bytes), then u16
    /// indices 0 1 2 0 (8 bytes).
    fn buffer() -> Vec<u8> {
        let mut b = Vec::new();
        for p in [
            [1f32, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            for c in p {
                b.extend(c.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0] {
            b.extend(i.to_le_bytes());
        }
        b
    }

    /// A glTF document over [`buffer`] (given by `uri`, or the GLB chunk if `None`): mesh 0 is
    /// the indexed triangle (0 1 2), mesh 1 the non-indexed TRIANGLES (first three points);
    /// `nodes` and `scenes` JSON as given; `extra_prims` more primitives of mesh 0.
    fn document(uri: Option<&str>, nodes: &str, extra_prims: &str) -> String {
        let uri = uri.map_or(String::new(), |u| format!(r#""uri": "{u}","#));
        format!(
            r#"{{"asset": {{"version": "2.0"}},
            "buffers": [{{{uri} "byteLength": 56}}],
            "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                            {{"buffer": 0, "byteOffset": 48, "byteLength": 8}}],
            "accessors": [
                {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 1]}},
                {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}},
                {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 1]}}],
            "meshes": [
                {{"name": "tri", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}{extra_prims}]}},
                {{"primitives": [{{"attributes": {{"POSITION": 2}}}}]}}],
            {nodes}}}"#
        )
    }

    fn data_uri() -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(buffer())
        )
    }

    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        while j.len() % 4 != 0 {
            j.push(b' ');
        }
        let mut b = bin.to_vec();
        while b.len() % 4 != 0 {
            b.push(0);
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(CHUNK_JSON.to_le_bytes());
        out.extend(j);
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(CHUNK_BIN.to_le_bytes());
        out.extend(b);
        out
    }

    fn parse_str(text: &str) -> Result<RawMesh, InputError> {
        parse_mesh(text.as_bytes(), MeshFormat::Gltf, "t.gltf", None)
    }

    /// Scene 1 (the default): node 0 turned 180° about z (a unit quaternion, exact) holding
    /// node 1, moved by (1, 0, 0) and scaled by 2, holding mesh 0; node 2, mirrored in x by its
    /// matrix, holds mesh 1. Scene 0 holds node 3 (mesh 1), not drawn.
    const NODES: &str = r#""nodes": [
            {"rotation": [0, 0, 1, 0], "children": [1]},
            {"translation": [1, 0, 0], "scale": [2, 2, 2], "mesh": 0},
            {"matrix": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "mesh": 1},
            {"mesh": 1}],
        "scenes": [{"nodes": [3]}, {"nodes": [0, 2]}], "scene": 1"#;

    #[test]
    fn node_transforms_data_uri() {
        let m = parse_str(&document(Some(&data_uri()), NODES, "")).unwrap();
        // Node 0 first: x → −(2x + 1), y → −2y.
        assert_eq!(
            m.positions[..4],
            [
                Vec3::new(-3.0, 0.0, 0.0),
                Vec3::new(-1.0, -2.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(-1.0, 0.0, 2.0)
            ]
        );
        // Node 2: mirrored, so the winding is flipped.
        assert_eq!(
            m.positions[4..],
            [
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, 0.0)
            ]
        );
        assert_eq!(m.triangles, vec![[0, 1, 2], [4, 6, 5]]);
        assert_eq!(m.format, MeshFormat::Gltf);
    }

    #[test]
    fn glb_and_external_bin() {
        let nodes = r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]"#;
        let m = parse_mesh(
            &glb(&document(None, nodes, ""), &buffer()),
            MeshFormat::Gltf,
            "t.glb",
            None,
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[1], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(m.triangles, vec![[0, 1, 2]]);

        let dir = std::env::temp_dir().join(format!("penumbra-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("m.gltf"),
            document(Some("the%20data.bin"), nodes, ""),
        )
        .unwrap();
        let e = read_mesh(&dir.join("m.gltf"), "m.gltf").unwrap_err();
        assert!(
            e.message.starts_with(&format!(
                "mesh 0 (\"tri\") primitive 0: POSITION accessor 0: cannot read buffer 0 file {}: ",
                dir.join("the data.bin").display()
            )),
            "{e}"
        );
        std::fs::write(dir.join("the data.bin"), buffer()).unwrap();
        assert_eq!(read_mesh(&dir.join("m.gltf"), "m.gltf").unwrap(), m);
        std::fs::remove_dir_all(&dir).unwrap();
        let e = parse_str(&document(Some("x.bin"), nodes, "")).unwrap_err();
        assert_eq!(
            e.message,
            "mesh 0 (\"tri\") primitive 0: POSITION accessor 0: buffer 0 is the file \"x.bin\", \
             and there is no directory to read it from"
        );
    }

    #[test]
    fn strips_fans_and_skipped_modes() {
        // Mesh 0 with a strip and a fan over 4 vertices (no indices), and a LINES primitive.
        let prims = r#", {"attributes": {"POSITION": 0}, "mode": 5},
                        {"attributes": {"POSITION": 0}, "mode": 6},
                        {"attributes": {"POSITION": 0}, "mode": 1}"#;
        let nodes = r#""nodes": [{"mesh": 0}]"#;
        let m = parse_str(&document(Some(&data_uri()), nodes, prims)).unwrap();
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [4, 5, 6], [6, 5, 7], [9, 10, 8], [10, 11, 8]]
        );
        // No scenes, no nodes: every mesh; lines only is an error naming it.
        let lines = document(Some(&data_uri()), r#""extensionsUsed": []"#, "")
            .replace(r#""indices": 1}"#, r#""indices": 1, "mode": 1}"#)
            .replace(
                r#"{"attributes": {"POSITION": 2}}"#,
                r#"{"attributes": {"POSITION": 2}, "mode": 0}"#,
            );
        assert_eq!(
            parse_str(&lines).unwrap_err().message,
            "the glTF file has no triangle primitive (mesh 0 (\"tri\") primitive 0 has mode \
             Lines: only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are read)"
        );
    }

    #[test]
    fn placed_elements_are_limited() {
        // Primitives placed by many nodes add up; the limit is on the sum.
        assert_eq!(within_limit((0, 0), MAX_ELEMENTS, MAX_ELEMENTS), Ok(()));
        assert_eq!(within_limit((MAX_ELEMENTS - 3, 7), 3, 1), Ok(()));
        assert_eq!(
            within_limit((MAX_ELEMENTS - 3, 7), 4, 1).unwrap_err(),
            "the file places more than 44739242 vertices or triangles (this primitive adds 4 \
             and 1 to 44739239 and 7)"
        );
        assert!(within_limit((0, MAX_ELEMENTS), 0, 1).is_err());
    }

    #[test]
    fn refused() {
        let nodes = r#""nodes": [{"mesh": 0}]"#;
        let sparse = document(Some(&data_uri()), nodes, "").replacen(
            r#""type": "VEC3","#,
            r#""type": "VEC3", "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 0}},"#,
            1,
        );
        assert_eq!(
            parse_str(&sparse).unwrap_err().message,
            "mesh 0 (\"tri\") primitive 0: POSITION accessor 0 is sparse: sparse accessors are \
             not supported"
        );
        let draco = document(Some(&data_uri()), nodes, "").replace(
            r#""asset""#,
            r#""extensionsRequired": ["KHR_draco_mesh_compression"], "extensionsUsed": ["KHR_draco_mesh_compression"], "asset""#,
        );
        assert_eq!(
            parse_str(&draco).unwrap_err().message,
            "requires the extension KHR_draco_mesh_compression (Draco-compressed meshes), which \
             this reader does not support"
        );
        let past = document(Some(&data_uri()), nodes, "").replace(
            r#""count": 3, "type": "SCALAR""#,
            r#""count": 5, "type": "SCALAR""#,
        );
        assert_eq!(
            parse_str(&past).unwrap_err().message,
            "mesh 0 (\"tri\") primitive 0: indices accessor 1 (5 elements of 2 bytes, stride 2, \
             offset 0) does not fit in buffer view 1 (8 bytes at offset 48 of buffer 0, 56 bytes)"
        );
        let far = document(Some(&data_uri()), nodes, "").replace(
            r#""count": 3, "type": "SCALAR""#,
            r#""count": 4, "type": "SCALAR""#,
        );
        // Index 3 is 0 again: fine; the count is not a multiple of 3.
        assert!(parse_str(&far)
            .unwrap_err()
            .message
            .contains("multiple of 3"));
        let e = parse_str(&document(
            Some(&data_uri()),
            r#""nodes": [{"mesh": 7}]"#,
            "",
        ))
        .unwrap_err();
        assert!(
            e.message
                .starts_with("glTF validation error at nodes[0].mesh: "),
            "{e}"
        );
        // Found by fuzzing (`fuzz/regressions/gltf/`): gltf-json's own validation panicked on
        // a POSITION index one past the accessors.
        let e = parse_str(
            &document(Some(&data_uri()), nodes, "").replace(r#""POSITION": 2"#, r#""POSITION": 3"#),
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            r#"glTF validation error at meshes[1].primitives[0].attributes["POSITION"]: Index out of bounds"#
        );
        let e = parse_str("{\"asset\": ").unwrap_err();
        assert!(e.message.starts_with("glTF JSON error: "), "{e}");
        let cycle = r#""nodes": [{"children": [1]}, {"children": [0], "mesh": 0}], "scenes": [{"nodes": [0]}]"#;
        assert_eq!(
            parse_str(&document(Some(&data_uri()), cycle, ""))
                .unwrap_err()
                .message,
            "node 0 is reached twice from the scene (a cycle, or a node with two parents)"
        );
        let short = b"glTF\x02\x00\x00\x00\x04\x00\x00\x00";
        assert_eq!(
            parse_mesh(short, MeshFormat::Gltf, "t.glb", None)
                .unwrap_err()
                .message,
            "GLB container: no JSON chunk"
        );
        let long = b"glTF\x02\x00\x00\x00\xff\x00\x00\x00";
        assert!(parse_mesh(long, MeshFormat::Gltf, "t.glb", None)
            .unwrap_err()
            .message
            .contains("gives a length of 255 bytes, the file has 12"));
    }
}
