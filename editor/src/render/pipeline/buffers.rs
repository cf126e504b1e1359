//! The GPU copies of one mesh ([`MeshBuffers`]: positions, vertex normals, heat-map scalars,
//! painted-mask weights, texture coordinates and colours, triangles and, once the wireframe is
//! wanted, its edges) and how they are filled; the draw vertices they are over and those
//! vertices' smooth-shading normals ([`DrawLayout`], [`draw_normals`]): the file's own vertices
//! (its appearance) or the mesh's, split where the shading splits at sharp edges.

use std::sync::Arc;

use super::MeshSource;
use crate::render::appearance::Appearance;
use crate::render::normals::{
    shading_normals, vertex_normals, CornerTable, SharpSplit, SHARP_EDGE_ANGLE,
};

/// GPU copies of one mesh, over its draw vertices (the file's own vertices when it has an
/// [`Appearance`], otherwise the mesh's).
pub(super) struct MeshBuffers {
    pub(super) positions: wgpu::Buffer,
    /// Smooth shading's unit normals of the positions now in `positions`, per draw vertex
    /// (area-weighted over the mesh's vertices, so smooth across the file's seams, and split at
    /// sharp edges: [`draw_normals`]).
    pub(super) normals: wgpu::Buffer,
    /// The heat map's per-vertex values.
    pub(super) scalars: wgpu::Buffer,
    /// The painted mask's per-vertex weights (0 to 1), tinted over the surface.
    pub(super) mask: wgpu::Buffer,
    /// Texture coordinates and linear RGBA colours per draw vertex (zeros when the file has
    /// none: the shader is told).
    pub(super) uvs: wgpu::Buffer,
    pub(super) colours: wgpu::Buffer,
    pub(super) triangles: wgpu::Buffer,
    /// The mesh's vertices (what scalars, weights and positions are given for).
    pub(super) vertex_count: usize,
    /// The draw vertices (the buffers' length).
    pub(super) draw_count: usize,
    pub(super) index_count: u32,
    /// Edge list for the wireframe, built when first needed (on the upload thread for a big
    /// mesh) from the draw triangles.
    pub(super) lines: Option<(wgpu::Buffer, u32)>,
    /// The mesh on screen: its triangles, and the positions last written.
    pub(super) source: Arc<dyn MeshSource>,
    /// The draw vertices' appearance: the file's materials, texture coordinates and colours,
    /// split at sharp edges where the shading splits (`layout.look`).
    pub(super) appearance: Option<Arc<Appearance>>,
    /// How the draw vertices came from the mesh's and get their normals.
    pub(super) layout: Arc<DrawLayout>,
    /// The corners around each vertex of the welded draw triangles, kept for every move.
    pub(super) corners: Arc<CornerTable>,
    /// The heat-map values and mask weights last written (per mesh vertex), written again if
    /// the draw vertices change ([`MeshBuffers::take_values`]).
    pub(super) scalar_values: Option<Vec<f32>>,
    pub(super) mask_values: Option<Vec<f32>>,
    /// The materials' textures and uniforms on the GPU, made on the render thread when first
    /// drawn (they need the queue).
    pub(super) materials: Option<Vec<MaterialGroup>>,
    /// Which `MeshRenderer::set_mesh` call this mesh answers.
    pub(super) generation: u64,
    /// What the caller said these buffers show (see [`super::MeshKey`]); `None`: not kept once
    /// another mesh is shown.
    pub(super) key: Option<super::MeshKey>,
}

/// One material's bind group (its uniform, texture and sampler).
pub(super) struct MaterialGroup {
    pub(super) bind_group: wgpu::BindGroup,
}

/// The triangles the renderer draws for `source` with the draw vertices of `look`: its
/// triangles (over the draw vertices) or the mesh's own.
pub(super) fn draw_triangles<'a>(
    source: &'a dyn MeshSource,
    look: Option<&'a Appearance>,
) -> &'a [[u32; 3]] {
    look.and_then(|l| l.triangles.as_deref())
        .unwrap_or(source.triangles())
}

