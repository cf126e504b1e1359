//! The 3D viewport renderer: our own wgpu pipeline ([`pipeline::MeshRenderer`],
//! `shaders/mesh.wgsl`) behind an `egui_wgpu` paint callback.
//!
//! The mesh is drawn into the renderer's own colour + depth texture (multisampled, resolved) in
//! the callback's `prepare` step, and that texture is shown as an ordinary egui image. So the
//! mesh gets a depth buffer whatever egui's own render pass has (eframe without `depth_buffer`,
//! or egui_kittest's single-sample pass with none), and the same code runs in the window and in
//! headless tests. The renderer takes positions, triangles, (through `set_scalars`) per-vertex
//! heat-map scalars and (through `set_mask`) the painted mask's weights, and knows nothing of
//! fairing. It computes the vertex normals smooth shading needs itself ([`normals`]); [`shading`] names the shading and lighting choices.

pub mod appearance;
pub mod colormap;
pub mod mipmaps;
pub mod normals;
pub mod pipeline;
pub mod shading;

pub use pipeline::{
    CornerNormals, DrawParams, HeldMesh, ImageCounts, MeshKey, MeshRenderer, MeshSource,
    UploadCounts, MAX_HELD_MESHES, SOFTWARE_SINGLE_SAMPLE_FACES,
};
pub use shading::{Lighting, Shading};

use egui_wgpu::wgpu;
use std::sync::Arc;

/// What the web page tells the renderer about the browser's GPU.
#[cfg(target_arch = "wasm32")]
pub mod page {
    use std::sync::atomic::{AtomicBool, Ordering};

    static SOFTWARE_WEBGPU: AtomicBool = AtomicBool::new(false);

    /// The page found that the browser's WebGPU adapter is a software renderer (its
    /// architecture is SwiftShader, or it is the browser's fallback adapter), which wgpu's
    /// adapter info does not say. Call before the renderer is made.
    pub fn set_software_webgpu(software: bool) {
        SOFTWARE_WEBGPU.store(software, Ordering::Relaxed);
    }

    /// Whether `info`'s adapter draws on the CPU: a CPU device, SwiftShader under WebGL2 (its
    /// name), or a WebGPU adapter the page found to be one.
    pub(super) fn software_renderer(info: &super::wgpu::AdapterInfo) -> bool {
        info.device_type == super::wgpu::DeviceType::Cpu
            || info.name.to_lowercase().contains("swiftshader")
            || (info.backend == super::wgpu::Backend::BrowserWebGpu
                && SOFTWARE_WEBGPU.load(Ordering::Relaxed))
    }
}

/// Every viewport's renderer, in egui_wgpu's callback resources (one entry per type, so the
/// renderers of several viewports share one list; a viewport knows its slot).
#[derive(Default)]
pub struct MeshRenderers(Vec<MeshRenderer>);

/// The app's handle on one renderer (its mesh and offscreen image). Several viewports (before
/// and after) each have their own.
pub struct Viewport3d {
    state: egui_wgpu::RenderState,
    texture: Option<egui::TextureId>,
    slot: usize,
}

impl Viewport3d {
    /// Creates a renderer (pipelines, buffers, target, upload thread) on the render state's
    /// device; `ctx` repaints when a background upload lands.
    pub fn new(state: &egui_wgpu::RenderState, ctx: &egui::Context) -> Self {
        let ctx = ctx.clone();
        let mut renderer = MeshRenderer::new(
            &state.device,
            &state.queue,
            Arc::new(move || ctx.request_repaint()),
        );
        let info = state.adapter.get_info();
        renderer.set_software_adapter(info.device_type == wgpu::DeviceType::Cpu);
        // In the page, a software renderer draws every mesh with one sample (docs/web.md).
        #[cfg(target_arch = "wasm32")]
        if page::software_renderer(&info) {
            renderer.set_single_sampled();
        }
        let mut egui_renderer = state.renderer.write();
        let resources = &mut egui_renderer.callback_resources;
        if resources.get::<MeshRenderers>().is_none() {
            resources.insert(MeshRenderers::default());
        }
        let slot = match resources.get_mut::<MeshRenderers>() {
            Some(list) => {
                list.0.push(renderer);
                list.0.len() - 1
            }
            None => 0,
        };
        drop(egui_renderer);
        Self {
            state: state.clone(),
            texture: None,
            slot,
        }
    }

    fn with_renderer<R>(&self, f: impl FnOnce(&mut MeshRenderer) -> R) -> Option<R> {
        let mut egui_renderer = self.state.renderer.write();
        egui_renderer
            .callback_resources
            .get_mut::<MeshRenderers>()
            .and_then(|list| list.0.get_mut(self.slot))
            .map(f)
    }

