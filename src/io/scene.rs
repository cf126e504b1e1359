//! Carrying a file's structure into another format: a glTF scene saved as OBJ, an OBJ with a
//! material library saved as glTF.
//!
//! [`Scene`] is what the writers of another format need from the source, read from it when it is
//! saved (`GltfSource::scene`, `obj::scene`): its file vertices (one per glTF accessor element as
//! read for one node, one per distinct OBJ `v/vt/vn` corner) placed on the welded vertices the
//! algorithms moved, with their UVs, colours and normals; its parts (a glTF node and its mesh, an
//! OBJ `o`/`g` pair), each with one triangle list per material; and its materials (base colour
//! and base colour texture).
//!
//! Positions come from the faired mesh in world space (OBJ has no transforms; glTF nodes are
//! written with none). Normals are the file's own, brought to world space and then turned with
//! their faces exactly as the same-format writers turn them (`super::source::NormalTurns`):
//! split normals (hard edges, UV seams) stay split, smooth ones stay smooth. A file with no
//! normals gets none in OBJ and area-weighted smooth ones in glTF (which wants them).
//!
//! Front ends read a loaded file's [`Scene`] through [`Source::scene`](super::Source::scene) to
//! draw its materials; building and writing one stays inside the library.
//!
//! Texture coordinates are in the library's convention (`uv_convention.rs`); written into another
//! format they follow their vertices' slide along the surface (`Scene::follow_slide`), as the
//! write-backs make them do.
//!
//! Images: an external image file is copied beside the output when it is not in the output's
//! folder already (as `<output stem>_<name>` when another file of that name is there), and
//! referred to by its file name; an image stored inside a glTF (buffer view or data: URI) is
//! written out as a file beside an OBJ's `.mtl` or a `.gltf`. A GLB embeds every image.

use super::normals::{dvec, NormalTurns, SmoothGroups};
use super::uv_follow::{UvTriangle, NO_UV};
use crate::mesh::TriMesh;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A source's structure, for writing it in another format.
#[derive(Debug, Default)]
pub struct Scene {
    pub vertices: Vec<SceneVertex>,
    /// Whether the file had UVs, colours and normals (on any of its parts).
    pub uvs: bool,
    pub colours: bool,
    pub normals: bool,
    pub parts: Vec<Part>,
    /// Whether parts are groups of named objects (an OBJ's `g`s under its `o`s): a glTF gets a
    /// node per object over a node per group. Otherwise (a glTF's nodes) a part is one node.
    pub groups_under_objects: bool,
    pub materials: Vec<Material>,
    /// Whether a primitive without a material is drawn with glTF's default material (a glTF's
    /// primitives), rather than with whatever its reader takes (an OBJ's faces before any
    /// `usemtl`). An OBJ written from the scene then names that material for it
    /// (`Material::gltf_default`).
    pub material_less_is_gltf_default: bool,
    /// What could not be read while building the scene (a missing `.mtl`, an unreadable image).
    pub warnings: Vec<String>,
}

/// One file vertex.
#[derive(Clone, Copy, Debug)]
pub struct SceneVertex {
    /// The welded vertex it became (its position in the faired mesh); `u32::MAX` if dropped.
    pub welded: u32,
    /// Its position as the file had it, in world space (for turning the normals).
    pub before: [f32; 3],
    pub uv: [f32; 2],
    pub colour: [f32; 4],
    /// In world space; turned with its faces by `Scene::turn_normals`.
    pub normal: [f32; 3],
    /// The slot its normal turns in (`NormalTurns`): the OBJ `vn` line, or for glTF given by
    /// `SmoothGroups`; `usize::MAX` for a vertex without a normal.
    pub slot: usize,
}

impl SceneVertex {
    pub(crate) fn new(welded: Option<usize>, before: [f32; 3]) -> SceneVertex {
        SceneVertex {
            welded: welded.map_or(u32::MAX, |w| w as u32),
            before,
            uv: [0.0; 2],
            colour: [1.0; 4],
            normal: [0.0; 3],
            slot: usize::MAX,
        }
    }
}