/// Where a mesh's draw vertices come from: the file's (its appearance) or the mesh's own,
/// split where smooth shading splits at sharp edges.
pub(super) struct DrawLayout {
    /// What is drawn: the file's appearance, that appearance split further
    /// ([`Appearance::split_for_shading`]), or, for a mesh with none that splits, a plain one
    /// over its shading vertices; `None`: the mesh's own vertices and triangles.
    pub(super) look: Option<Arc<Appearance>>,
    /// The split, when the shading splits, and the shading vertex of each draw vertex when they
    /// are not the same ones.
    split: Option<(SharpSplit, Option<Vec<u32>>)>,
}

/// A mesh's draw layout and the normals of its draw vertices for its positions now.
pub(super) struct DrawNormals {
    pub(super) layout: Arc<DrawLayout>,
    pub(super) normals: Vec<[f32; 3]>,
}

/// The triangles of `look` (or the mesh's) welded: each corner on its mesh vertex.
pub(super) fn welded_triangles<'a>(
    source: &'a dyn MeshSource,
    look: Option<&Appearance>,
) -> std::borrow::Cow<'a, [[u32; 3]]> {
    match look {
        Some(look) if look.triangles.is_some() => {
            let triangles = look.triangles.as_deref().unwrap_or_default();
            std::borrow::Cow::Owned(match &look.vertex_of {
                Some(map) => triangles
                    .iter()
                    .map(|t| t.map(|d| map.get(d as usize).copied().unwrap_or(u32::MAX)))
                    .collect(),
                None => triangles.to_vec(),
            })
        }
        _ => std::borrow::Cow::Borrowed(source.triangles()),
    }
}

/// The smooth-shading normals of `source`'s draw vertices for its positions, with the layout
/// they are for: `current` (the buffers' layout) when the shading splits as it does, a new one
/// otherwise (the buffers must then be made again). `corners` is the table of the welded draw
/// triangles. With no sharp edge the normals are the mesh's area-weighted vertex normals taken
/// onto the file's vertices, exactly as without any split.
pub(super) fn draw_normals(
    source: &dyn MeshSource,
    corners: &CornerTable,
    current: Option<&Arc<DrawLayout>>,
) -> DrawNormals {
    let positions = source.positions();
    let original = source.appearance();
    let welded = welded_triangles(source, original.as_deref());
    let (split, shading) = shading_normals(positions, &welded, Some(corners), SHARP_EDGE_ANGLE);
    let Some(split) = split else {
        // The file's vertices take their mesh vertices' normals, as they always have.
        let normals = match &original {
            Some(look) if look.vertex_of.is_some() => {
                look.gather(&vertex_normals(positions, source.triangles()))
            }
            _ => shading,
        };
        let layout = match current.filter(|c| c.split.is_none()) {
            Some(current) => current.clone(),
            None => Arc::new(DrawLayout {
                look: original,
                split: None,
            }),
        };
        return DrawNormals { layout, normals };
    };
    let same = current.filter(|c| c.split.as_ref().is_some_and(|(s, _)| *s == split));
    let layout = match same {
        Some(current) => current.clone(),
        None => {
            let (look, normal_of) = Appearance::split_for_shading(original.as_deref(), &split);
            Arc::new(DrawLayout {
                look: Some(Arc::new(look)),
                split: Some((split, normal_of)),
            })
        }
    };
    let normals = match layout.split.as_ref().and_then(|(_, n)| n.as_ref()) {
        Some(normal_of) => normal_of
            .iter()
            .map(|&s| shading.get(s as usize).copied().unwrap_or_default())
            .collect(),
        None => shading,
    };
    DrawNormals { layout, normals }
}

