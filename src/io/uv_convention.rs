//! The library's one texture-coordinate convention, and each format's own.
//!
//! Inside the library, texture coordinates are glTF's: u runs across the image from its left
//! column (0) to its right (1), and v *down* from its top row (0) to its bottom row (1). That is
//! the order in which an image's rows are stored and decoded, and the order in which wgpu samples
//! a texture uploaded as decoded, so the viewport needs no flip, and a glTF's
//! `KHR_texture_transform` (defined over TEXCOORD_n) applies as it is. Everything that holds UVs
//! per vertex in the library holds them this way: a [`crate::io::scene::Scene`]'s vertices (what
//! the viewport draws and what is carried into another format, the level chain included) and the
//! per-vertex UVs carried into another format.
//!
//! Each format's own, on disk:
//! - glTF `TEXCOORD_n`: v from the top row (glTF 2.0, "Images": the first pixel is the image's
//!   upper left corner). The library's.
//! - OBJ `vt`: v from the *bottom* row (Wavefront's convention, as every OBJ writer and viewer
//!   reads it).
//! - PLY `s t`, `u v`, `texture_u texture_v`: v from the bottom row, as in OBJ. The tools that
//!   write them store an OBJ's `vt` unchanged and write it out unchanged: trimesh (its PLY export
//!   writes its texture coordinates as `s t`, the same numbers its OBJ export writes as `vt`;
//!   `tests/texture_orientation.rs` reads such a file), MeshLab (`texture_u texture_v` from the
//!   same per-vertex coordinates its OBJ `vt` come from) and Blender (`s t` from the UV layer
//!   its OBJ exporter writes as `vt`).
//!
//! Readers turn a file's (u, v) into the library's with [`into_library`], writers turn them back
//! with [`into_file`]: for OBJ and PLY both are (u, 1 − v), worked in f64 so that the only
//! rounding is the one to f32 at the end. A file written back into its own format converts
//! nothing: its coordinates stay its own, and moving them to follow a slide along the surface
//! (barycentric interpolation, [`super::uv_follow`]) gives the same texture point in either
//! convention.

use super::Format;

/// Where a format counts its texture coordinates' v from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureVOrigin {
    /// v = 0 is the image's top row (glTF; the library's own convention).
    Top,
    /// v = 0 is the image's bottom row (OBJ `vt`, PLY texture coordinates).
    Bottom,
}

impl Format {
    /// Where the format's texture coordinates count v from (see the module docs of
    /// `io::uv_convention`); STL and OFF hold none and are given the library's own.
    pub fn texture_v_origin(self) -> TextureVOrigin {
        match self {
            Format::Obj | Format::Ply => TextureVOrigin::Bottom,
            _ => TextureVOrigin::Top,
        }
    }
}

/// A texture coordinate as `format`'s file holds it, in the library's convention.
pub(crate) fn into_library(format: Format, uv: [f32; 2]) -> [f32; 2] {
    match format.texture_v_origin() {
        TextureVOrigin::Top => uv,
        TextureVOrigin::Bottom => flip_v(uv),
    }
}

/// A texture coordinate in the library's convention, as `format`'s file holds it.
pub(crate) fn into_file(format: Format, uv: [f32; 2]) -> [f32; 2] {
    match format.texture_v_origin() {
        TextureVOrigin::Top => uv,
        TextureVOrigin::Bottom => flip_v(uv),
    }
}

/// (u, 1 − v), in f64 so that only the last step rounds.
fn flip_v([u, v]: [f32; 2]) -> [f32; 2] {
    [u, (1.0 - f64::from(v)) as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_and_ply_count_v_from_the_bottom_and_gltf_from_the_top() {
        for format in [Format::Obj, Format::Ply] {
            assert_eq!(into_library(format, [0.25, 0.0]), [0.25, 1.0]);
            assert_eq!(into_library(format, [0.25, 0.75]), [0.25, 0.25]);
            assert_eq!(into_file(format, [0.25, 1.0]), [0.25, 0.0]);
        }
        for format in [Format::Glb, Format::Gltf] {
            assert_eq!(into_library(format, [0.25, 0.75]), [0.25, 0.75]);
            assert_eq!(into_file(format, [0.25, 0.75]), [0.25, 0.75]);
        }
    }

    #[test]
    fn values_a_half_or_more_come_back_bit_for_bit() {
        // 1 − v is exact in f32 for v in [0.5, 1] (Sterbenz): those make the round trip exactly;
        // below a half the trip costs at most one rounding of 1 − v.
        for v in [0.5f32, 0.7, 0.958, 1.0, 0.042, 0.1, 1e-3] {
            let back = into_file(Format::Obj, into_library(Format::Obj, [0.0, v]))[1];
            if v >= 0.5 {
                assert_eq!(back.to_bits(), v.to_bits(), "{v}");
            }
            assert!((back - v).abs() <= f32::EPSILON, "{v}: {back}");
        }
    }
}
