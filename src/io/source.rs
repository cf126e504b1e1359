//! What a mesh was read from, kept so that a faired mesh is written back with only its shape
//! changed.
//!
//! Fairing, noise and multiresolution fairing move vertices and never change connectivity, so
//! everything else a file holds (a glTF scene's nodes, materials, textures, UVs, colours; an
//! OBJ's groups, materials, texture coordinates and polygons; a PLY's extra properties) can come
//! through untouched. [`Source`] keeps:
//! - the file itself (the OBJ or PLY bytes; for glTF the JSON document and its buffers), at most
//!   the file's own size;
//! - the map from the parser's vertices (an OBJ `v` line, a PLY vertex row, an element of a glTF
//!   POSITION accessor as read for one node) to the welded vertices the algorithms work on;
//! - a fingerprint of the welded triangles, so that a mesh with other connectivity (a level of
//!   the hierarchy, a subdivided copy) is never written into the source by mistake.
//!
//! Saving to the same family of format (OBJ, PLY, glTF/GLB) writes the source back with the new
//! positions and what depends on them: normals (and glTF tangents) are turned by the rotation
//! that takes the vertex's area-weighted normal before the change to the one after (so split
//! normals stay split, smooth ones stay smooth, and a file's own custom normals keep their
//! character), texture coordinates follow their vertex's slide along the surface so that the
//! texture stays where it was ([`super::uv_follow`]), and the glTF POSITION accessor's min/max
//! are recomputed. A vertex that did not move keeps its bytes (or its text) exactly, and so does
//! a normal whose faces did not move.
//! Saving to another format writes the mesh with what that format can hold per vertex (UVs and
//! vertex colours into glTF and OBJ, see [`super::carry`]; UVs turned into the output's own
//! convention, see `uv_convention.rs`, and following the slide as in a write-back) and names, in
//! the [`super::SaveReport`], everything else it cannot keep.

use super::carry::VertexAttributes;
use super::normals::{dvec, is_own_normal};
use super::origin::Origin;
use super::scene::{Scene, SceneVertex};
use super::{gltf, stl, Format};
use crate::mesh::TriMesh;
use std::path::PathBuf;

/// What a mesh was read from: kept by [`super::load`] in [`super::Loaded::source`], used by
/// [`super::save_with_source`].
#[derive(Debug)]
pub struct Source {
    pub(crate) format: Format,
    /// The file and the map from its vertices to the welded ones.
    pub(crate) origin: Origin,
    pub(crate) welded_triangles: usize,
    pub(crate) triangle_fingerprint: u64,
    pub(crate) data: SourceData,
}

/// The format-specific part of a [`Source`].
#[derive(Debug)]
pub(crate) enum SourceData {
    /// Nothing beyond positions and triangles is kept (STL, OFF).
    Plain,
    /// The file holds things no writer here carries (an STL's per-facet attribute bytes, an OFF's
    /// colours): named, in plain words, so that saving says they were not kept.
    Unkept(Vec<String>),
    /// A binary STL's header text (written back into an STL) and what is not kept.
    Stl(Box<stl::StlSource>),
    /// The OBJ file's bytes.
    Obj(Vec<u8>),
    /// The PLY file's bytes.
    Ply(Vec<u8>),
    /// The glTF document, its buffers and which accessor elements became which vertices.
    Gltf(Box<gltf::GltfSource>),
}

impl Source {
    /// A source that keeps nothing but the mesh (for meshes that come from no file).
    pub fn plain(mesh: &TriMesh) -> Source {
        Source {
            format: Format::Ply,
            origin: Origin {
                path: PathBuf::new(),
                base_dir: None,
                raw_to_welded: None,
                raw_vertices: mesh.positions.len(),
                welded_vertices: mesh.positions.len(),
            },
            welded_triangles: mesh.triangles.len(),
            triangle_fingerprint: fingerprint(&mesh.triangles),
            data: SourceData::Plain,
        }
    }