impl MeshBuffers {
    /// Writes new positions of the same connectivity and their normals (per draw vertex, for
    /// these buffers' layout).
    pub(super) fn write_positions(
        &mut self,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        normals: &[[f32; 3]],
    ) {
        match &self.appearance {
            Some(look) if look.vertex_of.is_some() => {
                let positions = look.gather(source.positions());
                queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(&positions));
            }
            _ => queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(source.positions())),
        }
        queue.write_buffer(&self.normals, 0, bytemuck::cast_slice(normals));
        self.source = source;
    }

    /// Writes per-mesh-vertex `values` (heat-map scalars, or mask weights when `mask`) into
    /// their buffer, taken onto the draw vertices, and keeps them.
    pub(super) fn write_per_vertex(&mut self, queue: &wgpu::Queue, values: &[f32], mask: bool) {
        let buffer = if mask { &self.mask } else { &self.scalars };
        match &self.appearance {
            Some(look) if look.vertex_of.is_some() => {
                queue.write_buffer(buffer, 0, bytemuck::cast_slice(&look.gather(values)));
            }
            _ => queue.write_buffer(buffer, 0, bytemuck::cast_slice(values)),
        }
        let kept = if mask {
            &mut self.mask_values
        } else {
            &mut self.scalar_values
        };
        *kept = Some(values.to_vec());
    }

    /// Takes over the place of `old`, these buffers being the same mesh with other draw
    /// vertices (a move changed where the shading splits): its key, generation and the heat-map
    /// values and mask weights written into it.
    pub(super) fn take_place_of(&mut self, queue: &wgpu::Queue, old: &mut MeshBuffers) {
        self.key = old.key;
        self.generation = old.generation;
        if let Some(values) = old.scalar_values.take() {
            self.write_per_vertex(queue, &values, false);
        }
        if let Some(values) = old.mask_values.take() {
            self.write_per_vertex(queue, &values, true);
        }
    }

    /// Buffers for `source` (and its wireframe edges when `with_lines`), answering the
    /// `MeshRenderer::set_mesh` call `generation`.
    pub(super) fn create(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        with_lines: bool,
        generation: u64,
    ) -> Self {
        let welded = welded_triangles(source.as_ref(), source.appearance().as_deref());
        let corners = Arc::new(CornerTable::new(source.positions().len(), &welded));
        drop(welded);
        let drawn = draw_normals(source.as_ref(), &corners, None);
        Self::create_with(
            device, queue, source, corners, drawn, with_lines, generation,
        )
    }

    /// [`Self::create`] with the corner table and the draw normals already made (a move that
    /// changed the draw vertices).
    pub(super) fn create_with(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        corners: Arc<CornerTable>,
        drawn: DrawNormals,
        with_lines: bool,
        generation: u64,
    ) -> Self {
        let positions = source.positions();
        let DrawNormals { layout, normals } = drawn;
        let appearance = layout.look.clone();
        let draw_positions = match &appearance {
            Some(look) if look.vertex_of.is_some() => Some(look.gather(positions)),
            _ => None,
        };
        let draw_count = draw_positions.as_ref().map_or(positions.len(), Vec::len);
        let triangles = draw_triangles(source.as_ref(), appearance.as_deref());
        let positions_buffer = filled_buffer(
            device,
            queue,
            "fairmesh positions",
            bytemuck::cast_slice(draw_positions.as_deref().unwrap_or(positions)),
            wgpu::BufferUsages::VERTEX,
        );
        let normals_buffer = filled_buffer(
            device,
            queue,
            "fairmesh normals",
            bytemuck::cast_slice(&normals),
            // COPY_SRC: tests read back what was uploaded.
            wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_SRC,
        );
        // Scalars and mask weights come later through `set_scalars` and `set_mask`; wgpu
        // zero-fills a buffer that is not mapped at creation.
        let per_vertex = |label, bytes: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (draw_count * bytes) as u64,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let scalars_buffer = per_vertex("fairmesh scalars", 4);
        let mask_buffer = per_vertex("fairmesh mask", 4);
        let filled = |label, contents: &[u8], bytes: usize| match contents.is_empty() {
            true => per_vertex(label, bytes),
            false => filled_buffer(device, queue, label, contents, wgpu::BufferUsages::VERTEX),
        };
        let look = appearance.as_deref();
        let uvs = look
            .and_then(|l| l.uvs.as_deref())
            .filter(|u| u.len() == draw_count);
        let colours = look
            .and_then(|l| l.colours.as_deref())
            .filter(|c| c.len() == draw_count);
        let uvs_buffer = filled("fairmesh uvs", bytemuck::cast_slice(uvs.unwrap_or(&[])), 8);
        let colours_buffer = filled(
            "fairmesh colours",
            bytemuck::cast_slice(colours.unwrap_or(&[])),
            16,
        );
        let triangles_buffer = filled_buffer(
            device,
            queue,
            "fairmesh triangles",
            bytemuck::cast_slice(triangles),
            wgpu::BufferUsages::INDEX,
        );
        let lines = with_lines.then(|| line_buffer(device, queue, triangles));
        Self {
            positions: positions_buffer,
            normals: normals_buffer,
            scalars: scalars_buffer,
            mask: mask_buffer,
            uvs: uvs_buffer,
            colours: colours_buffer,
            triangles: triangles_buffer,
            vertex_count: positions.len(),
            draw_count,
            index_count: (triangles.len() * 3) as u32,
            lines,
            appearance,
            layout,
            corners,
            scalar_values: None,
            mask_values: None,
            materials: None,
            source,
            generation,
            key: None,
        }
    }

    /// Bytes of GPU memory these buffers take.
    pub(super) fn gpu_bytes(&self) -> u64 {
        let buffers = [
            &self.positions,
            &self.normals,
            &self.scalars,
            &self.mask,
            &self.uvs,
            &self.colours,
            &self.triangles,
        ];
        let lines = self.lines.as_ref().map_or(0, |(buffer, _)| buffer.size());
        buffers.iter().map(|b| b.size()).sum::<u64>() + lines
    }
}

