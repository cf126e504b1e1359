//! Changes of the document as a whole, each undoable: installing a snapshot (a loaded file, undo,
//! redo), adding noise (on the io worker; in a page, in the engine's worker) and applying a
//! result.

use std::sync::Arc;

use crate::app::generation::GenerationId;
use crate::app::jobs::{JobKind, JobResult};
use crate::app::state::{Document, DocumentSnapshot, HierarchyState, Measures, MethodChoice};
use crate::app::App;
use fairmesh::TriMesh;

impl App {
    /// Makes `snapshot` the document. With `record`, the current document goes on the undo
    /// stack under that label first. Jobs of the replaced document become stale; the hierarchy
    /// is rebuilt unless the snapshot kept one.
    pub(in crate::app) fn install(&mut self, snapshot: DocumentSnapshot, record: Option<String>) {
        if let (Some(label), Some(current)) = (record, &self.document) {
            let mut previous = current.snapshot();
            previous.camera = Some(self.view.camera);
            self.history.record(label, previous);
        }
        // The camera follows the document: another file's comes back with it (undo and redo
        // across an Open), or the view is fitted to it; the same file's keeps the user's view.
        let other_file = self
            .document
            .as_ref()
            .is_none_or(|current| current.path != snapshot.path);
        let camera = snapshot.camera;
        let previous = self.document.take();
        // Freeing a big mesh and its hierarchy takes tens of milliseconds: not on the UI thread
        // (what the history keeps is shared, so this frees only what nobody else holds).
        if previous.is_some() {
            self.workers
                .io
                .submit(JobKind::Free, move || drop(previous));
        }
        let generation = self.work.document_generation.bump();
        let document = Document::from_snapshot(snapshot, generation);
        let needs_build = matches!(document.hierarchy, HierarchyState::Building);
        self.document = Some(document);
        // Undo and redo may bring back another mask: it is the file's mask from now on.
        self.painting.stroke = None;
        self.painting.mask_revision += 1;
        self.remember_mask();
        self.work.forget_results();
        if other_file {
            match camera {
                Some(camera) => self.view.camera = camera,
                None => self.fit_view(),
            }
        }
        if needs_build {
            self.start_hierarchy();
        } else {
            // Whatever was building belonged to the document just replaced.
            self.work.hierarchy_generation.bump();
            self.refresh_view();
        }
    }

    /// Adds noise to a copy of the document's mesh on the io worker (see `JobResult::Noised`).
    pub(in crate::app) fn add_noise(&mut self) {
        let Some(document) = &self.document else {
            self.error = Some("Nothing to add noise to: no mesh is loaded".into());
            return;
        };
        let options = self.settings.noise.options();
        if options.sigma <= 0.0 {
            self.error = Some("Noise: sigma must be above 0".into());
            return;
        }
        let mesh = document.original.clone();
        let clean = document.clean.clone().unwrap_or_else(|| mesh.clone());
        let document = document.generation;
        let document_generation = self.work.document_generation.clone();
        let label = format!(
            "Noise σ {} × edge, seed {}, {:?}",
            options.sigma, options.seed, options.mode
        );
        self.message = Some(format!("Adding noise ({label}) …"));
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        // In a page the noise is added (and measured) in the engine's worker, so that the page
        // goes on answering.
        #[cfg(target_arch = "wasm32")]
        let (tx, ctx, ticket, label) = {
            use crate::app::web::engine::{post_noise, NoisePost, Sending};
            let post = NoisePost {
                settings: self.settings.clone(),
                label: label.clone(),
                mesh: mesh.clone(),
                clean: clean.clone(),
                document,
                document_generation: document_generation.clone(),
            };
            match post_noise(post, Sending { tx, ctx, ticket }) {
                Ok(()) => return,
                Err(back) => (back.tx, back.ctx, back.ticket, label),
            }
        };
        self.workers.io.submit(JobKind::Noise, move || {
            if !document_generation.is_current(document) {
                return;
            }
            let mut noisy = mesh.as_ref().clone();
            fairmesh::noise::add_noise(&mut noisy, &options);
            let against_clean = Box::new(Measures::of(&clean, &noisy));
            let message = JobResult::Noised {
                document,
                label,
                noisy: Arc::new(noisy),
                clean,
                against_clean,
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// "Apply": the faired result becomes the document's mesh (undoable).
    pub(in crate::app) fn apply_faired_result(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let Some(faired) = &document.faired else {
            self.error = Some("Nothing to apply: no faired result yet".into());
            return;
        };
        let triangles = match &document.hierarchy {
            HierarchyState::Ready { hierarchy, .. } => hierarchy.base_mesh().triangles.clone(),
            _ => document.original.triangles.clone(),
        };
        if triangles
            .iter()
            .flatten()
            .any(|&c| c as usize >= faired.positions.len())
        {
            self.error = Some("The faired result does not fit the mesh".into());
            return;
        }
        let label = format!("Apply result ({})", faired.method.describe(faired.level));
        let mut snapshot = document.snapshot();
        snapshot.mesh = Arc::new(TriMesh {
            positions: faired.positions.as_ref().clone(),
            triangles,
        });
        snapshot.against_clean = faired.against_clean.clone();
        snapshot.hierarchy = None;
        snapshot.applied = true;
        self.install(snapshot, Some(label.clone()));
        self.message = Some(format!("{label}: the result is now the input mesh"));
    }

    /// The current document as undo and redo keep it, with the view of it.
    pub(in crate::app) fn current_snapshot(&self) -> Option<DocumentSnapshot> {
        let mut snapshot = self.document.as_ref()?.snapshot();
        snapshot.camera = Some(self.view.camera);
        Some(snapshot)
    }

    pub(in crate::app) fn undo(&mut self) {
        let Some(current) = self.current_snapshot() else {
            return;
        };
        let label = self.history.undo_label().map(str::to_owned);
        if let (Ok(previous), Some(label)) = (self.history.undo(current), label) {
            self.install(previous, None);
            self.message = Some(format!("Undone: {label}"));
        }
    }

    pub(in crate::app) fn redo(&mut self) {
        let Some(current) = self.current_snapshot() else {
            return;
        };
        let label = self.history.redo_label().map(str::to_owned);
        if let (Ok(next), Some(label)) = (self.history.redo(current), label) {
            self.install(next, None);
            self.message = Some(format!("Redone: {label}"));
        }
    }

    /// Noise was added: the noisy mesh becomes the document (undoable).
    pub(in crate::app) fn on_noised(
        &mut self,
        document: GenerationId,
        label: String,
        noisy: Arc<TriMesh>,
        clean: Arc<TriMesh>,
        against_clean: Measures,
    ) {
        let Some(current) = self.document.as_ref().filter(|d| d.generation == document) else {
            return;
        };
        let mut snapshot = current.snapshot();
        snapshot.mesh = noisy;
        snapshot.clean = Some(clean);
        snapshot.against_clean = Some(against_clean);
        snapshot.hierarchy = None;
        snapshot.applied = false;
        self.install(snapshot, Some(label.clone()));
        self.message = Some(format!(
            "{label}: the mesh before the noise is kept as the clean mesh"
        ));
    }
}
