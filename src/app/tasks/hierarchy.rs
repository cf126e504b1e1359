//! Building the decimation hierarchy (on the compute worker) and setting up its levels: launch
//! and result.

use std::sync::{Arc, PoisonError};
use std::time::{Duration, Instant};

use crate::app::jobs::JobResult;
use crate::app::sharp_edges::SharpEdgeLines;
use crate::app::state::HierarchyState;
use crate::app::App;
use crate::hierarchy::{self, HierarchyError};

impl App {
    pub(in crate::app) fn start_hierarchy(&mut self) {
        self.hierarchy_built_with = self.settings.hierarchy_key();
        let Some(document) = &mut self.document else {
            return;
        };
        let generation = self.hierarchy_generation.bump();
        document.hierarchy = HierarchyState::Building;
        self.hierarchy_progress.set(0.0);
        let mesh = document.original.clone();
        let topology = document.topology.clone();
        let mut options = self.settings.hierarchy_options();
        let source = document.source.clone();
        let document_generation = document.generation;
        let hierarchy_generation = self.hierarchy_generation.clone();
        let progress_out = self.hierarchy_progress.clone();
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.compute.submit(move || {
            if !hierarchy_generation.is_current(generation) {
                return;
            }
            let started = Instant::now();
            let mut progress = |fraction: f32| {
                progress_out.set(fraction);
                hierarchy_generation.is_current(generation)
            };
            // The file's own sharp edges (split normals, material boundaries) are kept
            // too when sharp edges are.
            if let Some(creases) = &mut options.creases {
                *creases = creases.clone().with_file_edges(source.hard_edges(&mesh));
            }
            let built =
                hierarchy::build_hierarchy_with_topology(&mesh, &topology, &options, &mut progress);
            let result = built.map(|built| {
                // Compared here, not on the UI thread (millions of triangles).
                let matches = built.base_mesh().triangles == mesh.triangles;
                let sharp_edges = if matches {
                    SharpEdgeLines::new(&mesh, built.crease_edges())
                } else {
                    SharpEdgeLines::default()
                };
                (Arc::new(built), matches, Arc::new(sharp_edges))
            });
            let message = JobResult::Hierarchy {
                document: document_generation,
                hierarchy: generation,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// Sets up every level of a new hierarchy (connectivity and fairing operator) on the compute
    /// worker, after the view's first fairing (already queued), so that moving the level slider
    /// later never waits for a level's set-up (bunny00: about 0.2 s for all 20 levels; a
    /// 1.2M-face mesh: about 2 s). One idle job per level, finest first: a fairing the user asks
    /// for meanwhile runs before the next level's set-up, so it waits for one level at most.
    pub(in crate::app) fn prepare_levels(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: u64,
    ) {
        for level in 1..hierarchy.level_count() {
            let options = self.settings.multires_options(level);
            let document_generation = self.document_generation.clone();
            let workspace = self.workspace.clone();
            let hierarchy = hierarchy.clone();
            let ticket = self.jobs.start();
            self.compute.submit_idle(move || {
                let _ticket = ticket;
                if !document_generation.is_current(document) {
                    return;
                }
                let mut workspace = workspace.lock().unwrap_or_else(PoisonError::into_inner);
                // Levels below `level` are there already (the first fairing or the jobs
                // before this one): this builds `level` and its fairing operator.
                workspace.prepare_for(&hierarchy, &options);
            });
        }
    }

    /// The hierarchy build finished: the view asks for its first result, the levels are set up.
    pub(in crate::app) fn on_hierarchy(
        &mut self,
        document: u64,
        hierarchy: u64,
        result: Result<(Arc<hierarchy::Hierarchy>, bool, Arc<SharpEdgeLines>), HierarchyError>,
        elapsed: Duration,
    ) {
        if !self.hierarchy_generation.is_current(hierarchy) {
            return;
        }
        let Some(current) = self.document.as_mut().filter(|d| d.generation == document) else {
            return;
        };
        match result {
            Ok((hierarchy, base_matches_original, sharp_edges)) => {
                let levels = (0..hierarchy.level_count())
                    .map(|l| hierarchy.level_info(l))
                    .collect::<Vec<_>>();
                current.level = if current.pick_start_level {
                    current.pick_start_level = false;
                    self.settings.start_level_for(&current.path, levels.len())
                } else {
                    current.level.min(levels.len().saturating_sub(1))
                };
                let warm = hierarchy.clone();
                current.hierarchy = HierarchyState::Ready {
                    base_matches_original,
                    sharp_edges,
                    hierarchy,
                    levels,
                    build_time: elapsed,
                };
                self.refresh_view();
                self.prepare_levels(warm, document);
            }
            Err(HierarchyError::Cancelled) => {
                current.hierarchy = HierarchyState::Failed("cancelled".into());
            }
            Err(error) => {
                let text = error.to_string();
                current.hierarchy = HierarchyState::Failed(text.clone());
                self.error = Some(text);
            }
        }
    }
}
