//! The editor in a web page (`wasm32` only): files come from the page and exports go back to it.
//!
//! A page has no file system, so every file set the user gives (picked with the file input,
//! dropped on the page, or fetched from a `?open=` URL with its companions) is put in a
//! [`fairmesh::io::MemoryFolder`] of its own, `/web/<hash of the mesh file>/`, and opened from
//! there like a file on disk: the library finds an OBJ's `.mtl` and images and a glTF's buffers
//! and images beside it. The folder's name follows the content, so a mask painted on a file is
//! found again when the same file is opened in a later visit (settings live in the browser's
//! storage). An export is written into the folder `/web/export/` and handed to the browser as a
//! download: one file as it is, several (an OBJ with its `.mtl` and images, a `.gltf` with its
//! `.bin` and images) as one `.zip` (`zip.rs`).
//!
//! The browser's answers arrive later (reading a file or a URL is asynchronous); they wait in
//! `events.rs` until the next frame's [`App::poll_web`] opens the file or shows the error.

mod download;
pub mod engine;
mod events;
mod fetch;
mod zip;

use std::path::{Path, PathBuf};

use fairmesh::io::MemoryFolder;
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsCast;

use crate::app::App;

pub use fetch::open_url;

/// The id of the page's hidden `<input type="file" multiple>` that "Open…" clicks.
pub const FILE_INPUT_ID: &str = "fairmesh-file-input";

/// The folder exports are written into before they are downloaded.
const EXPORT_ROOT: &str = "/web/export";

use events::{open_files, push, WebEvent};

thread_local! {
    /// The folder exports are written into, emptied before each.
    static EXPORT: MemoryFolder = MemoryFolder::new(EXPORT_ROOT);
}

/// Sets the page's performance mark `name` (`performance.mark`): where the time to the first
/// picture goes, read by the browser test. Nothing happens where there is no such clock.
pub fn mark(name: &str) {
    let performance = js_sys::Reflect::get(&js_sys::global(), &"performance".into());
    let Ok(performance) = performance else { return };
    let mark = js_sys::Reflect::get(&performance, &"mark".into());
    if let Ok(mark) = mark.and_then(JsCast::dyn_into::<js_sys::Function>) {
        let _ = mark.call1(&performance, &name.into());
    }
}

/// What the app showed at the end of its last frame, as JSON: the document, whether work is in
/// flight (`settled`), the hierarchy's levels, the level and result on screen, whether it is
/// being measured, the error, the status message, the frame's number and the engine's worker's
/// activity (the page's scripting hook; the browser test reads it).
pub fn status() -> String {
    events::STATUS.with(|kept| kept.borrow().clone())
}

/// Asks the app for something as its widgets would (the page's scripting hook, for automation
/// and the browser test): `level` N (the start level slider), `export` NAME (Export, the
/// download named NAME), `export_levels` (Export levels: the level chain as one `.zip`), `open`
/// URL (as `?open=`), `noise`, `undo`, `redo`, `fit`.
pub fn command(name: &str, value: &str) -> Result<(), String> {
    use crate::app::Command;
    let command = match name {
        "level" => Command::SetLevel(
            value
                .parse()
                .map_err(|_| format!("level: {value:?} is not a level number"))?,
        ),
        "export" => Command::Export(PathBuf::from(value)),
        "export_levels" => Command::ExportLevels,
        "open" => {
            open_url(value.to_owned());
            return Ok(());
        }
        "noise" => Command::AddNoise,
        "undo" => Command::Undo,
        "redo" => Command::Redo,
        "fit" => Command::FitView,
        _ => return Err(format!("{name}: no such command")),
    };
    push(WebEvent::Command(command));
    Ok(())
}