/// A buffer holding `contents` (whose length is a multiple of 4 bytes, as for `f32` and `u32`
/// data), written through `queue` rather than mapped at creation: a browser's WebGPU may refuse
/// the memory of a mapping at creation (Chromium throws a RangeError, "too large for the
/// implementation", for a buffer of a few hundred kB), while a queue write is sent in chunks.
/// The buffer also gets `COPY_DST` (a queue write needs it).
pub(super) fn filled_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: contents.len() as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    if !contents.is_empty() {
        queue.write_buffer(&buffer, 0, contents);
    }
    buffer
}

/// The wireframe's index buffer: each triangle's three edges as line segments (an edge shared by
/// two triangles is drawn twice, which looks the same and needs no edge map).
pub(super) fn line_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    triangles: &[[u32; 3]],
) -> (wgpu::Buffer, u32) {
    const BLOCK: usize = 4096;
    let count = triangles.len() * 6;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fairmesh wireframe edges"),
        size: (count * 4) as u64,
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    // Written through the queue's staging memory (not mapped at creation: see
    // `filled_buffer`), which is write-only (it may be write-combining memory): edges are built a
    // block of triangles at a time in a small scratch array and copied in, with no full-size
    // temporary. No staging memory (or no edges): the wireframe is just not drawn.
    let Some(mut view) = wgpu::BufferSize::new(buffer.size())
        .and_then(|size| queue.write_buffer_with(&buffer, 0, size))
    else {
        return (buffer, 0);
    };
    let mut scratch = vec![0u32; BLOCK * 6];
    for (block_index, block) in triangles.chunks(BLOCK).enumerate() {
        let edges = &mut scratch[..block.len() * 6];
        for (edge, &[a, b, c]) in edges.chunks_exact_mut(6).zip(block) {
            edge.copy_from_slice(&[a, b, b, c, c, a]);
        }
        let start = block_index * BLOCK * 6 * 4;
        view.slice(start..start + edges.len() * 4)
            .copy_from_slice(bytemuck::cast_slice(edges));
    }
    // Dropping the view queues the write.
    drop(view);
    (buffer, count as u32)
}

/// Parts of a mesh's buffers made when first drawn.
impl super::MeshRenderer {
    /// Uploads the textures and uniforms of the mesh's materials, and the "no material" group,
    /// when they are not on the GPU yet.
    pub(super) fn ensure_materials(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) {
        if self.gpu.materials.plain.is_none() {
            self.gpu.materials.plain = Some(self.gpu.materials.group(device, queue, None));
        }
        if let Some(mesh) = &mut self.mesh {
            if mesh.materials.is_none() {
                let looks = mesh
                    .appearance
                    .as_ref()
                    .map_or(&[][..], |a| &a.materials[..]);
                mesh.materials = Some(
                    looks
                        .iter()
                        .map(|look| MaterialGroup {
                            bind_group: self.gpu.materials.group(device, queue, Some(look)),
                        })
                        .collect(),
                );
            }
        }
    }
}