/// A named part: a glTF node with its mesh, or the faces under one OBJ `o` and `g`.
#[derive(Debug, Default)]
pub struct Part {
    /// The glTF node's name, or the OBJ `o` name.
    pub object: Option<String>,
    /// The glTF mesh's name, or the OBJ `g` name.
    pub group: Option<String>,
    pub primitives: Vec<Primitive>,
}

/// Triangles of one material, corners as indices into [`Scene::vertices`].
#[derive(Debug, Default)]
pub struct Primitive {
    pub material: Option<usize>,
    pub triangles: Vec<[u32; 3]>,
}

#[derive(Debug)]
pub struct Material {
    pub name: String,
    /// Linear RGBA (glTF baseColorFactor; an MTL's Kd and d).
    pub base_colour: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
    pub texture: Option<Image>,
    /// How the base colour texture is sampled (a glTF texture's sampler; defaults otherwise).
    pub sampler: TextureSampler,
    /// Which set of texture coordinates the base colour texture reads (glTF `texCoord`, 0 for
    /// `TEXCOORD_0`; the texture transform's own `texCoord` where it has one).
    pub tex_coord: u32,
    /// The base colour texture's `KHR_texture_transform`, where the file has one.
    pub texture_transform: Option<TextureTransform>,
}

impl Material {
    /// glTF's default material (glTF 2.0, "Materials": a primitive without one is drawn white,
    /// fully metallic and fully rough), under `name`.
    pub(crate) fn gltf_default(name: String) -> Material {
        Material {
            name,
            base_colour: [1.0; 4],
            metallic: 1.0,
            roughness: 1.0,
            texture: None,
            sampler: TextureSampler::default(),
            tex_coord: 0,
            texture_transform: None,
        }
    }
}

/// A glTF base colour texture's `KHR_texture_transform`: its texture coordinates are scaled,
/// then rotated, then offset before the texture is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureTransform {
    pub offset: [f32; 2],
    /// Radians: the texture coordinates turn counter-clockwise, the image clockwise.
    pub rotation: f32,
    pub scale: [f32; 2],
    /// The extension's object as the file wrote it, carried into a glTF output as it came.
    pub json: serde_json::Value,
}

impl TextureTransform {
    /// The extension's object (`None` when it is no object); fields it leaves out take the
    /// extension's defaults (offset 0, rotation 0, scale 1).
    pub fn from_gltf(json: &serde_json::Value) -> Option<TextureTransform> {
        json.as_object()?;
        let pair = |key: &str, default: f32| {
            let list = json.get(key).and_then(serde_json::Value::as_array);
            let at = |i: usize| {
                list.and_then(|l| l.get(i))
                    .and_then(serde_json::Value::as_f64)
                    .filter(|v| v.is_finite())
                    .map_or(default, |v| v as f32)
            };
            [at(0), at(1)]
        };
        Some(TextureTransform {
            offset: pair("offset", 0.0),
            rotation: (json.get("rotation").and_then(serde_json::Value::as_f64))
                .filter(|v| v.is_finite())
                .map_or(0.0, |v| v as f32),
            scale: pair("scale", 1.0),
            json: json.clone(),
        })
    }
}

/// How a texture is sampled, as a glTF sampler says (an MTL says nothing: the defaults).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureSampler {
    /// Magnified texels blend (LINEAR) or stay sharp squares (NEAREST).
    pub mag_linear: bool,
    /// Minified texels blend (LINEAR, or a *_MIPMAP_* filter's own choice between texels).
    pub min_linear: bool,
    /// How texture coordinates outside 0..1 wrap, along u (wrapS) and v (wrapT).
    pub wrap: [TextureWrap; 2],
    /// Whether a minified texture reads from its mipmaps (its halved copies), and how it goes
    /// between two of them.
    pub mipmaps: MipmapFilter,
}

