//! The GPU copies of one mesh ([`MeshBuffers`]: positions, vertex normals, heat-map scalars,
//! painted-mask weights, triangles and, once the wireframe is wanted, its edges) and how they
//! are filled.

use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::MeshSource;
use crate::render::normals::vertex_normals;

/// GPU copies of one mesh.
pub(super) struct MeshBuffers {
    pub(super) positions: wgpu::Buffer,
    /// Area-weighted unit vertex normals of the positions now in `positions`.
    pub(super) normals: wgpu::Buffer,
    /// The heat map's per-vertex values.
    pub(super) scalars: wgpu::Buffer,
    /// The painted mask's per-vertex weights (0 to 1), tinted over the surface.
    pub(super) mask: wgpu::Buffer,
    pub(super) triangles: wgpu::Buffer,
    pub(super) vertex_count: usize,
    pub(super) index_count: u32,
    /// Edge list for the wireframe, built when first needed (on the upload thread for a big
    /// mesh) from `source`'s triangles.
    pub(super) lines: Option<(wgpu::Buffer, u32)>,
    /// The mesh on screen: its triangles, and the positions last written.
    pub(super) source: Arc<dyn MeshSource>,
    /// Which `MeshRenderer::set_mesh` call this mesh answers.
    pub(super) generation: u64,
}

impl MeshBuffers {
    /// Writes new positions of the same connectivity and their normals.
    pub(super) fn write_positions(
        &mut self,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        normals: &[[f32; 3]],
    ) {
        queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(source.positions()));
        queue.write_buffer(&self.normals, 0, bytemuck::cast_slice(normals));
        self.source = source;
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
        let triangles = source.triangles();
        let positions_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh positions"),
            contents: bytemuck::cast_slice(positions),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let normals_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh normals"),
            contents: bytemuck::cast_slice(&vertex_normals(positions, triangles)),
            // COPY_SRC: tests read back what was uploaded.
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
        // Scalars and mask weights come later through `set_scalars` and `set_mask`; wgpu
        // zero-fills a buffer that is not mapped at creation.
        let per_vertex = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (positions.len() * 4) as u64,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let scalars_buffer = per_vertex("fairmesh scalars");
        let mask_buffer = per_vertex("fairmesh mask");
        let triangles_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh triangles"),
            contents: bytemuck::cast_slice(triangles),
            usage: wgpu::BufferUsages::INDEX,
        });
        let lines = with_lines.then(|| line_buffer(device, triangles));
        Self {
            positions: positions_buffer,
            normals: normals_buffer,
            scalars: scalars_buffer,
            mask: mask_buffer,
            triangles: triangles_buffer,
            vertex_count: positions.len(),
            index_count: (triangles.len() * 3) as u32,
            lines,
            source,
            generation,
        }
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
