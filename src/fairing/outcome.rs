//! One fairing run as the front ends report it: [`fair_measured`] runs any method (as
//! [`super::fair_with_progress`]) and measures around it what the algorithm's own
//! [`FairReport`] does not hold (the time, the volume change, how far the vertices slid along the
//! surface and the texture with them); [`FairOutcome::to_json`] is the report `fairmesh fair
//! --json` prints and the Python package returns as a dict, field for field, so that the two
//! cannot drift apart.
//!
//! Not part of the paper: reporting only. The fairing itself is the method's own.

use crate::clock::Instant;

use super::{FairReport, FairVariant, Mask, MethodOptions};
use crate::mesh::{Topology, TriMesh};
use crate::metrics::{self, Comparison};
use crate::{Cancelled, Progress};

/// What [`fair_measured`] measured around the fairing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FairOutcome {
    /// The method's own report.
    pub report: FairReport,
    /// Milliseconds the fairing took (wall clock, the measuring around it not counted).
    pub time_ms: f64,
    /// The enclosed volume's change in percent; `None` when the input encloses no volume.
    pub volume_change_percent: Option<f64>,
    /// With texture coordinates: how far the tangential relaxation slid the vertices along the
    /// surface (root mean square, in mean edge lengths of the input); `None` when nothing slid.
    pub texture_slide: Option<f64>,
}

/// Fairs `mesh` in place with `options` (within `mask`, if any), reporting to `progress` as
/// [`super::fair_with_progress`] does, and measures the run: its time, the volume change and,
/// when the mesh is `textured`, how far its vertices slid along the surface.
pub fn fair_measured(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &MethodOptions,
    mask: Option<&Mask>,
    textured: bool,
    progress: &mut dyn Progress,
) -> Result<FairOutcome, Cancelled> {
    let edge = metrics::mean_edge_length(mesh);
    let volume_before = metrics::signed_volume(mesh);
    let slides = matches!(options, MethodOptions::Constrained(o) if o.tangential_relaxation > 0.0
        && o.variant == FairVariant::Improved);
    let textured_input = (slides && textured).then(|| mesh.positions.clone());
    let started = Instant::now();
    let report = super::fair_with_progress(mesh, topology, options, mask, progress)?;
    let time_ms = started.elapsed().as_secs_f64() * 1e3;
    let volume_after = metrics::signed_volume(mesh);
    let volume_change_percent = (volume_before != 0.0)
        .then(|| 100.0 * (volume_after - volume_before) / volume_before.abs())
        .filter(|change| change.is_finite());
    let texture_slide = textured_input
        .filter(|_| report.rounds_run > 0)
        .map(|before| metrics::tangential_slide(&before, mesh) / edge)
        .filter(|slide| slide.is_finite());
    Ok(FairOutcome {
        report,
        time_ms,
        volume_change_percent,
        texture_slide,
    })
}

/// What the report says besides the run: the files, the mesh, the mask, the save.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReportContext<'a> {
    /// The input file, as named (`None` for arrays).
    pub input: Option<&'a str>,
    /// The output file, as named (`None` before a save).
    pub output: Option<&'a str>,
    /// Whether the mesh is closed (its volume change is then more than indicative).
    pub closed: bool,
    pub mask: Option<&'a Mask>,
    /// Whether the saved file's texture coordinates followed the slide (`None` before a save).
    pub texture_follows: Option<bool>,
    /// The result measured against the input, when asked for.
    pub measures: Option<&'a Comparison>,
}

