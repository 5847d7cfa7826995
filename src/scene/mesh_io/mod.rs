//! Mesh files: OBJ, PLY, STL and glTF 2.0 read into one [`RawMesh`], the triangles as the file
//! holds them, before any repair.
//!
//! One reader per format, each in its own module ([`obj`], [`ply`], [`stl`], [`mod@gltf`]), each
//! behind the same two entry points: [`read_mesh`] (a file, format from its extension) and
//! [`parse_mesh`] (bytes in memory, for fuzzing). What each reader accepts, tolerates and
//! refuses, and which crate it uses and why, is in `docs/mesh-formats.md` and each module's
//! doc.
//!
//! The design choice: readers only *read*. They do not weld, drop degenerate triangles or
//! reorient: a [`RawMesh`] may have duplicated corners (STL always has: three per facet),
//! degenerate triangles and holes. Turning it into a scene [`Mesh`] is a separate step: mesh
//! repair ([`super::repair`]), whose weld is the only one of the load path (bit-identical
//! positions become one vertex, numbered by first appearance, which is what OBJ loading always
//! did, so existing scenes render the same). Every reader does check what would
//! make later steps meaningless: every coordinate finite (the error names the vertex: its index,
//! and its line in text formats), every index inside the positions, at least one triangle.
//!
//! Every file goes through [`read_input_file`] (regular file, size cap), glTF's external
//! buffers included.

pub mod gltf;
pub mod obj;
pub mod ply;
pub mod stl;

use super::input_file::read_input_file;
use super::procedural::transform_point;
use super::repair::weld_map;
use super::Mesh;
use crate::error::InputError;
use glam::{Mat4, Vec3, Vec4};
use std::path::Path;

/// A mesh as its file holds it, in the file's world space (glTF node transforms applied),
/// before any repair: corners may be duplicated, triangles degenerate, the mesh open.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMesh {
    /// Vertex positions, all finite.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`; every index is `< positions.len()`.
    pub triangles: Vec<[u32; 3]>,
    /// The format the mesh was read from.
    pub format: MeshFormat,
    /// Faces with more than three corners that were fan-triangulated (OBJ, PLY).
    pub polygons_triangulated: usize,
}

/// The mesh file formats [`read_mesh`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`), [`obj`].
    Obj,
    /// Stanford PLY (`.ply`), ASCII or binary, [`ply`].
    Ply,
    /// STL (`.stl`), ASCII or binary, [`stl`].
    Stl,
    /// glTF 2.0 (`.gltf` with its buffers, or `.glb`), [`mod@gltf`].
    Gltf,
}

/// The file name extensions [`read_mesh`] knows (lower case), with their formats.
const EXTENSIONS: [(&str, MeshFormat); 5] = [
    ("obj", MeshFormat::Obj),
    ("ply", MeshFormat::Ply),
    ("stl", MeshFormat::Stl),
    ("gltf", MeshFormat::Gltf),
    ("glb", MeshFormat::Gltf),
];

impl MeshFormat {
    /// The format's name in messages: "OBJ", "PLY", "STL", "glTF".
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Stl => "STL",
            MeshFormat::Gltf => "glTF",
        }
    }

    /// The format for a file name's extension (case-insensitive), if it is one of
    /// `.obj .ply .stl .gltf .glb`.
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        EXTENSIONS
            .iter()
            .find(|(e, _)| *e == ext)
            .map(|(_, format)| *format)
    }
}

/// Reads the mesh file at `path`, its format chosen by its extension (case-insensitive:
/// `.obj .ply .stl .gltf .glb`); errors name `display_name`. glTF buffers in other files are
/// read relative to `path`'s directory.
///
/// Errors: an unknown extension (the message lists the known ones), an unreadable file (the
/// rule of [`read_input_file`]), and every error of [`parse_mesh`].
pub fn read_mesh(path: &Path, display_name: &str) -> Result<RawMesh, InputError> {
    let format = MeshFormat::from_path(path).ok_or_else(|| {
        let known: Vec<String> = EXTENSIONS.iter().map(|(e, _)| format!(".{e}")).collect();
        InputError::new(
            display_name,
            format!(
                "unknown mesh file extension (known: {}, in any case)",
                known.join(" ")
            ),
        )
    })?;
    let bytes = read_input_file(path).map_err(|m| {
        InputError::new(
            display_name,
            format!("cannot read {} file: {m}", format.name()),
        )
    })?;
    parse_mesh(&bytes, format, display_name, path.parent())
}