    /// Shows a mesh with new connectivity (a big one uploads in the background: call only when
    /// the connectivity changed, [`Self::set_positions`] otherwise).
    pub fn set_mesh(&self, source: Arc<dyn MeshSource>) {
        let device = &self.state.device;
        self.with_renderer(|r| r.set_mesh(device, source));
    }

    /// Shows a mesh the renderer keeps on the GPU under `key` (its family's mesh replaced);
    /// see [`MeshRenderer::set_mesh_keyed`].
    pub fn set_mesh_keyed(&self, source: Arc<dyn MeshSource>, key: MeshKey) {
        let device = &self.state.device;
        self.with_renderer(|r| r.set_mesh_keyed(device, source, Some(key)));
    }

    /// Shows the held mesh `key` without uploading anything; `false` when it is not held.
    pub fn show_held(&self, key: MeshKey) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.show_held(queue, key))
            .unwrap_or(false)
    }

    /// Moves `key`'s family's held mesh to `source`'s positions and shows it; `false` when none
    /// with that vertex count is held.
    pub fn set_positions_keyed(&self, source: Arc<dyn MeshSource>, key: MeshKey) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.set_positions_keyed(queue, source, key))
            .unwrap_or(false)
    }

    /// Drops the held meshes (not the one on screen) whose key `keep` refuses.
    pub fn retain_held(&self, keep: impl Fn(MeshKey) -> bool) {
        self.with_renderer(|r| r.retain_held(keep));
    }

    /// What this renderer has written to the GPU so far.
    pub fn uploads(&self) -> UploadCounts {
        self.with_renderer(|r| r.uploads).unwrap_or_default()
    }

    /// Meshes held on the GPU (the one on screen included) and the bytes they take.
    pub fn held_meshes(&self) -> (usize, u64) {
        self.with_renderer(|r| (r.meshes_held(), r.mesh_bytes()))
            .unwrap_or_default()
    }

    /// The meshes held on the GPU, the one on screen first, with their bytes and their kept
    /// images' bytes.
    pub fn held_list(&self) -> Vec<HeldMesh> {
        self.with_renderer(|r| r.held_list()).unwrap_or_default()
    }

    /// Bytes of the held meshes' kept images (their last complete images).
    pub fn image_bytes(&self) -> u64 {
        self.with_renderer(|r| r.image_bytes()).unwrap_or(0)
    }

    /// Why the mesh (or its wireframe, when on) is not drawn: too big for this GPU's buffers.
    pub fn problem(&self, wireframe: bool) -> Option<String> {
        self.with_renderer(|r| r.problem(wireframe)).flatten()
    }

    /// Uses at most `bytes` per GPU buffer (see [`MeshRenderer::cap_buffer_size`]).
    pub fn cap_buffer_size(&self, bytes: u64) {
        let device = &self.state.device;
        self.with_renderer(|r| r.cap_buffer_size(device, bytes));
    }

    /// Whether a background upload has not landed yet.
    pub fn upload_pending(&self) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.upload_pending(queue))
            .unwrap_or(false)
    }

    /// Whether a new image is being drawn over several frames (a big mesh on a software
    /// renderer: see [`MeshRenderer::set_faces_per_frame`]); the view shows the previous one.
    pub fn drawing(&self) -> bool {
        self.with_renderer(|r| r.drawing()).unwrap_or(false)
    }

    /// Meshes of at least `bytes` upload in the background (tests set 0 to exercise that path).
    pub fn set_async_upload_bytes(&self, bytes: usize) {
        self.with_renderer(|r| r.set_async_upload_bytes(bytes));
    }

    /// Moves the current mesh's vertices to `source`'s (same triangles); `false` when the
    /// vertex count differs.
    pub fn set_positions(&self, source: Arc<dyn MeshSource>) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.set_positions(queue, source))
            .unwrap_or(false)
    }

    /// The vertex normals uploaded for the mesh on screen (tests; waits for the GPU).
    pub fn read_back_normals(&self) -> Option<Vec<[f32; 3]>> {
        let (device, queue) = (&self.state.device, &self.state.queue);
        self.with_renderer(|r| r.read_back_normals(device, queue))
            .flatten()
    }

    /// Each drawn triangle's mesh vertices and its corners' normals (tests; waits for the GPU).
    pub fn read_back_corner_normals(&self) -> Option<Vec<CornerNormals>> {
        let (device, queue) = (&self.state.device, &self.state.queue);
        self.with_renderer(|r| r.read_back_corner_normals(device, queue))
            .flatten()
    }

    /// Replaces the per-vertex scalars; `false` when the count differs.
    pub fn set_scalars(&self, scalars: &[f32]) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.set_scalars(queue, scalars))
            .unwrap_or(false)
    }

    /// Replaces the painted mask's weights; `false` when the count differs.
    pub fn set_mask(&self, weights: &[f32]) -> bool {
        let queue = &self.state.queue;
        self.with_renderer(|r| r.set_mask(queue, weights))
            .unwrap_or(false)
    }

    /// Offscreen images drawn so far.
    pub fn images_drawn(&self) -> u64 {
        self.with_renderer(|r| r.image_counts().drawn).unwrap_or(0)
    }

    /// Images drawn, parts of images drawn over several frames, and images shown again from a
    /// held mesh's kept image, so far.
    pub fn image_counts(&self) -> ImageCounts {
        self.with_renderer(|r| r.image_counts()).unwrap_or_default()
    }

    /// CPU time of the last offscreen draw (see [`MeshRenderer::last_draw_time`]).
    pub fn last_draw_time(&self) -> std::time::Duration {
        self.with_renderer(|r| r.last_draw_time).unwrap_or_default()
    }

    /// Whether the adapter is a CPU (a software renderer such as lavapipe): every frame then
    /// costs tens of milliseconds of the same cores the background work runs on.
    pub fn software(&self) -> bool {
        self.state.adapter.get_info().device_type == wgpu::DeviceType::Cpu
    }

    /// Samples per pixel the mesh on screen is drawn with (4, or 1 on a software renderer for a
    /// big mesh, or in the web page for every mesh).
    pub fn samples(&self) -> u32 {
        self.with_renderer(|r| r.samples()).unwrap_or(0)
    }

    /// Adapter name and backend, for the performance readout.
    pub fn adapter_description(&self) -> String {
        let info = self.state.adapter.get_info();
        format!("{} ({:?})", info.name, info.backend)
    }

    /// Paints the viewport into `rect`: sizes the offscreen target to the rect's pixels, adds the
    /// paint callback that draws the mesh into it, and the image that shows it.
    pub fn paint(&mut self, painter: &egui::Painter, rect: egui::Rect, params: DrawParams) {
        self.paint_part(painter, rect, rect, params);
    }

    /// Like [`Self::paint`], but shows only the part of the image inside `visible` (a part of
    /// `rect`): the split view draws two renderers' images over one rect, each on its side.
    pub fn paint_part(
        &mut self,
        painter: &egui::Painter,
        rect: egui::Rect,
        visible: egui::Rect,
        mut params: DrawParams,
    ) {
        let visible = visible.intersect(rect);
        if !visible.is_positive() {
            return;
        }
        let pixels_per_point = painter.ctx().pixels_per_point();
        let size = [
            ((rect.width() * pixels_per_point).round() as u32).max(1),
            ((rect.height() * pixels_per_point).round() as u32).max(1),
        ];
        params.size = size;
        {
            let device = &self.state.device;
            let mut egui_renderer = self.state.renderer.write();
            let Some(renderer) = egui_renderer
                .callback_resources
                .get_mut::<MeshRenderers>()
                .and_then(|list| list.0.get_mut(self.slot))
            else {
                return;
            };
            let recreated = renderer.ensure_target(device, size);
            let view = renderer.color_view().cloned();
            if let Some(view) = view {
                match self.texture {
                    None => {
                        self.texture = Some(egui_renderer.register_native_texture(
                            device,
                            &view,
                            wgpu::FilterMode::Linear,
                        ));
                    }
                    Some(id) if recreated => egui_renderer.update_egui_texture_from_wgpu_texture(
                        device,
                        &view,
                        wgpu::FilterMode::Linear,
                        id,
                    ),
                    Some(_) => {}
                }
            }
        }
        let Some(texture) = self.texture else {
            return;
        };
        painter.add(egui_wgpu::Callback::new_paint_callback(
            visible,
            ViewportCallback {
                params,
                slot: self.slot,
            },
        ));
        let uv = |p: egui::Pos2| {
            egui::pos2(
                (p.x - rect.min.x) / rect.width(),
                (p.y - rect.min.y) / rect.height(),
            )
        };
        painter.image(
            texture,
            visible,
            egui::Rect::from_min_max(uv(visible.min), uv(visible.max)),
            egui::Color32::WHITE,
        );
    }
}

impl Drop for Viewport3d {
    fn drop(&mut self) {
        if let Some(id) = self.texture.take() {
            self.state.renderer.write().free_texture(&id);
        }
    }
}

/// The paint callback: draws the mesh into the offscreen target before egui's render pass
/// begins; the image shape that follows it shows the result.
struct ViewportCallback {
    params: DrawParams,
    slot: usize,
}

impl egui_wgpu::CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen_descriptor: &egui_wgpu::ScreenDescriptor,
        egui_encoder: &mut wgpu::CommandEncoder,
        callback_resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(renderer) = callback_resources
            .get_mut::<MeshRenderers>()
            .and_then(|list| list.0.get_mut(self.slot))
        {
            renderer.render(device, queue, egui_encoder, &self.params);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        _render_pass: &mut wgpu::RenderPass<'static>,
        _callback_resources: &egui_wgpu::CallbackResources,
    ) {
        // Nothing: the image shape drawn after this callback shows the offscreen target.
    }
}