impl FairOutcome {
    /// The report of a run of `options` on `mesh` (the faired mesh): the fields of `fairmesh
    /// fair --json`, in its order; `texture_follows` only where there is a slide, and the
    /// measures only when there are some.
    pub fn to_json(
        &self,
        options: &MethodOptions,
        mesh: &TriMesh,
        context: &ReportContext<'_>,
    ) -> serde_json::Value {
        let report = &self.report;
        let mut json = serde_json::json!({
            "method": options.method().name(),
            "variant": options.variant_name(),
            "input": context.input,
            "output": context.output,
            "vertices": mesh.vertex_count(),
            "faces": mesh.face_count(),
            "closed": context.closed,
            "iterations_run": report.iterations_run,
            "rounds_run": report.rounds_run,
            "noise_estimate": report.noise_estimate,
            "tangential_noise": report.tangential_noise,
            "crease_edges": report.crease_edges,
            "loose_triangles": report.loose_triangles,
            "time_ms": self.time_ms,
            "detection_ms": report.detection_ms,
            "phases_ms": report.phases,
            "risk_by_round": report.risk_by_round,
            "volume_change_percent": self.volume_change_percent,
            "max_move": report.max_move,
            "masked_vertices": context.mask.map(Mask::painted_count),
            "texture_slide": self.texture_slide,
            "texture_follows": self.texture_slide.and(context.texture_follows),
        });
        if let (Some(m), Some(map)) = (context.measures, json.as_object_mut()) {
            map.insert(
                "mean_surface_distance".into(),
                m.mean_surface_distance.into(),
            );
            map.insert("hausdorff".into(), m.hausdorff.into());
            if let Some(c) = &m.same_connectivity {
                map.insert("rms".into(), c.rms.into());
                map.insert("normal_error_deg".into(), c.normal_error_deg.into());
            }
        }
        json
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::{fair_with_progress, FairOptions};
    use crate::mesh::fixtures::irregular_sphere;
    use crate::noise::{add_noise, NoiseOptions};

    #[test]
    fn the_measured_run_is_the_methods_own_and_its_volume_change_is_the_meshes() {
        let mut noisy = irregular_sphere();
        add_noise(&mut noisy, &NoiseOptions::default());
        let topology = Topology::build(&noisy);
        let options = MethodOptions::Constrained(FairOptions::default());
        let mut plain = noisy.clone();
        let report = fair_with_progress(
            &mut plain,
            &topology,
            &options,
            None,
            &mut crate::NoProgress,
        )
        .unwrap();
        let mut measured = noisy.clone();
        let outcome = fair_measured(
            &mut measured,
            &topology,
            &options,
            None,
            false,
            &mut crate::NoProgress,
        )
        .unwrap();
        assert_eq!(measured.positions, plain.positions);
        assert_eq!(outcome.report.rounds_run, report.rounds_run);
        assert!(report.rounds_run > 0, "the noisy sphere is faired");
        // The volume change, measured independently (about the bounding box's centre).
        let expected = metrics::volume_change_percent(&noisy, &measured).unwrap();
        let got = outcome.volume_change_percent.unwrap();
        assert!(
            (got - expected).abs() < 1e-6 * expected.abs().max(1e-3),
            "{got} {expected}"
        );
        assert_eq!(outcome.texture_slide, None, "not textured: no slide");
    }

    #[test]
    fn the_report_names_the_run_and_says_nothing_of_a_slide_there_was_not() {
        let mesh = irregular_sphere();
        let outcome = FairOutcome {
            report: FairReport {
                rounds_run: 3,
                ..FairReport::default()
            },
            time_ms: 12.5,
            volume_change_percent: Some(0.25),
            texture_slide: None,
        };
        let options = MethodOptions::Constrained(FairOptions::default());
        let context = ReportContext {
            input: Some("in.obj"),
            texture_follows: Some(true),
            ..ReportContext::default()
        };
        let json = outcome.to_json(&options, &mesh, &context);
        assert_eq!(json["method"], "constrained");
        assert_eq!(json["variant"], "improved");
        assert_eq!(json["input"], "in.obj");
        assert!(json["output"].is_null());
        assert_eq!(json["vertices"], mesh.vertex_count());
        assert_eq!(json["rounds_run"], 3);
        assert_eq!(json["time_ms"], 12.5);
        assert_eq!(json["volume_change_percent"], 0.25);
        assert!(
            json["texture_follows"].is_null(),
            "no slide, so nothing followed"
        );
        assert!(json.get("hausdorff").is_none(), "not measured");
    }
}
