//! The side panel's Numbers section: the result measured against the input mesh and the clean
//! mesh (volume change, distances, RMS displacement, barycenter drift; the numbers of an older
//! result greyed while the new one is measured), then the shown mesh's size and the times of
//! loading, the hierarchy, the fairing and the measuring. Reads the app's state, writes nothing.

use super::panel_view::PanelView;
use super::state::{Document, FairedResult, HierarchyState, Measures, MethodChoice};
use super::tips::{FARTHER_THAN_NOISE, NOISE_ROW, ROW_TIPS};
use super::widgets::seconds;

/// What a greyed number in the Numbers panel means.
const PENDING_TIP: &str =
    "From the previous result: the result on screen is being measured, its numbers follow";

pub(super) fn show(ui: &mut egui::Ui, view: &PanelView) {
    measures(ui, view);
    timings(ui, view);
}

/// How one row of the measures grid shows a result's numbers.
type Row = fn(&Measures) -> String;

/// The measures grid's rows: name, and its value from a result's measures.
const ROWS: [(&str, Row); 5] = [
    ("Volume change", |m| {
        m.volume_change_percent
            .map_or("–".into(), |v| format!("{v:+.4} %"))
    }),
    ("Mean distance", |m| format!("{:.3e}", m.mean_distance)),
    ("Max distance", |m| format!("{:.3e}", m.max_distance)),
    ("RMS displacement", |m| {
        m.vertex_rms.map_or("–".into(), |v| format!("{v:.3e}"))
    }),
    ("Barycenter drift", |m| {
        m.barycenter_drift
            .map_or("–".into(), |v| format!("{v:.3e}"))
    }),
];

/// The result against the input mesh and, after noise, the clean mesh.
fn measures(ui: &mut egui::Ui, view: &PanelView) {
    let Some(document) = view.document else {
        return;
    };
    let faired = document.faired.as_ref();
    let has_clean = document.clean.is_some();
    ui.label(match faired {
        Some(f) => format!("Result: {}", f.method.describe(f.level)),
        None => "Result: none yet".to_owned(),
    });
    egui::Grid::new("fairmesh-measures")
        .num_columns(if has_clean { 3 } else { 2 })
        .striped(true)
        .show(ui, |ui| {
            ui.strong("Result vs.");
            ui.strong("input")
                .on_hover_text("The input mesh: the mesh the result was smoothed from");
            if has_clean {
                ui.strong("clean")
                    .on_hover_text("The clean mesh: the input mesh before noise was added");
            }
            ui.end_row();
            measure_rows(ui, document);
            if let Some(noise) = &document.against_clean {
                ui.label("Noise").on_hover_text(NOISE_ROW);
                ui.label(format!("{:.3e}", noise.mean_distance))
                    .on_hover_text(NOISE_ROW);
                ui.end_row();
            }
        });
    ui.small("Distances in model units.");
    if farther_than_noise(document) {
        ui.label(
            egui::RichText::new("Farther from clean than the noise was (point here for why)")
                .small()
                .color(ui.visuals().warn_fg_color),
        )
        .on_hover_text(FARTHER_THAN_NOISE);
    }
}

/// Whether the result, measured, is farther from the clean mesh than the input mesh is.
fn farther_than_noise(document: &Document) -> bool {
    let faired = document.faired.as_ref().filter(|f| !f.measures_pending);
    match (
        faired.and_then(|f| f.against_clean.as_ref()),
        &document.against_clean,
    ) {
        (Some(result), Some(noise)) => result.mean_distance > noise.mean_distance,
        _ => false,
    }
}

/// One grid row per entry of [`ROWS`]: the result against the input and, after noise, against
/// the clean mesh.
fn measure_rows(ui: &mut egui::Ui, document: &Document) {
    let faired = document.faired.as_ref();
    let against_document = faired.and_then(|f| f.against_document.as_ref());
    let against_clean = faired.and_then(|f| f.against_clean.as_ref());
    let has_clean = document.clean.is_some();
    let (lo, hi) = document.bounds;
    let diagonal = ((0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>()).sqrt() as f64;
    let pending = faired.is_some_and(|f| f.measures_pending);
    let value = |ui: &mut egui::Ui, text: String| {
        let label = ui.add_enabled(!pending, egui::Label::new(text));
        if pending {
            label.on_hover_text(PENDING_TIP);
        }
    };
    for ((name, row), (_, tip)) in ROWS.into_iter().zip(ROW_TIPS) {
        ui.label(name).on_hover_text(tip);
        match faired.and_then(|f| fresh(name, f, diagonal)) {
            Some((text, tip)) if tip.is_empty() => {
                ui.label(text);
            }
            Some((text, tip)) => {
                ui.label(text).on_hover_text(tip);
            }
            None => value(ui, against_document.map_or("–".into(), row)),
        }
        if has_clean {
            value(ui, against_clean.map_or("–".into(), row));
        }
        ui.end_row();
    }
}

/// The numbers of row `name` that come with the result itself (volume change and RMS
/// displacement against the input), with their tooltip (empty for none); `None` for the other
/// numbers, measured a moment later: until then they are the previous result's, greyed, and
/// saying so. `diagonal` is the input's bounding box diagonal.
fn fresh(name: &str, faired: &FairedResult, diagonal: f64) -> Option<(String, String)> {
    let percent = |v: f64| format!("{v:+.4} %");
    match name {
        "Volume change" if faired.volume_change.is_finite() => {
            Some((percent(faired.volume_change * 100.0), String::new()))
        }
        "Volume change" => Some((
            "–".into(),
            "The input mesh encloses no volume (a flat patch), so there is none to change".into(),
        )),
        "RMS displacement" => Some((
            format!("{:.3e}", faired.rms_displacement),
            format!(
                "{:.3} % of the bounding box diagonal",
                faired.rms_displacement / diagonal.max(f64::MIN_POSITIVE) * 100.0
            ),
        )),
        _ => None,
    }
}

/// The shown mesh's size and how long each step took.
fn timings(ui: &mut egui::Ui, view: &PanelView) {
    let Some(document) = view.document else {
        return;
    };
    let faired = document.faired.as_ref();
    egui::Grid::new("fairmesh-numbers")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("Shown vertices");
            ui.label(view.shown_counts.0.to_string());
            ui.end_row();
            ui.label("Shown faces");
            ui.label(view.shown_counts.1.to_string());
            ui.end_row();
            ui.label("Load time");
            ui.label(seconds(document.load_time));
            ui.end_row();
            ui.label("Hierarchy build");
            ui.label(match &document.hierarchy {
                HierarchyState::Ready { build_time, .. } => seconds(*build_time),
                HierarchyState::Building => "building …".into(),
                HierarchyState::Failed(_) => "–".into(),
            });
            ui.end_row();
            ui.label("Last fairing");
            ui.label(faired.map_or("–".into(), |f| seconds(f.elapsed)));
            ui.end_row();
            ui.label("Measuring");
            ui.label(faired.map_or("–".into(), |f| {
                if f.measures_pending {
                    "running…".into()
                } else {
                    seconds(f.measure_time)
                }
            }));
            ui.end_row();
        });
}