impl Default for TextureSampler {
    /// glTF's defaults where a sampler leaves a field out: linear filters, repeat. Where the
    /// minification filter is left out glTF lets the reader choose: mipmaps, blended between
    /// levels (LINEAR_MIPMAP_LINEAR), as most viewers do.
    fn default() -> Self {
        TextureSampler {
            mag_linear: true,
            min_linear: true,
            wrap: [TextureWrap::Repeat; 2],
            mipmaps: MipmapFilter::Linear,
        }
    }
}

/// The mipmaps a glTF minification filter asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MipmapFilter {
    /// NEAREST or LINEAR: the full-size texture alone.
    Off,
    /// NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST: the nearest level.
    Nearest,
    /// NEAREST_MIPMAP_LINEAR, LINEAR_MIPMAP_LINEAR: the two nearest levels blended.
    Linear,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureWrap {
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

impl TextureSampler {
    /// A glTF `samplers[]` entry (its GL enum values).
    pub(crate) fn from_gltf(sampler: &serde_json::Value) -> TextureSampler {
        let number = |key: &str| sampler.get(key).and_then(serde_json::Value::as_u64);
        let wrap = |key: &str| match number(key) {
            Some(33071) => TextureWrap::ClampToEdge,
            Some(33648) => TextureWrap::MirroredRepeat,
            _ => TextureWrap::Repeat,
        };
        TextureSampler {
            // 9728 NEAREST; 9984 NEAREST_MIPMAP_NEAREST and 9986 NEAREST_MIPMAP_LINEAR pick
            // the nearest texel within a level.
            mag_linear: number("magFilter") != Some(9728),
            min_linear: !matches!(number("minFilter"), Some(9728 | 9984 | 9986)),
            wrap: [wrap("wrapS"), wrap("wrapT")],
            mipmaps: match number("minFilter") {
                Some(9728 | 9729) => MipmapFilter::Off,
                Some(9984 | 9985) => MipmapFilter::Nearest,
                _ => MipmapFilter::Linear,
            },
        }
    }
}

#[derive(Debug, Clone)]
pub struct Image {
    /// The file name it gets beside the output (and had, for an external file).
    pub name: String,
    pub data: ImageData,
}

#[derive(Debug, Clone)]
pub enum ImageData {
    /// An external file, resolved against the input's folder.
    File(PathBuf),
    /// Bytes stored inside the input.
    Bytes(Vec<u8>),
}

impl ImageData {
    /// The image file's bytes: read from its file, or borrowed from the input that stored it.
    pub fn bytes(&self) -> std::io::Result<std::borrow::Cow<'_, [u8]>> {
        match self {
            ImageData::File(path) => super::files::read(path).map(std::borrow::Cow::Owned),
            ImageData::Bytes(bytes) => Ok(std::borrow::Cow::Borrowed(bytes)),
        }
    }
}

/// Where a scene's triangles and file vertices are, by welded vertex (see
/// [`Scene::derive`]).
struct BaseLookup {
    /// Base triangle (welded corners) -> (part, primitive, file corners).
    by_triangle: HashMap<[u32; 3], (usize, usize, [u32; 3])>,
    /// (welded vertex, part, primitive) -> its file vertex there.
    in_primitive: HashMap<(u32, usize, usize), u32>,
    /// Welded vertex -> its first file vertex.
    first_any: Vec<u32>,
}

/// Where an image goes beside an output: the name the output refers to it by, and the file to
/// write there (`None` when the input's own file is already in the output's folder).
pub(crate) struct PlacedImage {
    pub uri_name: String,
    pub write: Option<(PathBuf, ImageData)>,
}

impl Scene {
    /// Drop the triangles that lost a corner or whose corners were welded together (the loader
    /// dropped them too), and the primitives and parts left empty.
    pub(crate) fn drop_degenerate(&mut self) {
        let vertices = &self.vertices;
        let welded = |v: u32| vertices.get(v as usize).map_or(u32::MAX, |v| v.welded);
        for part in &mut self.parts {
            for primitive in &mut part.primitives {
                primitive.triangles.retain(|t| {
                    let [a, b, c] = t.map(welded);
                    a != u32::MAX && b != u32::MAX && c != u32::MAX && a != b && b != c && a != c
                });
            }
            part.primitives.retain(|p| !p.triangles.is_empty());
        }
        self.parts.retain(|p| !p.primitives.is_empty());
    }

