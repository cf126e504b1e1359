//! Writing a [`Scene`] (see [`crate::io::scene`]) as a new OBJ with its `.mtl` and images.

use crate::io::atomic;
use crate::io::carry::Gather;
use crate::io::scene::{ImageData, Scene, SceneVertex};
use crate::io::IoError;
use crate::mesh::TriMesh;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// An OBJ of `scene` at `path`, with a `.mtl` beside it (`<stem>.mtl`) when it has materials and
/// their textures copied or written beside it (see [`Scene::place_images`]): `v` per welded
/// vertex of `mesh` (with the vertex colour when the source had them), `vt` and `vn` per distinct
/// value, `o`, `g` and `usemtl` per part and material. Every file is staged and renamed into
/// place only when all are complete.
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
    // Distinct values, numbered in first use.
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
    let (uv_list, uv_index) = numbered(scene.vertices.iter().filter(used).map(|v| v.uv));
    let (normal_list, normal_index) =
        numbered(scene.vertices.iter().filter(used).map(|v| v.normal));
    let name_token = |name: &str| name.split_whitespace().collect::<Vec<_>>().join("_");

    let write_obj = |out: &mut dyn Write| -> std::io::Result<()> {
        writeln!(out, "# written by fairmesh")?;
        writeln!(
            out,
            "# {} vertices, {} triangles",
            mesh.positions.len(),
            scene.triangle_count()
        )?;
        if !scene.materials.is_empty() {
            writeln!(out, "mtllib {mtl_name}")?;
        }
        for (v, [x, y, z]) in mesh.positions.iter().enumerate() {
            match &colours {
                Some(colours) => {
                    let [r, g, b, _] = colours[v];
                    writeln!(out, "v {x} {y} {z} {r} {g} {b}")?
                }
                None => writeln!(out, "v {x} {y} {z}")?,
            }
        }
        if scene.uvs {
            for [u, v] in &uv_list {
                writeln!(out, "vt {u} {v}")?;
            }
        }
        if scene.normals {
            for [x, y, z] in &normal_list {
                writeln!(out, "vn {x} {y} {z}")?;
            }
        }
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
                if let Some(m) = primitive.material {
                    writeln!(out, "usemtl {}", name_token(&scene.materials[m].name))?;
                }
                for t in &primitive.triangles {
                    out.write_all(b"f")?;
                    for &corner in t {
                        let vertex = &scene.vertices[corner as usize];
                        let v = vertex.welded as u64 + 1;
                        let vt = uv_index
                            .get(&vertex.uv.map(f32::to_bits))
                            .map_or(1, |i| i + 1);
                        let vn = normal_index
                            .get(&vertex.normal.map(f32::to_bits))
                            .map_or(1, |i| i + 1);
                        match (scene.uvs, scene.normals) {
                            (true, true) => write!(out, " {v}/{vt}/{vn}")?,
                            (true, false) => write!(out, " {v}/{vt}")?,
                            (false, true) => write!(out, " {v}//{vn}")?,
                            (false, false) => write!(out, " {v}")?,
                        }
                    }
                    out.write_all(b"\n")?;
                }
            }
        }
        Ok(())
    };
    let write_mtl = |out: &mut dyn Write| -> std::io::Result<()> {
        writeln!(out, "# written by fairmesh")?;
        for (m, material) in scene.materials.iter().enumerate() {
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
    if !scene.materials.is_empty() {
        staged.push(atomic::stage(&mtl_path, write_mtl)?);
    }
    staged.push(atomic::stage(path, write_obj)?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}