    /// The format the mesh was read from.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Whether `mesh` has the connectivity of the mesh this source was loaded as (same vertex
    /// count and the same triangles), so that its positions can be written back into the source.
    pub fn matches(&self, mesh: &TriMesh) -> bool {
        mesh.positions.len() == self.origin.welded_vertices
            && mesh.triangles.len() == self.welded_triangles
            && fingerprint(&mesh.triangles) == self.triangle_fingerprint
    }

    /// What the file holds beyond positions and triangles, in plain words (for `info`, and for
    /// saying what an output format cannot keep). Empty for a bare mesh.
    pub fn contents(&self) -> Vec<String> {
        match &self.data {
            SourceData::Plain => Vec::new(),
            SourceData::Unkept(items) => items.clone(),
            SourceData::Stl(stl) => stl.contents(),
            SourceData::Obj(bytes) => super::obj::contents(bytes),
            SourceData::Ply(bytes) => super::ply::contents(bytes),
            SourceData::Gltf(gltf) => gltf.contents(),
        }
    }

    /// Whether the file gives its vertices texture coordinates (OBJ `vt`, PLY `u`/`v` or
    /// `s`/`t`, glTF `TEXCOORD_0`). Written back into the file's own format, or carried into
    /// another that holds them, they follow their vertices' slide along the surface (see
    /// [`super::SaveReport::texture_coordinates_follow`]).
    pub fn has_texture_coordinates(&self) -> bool {
        match &self.data {
            SourceData::Obj(bytes) => super::obj::has_texture_coordinates(bytes),
            SourceData::Ply(bytes) => super::ply::has_texture_coordinates(bytes),
            SourceData::Gltf(gltf) => gltf.has_texture_coordinates(),
            _ => false,
        }
    }

    /// The file's UVs and vertex colours per welded vertex (see `carry.rs`), for writing
    /// another format.
    pub fn vertex_attributes(&self) -> VertexAttributes {
        match &self.data {
            SourceData::Obj(bytes) => super::obj::vertex_attributes(bytes, &self.origin),
            SourceData::Ply(bytes) => super::ply::vertex_attributes(bytes, &self.origin),
            SourceData::Gltf(gltf) => gltf.vertex_attributes(&self.origin),
            _ => VertexAttributes::default(),
        }
    }

    /// The positions the mesh was loaded with, per welded vertex (a vertex no file vertex became
    /// keeps `mesh`'s), for following a slide from them to `mesh`'s; `None` for a format that
    /// holds no texture coordinates, or a file that cannot be read again.
    pub(crate) fn loaded_positions(&self, mesh: &TriMesh) -> Option<Vec<[f32; 3]>> {
        let mut before = mesh.positions.clone();
        let mut seen = vec![false; before.len()];
        let mut put = |welded: Option<usize>, position: [f32; 3]| {
            if let Some(w) = welded.filter(|&w| w < seen.len() && !seen[w]) {
                before[w] = position;
                seen[w] = true;
            }
        };
        match &self.data {
            SourceData::Ply(bytes) => {
                let parsed = super::ply::parse(bytes, &self.origin.path).ok()?;
                for (k, &p) in parsed.mesh.positions.iter().enumerate() {
                    put(self.origin.welded(k), p);
                }
            }
            SourceData::Obj(_) | SourceData::Gltf(_) => {
                let scene = self.scene(mesh)?;
                for vertex in &scene.vertices {
                    put(
                        (vertex.welded != u32::MAX).then_some(vertex.welded as usize),
                        vertex.before,
                    );
                }
            }
            _ => return None,
        }
        Some(before)
    }

    /// The file's parts, materials and file vertices (see [`super::scene`]) for writing another
    /// format, with normals turned to `mesh`'s positions; `None` for a format with no structure
    /// to carry (PLY, STL, OFF). Front ends read it to draw the file's materials.
    pub fn scene(&self, mesh: &TriMesh) -> Option<Scene> {
        match &self.data {
            SourceData::Obj(bytes) => Some(super::obj::scene(bytes, &self.origin, mesh)),
            SourceData::Gltf(gltf) => Some(gltf.scene(&self.origin, mesh)),
            _ => None,
        }
    }

