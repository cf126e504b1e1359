//! Saving with a source (see [`Source`]): written back into its own format, carried into another
//! (its scene, or what the format holds per vertex), or, for a mesh derived from the loaded one
//! by removing vertices, what can be kept per surviving vertex. Each way names, in the
//! [`SaveReport`], what the output does not keep.

use super::format::format_of;
use super::normals::unit_vertex_normals;
use super::save::{check_writable, save_as};
use super::scene::Scene;
use super::source::SourceData;
use super::stl::StlSource;
use super::text::and_list;
use super::{atomic, carry, gltf, obj, ply, stl, Format, IoError, SaveReport, Source};
use crate::mesh::TriMesh;
use std::path::Path;

/// Save `mesh` into what it was loaded from: to the same family of format (OBJ, PLY, glTF/GLB)
/// the source file comes back with only the positions and what depends on them changed (see
/// [`Source`]); to another format, the mesh is written with the source's UVs and vertex colours
/// where the format holds them (glTF, OBJ: one value per welded vertex); when `mesh` no longer
/// has the source's connectivity (a level of the hierarchy, a subdivided copy), it is written
/// bare. Either way the report names what the output does not keep. The write is atomic, as with
/// [`crate::io::save`].
pub fn save_with_source(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    source: &Source,
) -> Result<SaveReport, IoError> {
    let path = path.as_ref();
    let format = format_of(path)?;
    check_writable(mesh, path)?;
    let mut report = SaveReport::default();
    if let (SourceData::Stl(stl), Format::Stl) = (&source.data, format) {
        write_stl_header_back(path, mesh, stl, source, &mut report)?;
    } else if source.writes_back_as(format) && source.matches(mesh) {
        write_back(path, format, mesh, source, &mut report)?;
    } else {
        let carries = !source.writes_back_as(format) && source.matches(mesh);
        let scene = (carries && matches!(format, Format::Obj | Format::Glb | Format::Gltf))
            .then(|| source.scene(mesh))
            .flatten();
        match scene {
            Some(scene) => write_carried_scene(path, format, mesh, source, scene, &mut report)?,
            None => write_carried_attributes(path, format, mesh, source, carries, &mut report)?,
        }
    }
    Ok(report)
}

/// STL keeps nothing per vertex: its header is written back whatever the connectivity.
fn write_stl_header_back(
    path: &Path,
    mesh: &TriMesh,
    stl: &StlSource,
    source: &Source,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    atomic::write(path, |w| stl::write_with_header(w, mesh, &stl.header))?;
    if !stl.unkept.is_empty() {
        report.warnings.push(format!(
            "not kept from {}: {}",
            source.origin.path.display(),
            stl.unkept.join("; ")
        ));
    }
    Ok(())
}

/// Into its own format (OBJ, PLY, glTF/GLB), with the source's connectivity: the file comes
/// back with only the positions and what depends on them changed.
fn write_back(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    source: &Source,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    let origin = &source.origin;
    match &source.data {
        SourceData::Obj(bytes) => {
            // Its material libraries and their images go beside it; every file is staged and
            // renamed into place only when all are complete.
            let copies = obj::companion_copies(bytes, origin, path, &mut report.warnings);
            let staged_copies = obj::stage_copies(&copies, path)?;
            let mut shared = 0;
            let staged_obj = atomic::stage(path, |w| {
                shared = obj::write_back(w, bytes, origin, mesh)?;
                Ok(())
            })?;
            for staged in staged_copies {
                staged.commit()?;
            }
            staged_obj.commit()?;
            report.texture_coordinates_follow = true;
            if shared > 0 {
                report.warnings.push(format!(
                    "{shared} texture coordinates of {} are each shared by several \
                     vertices that moved, so they stay where they were (the texture slides \
                     with those vertices)",
                    origin.path.display()
                ));
            }
        }
        SourceData::Ply(bytes) => {
            atomic::write(path, |w| {
                report.texture_coordinates_follow = ply::write_back(w, bytes, origin, mesh)?;
                Ok(())
            })?;
            if ply::has_face_texture_coordinates(bytes)
                && source
                    .loaded_positions(mesh)
                    .is_some_and(|p| p != mesh.positions)
            {
                report.warnings.push(format!(
                    "the per-face texture coordinates (texcoord) of {} stay with their corners,                      so the texture slides with the vertices that moved (only per-vertex texture                      coordinates follow the slide)",
                    origin.path.display()
                ));
            }
        }
        SourceData::Gltf(gltf) => gltf::write_back(path, format, gltf, origin, mesh, report)?,
        SourceData::Plain | SourceData::Unkept(_) | SourceData::Stl(_) => {
            save_as(path, mesh, format)?
        }
    }
    Ok(())
}