    /// Give each file normal that has no slot yet one from `SmoothGroups` (a normal that is the
    /// normal of its own faces gets a slot of its own, so flat parts stay flat per face).
    pub(crate) fn assign_smooth_slots(&mut self) {
        let mut own = NormalTurns::new(self.vertices.len());
        for part in &self.parts {
            for primitive in &part.primitives {
                for t in &primitive.triangles {
                    let before = t.map(|v| dvec(self.vertices[v as usize].before));
                    own.add(t.map(|v| v as usize), before, before);
                }
            }
        }
        let mut groups = SmoothGroups::default();
        for (k, vertex) in self.vertices.iter_mut().enumerate() {
            if vertex.slot == usize::MAX && vertex.normal != [0.0; 3] {
                let welded = (vertex.welded != u32::MAX).then_some(vertex.welded as usize);
                vertex.slot = groups.slot_for(own.area_before(k), welded, vertex.normal);
            }
        }
    }

    /// Turn every file normal with its faces, from the file's positions to `mesh`'s.
    pub(crate) fn turn_normals(&mut self, mesh: &TriMesh) {
        if !self.normals {
            return;
        }
        let mut turns = NormalTurns::new(0);
        for part in &self.parts {
            for primitive in &part.primitives {
                for t in &primitive.triangles {
                    let corners = t.map(|v| &self.vertices[v as usize]);
                    if corners.iter().any(|c| c.slot == usize::MAX) {
                        continue;
                    }
                    let after = corners.map(|c| dvec(mesh.positions[c.welded as usize]));
                    turns.add(
                        corners.map(|c| c.slot),
                        corners.map(|c| dvec(c.before)),
                        after,
                    );
                }
            }
        }
        for vertex in &mut self.vertices {
            if vertex.slot == usize::MAX {
                continue;
            }
            if let Some(turn) = turns.turn(vertex.slot) {
                vertex.normal = turn.normal(vertex.normal);
            }
        }
        self.fill_missing_normals(mesh);
    }

    /// Give the vertices with no (or a zero) normal the area-weighted normal of their welded
    /// vertex in `mesh` (a part with no normals beside one with them; glTF output wants them).
    pub(crate) fn fill_missing_normals(&mut self, mesh: &TriMesh) {
        let missing = |v: &SceneVertex| v.welded != u32::MAX && v.normal == [0.0; 3];
        if !self.vertices.iter().any(missing) {
            return;
        }
        let smooth = super::normals::unit_vertex_normals(mesh);
        for vertex in &mut self.vertices {
            if missing(vertex) {
                vertex.normal = smooth[vertex.welded as usize];
            }
        }
    }

    /// What the scene carries into another format, in plain words.
    pub(crate) fn carried(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self
            .parts
            .iter()
            .any(|p| p.object.is_some() || p.group.is_some())
        {
            out.push("names");
        }
        if !self.materials.is_empty() {
            out.push("materials");
        }
        if self.materials.iter().any(|m| m.texture.is_some()) {
            out.push("textures");
        }
        if self.uvs {
            out.push("UVs");
        }
        if self.normals {
            out.push("normals");
        }
        if self.colours {
            out.push("vertex colours");
        }
        out
    }