    /// The edges the file marks as sharp, as pairs of loaded vertices `[a, b]` (`a < b`,
    /// ascending): where the file's faces on the two sides of an edge have different normals at
    /// either end (a hard edge of a smooth-shaded file) or different materials. Crease detection
    /// takes them as feature edges whatever their angle
    /// ([`crate::fairing::CreaseOptions::with_file_edges`]). Not counted: the normals of a
    /// flat-shaded file (nine faces in ten or more carry their own face normal at every corner),
    /// which split at every edge and so say nothing about which are sharp; and UV seams, which a
    /// scan's texture atlas puts along arbitrary edges. Empty for a format with no such structure
    /// (PLY, STL, OFF) and for a mesh that is not the one loaded from this source.
    pub fn hard_edges(&self, mesh: &TriMesh) -> Vec<[u32; 2]> {
        if !self.matches(mesh) {
            return Vec::new();
        }
        // An OBJ with neither normals nor materials marks nothing: a byte search says so without
        // reading its scene.
        if let SourceData::Obj(bytes) = &self.data {
            let has = |word: &[u8]| bytes.windows(word.len()).any(|w| w == word);
            if !has(b"vn ") && !has(b"usemtl") {
                return Vec::new();
            }
        }
        let Some(scene) = self.scene(mesh) else {
            return Vec::new();
        };
        let triangles = || {
            scene
                .parts
                .iter()
                .flat_map(|part| &part.primitives)
                .flat_map(|p| p.triangles.iter().map(move |t| (p.material, t)))
        };
        let corners = |t: &[u32; 3]| t.map(|v| &scene.vertices[v as usize]);
        let own_normals = triangles()
            .filter(|(_, t)| {
                let [a, b, c] = corners(t);
                let own = (dvec(b.before) - dvec(a.before)).cross(dvec(c.before) - dvec(a.before));
                [a, b, c].iter().all(|v| is_own_normal(own, v.normal))
            })
            .count();
        let normals = scene.normals && 10 * own_normals < 9 * triangles().count();
        // Only an edge between two vertices where the faces disagree (about the material or the
        // normal) can be sharp: those first (one pass, no table), so that a file with none costs
        // no more.
        let split = split_at_vertices(&scene, mesh.positions.len(), |material, v| {
            (material, normals.then(|| v.normal.map(f32::to_bits)))
        });
        if !split.contains(&true) {
            return Vec::new();
        }
        // What one side of an edge says: its material and the normal at each end.
        type Side = (Option<usize>, [Option<[u32; 3]>; 2]);
        let mut first: std::collections::HashMap<[u32; 2], Side> = std::collections::HashMap::new();
        let mut hard = Vec::new();
        for (material, t) in triangles() {
            let corners = corners(t);
            for k in 0..3 {
                let (x, y) = (corners[k], corners[(k + 1) % 3]);
                let (a, b) = if x.welded < y.welded { (x, y) } else { (y, x) };
                if a.welded == b.welded || !split[a.welded as usize] || !split[b.welded as usize] {
                    continue;
                }
                let key = [a.welded, b.welded];
                let side = (
                    material,
                    [a, b].map(|v| normals.then(|| v.normal.map(f32::to_bits))),
                );
                match first.entry(key) {
                    std::collections::hash_map::Entry::Vacant(slot) => {
                        slot.insert(side);
                    }
                    std::collections::hash_map::Entry::Occupied(seen) => {
                        if *seen.get() != side {
                            hard.push(key);
                        }
                    }
                }
            }
        }
        hard.sort_unstable();
        hard.dedup();
        hard
    }

    /// How many welded vertices have file vertices with different normals (hard edges, split
    /// seams); 0 for a file with no normals or no structure.
    pub(crate) fn split_normal_vertices(&self, mesh: &TriMesh) -> usize {
        let Some(scene) = self.scene(mesh).filter(|s| s.normals) else {
            return 0;
        };
        split_at_vertices(&scene, mesh.positions.len(), |_, v| v.normal)
            .iter()
            .filter(|&&s| s)
            .count()
    }

