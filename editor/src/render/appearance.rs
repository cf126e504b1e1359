//! What a surface looks like beyond its shape: the file's materials (base colour factor and base
//! colour texture with its sampler), texture coordinates and vertex colours, as the renderer
//! draws them ([`Appearance`]). The app makes one from the file it loaded; the renderer knows
//! nothing of files.
//!
//! A file splits a vertex where its texture coordinates, colours or materials differ (a UV
//! seam); the shape is one welded vertex there. The renderer draws the file's own vertices (the
//! "draw vertices"), each standing on a mesh vertex ([`Appearance::vertex_of`]) whose position,
//! normal, heat-map value and mask weight it takes: so a moved (faired) mesh carries its
//! texture with it, as the file's texture coordinates say, and smooth shading stays smooth
//! across a seam.
//!
//! Where smooth shading splits at a sharp edge ([`crate::render::normals`]), the draw vertices
//! split further, one per file vertex and smoothing group ([`Appearance::split_for_shading`]):
//! the same kind of draw vertices, standing on mesh vertices, so positions, heat-map values and
//! mask weights reach them the same way. A mesh with no appearance gets a plain one for that.

use std::sync::Arc;

use super::normals::SharpSplit;

/// How a texture's texels are filtered and wrapped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    pub mag_linear: bool,
    pub min_linear: bool,
    /// Along u and v.
    pub wrap: [Wrap; 2],
    /// Whether a minified texture reads its mipmaps (made on upload, see
    /// [`crate::render::mipmaps`]), and how it goes between two of them.
    pub mipmaps: Mipmaps,
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            mag_linear: true,
            min_linear: true,
            wrap: [Wrap::Repeat; 2],
            mipmaps: Mipmaps::Linear,
        }
    }
}

/// A texture's mipmaps as its sampler asks for them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mipmaps {
    /// The full-size texture alone.
    Off,
    /// The nearest level.
    Nearest,
    /// The two nearest levels, blended.
    Linear,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A decoded base colour texture: sRGB-encoded RGBA8 rows, top row first.
#[derive(Clone, Debug)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub sampling: Sampling,
}

/// One material as the viewport draws it.
#[derive(Clone, Debug)]
pub struct MaterialLook {
    /// Linear RGBA (glTF baseColorFactor, an MTL's Kd).
    pub base_colour: [f32; 4],
    pub texture: Option<TextureImage>,
    /// Where the texture is read for texture coordinates (u, v): at the two rows of this 3×3
    /// matrix times (u, v, 1) (glTF `KHR_texture_transform`; [`UV_IDENTITY`] without one).
    pub uv_transform: [[f32; 3]; 2],
}

/// Texture coordinates read as they are.
pub const UV_IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// A run of [`Appearance::triangles`] drawn with one material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// Index into [`Appearance::materials`], `None` for the file's "no material" (white).
    pub material: Option<usize>,
    pub first: u32,
    pub end: u32,
}

/// The surface's materials, texture coordinates and vertex colours over its draw vertices.
#[derive(Clone, Debug, Default)]
pub struct Appearance {
    /// The mesh vertex each draw vertex stands on; `None`: the draw vertices are the mesh's.
    pub vertex_of: Option<Vec<u32>>,
    /// Per draw vertex, in the library's convention (v from the image's top row, as the texture
    /// is uploaded and sampled; see `io::TextureVOrigin`); `None` when the file has none.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Per draw vertex, linear RGBA; `None` when the file has none.
    pub colours: Option<Vec<[f32; 4]>>,
    /// Triangles over the draw vertices, in batches of one material; `None`: the mesh's own.
    pub triangles: Option<Vec<[u32; 3]>>,
    /// Runs of the triangles (the draw triangles, or the mesh's) by material, in order, covering
    /// them all.
    pub batches: Vec<Batch>,
    /// Shared: a split for shading ([`Self::split_for_shading`]) draws the same materials.
    pub materials: Arc<[MaterialLook]>,
}

impl Appearance {
    /// Whether it shows anything beyond the shape (a colour, a texture, a material).
    pub fn is_plain(&self) -> bool {
        self.colours.is_none()
            && self
                .materials
                .iter()
                .all(|m| m.texture.is_none() && m.base_colour == [1.0; 4])
            && self.batches.iter().all(|b| b.material.is_none())
    }

    /// How many draw vertices there are for a mesh of `mesh_vertices` vertices.
    pub fn draw_vertex_count(&self, mesh_vertices: usize) -> usize {
        self.vertex_of.as_ref().map_or(mesh_vertices, Vec::len)
    }

