//! The viewport's colours from the loaded file ([`appearance_of`]): its materials' base colour
//! factors and base colour textures (decoded PNG or JPEG, with the glTF sampler's filters,
//! mipmaps and wrapping, and its `KHR_texture_transform`), its texture coordinates and its vertex colours (glTF COLOR_0, PLY colours; OBJ has
//! none), as the renderer's [`Appearance`]. A texture that cannot be decoded (a broken or cut-off
//! file, a format other than PNG and JPEG) leaves its material's base colour alone, and a warning
//! that names the file and the image. The io layer keeps the file ([`fairmesh::io::Source`]); this
//! is where the app turns it into what the viewport draws.

use std::collections::BTreeMap;

use crate::render::appearance::{
    Appearance, Batch, MaterialLook, Mipmaps, Sampling, TextureImage, Wrap, UV_IDENTITY,
};
use fairmesh::io::scene::{
    Material, MipmapFilter, Scene, TextureSampler, TextureTransform, TextureWrap,
};
use fairmesh::io::{Format, Source};
use fairmesh::TriMesh;

/// What the viewport shows of `source`'s colours over `mesh` (the mesh loaded from it, or one
/// with its triangles); `None` when the file has none to show or `mesh` has other triangles.
/// Beside it, a warning for each texture that could not be decoded (`file`: the file's name,
/// as the warnings name it).
pub(super) fn appearance_of(
    source: &Source,
    mesh: &TriMesh,
    file: &str,
) -> (Option<Appearance>, Vec<String>) {
    let mut warnings = Vec::new();
    if !source.matches(mesh) {
        return (None, warnings);
    }
    // An OBJ with nothing beyond positions and faces (no materials, texture coordinates or
    // vertex colours: `contents` names each of them) has no look of its own, which a scan of
    // its lines tells without reading its scene (on the bundled bunny in the page, 150 ms of the
    // frame that draws its first picture).
    if source.format() == Format::Obj && source.contents().is_empty() {
        return (None, warnings);
    }
    let appearance = match source.scene(mesh) {
        Some(scene) => from_scene(&scene, mesh.positions.len(), file, &mut warnings),
        None => from_vertex_colours(source),
    };
    (appearance.filter(|a| !a.is_plain()), warnings)
}

/// A glTF scene's or an OBJ's parts: draw vertices are the file's vertices, triangles grouped
/// by material.
fn from_scene(
    scene: &Scene,
    mesh_vertices: usize,
    file: &str,
    warnings: &mut Vec<String>,
) -> Option<Appearance> {
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
                texture: texture_of(m, file, warnings),
                uv_transform: m.texture_transform.as_ref().map_or(UV_IDENTITY, uv_rows),
            })
            .collect(),
    })
}

/// A texture transform as the two rows of a 3×3 matrix over (u, v, 1): translation × rotation ×
/// scale, as the extension defines it, the rotation taking (u, v) to
/// (u cos r + v sin r, −u sin r + v cos r). That is the direction of the extension's example
/// (offset (0, 1), a quarter turn and scale ½ read the lower left quadrant) and of three.js; the
/// extension's GLSL snippet, read as GLSL's column-major `mat3`, turns the other way.
fn uv_rows(transform: &TextureTransform) -> [[f32; 3]; 2] {
    let (sin, cos) = transform.rotation.sin_cos();
    let [sx, sy] = transform.scale;
    let [ox, oy] = transform.offset;
    [[cos * sx, sin * sy, ox], [-sin * sx, cos * sy, oy]]
}

/// `material`'s base colour texture, decoded; `None` (and a warning naming `file` and the
/// image) when it cannot be read or decoded, or reads texture coordinates other than the first
/// set (the only one the viewport has).
fn texture_of(material: &Material, file: &str, warnings: &mut Vec<String>) -> Option<TextureImage> {
    let image = material.texture.as_ref()?;
    let decoded = match image.data.bytes() {
        Ok(_) if material.tex_coord != 0 => Err(format!(
            "it reads texture coordinates TEXCOORD_{}; the viewport has TEXCOORD_0 alone",
            material.tex_coord
        )),
        Ok(bytes) => decode_texture(&bytes),
        Err(error) => Err(format!("it could not be read: {error}")),
    };
    match decoded {
        Ok((width, height, rgba)) => Some(TextureImage {
            width,
            height,
            rgba,
            sampling: sampling(material.sampler),
        }),
        Err(why) => {
            warnings.push(format!(
                "{file}: the base colour texture '{}' of material '{}' is not shown ({why}); \
                 the material shows its base colour alone",
                image.name, material.name
            ));
            None
        }
    }
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
        mipmaps: match sampler.mipmaps {
            MipmapFilter::Off => Mipmaps::Off,
            MipmapFilter::Nearest => Mipmaps::Nearest,
            MipmapFilter::Linear => Mipmaps::Linear,
        },
    }
}

/// A PNG's or JPEG's pixels as 8-bit RGBA (width, height, rows top first), or why there are
/// none, in words that follow "is not shown (".
fn decode_texture(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        decode_png(bytes).ok_or_else(|| "a PNG that could not be decoded".to_owned())
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        decode_jpeg(bytes).map_err(|why| format!("a JPEG that could not be decoded: {why}"))
    } else {
        Err("the viewport draws PNG and JPEG textures, and this is neither".to_owned())
    }
}