    /// [`Source::contents`] without what `scene` brings into `format` (OBJ or glTF); the node
    /// tree, written into an OBJ, is named for what it loses (its hierarchy and transforms).
    pub(crate) fn contents_beyond_scene(&self, scene: &Scene, format: Format) -> Vec<String> {
        let numbered = |item: &str, what: &str| {
            item.starts_with(|c: char| c.is_ascii_digit())
                && (item.contains(&format!(" {what} (")) || item.contains(&format!(" {what}s (")))
        };
        self.contents()
            .into_iter()
            .filter_map(|item| {
                let carried = (scene.normals && (item == "normals" || item.starts_with("normals (")))
                    || (scene.uvs
                        && (item == "UVs (TEXCOORD_0)" || item.starts_with("texture coordinates (")))
                    || (scene.colours
                        && (item == "vertex colours (COLOR_0)" || item == "vertex colours"))
                    || item.ends_with("object and group names (o, g)")
                    || (!scene.materials.is_empty()
                        && (numbered(&item, "material") || numbered(&item, "texture")));
                if carried {
                    return None;
                }
                if let Some(list) = item.strip_prefix("extensions ") {
                    let carried = |name: &str| {
                        name == "KHR_texture_transform"
                            && format != Format::Obj
                            && scene.texture_transforms_carried()
                    };
                    let left: Vec<&str> = list.split(", ").filter(|n| !carried(n)).collect();
                    return (!left.is_empty()).then(|| format!("extensions {}", left.join(", ")));
                }
                if item.starts_with("the node tree") && format == Format::Obj {
                    return Some(
                        "the node tree's hierarchy and transforms (node names became `o` names and mesh names `g` names; the transforms are baked into the positions)".into(),
                    );
                }
                Some(item)
            })
            .collect()
    }

    /// [`Source::contents`] without what `carried` brought into the output.
    pub(crate) fn contents_beyond(&self, carried: &VertexAttributes) -> Vec<String> {
        let uvs = carried.uvs.is_some();
        let colours = carried.colours.is_some();
        let carried_property = |name: &str| {
            (colours && matches!(name, "red" | "green" | "blue" | "alpha"))
                || (uvs && matches!(name, "s" | "t" | "u" | "v" | "texture_u" | "texture_v"))
        };
        self.contents()
            .into_iter()
            .filter_map(|item| {
                if (uvs
                    && (item == "UVs (TEXCOORD_0)" || item.starts_with("texture coordinates (")))
                    || (colours && (item == "vertex colours (COLOR_0)" || item == "vertex colours"))
                {
                    return None;
                }
                match item.strip_prefix("vertex properties ") {
                    Some(list) => {
                        let left: Vec<&str> =
                            list.split(", ").filter(|p| !carried_property(p)).collect();
                        (!left.is_empty()).then(|| format!("vertex properties {}", left.join(", ")))
                    }
                    None => Some(item),
                }
            })
            .collect()
    }

    /// How many vertices the file holds, in its own order (before welding and clean-up).
    pub fn file_vertex_count(&self) -> usize {
        self.origin.raw_vertices
    }

    /// The loaded (welded) vertex that the file's vertex `file_vertex` (0-based, in the file's
    /// order) became; `None` when it is out of range or was dropped (unused by any triangle).
    pub fn loaded_vertex(&self, file_vertex: usize) -> Option<usize> {
        if file_vertex >= self.origin.raw_vertices {
            return None;
        }
        self.origin.welded(file_vertex)
    }

    /// Whether writing `format` can carry the source through.
    pub(crate) fn writes_back_as(&self, format: Format) -> bool {
        match self.data {
            SourceData::Plain | SourceData::Unkept(_) => false,
            SourceData::Stl(_) => format == Format::Stl,
            SourceData::Obj(_) => format == Format::Obj,
            SourceData::Ply(_) => format == Format::Ply,
            SourceData::Gltf(_) => matches!(format, Format::Gltf | Format::Glb),
        }
    }
}

