//! Exporting the result and the level chain (on the io worker): launch and result.

use std::path::PathBuf;
use std::time::Duration;
use web_time::Instant;

use crate::app::jobs::{JobKind, JobResult, LevelChainError};
use crate::app::state::HierarchyState;
use crate::app::view_sync::SharedMesh;
use crate::app::App;
use fairmesh::io::IoError;
use fairmesh::TriMesh;

impl App {
    /// Export to a typed path: asks first when the file exists (see `confirm_replace.rs`).
    pub(in crate::app) fn export(&mut self, path: PathBuf) {
        if self.export_refused(&path) {
            return;
        }
        // A page downloads the export (the browser asks where to keep it): nothing to replace.
        #[cfg(not(target_arch = "wasm32"))]
        if path.exists() {
            self.confirm_replace = Some(path);
            return;
        }
        self.write_export(path);
    }

    /// Why nothing can be exported to `path` now, as the error shown (true when refused).
    fn export_refused(&mut self, path: &std::path::Path) -> bool {
        let error = if self.document.is_none() {
            "Nothing to export: no mesh is loaded"
        } else if path.as_os_str().is_empty() {
            "Export: type a file path first"
        } else {
            return false;
        };
        self.error = Some(error.into());
        true
    }

    /// Writes the result to `path` without asking (the user agreed to replace it, or picked it
    /// in the system's save dialog, which asked already).
    pub(in crate::app) fn write_export(&mut self, path: PathBuf) {
        if self.export_refused(&path) {
            return;
        }
        let Some(document) = &self.document else {
            return;
        };
        #[cfg(target_arch = "wasm32")]
        let path = Self::web_export_path(&path);
        // The faired positions go with M0's triangles (the hierarchy's base mesh).
        let file_source = document.source.clone();
        let (positions, triangles_source) = match (&document.faired, &document.hierarchy) {
            (Some(faired), HierarchyState::Ready { hierarchy, .. }) => (
                Some(faired.positions.clone()),
                SharedMesh::Base(hierarchy.clone()),
            ),
            _ => (None, SharedMesh::Mesh(document.original.clone())),
        };
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.message = Some(format!("Exporting to {} …", path.display()));
        self.workers.io.submit(JobKind::Export, move || {
            let started = Instant::now();
            let source = triangles_source.mesh();
            let mesh = match positions {
                Some(positions) if positions.len() == source.positions.len() => TriMesh {
                    positions: positions.as_ref().clone(),
                    triangles: source.triangles.clone(),
                },
                _ => source.clone(),
            };
            let result = fairmesh::io::save_with_source(&path, &mesh, &file_source)
                .map(|report| report.warnings);
            let message = JobResult::Exported {
                path,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// The folder the level chain goes to: the typed one, or `<stem>_levels` next to the file.
    pub fn levels_folder(&self) -> Option<PathBuf> {
        let typed = self.settings.level_chain.folder.trim();
        if !typed.is_empty() {
            return Some(PathBuf::from(typed));
        }
        let path = &self.document.as_ref()?.path;
        let stem = path.file_stem()?.to_string_lossy().into_owned();
        Some(path.with_file_name(format!("{stem}_levels")))
    }

    /// Writes levels `levels_from..=levels_to` as `<stem>_L<level>.glb` on the io worker (in a
    /// page, into a folder `<stem>_levels` that is downloaded as one `.zip`).
    pub(in crate::app) fn export_levels(&mut self) {
        let Some(document) = &self.document else {
            self.error = Some("Nothing to export: no mesh is loaded".into());
            return;
        };
        let HierarchyState::Ready { hierarchy, .. } = &document.hierarchy else {
            self.error = Some("Export levels: the hierarchy is not built yet".into());
            return;
        };
        let hierarchy = hierarchy.clone();
        let file_source = document.source.clone();
        let top = hierarchy.level_count().saturating_sub(1);
        let to = self.settings.level_chain.to.min(top);
        let from = self.settings.level_chain.from.min(to);
        let stem = document
            .path
            .file_stem()
            .map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
        // A page writes the levels into its export folder and downloads them as one `.zip`.
        #[cfg(target_arch = "wasm32")]
        let folder = Self::web_export_path(std::path::Path::new(&format!("{stem}_levels")));
        #[cfg(not(target_arch = "wasm32"))]
        let Some(folder) = self.levels_folder() else {
            self.error = Some("Export levels: type a folder first".into());
            return;
        };
        self.message = Some(format!(
            "Exporting levels M{from} … M{to} to {} …",
            folder.display()
        ));
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.workers.io.submit(JobKind::LevelChain, move || {
            let started = Instant::now();
            // A page's export folder is in memory: nothing to create.
            #[cfg(target_arch = "wasm32")]
            let created = Ok(());
            #[cfg(not(target_arch = "wasm32"))]
            let created = std::fs::create_dir_all(&folder);
            let result = created
                .map_err(|source| LevelChainError::CreateFolder {
                    folder: folder.clone(),
                    source,
                })
                .and_then(|()| {
                    (from..=to)
                        .map(|level| {
                            let path = folder.join(format!("{stem}_L{level:02}.glb"));
                            let (mesh, vertex_origin, face_origin) =
                                hierarchy.level_for_export(level);
                            let derivation = fairmesh::io::Derivation {
                                base: hierarchy.base_mesh(),
                                vertex_origin: &vertex_origin,
                                face_origin: &face_origin,
                            };
                            fairmesh::io::save_derived_with_source(
                                &path,
                                &mesh,
                                &derivation,
                                &file_source,
                            )
                            .map(|report| (path, report.warnings))
                            .map_err(LevelChainError::Save)
                        })
                        .collect::<Result<Vec<_>, _>>()
                })
                .map(|written| {
                    let mut warnings: Vec<String> = written
                        .iter()
                        .flat_map(|(_, w)| w.iter().cloned())
                        .collect();
                    // Every coarse level loses the same things: say it once.
                    warnings.dedup();
                    warnings.extend(hierarchy.levels_warning());
                    (
                        written.into_iter().map(|(path, _)| path).collect(),
                        warnings,
                    )
                });
            let message = JobResult::LevelsExported {
                folder,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// The export was written (or failed).
    pub(in crate::app) fn on_exported(
        &mut self,
        path: PathBuf,
        result: Result<Vec<String>, IoError>,
        elapsed: Duration,
    ) {
        match result {
            Ok(warnings) => {
                #[cfg(target_arch = "wasm32")]
                let path = match self.download_export(&path) {
                    Some(download) => PathBuf::from(format!("a download, {download}")),
                    None => return,
                };
                #[cfg(not(target_arch = "wasm32"))]
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    self.settings.files.last_dir = Some(dir.to_path_buf());
                }
                self.message = Some(format!(
                    "Exported to {} ({:.2} s){}",
                    path.display(),
                    elapsed.as_secs_f64(),
                    notes(&warnings)
                ));
            }
            Err(error) => {
                self.message = None;
                self.error = Some(format!("Export failed: {error}"));
            }
        }
    }

    /// The level chain was written (or failed).
    pub(in crate::app) fn on_levels_exported(
        &mut self,
        folder: PathBuf,
        result: Result<(Vec<PathBuf>, Vec<String>), LevelChainError>,
        elapsed: Duration,
    ) {
        match result {
            Ok((paths, warnings)) => {
                #[cfg(target_arch = "wasm32")]
                let folder = match self.download_export(&folder) {
                    Some(download) => PathBuf::from(format!("a download, {download}")),
                    None => return,
                };
                self.message = Some(format!(
                    "Exported {} levels to {} ({:.2} s){}",
                    paths.len(),
                    folder.display(),
                    elapsed.as_secs_f64(),
                    notes(&warnings)
                ));
            }
            Err(error) => {
                self.message = None;
                self.error = Some(format!(
                    "Level export failed: {}",
                    level_chain_failure(&error)
                ));
            }
        }
    }
}

/// Why the level chain was not written, in the words after "Level export failed: ".
fn level_chain_failure(error: &LevelChainError) -> String {
    match error {
        LevelChainError::CreateFolder { folder, source } => {
            format!("cannot create {}: {source}", folder.display())
        }
        LevelChainError::Save(error) => error.to_string(),
    }
}

/// What an export could not keep, as a note after its status message.
fn notes(warnings: &[String]) -> String {
    if warnings.is_empty() {
        String::new()
    } else {
        format!(". Note: {}", warnings.join(". "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_chain_failure_names_the_folder_or_the_file() {
        let folder = PathBuf::from("/read-only/bunny_levels");
        let create = LevelChainError::CreateFolder {
            folder: folder.clone(),
            source: std::io::Error::from(std::io::ErrorKind::PermissionDenied),
        };
        assert_eq!(
            level_chain_failure(&create),
            format!(
                "cannot create /read-only/bunny_levels: {}",
                std::io::Error::from(std::io::ErrorKind::PermissionDenied)
            )
        );
        let path = folder.join("bunny_L03.glb");
        let save = LevelChainError::Save(IoError::Write {
            path: path.clone(),
            source: std::io::Error::from(std::io::ErrorKind::StorageFull),
        });
        assert!(
            level_chain_failure(&save).starts_with("/read-only/bunny_levels/bunny_L03.glb: "),
            "{}",
            level_chain_failure(&save)
        );
    }
}
