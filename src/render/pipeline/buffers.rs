//! The GPU copies of one mesh ([`MeshBuffers`]: positions, vertex normals, heat-map scalars,
//! painted-mask weights, texture coordinates and colours, triangles and, once the wireframe is
//! wanted, its edges) and how they are filled.

use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::MeshSource;
use crate::render::appearance::Appearance;
use crate::render::normals::vertex_normals;

/// GPU copies of one mesh, over its draw vertices (the file's own vertices when it has an
/// [`Appearance`], otherwise the mesh's).
pub(super) struct MeshBuffers {
    pub(super) positions: wgpu::Buffer,
    /// Area-weighted unit vertex normals of the positions now in `positions` (computed on the
    /// mesh's vertices, so they are smooth across the file's seams).
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
    /// The file's materials, texture coordinates and colours, when it has any to show.
    pub(super) appearance: Option<Arc<Appearance>>,
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

/// The triangles the renderer draws for `source`: its appearance's (over the draw vertices) or
/// its own.
pub(super) fn draw_triangles(source: &dyn MeshSource) -> std::borrow::Cow<'_, [[u32; 3]]> {
    match source.appearance() {
        Some(appearance) => match &appearance.triangles {
            Some(triangles) => std::borrow::Cow::Owned(triangles.clone()),
            None => std::borrow::Cow::Borrowed(source.triangles()),
        },
        None => std::borrow::Cow::Borrowed(source.triangles()),
    }
}

impl MeshBuffers {
    /// Writes new positions of the same connectivity and their normals (per mesh vertex).
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
                queue.write_buffer(
                    &self.normals,
                    0,
                    bytemuck::cast_slice(&look.gather(normals)),
                );
            }
            _ => {
                queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(source.positions()));
                queue.write_buffer(&self.normals, 0, bytemuck::cast_slice(normals));
            }
        }
        self.source = source;
    }

    /// Writes per-mesh-vertex `values` (scalars or mask weights) into `buffer`, taken onto the
    /// draw vertices.
    pub(super) fn write_per_vertex(
        &self,
        queue: &wgpu::Queue,
        buffer: &wgpu::Buffer,
        values: &[f32],
    ) {
        match &self.appearance {
            Some(look) if look.vertex_of.is_some() => {
                queue.write_buffer(buffer, 0, bytemuck::cast_slice(&look.gather(values)));
            }
            _ => queue.write_buffer(buffer, 0, bytemuck::cast_slice(values)),
        }
    }

    /// Buffers for `source` (and its wireframe edges when `with_lines`), answering the
    /// `MeshRenderer::set_mesh` call `generation`.
    pub(super) fn create(
        device: &wgpu::Device,
        source: Arc<dyn MeshSource>,
        with_lines: bool,
        generation: u64,
    ) -> Self {
        let positions = source.positions();
        let mesh_triangles = source.triangles();
        let appearance = source.appearance();
        let normals = vertex_normals(positions, mesh_triangles);
        let (draw_positions, draw_normals) = match &appearance {
            Some(look) if look.vertex_of.is_some() => {
                (Some(look.gather(positions)), Some(look.gather(&normals)))
            }
            _ => (None, None),
        };
        let draw_count = draw_positions.as_ref().map_or(positions.len(), Vec::len);
        let triangles = draw_triangles(source.as_ref());
        let positions_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh positions"),
            contents: bytemuck::cast_slice(draw_positions.as_deref().unwrap_or(positions)),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let normals_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh normals"),
            contents: bytemuck::cast_slice(draw_normals.as_deref().unwrap_or(&normals)),
            // COPY_SRC: tests read back what was uploaded.
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
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
            false => device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::VERTEX,
            }),
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
        let triangles_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh triangles"),
            contents: bytemuck::cast_slice(&triangles),
            usage: wgpu::BufferUsages::INDEX,
        });
        let lines = with_lines.then(|| line_buffer(device, &triangles));
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

/// The wireframe's index buffer: each triangle's three edges as line segments (an edge shared by
/// two triangles is drawn twice, which looks the same and needs no edge map).
pub(super) fn line_buffer(device: &wgpu::Device, triangles: &[[u32; 3]]) -> (wgpu::Buffer, u32) {
    const BLOCK: usize = 4096;
    let count = triangles.len() * 6;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fairmesh wireframe edges"),
        size: (count * 4) as u64,
        usage: wgpu::BufferUsages::INDEX,
        mapped_at_creation: true,
    });
    // The mapping is write-only (it may be write-combining memory): edges are built a block of
    // triangles at a time in a small scratch array and copied in, with no full-size temporary.
    let mut scratch = vec![0u32; BLOCK * 6];
    match buffer.slice(..).get_mapped_range_mut() {
        Ok(mut view) => {
            for (block_index, block) in triangles.chunks(BLOCK).enumerate() {
                let edges = &mut scratch[..block.len() * 6];
                for (edge, &[a, b, c]) in edges.chunks_exact_mut(6).zip(block) {
                    edge.copy_from_slice(&[a, b, b, c, c, a]);
                }
                let start = block_index * BLOCK * 6 * 4;
                view.slice(start..start + edges.len() * 4)
                    .copy_from_slice(bytemuck::cast_slice(edges));
            }
        }
        // Cannot happen for a buffer mapped at creation; the wireframe is then just not drawn.
        Err(_) => {
            buffer.unmap();
            return (buffer, 0);
        }
    }
    buffer.unmap();
    (buffer, count as u32)
}

/// Parts of a mesh's buffers made when first drawn.
impl super::MeshRenderer {
    /// Uploads the textures and uniforms of the mesh's materials, and the "no material" group,
    /// when they are not on the GPU yet.
    pub(super) fn ensure_materials(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) {
        if self.materials.plain.is_none() {
            self.materials.plain = Some(self.materials.group(device, queue, None));
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
                            bind_group: self.materials.group(device, queue, Some(look)),
                        })
                        .collect(),
                );
            }
        }
    }
}
