//! Writing a [`Scene`] (see [`crate::io::scene`]) as a new OBJ with its `.mtl` and images.

use crate::io::atomic;
use crate::io::carry::Gather;
use crate::io::scene::{ImageData, Material, PlacedImage, Scene, SceneVertex};
use crate::io::uv_convention::into_file;
use crate::io::{Format, IoError};
use crate::mesh::TriMesh;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// An OBJ of `scene` at `path`, with a `.mtl` beside it (`<stem>.mtl`) when it has materials and
/// their textures copied or written beside it (see [`Scene::place_images`]): `v` per welded
/// vertex of `mesh` (with the vertex colour when the source had them), `vt` (in OBJ's convention)
/// and `vn` per distinct value, `o`, `g` and `usemtl` per part and material. Every group's faces
/// state their material: a primitive without one, in a scene whose materials are glTF's (or
/// beside primitives with one, which would otherwise lend it theirs), takes glTF's default
/// material under a name of its own ([`default_material_name`]). Every file is staged and
/// renamed into place only when all are complete.
pub(crate) fn write_scene(
    path: &Path,
    scene: &Scene,
    mesh: &TriMesh,
    merged_colours: &mut usize,
) -> Result<(), IoError> {
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path.file_name().map_or_else(
        || "materials.mtl".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    let placed = scene.place_images(path);
    let default_material = default_material_name(scene);
    let used = |v: &&SceneVertex| v.welded != u32::MAX;
    // One colour per `v` line: the first file vertex's.
    let colours = scene.colours.then(|| {
        let mut gather = Gather::<4>::new(mesh.positions.len(), [1.0; 4]);
        for vertex in scene.vertices.iter().filter(used) {
            gather.put(Some(vertex.welded as usize), vertex.colour);
        }
        let (values, merged) = gather.finish();
        *merged_colours = merged;
        values
    });
    let (uv_list, uv_index) = numbered(scene.vertices.iter().filter(used).map(|v| v.uv));
    let (normal_list, normal_index) =
        numbered(scene.vertices.iter().filter(used).map(|v| v.normal));
    let text = ObjText {
        scene,
        mesh,
        mtl_name,
        default_material: default_material.clone(),
        colours,
        uv_list,
        uv_index,
        normal_list,
        normal_index,
    };
    let mut staged = Vec::new();
    for (target, data) in placed.iter().flatten().filter_map(|p| p.write.as_ref()) {
        let bytes = data.bytes().map_err(|source| IoError::Read {
            path: match data {
                ImageData::File(file) => file.clone(),
                ImageData::Bytes(_) => target.clone(),
            },
            source,
        })?;
        staged.push(atomic::stage(target, |w| w.write_all(&bytes))?);
    }
    if !scene.materials.is_empty() || default_material.is_some() {
        staged.push(atomic::stage(&mtl_path, |out| {
            write_mtl(out, scene, &placed, default_material.as_deref())
        })?);
    }
    staged.push(atomic::stage(path, |out| text.write(out))?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}

/// Distinct values, numbered in first use.
fn numbered<const N: usize>(
    values: impl Iterator<Item = [f32; N]>,
) -> (Vec<[f32; N]>, HashMap<[u32; N], usize>) {
    let mut list = Vec::new();
    let mut index = HashMap::new();
    for value in values {
        index.entry(value.map(f32::to_bits)).or_insert_with(|| {
            list.push(value);
            list.len() - 1
        });
    }
    (list, index)
}

/// The name the `.mtl` gives glTF's default material, when some primitive needs it (see
/// [`write_scene`]): `gltf_default`, or `gltf_default_<n>` when a material has that name.
fn default_material_name(scene: &Scene) -> Option<String> {
    let without = scene
        .parts
        .iter()
        .flat_map(|part| &part.primitives)
        .any(|p| p.material.is_none_or(|m| m >= scene.materials.len()));
    let others_would_lend_theirs = !scene.materials.is_empty();
    if !without || !(scene.material_less_is_gltf_default || others_would_lend_theirs) {
        return None;
    }
    let taken = |name: &str| scene.materials.iter().any(|m| name_token(&m.name) == name);
    let mut name = "gltf_default".to_string();
    let mut n = 1;
    while taken(&name) {
        n += 1;
        name = format!("gltf_default_{n}");
    }
    Some(name)
}

/// A name as one OBJ token (its words joined by `_`).
fn name_token(name: &str) -> String {
    name.split_whitespace().collect::<Vec<_>>().join("_")
}

/// What the OBJ's text is made of: the scene and mesh, the `.mtl`'s name, the colour of each
/// `v`, and the distinct UVs and normals with their numbers.
struct ObjText<'a> {
    scene: &'a Scene,
    mesh: &'a TriMesh,
    mtl_name: String,
    /// The `.mtl` name of the material for primitives without one, where they get one.
    default_material: Option<String>,
    colours: Option<Vec<[f32; 4]>>,
    uv_list: Vec<[f32; 2]>,
    uv_index: HashMap<[u32; 2], usize>,
    normal_list: Vec<[f32; 3]>,
    normal_index: HashMap<[u32; 3], usize>,
}

impl ObjText<'_> {
    /// The OBJ: header, `v`, `vt` and `vn` lines, then the parts.
    fn write(&self, out: &mut dyn Write) -> std::io::Result<()> {
        let (scene, mesh) = (self.scene, self.mesh);
        writeln!(out, "# written by fairmesh")?;
        writeln!(
            out,
            "# {} vertices, {} triangles",
            mesh.positions.len(),
            scene.triangle_count()
        )?;
        if !scene.materials.is_empty() || self.default_material.is_some() {
            writeln!(out, "mtllib {}", self.mtl_name)?;
        }
        for (v, [x, y, z]) in mesh.positions.iter().enumerate() {
            match &self.colours {
                Some(colours) => {
                    let [r, g, b, _] = colours[v];
                    writeln!(out, "v {x} {y} {z} {r} {g} {b}")?
                }
                None => writeln!(out, "v {x} {y} {z}")?,
            }
        }
        if scene.uvs {
            for &uv in &self.uv_list {
                let [u, v] = into_file(Format::Obj, uv);
                writeln!(out, "vt {u} {v}")?;
            }
        }
        if scene.normals {
            for [x, y, z] in &self.normal_list {
                writeln!(out, "vn {x} {y} {z}")?;
            }
        }
        self.write_parts(out)
    }

    /// Per part its `o` (when it changes) and `g`, per primitive its `usemtl` and `f` lines.
    fn write_parts(&self, out: &mut dyn Write) -> std::io::Result<()> {
        let scene = self.scene;
        let mut last_object: Option<&str> = None;
        for part in &scene.parts {
            if let Some(object) = part.object.as_deref() {
                if last_object != Some(object) {
                    writeln!(out, "o {object}")?;
                    last_object = Some(object);
                }
            }
            if let Some(group) = &part.group {
                writeln!(out, "g {}", name_token(group))?;
            }
            for primitive in &part.primitives {
                match primitive.material.and_then(|m| scene.materials.get(m)) {
                    Some(material) => writeln!(out, "usemtl {}", name_token(&material.name))?,
                    None => {
                        if let Some(name) = &self.default_material {
                            writeln!(out, "usemtl {name}")?;
                        }
                    }
                }
                for t in &primitive.triangles {
                    out.write_all(b"f")?;
                    for &corner in t {
                        self.write_corner(out, &scene.vertices[corner as usize])?;
                    }
                    out.write_all(b"\n")?;
                }
            }
        }
        Ok(())
    }

    /// One face corner: `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based.
    fn write_corner(&self, out: &mut dyn Write, vertex: &SceneVertex) -> std::io::Result<()> {
        let v = vertex.welded as u64 + 1;
        let vt = self
            .uv_index
            .get(&vertex.uv.map(f32::to_bits))
            .map_or(1, |i| i + 1);
        let vn = self
            .normal_index
            .get(&vertex.normal.map(f32::to_bits))
            .map_or(1, |i| i + 1);
        match (self.scene.uvs, self.scene.normals) {
            (true, true) => write!(out, " {v}/{vt}/{vn}"),
            (true, false) => write!(out, " {v}/{vt}"),
            (false, true) => write!(out, " {v}//{vn}"),
            (false, false) => write!(out, " {v}"),
        }
    }
}

/// The `.mtl`: per material its name, base colour (`Kd`, `d`), metallic (`Pm`), roughness (`Pr`)
/// and the base colour texture's file as `placed` beside the OBJ; then glTF's default material
/// as `default_material` where the OBJ uses it.
fn write_mtl(
    out: &mut dyn Write,
    scene: &Scene,
    placed: &[Option<PlacedImage>],
    default_material: Option<&str>,
) -> std::io::Result<()> {
    writeln!(out, "# written by fairmesh")?;
    let default = default_material.map(|name| Material::gltf_default(name.to_string()));
    for (m, material) in scene.materials.iter().chain(&default).enumerate() {
        let [r, g, b, a] = material.base_colour;
        writeln!(out, "\nnewmtl {}", name_token(&material.name))?;
        writeln!(out, "Kd {r} {g} {b}")?;
        writeln!(out, "d {a}")?;
        writeln!(out, "Pm {}", material.metallic)?;
        writeln!(out, "Pr {}", material.roughness)?;
        if let Some(Some(image)) = placed.get(m) {
            writeln!(out, "map_Kd {}", image.uri_name)?;
        }
    }
    Ok(())
}
