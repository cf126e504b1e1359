//! Faired results kept by start level. The hierarchy and the fairing settings do not change
//! while the start-level slider moves, so a level's result is the same every time it is asked
//! for: going back to a level already seen shows its result in the next frame instead of
//! fairing again, and while the slider rests the compute worker fairs the levels next to it
//! ahead of time ([`AHEAD_REACH`]), so that the next step shows at once too. A result is kept
//! with its measures once they arrive, so a kept result needs no measuring either.
//!
//! Everything a result depends on besides its level ([`ResultKey`]: the document, the
//! hierarchy, the document's mesh, the painted mask, the fairing settings) is compared on every
//! use; when any of it differs, everything kept is dropped. What is kept stays within
//! [`KEPT_BYTES`] (the least recently shown results go first), at least [`KEPT_AT_LEAST`].

use std::sync::{Arc, Weak};
use std::time::Duration;

use fairmesh::fairing::{Mask, Method};
use fairmesh::hierarchy::Hierarchy;
use fairmesh::TriMesh;

use super::generation::GenerationId;
use super::state::{FairingKey, Measures};

/// How many levels either side of the one on screen are faired ahead while the slider rests.
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
pub(in crate::app) const AHEAD_REACH: usize = 2;

/// The most memory the kept results take (positions and measures): 36 results of a 1.2M-face
/// mesh (7.2 MB of positions each), every level of most meshes.
pub(in crate::app) const KEPT_BYTES: usize = 256 << 20;

/// Results kept whatever their size: the one on screen and the two next to it.
pub(in crate::app) const KEPT_AT_LEAST: usize = 3;

/// Everything besides the start level that a faired result depends on. The hierarchy and the
/// document's mesh are named by their allocations, held weakly: a key keeps neither alive (a
/// hierarchy built anew frees the old one), and while it exists no other can take the address.
/// Whether the noise was removed first comes with the hierarchy (built on the denoised mesh).
#[derive(Clone)]
pub struct ResultKey {
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) hierarchy: Weak<Hierarchy>,
    /// The document's mesh (noise and Apply replace it).
    pub(in crate::app) original: Weak<TriMesh>,
    pub(in crate::app) mask: Option<Mask>,
    pub(in crate::app) fairing: FairingKey,
}

impl PartialEq for ResultKey {
    fn eq(&self, other: &Self) -> bool {
        self.document == other.document
            && Weak::ptr_eq(&self.hierarchy, &other.hierarchy)
            && Weak::ptr_eq(&self.original, &other.original)
            && self.mask == other.mask
            && self.fairing == other.fairing
    }
}

/// One kept result: what the view shows for it.
#[derive(Clone)]
pub(in crate::app) struct KeptResult {
    pub(in crate::app) positions: Arc<Vec<[f32; 3]>>,
    pub(in crate::app) method: Method,
    pub(in crate::app) volume_change: f64,
    pub(in crate::app) rms_displacement: f64,
    pub(in crate::app) folds_left: usize,
    /// How long its fairing took.
    pub(in crate::app) elapsed: Duration,
    /// Its measures (against the document's mesh, against the clean one), once measured.
    pub(in crate::app) measures: Option<(Option<Measures>, Option<Measures>, Duration)>,
}

impl KeptResult {
    /// Memory it holds: its positions and its measures' distances.
    fn bytes(&self) -> usize {
        let distances = |m: &Option<Measures>| m.as_ref().map_or(0, |m| m.vertex_distances.len());
        let measured = self.measures.as_ref().map_or(0, |(document, clean, _)| {
            distances(document) + distances(clean)
        });
        self.positions.len() * 12 + measured * 4
    }
}

/// The kept results of one [`ResultKey`], most recently shown last.
#[derive(Default)]
pub(in crate::app) struct KeptResults {
    key: Option<ResultKey>,
    results: Vec<(usize, KeptResult)>,
}

impl KeptResults {
    /// The result kept for `level` under `key`, which becomes the most recently shown.
    pub(in crate::app) fn take_out(&mut self, key: &ResultKey, level: usize) -> Option<KeptResult> {
        if self.key.as_ref() != Some(key) {
            return None;
        }
        let at = self.results.iter().position(|(l, _)| *l == level)?;
        let entry = self.results.remove(at);
        let result = entry.1.clone();
        self.results.push(entry);
        Some(result)
    }

    /// Keeps `result` for `level` under `key` (dropping everything kept under another key), the
    /// most recently shown; the least recently shown go while over [`KEPT_BYTES`].
    pub(in crate::app) fn keep(&mut self, key: ResultKey, level: usize, result: KeptResult) {
        if self.key.as_ref() != Some(&key) {
            self.results.clear();
            self.key = Some(key);
        }
        self.results.retain(|(l, _)| *l != level);
        self.results.push((level, result));
        while self.results.len() > KEPT_AT_LEAST
            && self.results.iter().map(|(_, r)| r.bytes()).sum::<usize>() > KEPT_BYTES
        {
            self.results.remove(0);
        }
    }

    /// Keeps `result`, faired ahead for `level` under `key`, as the least recently shown (the
    /// first to go), if there is room for it within [`KEPT_BYTES`]: a result faired ahead never
    /// pushes out one that was shown.
    pub(in crate::app) fn keep_ahead(&mut self, key: ResultKey, level: usize, result: KeptResult) {
        if self.key.as_ref() != Some(&key) || !self.room_for(result.positions.len()) {
            return;
        }
        self.results.retain(|(l, _)| *l != level);
        self.results.insert(0, (level, result));
    }