    /// The scene of a mesh derived from this one's welded mesh `base` by removing vertices (a
    /// coarse level of the hierarchy): `mesh`'s vertex `j` is base vertex `vertex_origin[j]`, its
    /// triangle `i` what is left of base triangle `face_origin[i]`. Each triangle stays in its
    /// base triangle's part and material; a corner whose vertex survived keeps its file vertex
    /// (UV, colour); a corner moved onto another vertex by a collapse takes that vertex's file
    /// vertex in the same material (or its first). Normals are left to be recomputed (they are
    /// zero here: see [`Scene::fill_missing_normals`]). The number of level triangles whose base
    /// triangle was not found (they go to an unnamed part) comes back too.
    pub(crate) fn derive(
        &self,
        base: &TriMesh,
        mesh: &TriMesh,
        vertex_origin: &[u32],
        face_origin: &[u32],
    ) -> (Scene, usize) {
        let canonical = |t: [u32; 3]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        let BaseLookup {
            by_triangle,
            in_primitive,
            first_any,
        } = self.base_lookup(base.positions.len(), canonical);
        let mut derived = self.empty_copy();
        let mut unplaced = Primitive::default();
        let mut index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut vertex_of = |file: u32, level: u32, vertices: &mut Vec<SceneVertex>| {
            *index.entry((file, level)).or_insert_with(|| {
                let mut vertex = self
                    .vertices
                    .get(file as usize)
                    .copied()
                    .unwrap_or_else(|| SceneVertex::new(None, [0.0; 3]));
                vertex.welded = level;
                vertex.normal = [0.0; 3];
                vertex.slot = usize::MAX;
                vertices.push(vertex);
                (vertices.len() - 1) as u32
            })
        };
        for (i, t) in mesh.triangles.iter().enumerate() {
            let origin = face_origin
                .get(i)
                .and_then(|&f| base.triangles.get(f as usize))
                .and_then(|&b| by_triangle.get(&canonical(b)));
            let base_of = |v: u32| vertex_origin.get(v as usize).copied().unwrap_or(u32::MAX);
            let corners = t.map(|level| {
                let b = base_of(level);
                let file = match origin {
                    Some(&(p, q, corners)) => corners
                        .into_iter()
                        .find(|&c| self.vertices[c as usize].welded == b)
                        .or_else(|| in_primitive.get(&(b, p, q)).copied()),
                    None => None,
                }
                .or_else(|| first_any.get(b as usize).copied())
                .unwrap_or(u32::MAX);
                vertex_of(file, level, &mut derived.vertices)
            });
            match origin {
                Some(&(p, q, _)) => derived.parts[p].primitives[q].triangles.push(corners),
                None => unplaced.triangles.push(corners),
            }
        }
        let unplaced_count = unplaced.triangles.len();
        if unplaced_count > 0 {
            derived.parts.push(Part {
                primitives: vec![unplaced],
                ..Part::default()
            });
        }
        for part in &mut derived.parts {
            part.primitives.retain(|p| !p.triangles.is_empty());
        }
        derived.parts.retain(|p| !p.primitives.is_empty());
        derived.fill_missing_normals(mesh);
        (derived, unplaced_count)
    }

    /// Where the triangles and file vertices of this scene are, by the welded (base) vertices
    /// of `base_vertices`: base triangle (welded corners, `canonical` order) -> (part, primitive,
    /// file corners), found also reversed (a triangle the loader turned over to orient the mesh
    /// consistently); (welded vertex, part, primitive) -> its file vertex there; welded vertex
    /// -> its first file vertex.
    fn base_lookup(
        &self,
        base_vertices: usize,
        canonical: impl Fn([u32; 3]) -> [u32; 3],
    ) -> BaseLookup {
        // Base triangle (welded corners) -> (part, primitive, file corners); a triangle the
        // loader turned over (to orient the mesh consistently) is found reversed.
        let mut by_triangle: HashMap<[u32; 3], (usize, usize, [u32; 3])> = HashMap::new();
        let mut in_primitive: HashMap<(u32, usize, usize), u32> = HashMap::new();
        let mut first_any = vec![u32::MAX; base_vertices];
        for (p, part) in self.parts.iter().enumerate() {
            for (q, primitive) in part.primitives.iter().enumerate() {
                for &t in &primitive.triangles {
                    let welded = t.map(|v| self.vertices[v as usize].welded);
                    by_triangle.entry(canonical(welded)).or_insert((p, q, t));
                    by_triangle
                        .entry(canonical([welded[0], welded[2], welded[1]]))
                        .or_insert((p, q, t));
                    for k in 0..3 {
                        in_primitive.entry((welded[k], p, q)).or_insert(t[k]);
                        if let Some(first) = first_any.get_mut(welded[k] as usize) {
                            if *first == u32::MAX {
                                *first = t[k];
                            }
                        }
                    }
                }
            }
        }
        BaseLookup {
            by_triangle,
            in_primitive,
            first_any,
        }
    }

