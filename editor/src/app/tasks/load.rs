//! Loading a file (on the io worker) and the file dialogs: launch and result.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use web_time::Instant;

use crate::app::generation::GenerationId;
use crate::app::jobs::{DialogPurpose, JobKind, JobResult, LoadedMesh};
use crate::app::state::{self, DocumentSnapshot};
use crate::app::App;
use fairmesh::io::IoError;

/// The bundled bunny when `path` names it (`@bunny`).
#[cfg(not(target_arch = "wasm32"))]
fn load_bundled(
    path: &std::path::Path,
) -> Option<Result<fairmesh::io::Loaded, fairmesh::io::IoError>> {
    fairmesh::bundled::is_bunny_pseudo_path(path)
        .then(|| fairmesh::bundled::load_bunny(&fairmesh::io::LoadOptions::default()))
}

/// A page fetches the bunny as the file beside it (`App::open`), so nothing is bundled here.
#[cfg(target_arch = "wasm32")]
fn load_bundled(
    _path: &std::path::Path,
) -> Option<Result<fairmesh::io::Loaded, fairmesh::io::IoError>> {
    None
}

impl App {
    /// Starts loading `path` on the io worker; the current mesh stays until it arrives.
    pub(in crate::app) fn open(&mut self, path: PathBuf) {
        // In a page, a typed path that is no file given to the page is a URL to fetch; the
        // bunny is the file `bunny00.obj` beside the page (the module does not carry it: it
        // would be a sixth of its download).
        #[cfg(target_arch = "wasm32")]
        if fairmesh::bundled::is_bunny_pseudo_path(&path) {
            crate::app::web::open_url(fairmesh::bundled::BUNNY_FILE_NAME.to_owned());
            return;
        } else if !fairmesh::io::exists(&path) {
            crate::app::web::open_url(path.display().to_string());
            return;
        }
        let generation = self.work.load_generation.bump();
        self.work.loading = Some(path.clone());
        self.open_path = path.display().to_string();
        // A page's files sit in an in-memory folder whose name means nothing to the user.
        #[cfg(target_arch = "wasm32")]
        if let Some(name) = path.file_name().filter(|_| fairmesh::io::exists(&path)) {
            self.open_path = name.to_string_lossy().into_owned();
        }
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.workers.io.submit(JobKind::Load, move || {
            let started = Instant::now();
            // The bundled bunny comes from the binary itself; it is named by its file name, so
            // its default export is `bunny00_faired.glb` in the working directory.
            let (path, loaded) = match load_bundled(&path) {
                Some(loaded) => (PathBuf::from(fairmesh::bundled::BUNNY_FILE_NAME), loaded),
                None => {
                    let loaded = fairmesh::io::load(&path);
                    (path, loaded)
                }
            };
            let result = loaded.and_then(|loaded| {
                if loaded.mesh.triangles.is_empty() {
                    Err(no_triangles(&path))
                } else {
                    Ok(Box::new(LoadedMesh {
                        mesh: loaded.mesh,
                        topology: Arc::new(loaded.topology),
                        report: loaded.report,
                        source: loaded.source,
                    }))
                }
            });
            let message = JobResult::Loaded {
                load_generation: generation,
                path,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// A page has no system dialogs: Open… clicks the page's file input, and Export as… exports
    /// to the typed name (the browser asks where to keep the download).
    #[cfg(target_arch = "wasm32")]
    pub(in crate::app) fn open_dialog(&mut self, purpose: DialogPurpose) {
        match purpose {
            DialogPurpose::Open => self.open_file_input(),
            DialogPurpose::Export => {
                let path = self
                    .document
                    .as_ref()
                    .map(|d| PathBuf::from(&d.export_path))
                    .unwrap_or_default();
                self.export(path);
            }
        }
    }

    #[cfg(not(target_arch = "wasm32"))]
    pub(in crate::app) fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.dialog_open {
            return;
        }
        let start_dir = self.settings.files.last_dir.clone().or_else(|| {
            self.document
                .as_ref()
                .and_then(|d| d.path.parent().map(std::path::Path::to_path_buf))
        });
        let default_name = self.document.as_ref().and_then(|d| {
            PathBuf::from(&d.export_path)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        });
        let (tx, ctx) = (self.workers.results_tx.clone(), self.ctx.clone());
        let ticket = self.workers.jobs.start();
        let spawned = std::thread::Builder::new()
            .name("fairmesh-dialog".into())
            .spawn(move || {
                let mut dialog = rfd::FileDialog::new();
                if let Some(dir) = start_dir {
                    dialog = dialog.set_directory(dir);
                }
                let path = match purpose {
                    DialogPurpose::Open => dialog
                        .add_filter("Meshes", &["obj", "glb", "gltf", "ply", "stl", "off"])
                        .add_filter("All files", &["*"])
                        .pick_file(),
                    DialogPurpose::Export => {
                        if let Some(name) = default_name {
                            dialog = dialog.set_file_name(name);
                        }
                        dialog
                            .add_filter("glTF binary", &["glb"])
                            .add_filter("glTF", &["gltf"])
                            .add_filter("Wavefront OBJ", &["obj"])
                            .add_filter("PLY", &["ply"])
                            .add_filter("STL", &["stl"])
                            .add_filter("OFF", &["off"])
                            .save_file()
                    }
                };
                Self::send_result(&tx, &ctx, JobResult::DialogPicked { purpose, path }, ticket);
            });
        match spawned {
            Ok(_) => self.dialog_open = true,
            Err(error) => self.error = Some(format!("Cannot open a file dialog: {error}")),
        }
    }

    /// A file finished loading (or failed to): it becomes the document.
    pub(in crate::app) fn on_loaded(
        &mut self,
        load_generation: GenerationId,
        path: PathBuf,
        result: Result<Box<LoadedMesh>, IoError>,
        elapsed: Duration,
    ) {
        if !self.work.load_generation.is_current(load_generation) {
            return;
        }
        let requested = self.work.loading.take();
        #[cfg(target_arch = "wasm32")]
        crate::app::web::mark("fairmesh_loaded");
        match result {
            Ok(loaded) => {
                if let Some(requested) = requested {
                    // The path as asked for (`@bunny` for the bundled one), made absolute.
                    let requested = if fairmesh::bundled::is_bunny_pseudo_path(&requested) {
                        requested
                    } else {
                        std::path::absolute(&requested).unwrap_or(requested)
                    };
                    self.settings.files.remember_recent(&requested);
                }
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    self.settings.files.last_dir = Some(dir.to_path_buf());
                }
                let loaded = *loaded;
                let name = path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_else(|| path.display().to_string());
                // The mask last painted on this file comes back with it.
                let mask = self
                    .settings
                    .paint
                    .mask_for(&path, loaded.mesh.positions.len());
                let snapshot = DocumentSnapshot {
                    mask,
                    export_path: state::default_export_path(&path).display().to_string(),
                    path,
                    mesh: Arc::new(loaded.mesh),
                    topology: loaded.topology,
                    source: loaded.source,
                    clean: None,
                    against_clean: None,
                    report: loaded.report,
                    load_time: elapsed,
                    level: 0,
                    hierarchy: None,
                    applied: false,
                    camera: None,
                };
                self.install(snapshot, Some(format!("Open {name}")));
                if let Some(document) = &mut self.document {
                    document.pick_start_level = true;
                }
                self.error = None;
                // What the status bar said was about the previous file.
                self.message = None;
                self.fit_view();
            }
            Err(error) => {
                self.error = Some(format!("Could not open the file: {error}"));
            }
        }
    }

    /// A file dialog closed.
    pub(in crate::app) fn on_dialog_picked(
        &mut self,
        purpose: DialogPurpose,
        path: Option<PathBuf>,
    ) {
        self.dialog_open = false;
        match (purpose, path) {
            (DialogPurpose::Open, Some(path)) => self.open(path),
            (DialogPurpose::Export, Some(path)) => {
                if let Some(document) = &mut self.document {
                    document.export_path = path.display().to_string();
                }
                // The system's save dialog asked about replacing an existing file already.
                self.write_export(path);
            }
            (_, None) => {
                self.message =
                    Some("No file chosen (if no dialog appeared, type a path instead)".into());
            }
        }
    }
}

/// The error of a file that loads but holds no triangles: nothing to fair.
fn no_triangles(path: &std::path::Path) -> IoError {
    IoError::Invalid {
        path: path.to_path_buf(),
        message: "the file holds no triangles".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_without_triangles_is_named_with_what_is_wrong() {
        let error = no_triangles(std::path::Path::new("/scans/points.ply"));
        assert_eq!(
            error.to_string(),
            "/scans/points.ply: the file holds no triangles"
        );
    }
}
