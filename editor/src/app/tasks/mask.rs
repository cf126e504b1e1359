//! The painted mask (where to fair): brush strokes, clear and invert, each one undo step; the
//! mask is remembered per file in the settings and handed to every fairing
//! ([`fairmesh::fairing::mask`]).

use crate::app::paint::{brush_hits, BrushView};
use crate::app::state::ViewMode;
use crate::app::App;
use fairmesh::fairing::Mask;

impl App {
    /// The document's mask (`None`: the whole mesh is faired).
    pub fn mask(&self) -> Option<Mask> {
        self.document.as_ref().and_then(|d| d.mask.clone())
    }

    /// Whether the left button paints (instead of orbiting).
    pub fn paint_mode(&self) -> bool {
        self.painting.paint_mode
    }

    pub fn set_paint_mode(&mut self, on: bool) {
        self.painting.paint_mode = on;
    }

    /// One dab of the brush at `view.cursor`: raises (or, erasing, lowers) the mask under it.
    /// The first dab of a stroke records the mask before it for undo.
    pub(in crate::app) fn paint_dab(&mut self, view: &BrushView, erase: bool) {
        let Some(document) = &self.document else {
            return;
        };
        if self.settings.view.view_mode == ViewMode::Level {
            self.message = Some("Painting needs the full mesh: switch the view to Faired".into());
            return;
        }
        let mesh = &document.original;
        // Pick on what is on screen: the result when it has the document's vertices.
        let positions = match &document.faired {
            Some(faired)
                if self.settings.view.view_mode == ViewMode::Faired
                    && faired.positions.len() == mesh.positions.len() =>
            {
                faired.positions.as_slice()
            }
            _ => mesh.positions.as_slice(),
        };
        let hits = brush_hits(positions, &mesh.triangles, view);
        if self.painting.stroke.is_none() {
            if hits.is_empty() {
                return;
            }
            let label = if erase { "Erase mask" } else { "Paint mask" };
            if let Some(previous) = self.current_snapshot() {
                self.history.record(label, previous);
            }
            // Erasing with no mask starts from "fair everything": it protects what it touches.
            let start = if erase { 1.0 } else { 0.0 };
            self.painting.stroke = Some(match &document.mask {
                Some(mask) => mask.weights().to_vec(),
                None => vec![start; mesh.positions.len()],
            });
        }
        let Some(weights) = self.painting.stroke.as_mut() else {
            return;
        };
        for (v, fraction) in hits {
            let brush = self.settings.paint.weight_at(fraction);
            let Some(w) = weights.get_mut(v as usize) else {
                continue;
            };
            *w = if erase {
                w.min(1.0 - brush)
            } else {
                w.max(brush)
            };
        }
        let mask = Mask::new(weights.clone()).ok();
        if let Some(document) = &mut self.document {
            document.mask = mask;
        }
        self.painting.mask_revision += 1;
    }

    /// The stroke ended: the mask is remembered for the file and the mesh faired with it.
    pub(in crate::app) fn end_stroke(&mut self) {
        if self.painting.stroke.take().is_none() {
            return;
        }
        self.remember_mask();
        self.refair_with_mask();
    }

    /// Replaces the mask by what `change` makes of it, as one undo step named `label`.
    pub(in crate::app) fn change_mask(
        &mut self,
        label: &str,
        change: impl FnOnce(Option<Mask>) -> Option<Mask>,
    ) {
        let Some(previous) = self.current_snapshot() else {
            return;
        };
        let Some(document) = &mut self.document else {
            return;
        };
        let changed = change(document.mask.clone());
        if changed == document.mask {
            return;
        }
        document.mask = changed;
        self.history.record(label, previous);
        self.painting.mask_revision += 1;
        self.message = Some(format!("{label} (undo with Ctrl+Z)"));
        self.remember_mask();
        self.refair_with_mask();
    }

    /// Keeps the document's mask in the settings, under its file (bounded in size).
    pub(in crate::app) fn remember_mask(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        if !self
            .settings
            .paint
            .remember(&document.path, document.mask.as_ref())
        {
            self.message = Some(
                "The mask is too scattered to be remembered for next time (it still applies now)"
                    .into(),
            );
        }
    }

    /// Fairs again with the current mask (an applied result is faired again too: the user asked
    /// for a change).
    fn refair_with_mask(&mut self) {
        if let Some(document) = &mut self.document {
            document.applied = false;
        }
        self.refresh_view();
    }

    /// The mask's revision while it is tinted over the mesh.
    pub(in crate::app) fn mask_tint(&self) -> Option<u64> {
        let document = self.document.as_ref()?;
        (self.settings.paint.show_mask && document.mask.is_some())
            .then_some(self.painting.mask_revision)
    }
}