/// An order-dependent fingerprint of a triangle list (FNV-style mixing of the indices).
pub(crate) fn fingerprint(triangles: &[[u32; 3]]) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64 ^ triangles.len() as u64;
    for t in triangles {
        for &v in t {
            hash = (hash ^ v as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        hash = hash.rotate_left(7);
    }
    hash
}

/// Per loaded vertex (of `vertex_count`): whether the file's faces disagree there about `key`
/// (of a face's material and its file vertex at that corner).
fn split_at_vertices<K: PartialEq + Copy>(
    scene: &Scene,
    vertex_count: usize,
    key: impl Fn(Option<usize>, &SceneVertex) -> K,
) -> Vec<bool> {
    let mut first: Vec<Option<K>> = vec![None; vertex_count];
    let mut split = vec![false; vertex_count];
    for primitive in scene.parts.iter().flat_map(|part| &part.primitives) {
        for &v in primitive.triangles.iter().flatten() {
            let vertex = &scene.vertices[v as usize];
            let here = key(primitive.material, vertex);
            let w = vertex.welded as usize;
            match first[w] {
                None => first[w] = Some(here),
                Some(seen) => split[w] |= seen != here,
            }
        }
    }
    split
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quick answer agrees with reading every texture coordinate, in each format, with
    /// and without them.
    #[test]
    fn has_texture_coordinates_agrees_with_the_texture_coordinates_read() {
        let roundtrip = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/roundtrip/");
        let file = |name: &str| std::fs::read(format!("{roundtrip}{name}")).unwrap();
        let square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n";
        let uv = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
        let ply = |props: &str, rows: &str| {
            format!(
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\n{props}element face 1\nproperty list uchar int vertex_indices\n\
                 end_header\n{rows}3 0 1 2\n"
            )
            .into_bytes()
        };
        let cases: Vec<(&str, Format, Vec<u8>, bool)> = vec![
            ("textured.obj", Format::Obj, file("textured.obj"), true),
            ("scene.glb", Format::Glb, file("scene.glb"), true),
            ("colored.ply", Format::Ply, file("colored.ply"), false),
            (
                "v/vt faces",
                Format::Obj,
                format!("{square}{uv}f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n").into_bytes(),
                true,
            ),
            (
                "vt lines no face uses",
                Format::Obj,
                format!("{square}{uv}f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n").into_bytes(),
                false,
            ),
            (
                "a vt index past the vt lines",
                Format::Obj,
                format!("{square}vt 0 0\nf 1/2 2/2 3/2\n").into_bytes(),
                false,
            ),
            (
                "relative v/vt",
                Format::Obj,
                format!("{square}{uv}f -4/-4 -3/-3 -2/-2\n").into_bytes(),
                true,
            ),
            (
                "PLY u v",
                Format::Ply,
                ply(
                    "property float u\nproperty float v\n",
                    "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n",
                ),
                true,
            ),
            (
                "PLY none",
                Format::Ply,
                ply("", "0 0 0\n1 0 0\n0 1 0\n"),
                false,
            ),
        ];
        for (name, format, bytes, expected) in cases {
            let loaded = crate::io::load_from_bytes(&bytes, format, name, &Default::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let source = &loaded.source;
            assert_eq!(source.has_texture_coordinates(), expected, "{name}");
            assert_eq!(
                source.vertex_attributes().uvs.is_some(),
                expected,
                "{name}: read in full"
            );
        }
    }

    #[test]
    fn fingerprint_sees_order_and_values() {
        let a = [[0, 1, 2], [2, 1, 3]];
        let b = [[2, 1, 3], [0, 1, 2]];
        let c = [[0, 1, 2], [2, 3, 1]];
        assert_ne!(fingerprint(&a), fingerprint(&b));
        assert_ne!(fingerprint(&a), fingerprint(&c));
        assert_eq!(fingerprint(&a), fingerprint(&a.clone()));
    }
}