    /// This scene's parts, primitives (with no triangles) and materials, with no vertices.
    fn empty_copy(&self) -> Scene {
        Scene {
            uvs: self.uvs,
            colours: self.colours,
            normals: self.normals,
            groups_under_objects: self.groups_under_objects,
            material_less_is_gltf_default: self.material_less_is_gltf_default,
            parts: self
                .parts
                .iter()
                .map(|part| Part {
                    object: part.object.clone(),
                    group: part.group.clone(),
                    primitives: part
                        .primitives
                        .iter()
                        .map(|p| Primitive {
                            material: p.material,
                            triangles: Vec::new(),
                        })
                        .collect(),
                })
                .collect(),
            materials: self
                .materials
                .iter()
                .map(|m| Material {
                    name: m.name.clone(),
                    base_colour: m.base_colour,
                    metallic: m.metallic,
                    roughness: m.roughness,
                    texture: m.texture.clone(),
                    sampler: m.sampler,
                    tex_coord: m.tex_coord,
                    texture_transform: m.texture_transform.clone(),
                })
                .collect(),
            ..Scene::default()
        }
    }

    /// Whether a glTF written from this scene carries the source's `KHR_texture_transform`:
    /// some base colour texture has one over TEXCOORD_0 (the one set of texture coordinates
    /// written; a transform over another set is named in the warnings when read).
    pub(crate) fn texture_transforms_carried(&self) -> bool {
        self.materials
            .iter()
            .any(|m| m.texture.is_some() && m.texture_transform.is_some() && m.tex_coord == 0)
    }

    /// Moves the texture coordinates of the file vertices whose welded vertex moved (from their
    /// `before` to `mesh`'s position) so that the texture stays where it was on the surface, as
    /// the write-backs do ([`super::uv_follow`]). A texture coordinate here is one welded vertex's
    /// UV value: the file vertices of one welded vertex with the same UV (an OBJ corner's other
    /// normals, a glTF vertex repeated in another primitive) walk as one, and each side of a UV
    /// seam walks in its own chart. Returns whether the UVs followed (the scene has UVs).
    pub(crate) fn follow_slide(&mut self, mesh: &TriMesh) -> bool {
        if !self.uvs {
            return false;
        }
        let n = mesh.positions.len();
        let mut before = mesh.positions.clone();
        let mut seen = vec![false; n];
        for vertex in &self.vertices {
            let w = vertex.welded as usize;
            if w < n && !seen[w] {
                before[w] = vertex.before;
                seen[w] = true;
            }
        }
        if before == mesh.positions {
            return true;
        }
        let mut slots: HashMap<(u32, [u32; 2]), u32> = HashMap::new();
        let mut uvs: Vec<[f64; 2]> = Vec::new();
        let slot_of: Vec<u32> = self
            .vertices
            .iter()
            .map(|vertex| {
                if vertex.welded as usize >= n {
                    return NO_UV;
                }
                let key = (vertex.welded, vertex.uv.map(f32::to_bits));
                *slots.entry(key).or_insert_with(|| {
                    uvs.push(vertex.uv.map(f64::from));
                    (uvs.len() - 1) as u32
                })
            })
            .collect();
        let vertices = &self.vertices;
        let triangles: Vec<UvTriangle> = (self.parts.iter())
            .flat_map(|part| &part.primitives)
            .flat_map(|p| &p.triangles)
            .filter(|t| {
                t.iter()
                    .all(|&c| slot_of.get(c as usize).is_some_and(|&s| s != NO_UV))
            })
            .map(|t| t.map(|c| [vertices[c as usize].welded, slot_of[c as usize]]))
            .collect();
        let followed = super::uv_follow::follow(&before, &mesh.positions, &triangles, &uvs);
        for (vertex, &slot) in self.vertices.iter_mut().zip(&slot_of) {
            if let Some(Some(uv)) = followed.moved.get(slot as usize) {
                vertex.uv = uv.map(|c| c as f32);
            }
        }
        true
    }