    /// `values` per mesh vertex, taken onto the draw vertices (a draw vertex on no such vertex
    /// gets the default).
    pub fn gather<T: Copy + Default>(&self, values: &[T]) -> Vec<T> {
        match &self.vertex_of {
            Some(map) => map
                .iter()
                .map(|&v| values.get(v as usize).copied().unwrap_or_default())
                .collect(),
            None => values.to_vec(),
        }
    }

    /// The draw vertices of `look` (the mesh's own vertices when `None`) split where `split`
    /// splits the shading, over `split`'s triangles (those of `look`, or the mesh's, welded:
    /// each draw corner on its mesh vertex, in the same order). A draw vertex whose corners lie
    /// in one smoothing group stays as it is; each further group it meets adds a copy (same
    /// texture coordinates and colour). Beside the appearance, the shading vertex of each new
    /// draw vertex, when they are not the same ones (a `look` with draw vertices of its own).
    pub fn split_for_shading(
        look: Option<&Appearance>,
        split: &SharpSplit,
    ) -> (Appearance, Option<Vec<u32>>) {
        let (Some(look), Some(draw_triangles)) = (look, look.and_then(|l| l.triangles.as_ref()))
        else {
            // The draw vertices are the mesh's: they become the shading vertices.
            let uvs = look.and_then(|l| l.uvs.as_deref());
            let colours = look.and_then(|l| l.colours.as_deref());
            let appearance = Appearance {
                vertex_of: Some(split.vertex_of().to_vec()),
                uvs: uvs.map(|u| gather_by(u, split.vertex_of())),
                colours: colours.map(|c| gather_by(c, split.vertex_of())),
                triangles: Some(split.triangles().to_vec()),
                batches: look.map_or_else(Vec::new, |l| l.batches.clone()),
                materials: look.map_or_else(|| Arc::from([]), |l| l.materials.clone()),
            };
            return (appearance, None);
        };
        let draw_count = look.draw_vertex_count(split.vertex_of().len());
        // The shading vertex each draw vertex keeps (its first corner's); a later corner in
        // another group makes or finds the copy for that group.
        let mut shading_of = vec![u32::MAX; draw_count];
        let mut copies: std::collections::HashMap<(u32, u32), u32> = Default::default();
        let mut original_of: Vec<u32> = (0..draw_count as u32).collect();
        let mut triangles = Vec::with_capacity(draw_triangles.len());
        for (t, s) in draw_triangles.iter().zip(split.triangles()) {
            let mut corners = *t;
            for (d, &s) in corners.iter_mut().zip(s) {
                let Some(kept) = shading_of.get_mut(*d as usize) else {
                    continue; // a corner on no draw vertex: drawn as it was
                };
                if *kept == u32::MAX {
                    *kept = s;
                } else if *kept != s {
                    let next = original_of.len() as u32;
                    *d = *copies.entry((*d, s)).or_insert_with(|| {
                        original_of.push(*d);
                        next
                    });
                }
            }
            triangles.push(corners);
        }
        let mut normal_of: Vec<u32> = original_of
            .iter()
            .map(|&d| shading_of[d as usize])
            .collect();
        for (&(_, s), &copy) in &copies {
            normal_of[copy as usize] = s;
        }
        // A draw vertex no triangle uses stands for its mesh vertex's first group.
        let mesh_vertex = |d: u32| {
            let map = look.vertex_of.as_deref();
            map.map_or(d, |map| map.get(d as usize).copied().unwrap_or(0))
        };
        for (d, s) in normal_of.iter_mut().enumerate() {
            if *s == u32::MAX {
                *s = mesh_vertex(d as u32);
            }
        }
        let appearance = Appearance {
            vertex_of: Some(original_of.iter().map(|&d| mesh_vertex(d)).collect()),
            uvs: look.uvs.as_deref().map(|u| gather_by(u, &original_of)),
            colours: look.colours.as_deref().map(|c| gather_by(c, &original_of)),
            triangles: Some(triangles),
            batches: look.batches.clone(),
            materials: look.materials.clone(),
        };
        (appearance, Some(normal_of))
    }
}

/// `values[i]` for each index `i` of `by` (the default where there is none).
fn gather_by<T: Copy + Default>(values: &[T], by: &[u32]) -> Vec<T> {
    by.iter()
        .map(|&i| values.get(i as usize).copied().unwrap_or_default())
        .collect()
}