/// A glTF scene or an OBJ into OBJ or glTF: its parts, materials, UVs (following the slide),
/// normals and colours.
fn write_carried_scene(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    source: &Source,
    mut scene: Scene,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    report.texture_coordinates_follow = scene.follow_slide(mesh);
    let merged_colours = write_scene(path, format, &mut scene, mesh)?;
    let mut lost = source.contents_beyond_scene(&scene, format);
    if merged_colours > 0 {
        lost.push(merged_colour_borders(merged_colours));
    }
    if format == Format::Obj {
        lost.extend(carry::alpha_lost_in_obj(scene.translucent_vertices()));
    }
    lost.append(&mut scene.warnings);
    if !lost.is_empty() {
        report.warnings.push(format!(
            "{}; not kept from {}: {}",
            written_as(format, &scene.carried()),
            source.origin.path.display(),
            lost.join("; ")
        ));
    }
    Ok(())
}

/// Otherwise what the format can hold per vertex (UVs, colours; normals into PLY) is carried
/// when the mesh still has the source's vertices (`carries`), the UVs following the slide; the
/// rest is named.
fn write_carried_attributes(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    source: &Source,
    carries: bool,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    let holds = matches!(
        format,
        Format::Obj | Format::Glb | Format::Gltf | Format::Ply
    );
    let mut extra = if carries && holds {
        source.vertex_attributes()
    } else {
        carry::VertexAttributes::default()
    };
    if let Some(uvs) = extra.uvs.as_mut() {
        if let Some(before) = source.loaded_positions(mesh) {
            carry::follow_slide(uvs, &before, mesh);
            report.texture_coordinates_follow = true;
        }
    }
    let (mut kept, mut lost) = extra.describe();
    let mut beyond = source.contents_beyond(&extra);
    if format == Format::Ply && carries {
        // Normals, when the file had them, are recomputed from the faired shape: one per
        // vertex, so the split ones (hard edges) become smooth; how many is said.
        let had_normals = beyond
            .iter()
            .any(|item| item == "normals" || item.starts_with("normals ("));
        let normals = had_normals.then(|| unit_vertex_normals(mesh));
        atomic::write(path, |w| {
            ply::write_with(w, mesh, &extra, normals.as_deref())
        })?;
        if had_normals {
            kept.push("normals (recomputed)");
            beyond.retain(|item| item != "normals" && !item.starts_with("normals ("));
            let split = source.split_normal_vertices(mesh);
            if split > 0 {
                lost.push(format!(
                    "the split normals (hard edges, seams) at {split} vertices: a PLY vertex holds one normal, recomputed smooth from the faired shape"
                ));
            }
        }
    } else {
        write_with_attributes(path, format, mesh, &extra)?;
    }
    if format == Format::Obj {
        let translucent = extra.colours.as_deref().map_or(0, carry::translucent);
        lost.extend(carry::alpha_lost_in_obj(translucent));
    }
    lost.extend(beyond);
    if !lost.is_empty() {
        let why = if source.writes_back_as(format) {
            "the mesh no longer has its connectivity (a level of the hierarchy or a changed copy), so it is written as a bare mesh".to_string()
        } else {
            written_as(format, &kept)
        };
        report.warnings.push(format!(
            "{why}; not kept from {}: {}",
            source.origin.path.display(),
            lost.join("; ")
        ));
    }
    Ok(())
}

/// `mesh` in `format`, with the per-vertex UVs and colours of `extra` where the format holds
/// them (OBJ, glTF/GLB, PLY).
fn write_with_attributes(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    extra: &carry::VertexAttributes,
) -> Result<(), IoError> {
    match format {
        Format::Obj => atomic::write(path, |w| obj::write_with(w, mesh, extra)),
        Format::Glb => atomic::write(path, |w| gltf::write_glb_with(w, mesh, extra)),
        Format::Gltf => gltf::write_gltf_with(path, mesh, extra),
        Format::Ply => atomic::write(path, |w| ply::write_with(w, mesh, extra, None)),
        _ => save_as(path, mesh, format),
    }
}