    /// How many welded vertices have a colour that is not opaque (alpha below 1), among the
    /// file vertices the triangles use.
    pub(crate) fn translucent_vertices(&self) -> usize {
        if !self.colours {
            return 0;
        }
        let mut seen = std::collections::HashSet::new();
        for primitive in self.parts.iter().flat_map(|p| &p.primitives) {
            for &v in primitive.triangles.iter().flatten() {
                if let Some(vertex) = self.vertices.get(v as usize) {
                    if vertex.colour[3] < 1.0 && vertex.welded != u32::MAX {
                        seen.insert(vertex.welded);
                    }
                }
            }
        }
        seen.len()
    }

    /// How many triangles in all.
    pub(crate) fn triangle_count(&self) -> usize {
        self.parts
            .iter()
            .flat_map(|p| &p.primitives)
            .map(|p| p.triangles.len())
            .sum()
    }

    /// Where each material's texture goes beside `output` (by material index).
    pub(crate) fn place_images(&self, output: &Path) -> Vec<Option<PlacedImage>> {
        let (out_dir, stem) = super::folder_and_stem(output);
        let same_dir = |file: &Path| {
            file.parent().is_some_and(|d| {
                let d = if d.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    d
                };
                super::files::same_file(d, &out_dir)
            })
        };
        // (name used, what is there) so that two images of one name do not overwrite each other.
        let mut taken: Vec<(String, String)> = Vec::new();
        let identity = |data: &ImageData| match data {
            ImageData::File(path) => format!("file:{}", path.display()),
            ImageData::Bytes(bytes) => format!("bytes:{:016x}", hash_bytes(bytes)),
        };
        self.materials
            .iter()
            .map(|material| {
                let image = material.texture.as_ref()?;
                if let ImageData::File(file) = &image.data {
                    if same_dir(file) {
                        return Some(PlacedImage {
                            uri_name: image.name.clone(),
                            write: None,
                        });
                    }
                }
                let id = identity(&image.data);
                if let Some((name, _)) = taken.iter().find(|(_, other)| *other == id) {
                    return Some(PlacedImage {
                        uri_name: name.clone(),
                        write: None,
                    });
                }
                let mut name = image.name.clone();
                // A file of that name already beside the output is a clash unless it holds the
                // same bytes (an earlier export, or the write-back's copy of the image).
                let clash = |name: &str, taken: &[(String, String)]| {
                    let target = out_dir.join(name);
                    taken.iter().any(|(n, _)| n == name)
                        || (super::files::exists(&target)
                            && super::files::read(&target).ok().as_deref()
                                != image.data.bytes().ok().as_deref())
                };
                if clash(&name, &taken) {
                    name = format!("{stem}_{}", image.name);
                }
                taken.push((name.clone(), id));
                Some(PlacedImage {
                    uri_name: name.clone(),
                    write: Some((out_dir.join(&name), image.data.clone())),
                })
            })
            .collect()
    }
}

fn hash_bytes(bytes: &[u8]) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// A file name for an image: `name` (a glTF image's name, or a file name) cleaned of characters
/// that do not belong in one, with an extension for its MIME type if it has none.
pub(crate) fn image_file_name(name: &str, mime: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '.' | '-' | '_') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let clean = clean.trim_start_matches('.').to_string();
    let clean = if clean.is_empty() {
        "image".to_string()
    } else {
        clean
    };
    if Path::new(&clean).extension().is_some() {
        return clean;
    }
    let extension = match mime {
        "image/jpeg" => "jpg",
        "image/webp" => "webp",
        "image/ktx2" => "ktx2",
        _ => "png",
    };
    format!("{clean}.{extension}")
}