/// Reads the browser's files (picked or dropped) and opens them together.
fn read_and_open(files: Vec<web_sys::File>, from: &'static str) {
    wasm_bindgen_futures::spawn_local(async move {
        let mut read = Vec::new();
        for file in files {
            let name = file.name();
            match wasm_bindgen_futures::JsFuture::from(file.array_buffer()).await {
                Ok(buffer) => read.push((name, js_sys::Uint8Array::new(&buffer).to_vec())),
                Err(error) => {
                    push(WebEvent::Failed(format!(
                        "{name}: the browser could not read the file ({})",
                        events::describe(&error)
                    )));
                    return;
                }
            }
        }
        if !read.is_empty() {
            open_files(read, from);
        }
    });
}

/// Hooks the page's file input up (once): a change reads the chosen files and opens them.
pub fn listen_to_file_input() {
    let Some(input) = file_input() else {
        return;
    };
    let on_change = Closure::<dyn FnMut()>::new(move || {
        let Some(input) = file_input() else {
            return;
        };
        let Some(list) = input.files() else {
            return;
        };
        let files = (0..list.length()).filter_map(|i| list.get(i)).collect();
        read_and_open(files, "the chosen files");
        // Choosing the same files again must fire again.
        input.set_value("");
    });
    input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
    // The listener lives as long as the page.
    on_change.forget();
}

fn file_input() -> Option<web_sys::HtmlInputElement> {
    web_sys::window()?
        .document()?
        .get_element_by_id(FILE_INPUT_ID)?
        .dyn_into()
        .ok()
}

impl App {
    /// Opens what the page's asynchronous work has brought since the last frame.
    pub(in crate::app) fn poll_web(&mut self) {
        for event in events::take(&self.ctx) {
            match event {
                WebEvent::Open(path) => self.open(path),
                WebEvent::Failed(error) => {
                    self.work.loading = None;
                    self.error = Some(format!("Could not open the file: {error}"));
                }
                WebEvent::Command(command) => self.push_command(command),
            }
        }
    }

    /// Sets the mark `fairmesh_first_picture` at the start of the first frame after the one
    /// that drew the first image of a mesh: the browser showed that image when its frame ended,
    /// just before this one (a `status()` only says so after this frame's end).
    pub(in crate::app) fn mark_first_picture(&self) {
        thread_local! {
            static MARKED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
        }
        if MARKED.get() {
            return;
        }
        if self.viewports().any(|v| v.images_drawn() > 0) {
            MARKED.set(true);
            mark("fairmesh_first_picture");
        }
    }

    /// Keeps what the frame showed for [`status`], as JSON.
    pub(in crate::app) fn publish_status(&self) {
        let status = self.status();
        let milliseconds = |time: std::time::Duration| time.as_secs_f64() * 1e3;
        let document = self.document.as_ref();
        let (denoise_ms, build_ms) = match document.map(|d| &d.hierarchy) {
            Some(crate::app::state::HierarchyState::Ready {
                build_time,
                denoise,
                ..
            }) => (
                denoise.as_ref().map(|d| milliseconds(d.time)),
                Some(milliseconds(*build_time)),
            ),
            _ => (None, None),
        };
        let engine_activity = engine::engine_activity();
        let fair_ms = document
            .and_then(|d| d.faired.as_ref())
            .map(|f| milliseconds(f.elapsed));
        let json = serde_json::json!({
            "denoise_ms": denoise_ms,
            "hierarchy_ms": build_ms,
            "fair_ms": fair_ms,
            "load_ms": self.document.as_ref().map(|d| d.load_time.as_secs_f64() * 1e3),
            "document": status.document.map(|p| p.display().to_string()),
            "loading": status.loading,
            "settled": self.is_settled(),
            "hierarchy_ready": status.hierarchy_ready,
            "hierarchy_building": matches!(
                document.map(|d| &d.hierarchy),
                Some(crate::app::state::HierarchyState::Building)
            ),
            "hierarchy_progress": self.work.hierarchy_progress.get(),
            // The result on screen is being measured (its numbers and heat map are on the way).
            "measuring": status.measuring,
            // Which frame published this: the page drew that many frames since it started.
            "frame": self.ctx.cumulative_frame_nr(),
            // The engine's worker runs a job, and the messages had from it so far.
            "engine_busy": engine_activity.0,
            "engine_heard": engine_activity.1,
            "level_count": status.level_count,
            "level": status.level,
            "faired_serial": status.faired_serial,
            "faired_level": status.faired_level,
            "shown_serial": status.view.shown_serial,
            "shown_vertices": status.view.shown_vertices,
            "shown_faces": status.view.shown_faces,
            "images_drawn": status.view.images_drawn,
            "error": status.error,
            "message": status.message,
            "warnings": self.appearance_warnings(),
            "export_path": self.document.as_ref().map(|d| d.export_path.clone()),
            "adapter": self.view.viewport.as_ref().map(|v| v.adapter_description()),
            "samples": self.view.viewport.as_ref().map(|v| v.samples()),
        });
        events::STATUS.with(|kept| *kept.borrow_mut() = json.to_string());
    }

