//! "Save image" (Ctrl+Shift+S): the 3D view's pixels, without the side panel or the mouse
//! hints, written as a PNG beside the document (`<name>_view.png`, then `<name>_view_2.png` and
//! so on: an earlier image is never replaced). The frame after the request is drawn without the
//! hints and captured with eframe's screenshot command; the io worker crops and writes it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::app::jobs::{JobKind, JobResult};
use crate::app::panel_view::{Commands, PanelView};
use crate::app::{App, Command};

/// The toolbar's button.
pub(in crate::app) fn button(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) {
    let response = ui
        .add_enabled(view.document.is_some(), egui::Button::new("Save image"))
        .on_hover_text(
            "Save the 3D view as a PNG picture beside the mesh file, named <name>_view.png \
             (Ctrl+Shift+S)",
        )
        .on_disabled_hover_text("Open a mesh first");
    if response.clicked() {
        commands.push(Command::SaveViewImage);
    }
}

impl App {
    /// Asks for the next frame to be captured.
    pub(in crate::app) fn save_view_image(&mut self) {
        if self.document.is_none() {
            self.error = Some("Save image: no mesh is loaded".into());
            return;
        }
        self.view.capture_next_frame = true;
        self.ctx.request_repaint();
    }

    /// Sends the screenshot command for this frame; its image comes back as a job result.
    pub(in crate::app) fn capture_view(&mut self, ctx: &egui::Context) {
        let (Some(document), Some(rect)) = (&self.document, self.view.viewport_rect) else {
            return;
        };
        let beside = document.path.clone();
        let pixels_per_point = ctx.pixels_per_point();
        let (tx, repaint, ticket) = (
            self.workers.results_tx.clone(),
            ctx.clone(),
            self.workers.jobs.start(),
        );
        let callback = egui::ScreenshotCallback::new(move |image| {
            let message = JobResult::ViewCaptured {
                image,
                rect,
                pixels_per_point,
                beside,
            };
            Self::send_result(&tx, &repaint, message, ticket);
        });
        ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(callback));
        self.message = Some("Saving the view as an image …".into());
    }

    /// Crops the window's image to the view and writes it on the io worker.
    pub(in crate::app) fn on_view_captured(
        &mut self,
        image: Arc<egui::ColorImage>,
        rect: egui::Rect,
        pixels_per_point: f32,
        beside: PathBuf,
    ) {
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.workers.io.submit(JobKind::ViewImage, move || {
            let path = free_image_path(&beside);
            // A page downloads the image (written into the export folder first).
            #[cfg(target_arch = "wasm32")]
            let path = Self::web_export_path(&path);
            let result = write_png(&path, &crop(&image, rect, pixels_per_point)).map(|()| path);
            Self::send_result(&tx, &ctx, JobResult::ViewImageSaved { result }, ticket);
        });
    }

    pub(in crate::app) fn on_view_image_saved(
        &mut self,
        result: Result<PathBuf, fairmesh::io::IoError>,
    ) {
        match result {
            Ok(path) => {
                #[cfg(target_arch = "wasm32")]
                let path = match self.download_export(&path) {
                    Some(download) => PathBuf::from(format!("a download, {download}")),
                    None => return,
                };
                self.message = Some(format!("Saved the view to {}", path.display()));
            }
            Err(error) => {
                self.message = None;
                self.error = Some(format!("Save image failed: {error}"));
            }
        }
    }
}

/// `<name>_view.png` beside `document`, or the first `<name>_view_<n>.png` (n from 2) that
/// does not exist yet.
pub fn free_image_path(document: &Path) -> PathBuf {
    let stem = document
        .file_stem()
        .map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
    let candidate = |n: usize| {
        let name = if n < 2 {
            format!("{stem}_view.png")
        } else {
            format!("{stem}_view_{n}.png")
        };
        document.with_file_name(name)
    };
    (1..)
        .map(candidate)
        .find(|path| !path.exists())
        .expect("some number is free")
}

/// The part of `image` (the whole window) under `rect` (points), clamped to the image.
fn crop(image: &egui::ColorImage, rect: egui::Rect, pixels_per_point: f32) -> egui::ColorImage {
    let [width, height] = image.size;
    let to_pixels = |value: f32, limit: usize| {
        ((value * pixels_per_point).round().max(0.0) as usize).min(limit)
    };
    let (x0, x1) = (to_pixels(rect.min.x, width), to_pixels(rect.max.x, width));
    let (y0, y1) = (to_pixels(rect.min.y, height), to_pixels(rect.max.y, height));
    image.region_by_pixels([x0, y0], [x1.saturating_sub(x0), y1.saturating_sub(y0)])
}

/// Writes `image` as an 8-bit RGBA PNG, atomically (a failed write leaves no file behind).
fn write_png(path: &Path, image: &egui::ColorImage) -> Result<(), fairmesh::io::IoError> {
    let [width, height] = image.size;
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|pixel| pixel.to_srgba_unmultiplied())
        .collect();
    fairmesh::io::write_atomically(path, |out| {
        let mut encoder = png::Encoder::new(out, width as u32, height as u32);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&bytes)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })
}