    /// Whether a result of `vertices` vertices fits within [`KEPT_BYTES`] beside those kept (or
    /// fewer than [`KEPT_AT_LEAST`] are kept).
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub(in crate::app) fn room_for(&self, vertices: usize) -> bool {
        let used: usize = self.results.iter().map(|(_, r)| r.bytes()).sum();
        self.results.len() < KEPT_AT_LEAST || used + vertices * 12 <= KEPT_BYTES
    }

    /// Adds the measures of the kept result whose positions are `positions` (the same
    /// allocation), if it is still kept.
    pub(in crate::app) fn add_measures(
        &mut self,
        positions: &Arc<Vec<[f32; 3]>>,
        measures: (Option<Measures>, Option<Measures>, Duration),
    ) {
        if let Some((_, kept)) = self
            .results
            .iter_mut()
            .find(|(_, r)| Arc::ptr_eq(&r.positions, positions))
        {
            kept.measures = Some(measures);
        }
    }

    /// The levels within [`AHEAD_REACH`] of `level` (up to `top`) with no result kept under
    /// `key`, nearest first, the coarser first at the same distance (the way a user looking for
    /// a smoother result goes).
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub(in crate::app) fn missing_near(
        &self,
        key: &ResultKey,
        level: usize,
        top: usize,
    ) -> Vec<usize> {
        // Compared once: the key holds the painted mask, one weight per vertex.
        let same_key = self.key.as_ref() == Some(key);
        let kept = |l: usize| same_key && self.results.iter().any(|(k, _)| *k == l);
        (1..=AHEAD_REACH)
            .flat_map(|d| {
                [
                    level.checked_add(d).filter(|&l| l <= top),
                    level.checked_sub(d),
                ]
            })
            .flatten()
            .filter(|&l| !kept(l))
            .collect()
    }

    /// How many results are kept.
    pub(in crate::app) fn len(&self) -> usize {
        self.results.len()
    }

    /// Drops everything kept (a new document).
    pub(in crate::app) fn clear(&mut self) {
        self.results.clear();
        self.key = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::state::FairingSettings;

    fn key(hierarchy: &Arc<Hierarchy>, original: &Arc<TriMesh>) -> ResultKey {
        ResultKey {
            document: GenerationId::default(),
            hierarchy: Arc::downgrade(hierarchy),
            original: Arc::downgrade(original),
            mask: None,
            fairing: FairingSettings::default().key(),
        }
    }

    fn result(vertices: usize) -> KeptResult {
        KeptResult {
            positions: Arc::new(vec![[0.0; 3]; vertices]),
            method: Method::default(),
            volume_change: 0.0,
            rms_displacement: 0.0,
            folds_left: 0,
            elapsed: Duration::ZERO,
            measures: None,
        }
    }

    fn setup() -> (Arc<Hierarchy>, Arc<TriMesh>) {
        let mesh = fairmesh::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.25);
        let hierarchy = fairmesh::hierarchy::build_hierarchy(
            &mesh,
            &Default::default(),
            &mut fairmesh::NoProgress,
        )
        .unwrap();
        (Arc::new(hierarchy), Arc::new(mesh))
    }

    #[test]
    fn a_result_comes_back_only_under_the_same_key_and_level() {
        let (hierarchy, original) = setup();
        let mut kept = KeptResults::default();
        let first = key(&hierarchy, &original);
        kept.keep(first.clone(), 3, result(10));
        assert!(kept.take_out(&first, 3).is_some());
        assert!(kept.take_out(&first, 2).is_none());
        // Another setting, another mesh (noise), another mask: not the same result.
        let mut iterations = first.clone();
        let mut settings = FairingSettings::default();
        settings.iterations += 1;
        iterations.fairing = settings.key();
        assert!(kept.take_out(&iterations, 3).is_none());
        let noisy_mesh = Arc::new(original.as_ref().clone());
        let noisy = key(&hierarchy, &noisy_mesh);
        assert!(kept.take_out(&noisy, 3).is_none());
        let mut masked = first.clone();
        masked.mask = Some(Mask::from_vertices(original.vertex_count(), [0]));
        assert!(kept.take_out(&masked, 3).is_none());
        // Keeping under another key drops the rest.
        kept.keep(iterations.clone(), 4, result(10));
        assert_eq!(kept.len(), 1);
        assert!(kept.take_out(&first, 3).is_none());
        assert!(kept.take_out(&iterations, 4).is_some());
    }

    #[test]
    fn over_the_budget_the_least_recently_shown_go_first() {
        let (hierarchy, original) = setup();
        let mut kept = KeptResults::default();
        let key = key(&hierarchy, &original);
        // Each a third of the budget: three fit, the fourth pushes out the oldest shown.
        let vertices = KEPT_BYTES / 12 / 3;
        for level in 1..=3 {
            kept.keep(key.clone(), level, result(vertices));
        }
        assert!(kept.take_out(&key, 1).is_some(), "level 1 shown again");
        kept.keep(key.clone(), 4, result(vertices));
        assert_eq!(kept.len(), 3);
        assert!(
            kept.take_out(&key, 2).is_none(),
            "the least recently shown went"
        );
        for level in [1, 3, 4] {
            assert!(kept.take_out(&key, level).is_some(), "level {level}");
        }
    }

    #[test]
    fn the_levels_to_fair_ahead_are_the_nearest_missing_ones() {
        let (hierarchy, original) = setup();
        let mut kept = KeptResults::default();
        let key = key(&hierarchy, &original);
        assert_eq!(kept.missing_near(&key, 5, 10), vec![6, 4, 7, 3]);
        assert_eq!(kept.missing_near(&key, 0, 10), vec![1, 2]);
        assert_eq!(kept.missing_near(&key, 10, 10), vec![9, 8]);
        kept.keep(key.clone(), 6, result(1));
        kept.keep(key.clone(), 3, result(1));
        assert_eq!(kept.missing_near(&key, 5, 10), vec![4, 7]);
    }
}