/// `scene` as OBJ or glTF/GLB; returns at how many vertices an OBJ merged colour borders.
fn write_scene(
    path: &Path,
    format: Format,
    scene: &mut Scene,
    mesh: &TriMesh,
) -> Result<usize, IoError> {
    let mut merged_colours = 0;
    match format {
        Format::Obj => obj::write_scene(path, scene, mesh, &mut merged_colours)?,
        _ => gltf::write_scene(path, format == Format::Glb, scene, mesh)?,
    }
    Ok(merged_colours)
}

/// What an OBJ lost where it merged the colour borders at `vertices` vertices.
fn merged_colour_borders(vertices: usize) -> String {
    format!(
        "the colour borders at {vertices} vertices (an OBJ vertex keeps one colour; the first was kept)"
    )
}

/// Where a mesh derived from a loaded one by removing vertices (a coarse level of the
/// hierarchy) came from, for [`save_derived_with_source`].
#[derive(Clone, Copy, Debug)]
pub struct Derivation<'a> {
    /// The mesh it was derived from, with the loaded connectivity (its positions do not matter).
    pub base: &'a TriMesh,
    /// Per vertex of the derived mesh: the vertex of `base` it is.
    pub vertex_origin: &'a [u32],
    /// Per triangle of the derived mesh: the triangle of `base` it is what is left of.
    pub face_origin: &'a [u32],
}

impl Derivation<'_> {
    /// Whether it fits `mesh` (an origin per vertex and triangle) and `source` (a base with the
    /// loaded connectivity, and origins among its vertices).
    fn fits(&self, mesh: &TriMesh, source: &Source) -> bool {
        self.vertex_origin.len() == mesh.positions.len()
            && self.face_origin.len() == mesh.triangles.len()
            && source.matches(self.base)
            && self
                .vertex_origin
                .iter()
                .all(|&v| (v as usize) < self.base.positions.len())
    }
}

/// Save a mesh derived from the loaded one by removing vertices (a coarse level of the
/// hierarchy), keeping what can be kept per surviving vertex: into OBJ or glTF, from a glTF or
/// OBJ source, its part names, materials (and textures), and the UVs and colours of the kept
/// vertices (a corner moved onto another vertex takes that vertex's UV in the same material; a
/// kept vertex the level placed anew has its UVs follow it over the level's faces as they lay
/// at the loaded positions, as a write-back has them follow);
/// into OBJ, glTF or PLY from any source, the UVs and colours of the kept vertices. Normals are
/// recomputed, smooth, from the coarse shape. The report names what is not kept (split normals,
/// morph targets, the node tree's transforms, ...). A derivation that does not fit `mesh` or
/// `source` is written as [`save_with_source`] writes it (bare, with the report saying so).
pub fn save_derived_with_source(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    derivation: &Derivation<'_>,
    source: &Source,
) -> Result<SaveReport, IoError> {
    let path = path.as_ref();
    let format = format_of(path)?;
    if !derivation.fits(mesh, source)
        || (source.matches(mesh) && mesh.positions.len() == derivation.base.positions.len())
    {
        return save_with_source(path, mesh, source);
    }
    check_writable(mesh, path)?;
    let mut report = SaveReport::default();
    let scene = matches!(format, Format::Obj | Format::Glb | Format::Gltf)
        .then(|| source.scene(derivation.base))
        .flatten();
    let (kept, lost) = match scene {
        Some(scene) => write_derived_scene(path, format, mesh, derivation, source, scene)?,
        None => write_derived_attributes(path, format, mesh, derivation, source)?,
    };
    report.texture_coordinates_follow = kept.contains(&"UVs");
    if !lost.is_empty() {
        let how = if kept.is_empty() {
            format!("it is written as a bare {format} mesh")
        } else {
            format!(
                "it is written as {format} with the {} of the kept vertices",
                and_list(&kept)
            )
        };
        report.warnings.push(format!(
            "a coarser level has fewer vertices: {how}; not kept from {}: {}",
            source.origin.path.display(),
            lost.join("; ")
        ));
    }
    Ok(report)
}