/// A JPEG's pixels as 8-bit RGBA, or the decoder's reason. The decoder runs in strict mode, so
/// that a cut-off file is an error rather than an image with its missing part grey; a panic
/// inside it is an error too.
fn decode_jpeg(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    use zune_core::{bytestream::ZCursor, colorspace::ColorSpace, options::DecoderOptions};
    let options = DecoderOptions::default()
        .jpeg_set_out_colorspace(ColorSpace::RGBA)
        .set_strict_mode(true);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decoder.decode()));
    let pixels = decoded
        .map_err(|_| "the decoder failed".to_owned())?
        .map_err(|error| error.to_string().trim().to_owned())?;
    let (width, height) = decoder
        .dimensions()
        .ok_or_else(|| "no image size".to_owned())?;
    let (width, height) = (width as u32, height as u32);
    match pixels.len() == width as usize * height as usize * 4 {
        true => Ok((width, height, pixels)),
        false => Err(format!(
            "{} bytes of pixels for {width}×{height}",
            pixels.len()
        )),
    }
}

/// A PNG's pixels as 8-bit RGBA (width, height, rows top first); `None` when it cannot be
/// decoded.
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

#[cfg(test)]
mod tests {
    use super::{decode_texture, uv_rows};
    use fairmesh::io::scene::TextureTransform;

    #[test]
    fn a_texture_transform_is_composed_as_the_extension_says() {
        let read = |json: &str| {
            let transform = TextureTransform::from_gltf(&serde_json::from_str(json).unwrap());
            uv_rows(&transform.unwrap())
        };
        assert_eq!(read("{}"), [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // The extension's example: the lower left quadrant of the image (v down), turned a
        // quarter clockwise.
        let [u, v] = read(r#"{"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}"#);
        let at = |(x, y): (f32, f32)| {
            let row = |r: [f32; 3]| r[0] * x + r[1] * y + r[2];
            [row(u), row(v)]
        };
        for (corner, read_at) in [
            ((0.0, 0.0), [0.0, 1.0]),
            ((1.0, 0.0), [0.0, 0.5]),
            ((0.0, 1.0), [0.5, 1.0]),
            ((1.0, 1.0), [0.5, 0.5]),
        ] {
            let got = at(corner);
            assert!(
                (got[0] - read_at[0]).abs() < 1e-6 && (got[1] - read_at[1]).abs() < 1e-6,
                "{corner:?}: {got:?}"
            );
        }
        // Scale, then offset, with no rotation.
        let moved = read(r#"{"offset": [0.25, 0.5], "scale": [2, 3]}"#);
        assert_eq!(moved, [[2.0, 0.0, 0.25], [0.0, 3.0, 0.5]]);
    }

    /// A 64×32 JPEG of a left-to-right red ramp over green with blue stripes, as an encoder
    /// writes it.
    fn jpeg() -> Vec<u8> {
        let image = image::RgbImage::from_fn(64, 32, |x, y| {
            image::Rgb([x as u8 * 4, 128, if (x + y) % 8 < 4 { 0 } else { 64 }])
        });
        let mut bytes = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 95)
            .encode_image(&image)
            .expect("encoded");
        bytes
    }

    #[test]
    fn a_jpeg_decodes_to_rgba() {
        let (width, height, rgba) = decode_texture(&jpeg()).expect("decoded");
        assert_eq!((width, height), (64, 32));
        assert_eq!(rgba.len(), 64 * 32 * 4);
        let pixel = |x: usize, y: usize| &rgba[(y * 64 + x) * 4..][..4];
        // Lossy, so near: the ramp's ends, green at half, opaque.
        assert!(
            pixel(0, 4)[0] < 40 && pixel(63, 4)[0] > 200,
            "{:?}",
            pixel(63, 4)
        );
        assert!((i32::from(pixel(8, 2)[1]) - 128).abs() < 24);
        assert!(rgba.chunks(4).all(|p| p[3] == 255));
    }

    #[test]
    fn a_cut_off_or_broken_jpeg_is_an_error_not_a_panic() {
        let whole = jpeg();
        // In the header, in the scan data (its last third). Only the end-of-image marker
        // missing is no loss: it decodes.
        for keep in [3, 20, whole.len() / 2, whole.len() * 5 / 6] {
            let why = decode_texture(&whole[..keep]).expect_err("cut off");
            assert!(
                why.starts_with("a JPEG that could not be decoded"),
                "{keep}: {why}"
            );
        }
        assert!(decode_texture(&whole[..whole.len() - 2]).is_ok());
        let mut scrambled = whole.clone();
        for byte in scrambled.iter_mut().skip(2).step_by(7) {
            *byte ^= 0x5A;
        }
        assert!(decode_texture(&scrambled).is_err());
        let why = decode_texture(b"RIFF....WEBPVP8 ").expect_err("not PNG nor JPEG");
        assert!(why.contains("PNG and JPEG"), "{why}");
    }
}
