//! The viewport's colours from the loaded file ([`appearance_of`]): its materials' base colour
//! factors and base colour textures (decoded PNG, with the glTF sampler's filters and wrapping),
//! its texture coordinates and its vertex colours (glTF COLOR_0, PLY colours; OBJ has none), as
//! the renderer's [`Appearance`]. The io layer keeps the file ([`crate::io::Source`]); this is
//! where the app turns it into what the viewport draws.

use std::collections::BTreeMap;

use crate::io::scene::{Scene, TextureSampler, TextureWrap};
use crate::io::{Format, Source};
use crate::render::appearance::{Appearance, Batch, MaterialLook, Sampling, TextureImage, Wrap};
use crate::TriMesh;

/// What the viewport shows of `source`'s colours over `mesh` (the mesh loaded from it, or one
/// with its triangles); `None` when the file has none to show or `mesh` has other triangles.
pub(super) fn appearance_of(source: &Source, mesh: &TriMesh) -> Option<Appearance> {
    if !source.matches(mesh) {
        return None;
    }
    let appearance = match source.scene(mesh) {
        Some(scene) => from_scene(&scene, mesh.positions.len()),
        None => from_vertex_colours(source),
    }?;
    (!appearance.is_plain()).then_some(appearance)
}

/// A glTF scene's or an OBJ's parts: draw vertices are the file's vertices, triangles grouped
/// by material.
fn from_scene(scene: &Scene, mesh_vertices: usize) -> Option<Appearance> {
    let on_mesh = |v: u32| {
        scene
            .vertices
            .get(v as usize)
            .is_some_and(|sv| (sv.welded as usize) < mesh_vertices)
    };
    let mut by_material: BTreeMap<Option<usize>, Vec<[u32; 3]>> = BTreeMap::new();
    for primitive in scene.parts.iter().flat_map(|p| &p.primitives) {
        let material = primitive.material.filter(|&m| m < scene.materials.len());
        let kept = (primitive.triangles.iter()).filter(|t| t.iter().all(|&v| on_mesh(v)));
        by_material.entry(material).or_default().extend(kept);
    }
    let mut triangles = Vec::new();
    let mut batches = Vec::new();
    for (material, list) in by_material {
        let first = triangles.len() as u32;
        triangles.extend(list);
        batches.push(Batch {
            material,
            first,
            end: triangles.len() as u32,
        });
    }
    if triangles.is_empty() {
        return None;
    }
    let vertex_of = scene
        .vertices
        .iter()
        .map(|v| v.welded.min(mesh_vertices.saturating_sub(1) as u32))
        .collect();
    Some(Appearance {
        vertex_of: Some(vertex_of),
        uvs: scene
            .uvs
            .then(|| scene.vertices.iter().map(|v| v.uv).collect()),
        colours: scene
            .colours
            .then(|| scene.vertices.iter().map(|v| v.colour).collect()),
        triangles: Some(triangles),
        batches,
        materials: scene
            .materials
            .iter()
            .map(|m| MaterialLook {
                base_colour: m.base_colour,
                texture: m
                    .texture
                    .as_ref()
                    .and_then(|image| decode_png(&image.data.bytes().ok()?))
                    .map(|(width, height, rgba)| TextureImage {
                        width,
                        height,
                        rgba,
                        sampling: sampling(m.sampler),
                    }),
            })
            .collect(),
    })
}

/// A PLY's colours, one per welded vertex (the mesh's own vertices and triangles).
fn from_vertex_colours(source: &Source) -> Option<Appearance> {
    let attributes = source.vertex_attributes();
    let mut colours = attributes.colours?;
    if source.format() == Format::Ply {
        // A PLY's 8-bit colours are sRGB-encoded, as scanners and image tools write them.
        for colour in &mut colours {
            for c in &mut colour[..3] {
                *c = srgb_to_linear(*c);
            }
        }
    }
    Some(Appearance {
        colours: Some(colours),
        ..Appearance::default()
    })
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn sampling(sampler: TextureSampler) -> Sampling {
    let wrap = |w| match w {
        TextureWrap::Repeat => Wrap::Repeat,
        TextureWrap::MirroredRepeat => Wrap::MirroredRepeat,
        TextureWrap::ClampToEdge => Wrap::ClampToEdge,
    };
    Sampling {
        mag_linear: sampler.mag_linear,
        min_linear: sampler.min_linear,
        wrap: [wrap(sampler.wrap[0]), wrap(sampler.wrap[1])],
    }
}

/// A PNG's pixels as 8-bit RGBA (width, height, rows top first); `None` for anything else
/// (a JPEG texture shows its material's base colour alone).
fn decode_png(bytes: &[u8]) -> Option<(u32, u32, Vec<u8>)> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().ok()?;
    let mut buffer = vec![0; reader.output_buffer_size()?];
    let frame = reader.next_frame(&mut buffer).ok()?;
    let pixels = &buffer[..frame.buffer_size()];
    let rgba: Vec<u8> = match frame.color_type {
        png::ColorType::Rgba => pixels.to_vec(),
        png::ColorType::Rgb => pixels
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        png::ColorType::GrayscaleAlpha => pixels
            .chunks_exact(2)
            .flat_map(|p| [p[0], p[0], p[0], p[1]])
            .collect(),
        png::ColorType::Grayscale => pixels.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::Indexed => return None,
    };
    (rgba.len() == (frame.width * frame.height * 4) as usize).then_some((
        frame.width,
        frame.height,
        rgba,
    ))
}