/// The MIME type of an image, from its first bytes or else the file name's extension.
pub(crate) fn image_mime_type(bytes: &[u8], name: &Path) -> &'static str {
    if bytes.starts_with(b"\x89PNG") {
        return "image/png";
    }
    if bytes.starts_with(&[0xFF, 0xD8]) {
        return "image/jpeg";
    }
    if bytes.get(8..12) == Some(b"WEBP") {
        return "image/webp";
    }
    match name
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("jpg" | "jpeg") => "image/jpeg",
        Some("webp") => "image/webp",
        Some("ktx2") => "image/ktx2",
        _ => "image/png",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_names_are_cleaned_and_get_an_extension() {
        assert_eq!(image_file_name("checker", "image/png"), "checker.png");
        assert_eq!(image_file_name("a b/c.jpg", "image/png"), "a_b_c.jpg");
        assert_eq!(image_file_name("../x", "image/jpeg"), "_x.jpg");
        assert_eq!(image_file_name("", "image/png"), "image.png");
    }

    #[test]
    fn welded_triangles_and_lost_corners_are_dropped() {
        let mut scene = Scene::default();
        for w in [Some(0), Some(1), Some(1), None, Some(2)] {
            scene.vertices.push(SceneVertex::new(w, [0.0; 3]));
        }
        scene.parts.push(Part {
            primitives: vec![
                Primitive {
                    material: None,
                    triangles: vec![[0, 1, 4], [0, 1, 2], [0, 3, 4]],
                },
                Primitive {
                    material: Some(0),
                    triangles: vec![[0, 2, 1]],
                },
            ],
            ..Default::default()
        });
        scene.drop_degenerate();
        assert_eq!(scene.parts[0].primitives.len(), 1);
        assert_eq!(scene.parts[0].primitives[0].triangles, vec![[0, 1, 4]]);
    }

    #[test]
    fn a_gltf_samplers_filters_and_wrapping_are_read() {
        let sampler = |json: &str| TextureSampler::from_gltf(&serde_json::from_str(json).unwrap());
        assert_eq!(sampler("{}"), TextureSampler::default());
        let pixel_art =
            sampler(r#"{"magFilter": 9728, "minFilter": 9984, "wrapS": 33071, "wrapT": 33648}"#);
        assert_eq!(
            pixel_art,
            TextureSampler {
                mag_linear: false,
                min_linear: false,
                wrap: [TextureWrap::ClampToEdge, TextureWrap::MirroredRepeat],
                mipmaps: MipmapFilter::Nearest,
            }
        );
        let smooth = sampler(r#"{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497}"#);
        assert!(smooth.mag_linear && smooth.min_linear);
        assert_eq!(smooth.wrap, [TextureWrap::Repeat; 2]);
        assert_eq!(smooth.mipmaps, MipmapFilter::Linear);
        // Each minification filter's mipmaps: none, the nearest level, or two blended.
        for (filter, mipmaps) in [
            (9728, MipmapFilter::Off),
            (9729, MipmapFilter::Off),
            (9984, MipmapFilter::Nearest),
            (9985, MipmapFilter::Nearest),
            (9986, MipmapFilter::Linear),
            (9987, MipmapFilter::Linear),
        ] {
            let read = sampler(&format!(r#"{{"minFilter": {filter}}}"#));
            assert_eq!(read.mipmaps, mipmaps, "{filter}");
        }
    }

    #[test]
    fn a_texture_transform_is_read_with_its_defaults() {
        let read = |json: &str| TextureTransform::from_gltf(&serde_json::from_str(json).unwrap());
        let plain = read("{}").unwrap();
        assert_eq!(
            (plain.offset, plain.rotation, plain.scale),
            ([0.0; 2], 0.0, [1.0; 2])
        );
        assert!(read("[1, 2]").is_none());
        let moved = read(r#"{"offset": [0.25, 0.5], "scale": [2, 3], "rotation": 1}"#).unwrap();
        assert_eq!(
            (moved.offset, moved.rotation, moved.scale),
            ([0.25, 0.5], 1.0, [2.0, 3.0])
        );
        assert_eq!(moved.json["scale"], serde_json::json!([2, 3]));
    }
}