    /// Hands the engine's worker what waits for it (`engine.rs`: the hierarchy and fairing run
    /// there), then runs one waiting background job on the page (it has no threads): loading
    /// or exporting first, then the hierarchy or fairing left to the page, then the measures.
    /// True when one ran.
    pub(in crate::app) fn run_one_job(&mut self) -> bool {
        engine::tick();
        let workers = &self.workers;
        workers.io.run_next() || workers.compute.run_next() || workers.measure.run_next()
    }

    /// "Open…": the page's file input (several files may be chosen together: an OBJ with its
    /// `.mtl` and images, a `.gltf` with its `.bin` and images).
    pub(in crate::app) fn open_file_input(&mut self) {
        match file_input() {
            Some(input) => input.click(),
            None => self.error = Some("The page has no file input to open files with".into()),
        }
    }

    /// Files dropped on the page this frame: read, then opened together.
    pub(in crate::app) fn open_dropped_files(&mut self, ctx: &egui::Context) {
        let dropped: Vec<egui::DroppedFileHandle> = ctx.input(|i| i.raw.dropped_files.clone());
        if dropped.is_empty() {
            return;
        }
        wasm_bindgen_futures::spawn_local(async move {
            let mut read = Vec::new();
            for file in &dropped {
                let name = file
                    .path()
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                match file.bytes_async().await {
                    Ok(bytes) => read.push((name, bytes)),
                    Err(error) => {
                        push(WebEvent::Failed(format!(
                            "{name}: the browser could not read the dropped file ({error})"
                        )));
                        return;
                    }
                }
            }
            open_files(read, "the dropped files");
        });
    }

    /// Where an export named like `path` is written before its download.
    pub(in crate::app) fn web_export_path(path: &Path) -> PathBuf {
        let name = path.file_name().map_or_else(
            || "export.glb".to_owned(),
            |n| n.to_string_lossy().into_owned(),
        );
        EXPORT.with(|folder| {
            // A new export replaces what the previous one left.
            folder.clear();
            folder.path(&name)
        })
    }

    /// The export was written into the export folder: hands it to the browser as a download
    /// and returns the download's name (`None`: it failed, and the error says why). Several
    /// files go as one `.zip` named after `path` (a file's companions beside it, or the level
    /// chain's folder with the levels in it).
    pub(in crate::app) fn download_export(&mut self, path: &Path) -> Option<String> {
        let files = EXPORT.with(MemoryFolder::files);
        let result = match files.as_slice() {
            [] => Err(format!("{}: the export wrote nothing", path.display())),
            [(name, bytes)] => {
                // A file in a folder (one level of the level chain) downloads under its own name.
                let name = name.file_name().unwrap_or(name.as_os_str());
                let name = name.to_string_lossy().into_owned();
                download::offer(&name, bytes).map(|()| name)
            }
            _ => {
                let stem = path
                    .file_stem()
                    .map_or_else(|| "export".into(), |s| s.to_string_lossy().into_owned());
                let name = format!("{stem}.zip");
                download::offer(&name, &zip::stored(&files)).map(|()| name)
            }
        };
        EXPORT.with(MemoryFolder::clear);
        match result {
            Ok(name) => Some(name),
            Err(error) => {
                self.message = None;
                self.error = Some(format!("Export failed: {error}"));
                None
            }
        }
    }
}
