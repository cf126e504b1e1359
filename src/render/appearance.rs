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
    /// Per draw vertex; `None` when the file has none.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Per draw vertex, linear RGBA; `None` when the file has none.
    pub colours: Option<Vec<[f32; 4]>>,
    /// Triangles over the draw vertices, in batches of one material; `None`: the mesh's own.
    pub triangles: Option<Vec<[u32; 3]>>,
    /// Runs of the triangles (the draw triangles, or the mesh's) by material, in order, covering
    /// them all.
    pub batches: Vec<Batch>,
    pub materials: Vec<MaterialLook>,
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
}