/// The source's scene derived onto the kept vertices, written as OBJ or glTF; returns what it
/// carried and what it did not keep.
fn write_derived_scene(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    derivation: &Derivation<'_>,
    source: &Source,
    scene: Scene,
) -> Result<(Vec<&'static str>, Vec<String>), IoError> {
    let (mut derived, unplaced) = scene.derive(
        derivation.base,
        mesh,
        derivation.vertex_origin,
        derivation.face_origin,
    );
    // Each kept vertex's file vertex holds where it was loaded: the UVs follow its move to the
    // level's position over the level's own faces as they lay before.
    derived.follow_slide(mesh);
    let merged_colours = write_scene(path, format, &mut derived, mesh)?;
    let mut lost: Vec<String> = Vec::new();
    if unplaced > 0 {
        lost.push(format!(
            "the part and material of {unplaced} triangles (their source triangle was not found)"
        ));
    }
    if merged_colours > 0 {
        lost.push(merged_colour_borders(merged_colours));
    }
    if format == Format::Obj {
        lost.extend(carry::alpha_lost_in_obj(derived.translucent_vertices()));
    }
    if scene.normals {
        lost.push("the file's own normals and their split (hard edges): they are recomputed, smooth, from the coarse shape".into());
    }
    let mut contents = source.contents_beyond_scene(&scene, format);
    if format != Format::Obj {
        for item in &mut contents {
            if item.starts_with("the node tree") {
                *item = format!("{item}: its hierarchy and transforms (each part becomes one node, names kept, transforms baked into the positions)");
            }
        }
    }
    lost.extend(contents);
    lost.extend(scene.warnings);
    Ok((derived.carried(), lost))
}

/// The source's UVs and colours of the kept vertices, written where the format holds them;
/// returns what it carried and what it did not keep.
fn write_derived_attributes(
    path: &Path,
    format: Format,
    mesh: &TriMesh,
    derivation: &Derivation<'_>,
    source: &Source,
) -> Result<(Vec<&'static str>, Vec<String>), IoError> {
    let full = source.vertex_attributes();
    let pick = |values: &[[f32; 2]]| -> Vec<[f32; 2]> {
        derivation
            .vertex_origin
            .iter()
            .map(|&v| values[v as usize])
            .collect()
    };
    let mut extra = carry::VertexAttributes {
        uvs: full.uvs.as_deref().map(pick),
        colours: full.colours.as_ref().map(|values| {
            derivation
                .vertex_origin
                .iter()
                .map(|&v| values[v as usize])
                .collect()
        }),
        uv_splits_merged: full.uv_splits_merged,
        colour_splits_merged: full.colour_splits_merged,
    };
    if let (Some(uvs), Some(loaded)) =
        (extra.uvs.as_mut(), source.loaded_positions(derivation.base))
    {
        // Each kept vertex's UV follows its move from where it was loaded to the level's
        // position, over the level's own faces as they lay before.
        let before: Vec<[f32; 3]> = (derivation.vertex_origin.iter())
            .map(|&v| loaded[v as usize])
            .collect();
        carry::follow_slide(uvs, &before, mesh);
    }
    let (carried, mut merged) = extra.describe();
    write_with_attributes(path, format, mesh, &extra)?;
    let holds = matches!(
        format,
        Format::Obj | Format::Glb | Format::Gltf | Format::Ply
    );
    if !holds {
        return Ok((Vec::new(), source.contents()));
    }
    let mut lost = Vec::new();
    lost.append(&mut merged);
    if format == Format::Obj {
        let translucent = extra.colours.as_deref().map_or(0, carry::translucent);
        lost.extend(carry::alpha_lost_in_obj(translucent));
    }
    lost.extend(source.contents_beyond(&extra));
    Ok((carried, lost))
}

/// How a warning says what a written file holds besides the bare mesh.
fn written_as(format: Format, kept: &[&str]) -> String {
    if kept.is_empty() {
        format!("it is written as a bare {format} mesh")
    } else {
        format!("it is written as {format} with its {}", and_list(kept))
    }
}