/// Parses a mesh file already in memory (used by [`read_mesh`] and by fuzzing); errors name
/// `display_name`. glTF buffers given by a relative URI are read from `base_dir`; with
/// `None` such a buffer is an error (the bytes are all there is). Never panics.
///
/// Errors (each naming the file and, where the format has them, the line, element, byte
/// offset, mesh or primitive): a syntax or structure error of the format, a non-finite
/// coordinate, an index outside the positions, no triangles at all.
pub fn parse_mesh(
    bytes: &[u8],
    format: MeshFormat,
    display_name: &str,
    base_dir: Option<&Path>,
) -> Result<RawMesh, InputError> {
    let mesh = match format {
        MeshFormat::Obj => obj::parse(bytes, display_name)?,
        MeshFormat::Ply => ply::parse(bytes, display_name)?,
        MeshFormat::Stl => stl::parse(bytes, display_name)?,
        MeshFormat::Gltf => gltf::parse(bytes, display_name, base_dir)?,
    };
    if mesh.triangles.is_empty() {
        return Err(InputError::new(
            display_name,
            format!("the {} file has no triangles", format.name()),
        ));
    }
    Ok(mesh)
}

impl RawMesh {
    /// The mesh moved by the scene file's `transform` `m`: `m` must be finite, affine and
    /// non-singular ([`check_transform`]); each point (w = 1) is transformed in f64 and rounded
    /// once to f32, and a negative determinant (a reflection) flips every triangle's winding so
    /// an outward-facing mesh stays outward-facing. Errors: a bad transform, or a transformed
    /// vertex beyond f32.
    pub fn transformed(mut self, m: Mat4) -> Result<RawMesh, String> {
        check_transform(&m).map_err(|e| format!("transform {e}"))?;
        let md = m.as_dmat4();
        for p in &mut self.positions {
            *p = transform_point(&md, *p);
        }
        if md.determinant() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
        if let Some(p) = self.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!(
                "transformed vertex ({}, {}, {}) overflows f32",
                p.x, p.y, p.z
            ));
        }
        Ok(self)
    }
}

/// The scene mesh of `raw` with only its bit-identical vertices joined: the weld of mesh
/// repair ([`super::repair`], −0 = +0, stored as +0, numbered in order of first appearance)
/// and nothing else (no vertex dropped, no triangle dropped or turned). Not on the load path,
/// which repairs (and so welds) every mesh; for the fuzz targets, which want the file's own
/// triangles in a mesh.
pub fn weld_identical(raw: RawMesh, name: &str, color: [f32; 3]) -> Mesh {
    let (canon, _) = weld_map(&raw.positions, 0.0);
    let mut remap = vec![0u32; canon.len()];
    let mut positions: Vec<Vec3> = Vec::new();
    for (i, &c) in canon.iter().enumerate() {
        remap[i] = if c as usize == i {
            positions.push(raw.positions[i] + Vec3::ZERO);
            (positions.len() - 1) as u32
        } else {
            remap[c as usize]
        };
    }
    let triangles = raw
        .triangles
        .iter()
        .map(|t| t.map(|i| remap[i as usize]))
        .collect();
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// Whether `m` can place a mesh: finite, affine (last row 0,0,0,1) and invertible; else why
/// not.
pub fn check_transform(m: &Mat4) -> Result<(), String> {
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

/// The message for vertex `index` (numbered as its format counts) at `v` not being finite;
/// `place` is where it is (`line 12`, `byte offset 300`), when the caller's message does not
/// already say.
fn non_finite_vertex(index: usize, place: Option<&str>, v: [f32; 3]) -> String {
    let at = place.map_or(String::new(), |p| format!(" ({p})"));
    format!(
        "vertex {index}{at} is not finite: ({}, {}, {})",
        v[0], v[1], v[2]
    )
}

/// Appends `corners` (indices into a mesh's positions) as triangles: a fan from the first
/// corner, `corners.len() − 2` triangles. Returns whether the face had more than 3 corners.
fn push_fan(triangles: &mut Vec<[u32; 3]>, corners: &[u32]) -> bool {
    for pair in corners.get(1..).unwrap_or_default().windows(2) {
        triangles.push([corners[0], pair[0], pair[1]]);
    }
    corners.len() > 3
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;
    use crate::scene::procedural::signed_volume6;

    /// Two triangles of a unit square written with copied corners, one corner −0.
    fn square() -> RawMesh {
        RawMesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-0.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            format: MeshFormat::Stl,
            polygons_triangulated: 0,
        }
    }

    #[test]
    fn weld_merges_bit_identical_positions_in_first_seen_order() {
        let m = weld_identical(square(), "sq", [0.5; 3]);
        assert_eq!(
            m.positions,
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0)
            ]
        );
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.positions[0].x.to_bits(), 0, "−0 stored as +0");
        assert_eq!(m.name, "sq");
    }

    #[test]
    fn transform_moves_and_reflection_flips_winding() {
        let t =
            Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * Mat4::from_scale(Vec3::splat(2.0));
        let m = square().transformed(t).unwrap();
        assert_eq!(m.positions[2], Vec3::new(3.0, 4.0, 3.0));
        assert_eq!(m.triangles, square().triangles);
        let mirror = square()
            .transformed(Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0)))
            .unwrap();
        assert_eq!(mirror.triangles, vec![[0, 2, 1], [3, 5, 4]]);
    }

    #[test]
    fn bad_transforms() {
        let e = square()
            .transformed(Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)))
            .unwrap_err();
        assert!(e.starts_with("transform is singular"), "{e}");
        let mut p = Mat4::IDENTITY;
        p.x_axis.w = 0.5;
        assert!(square().transformed(p).unwrap_err().contains("not affine"));
        let mut n = Mat4::IDENTITY;
        n.w_axis.x = f32::NAN;
        assert!(square().transformed(n).unwrap_err().contains("non-finite"));
        let big = Mat4::from_translation(Vec3::X * 3e38) * Mat4::from_scale(Vec3::splat(3e38));
        assert!(square().transformed(big).unwrap_err().contains("overflows"));
    }

    #[test]
    fn welded_cube_of_each_format_is_closed() {
        // The same unit cube in each format gives the same closed mesh (volume 1).
        for (name, bytes, format) in [
            ("c.obj", obj::tests::CUBE.as_bytes(), MeshFormat::Obj),
            ("c.ply", ply::tests::CUBE_ASCII.as_bytes(), MeshFormat::Ply),
        ] {
            let raw = parse_mesh(bytes, format, name, None).unwrap();
            let m = weld_identical(raw, name, [0.5; 3]);
            assert_eq!(m.positions.len(), 8, "{name}");
            assert_eq!(m.triangles.len(), 12, "{name}");
            adjacency::build(&m).unwrap();
            assert_eq!(signed_volume6(&m), 6.0, "{name}");
        }
    }

    #[test]
    fn extensions_and_missing_files() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a/B.GLB")),
            Some(MeshFormat::Gltf)
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("x.Stl")),
            Some(MeshFormat::Stl)
        );
        let e = read_mesh(Path::new("m.3ds"), "m.3ds").unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.3ds: unknown mesh file extension (known: .obj .ply .stl .gltf .glb, in any case)"
        );
        let e = read_mesh(Path::new("/nonexistent/dir/none.ply"), "none.ply").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("none.ply: cannot read PLY file: "),
            "{e}"
        );
    }

    #[test]
    fn fans() {
        let mut t = Vec::new();
        assert!(!push_fan(&mut t, &[0, 1, 2]));
        assert!(push_fan(&mut t, &[3, 4, 5, 6, 7]));
        assert!(!push_fan(&mut t, &[8, 9]));
        assert!(!push_fan(&mut t, &[]));
        assert_eq!(t, vec![[0, 1, 2], [3, 4, 5], [3, 5, 6], [3, 6, 7]]);
    }
}
