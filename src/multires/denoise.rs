//! The first stage of multiresolution fairing as the editor and `fairmesh multires` run it: the
//! mesh is denoised once with the automatic default of constrained fairing (the same run as
//! `fairmesh fair FILE`: noise estimate, rounds while the estimated error falls, creases kept,
//! relaxation where needed, volume given back), and the hierarchy is built on the result.
//!
//! Why a stage before the paper's loop (section 4.2), not the paper's loop alone: the level
//! fairings of the paper are a few iterations of the paper's operator per level, the same for
//! every mesh, with no idea of how noisy the mesh is; from a middle level they turn a box into a
//! blob and leave folded edges on a noisy scan, and from M0 they remove a fixed amount whatever
//! the noise. The automatic default reads the noise and stops when the estimated error of the
//! result stops falling (`crate::fairing::strength`). So start level 0 gives exactly that
//! result, and a coarser start level removes detail on top of it, as the paper's multires does:
//! its levels are built from, and its levels faired from, the denoised mesh.
//! [`Denoise::Off`] is the paper's loop alone.

use crate::fairing::{
    fair_constrained_with_progress, BoundaryMode, CreaseOptions, FairOptions, FairReport,
};
use crate::mesh::{Topology, TriMesh};
use crate::{Cancelled, Progress};

/// How much the first stage fairs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Denoise {
    /// The automatic strength: a clean mesh is left as it is, a noisy one faired round by round
    /// while the estimated error falls ([`crate::fairing::Strength::Auto`]).
    #[default]
    Automatic,
    /// Exactly this many rounds of the default's iterations (0: none).
    Rounds(usize),
    /// No first stage: the paper's multires alone.
    Off,
}

/// What the first stage is asked for: how much, and the options it shares with the rest.
#[derive(Clone, Debug)]
pub struct DenoiseOptions {
    pub denoise: Denoise,
    /// Sharp edges kept (with the file's own hard edges as
    /// [`CreaseOptions::with_file_edges`]), `None` to fair across them.
    pub creases: Option<CreaseOptions>,
    pub boundary: BoundaryMode,
}

impl Default for DenoiseOptions {
    /// The automatic default of `fairmesh fair`: automatic strength, sharp edges kept at the
    /// default angle, boundaries smoothed as curves.
    fn default() -> Self {
        Self {
            denoise: Denoise::Automatic,
            creases: Some(CreaseOptions::default()),
            boundary: BoundaryMode::Curve,
        }
    }
}

impl DenoiseOptions {
    /// The constrained fairing the first stage runs: [`FairOptions::default`] (the automatic
    /// default of `fairmesh fair`) with these creases and boundary, and the rounds of
    /// [`Denoise::Rounds`]; `None` for [`Denoise::Off`] and for no rounds.
    pub fn fair_options(&self) -> Option<FairOptions> {
        let options = FairOptions::default()
            .with_creases(self.creases.clone())
            .with_boundary(self.boundary);
        match self.denoise {
            Denoise::Automatic => Some(options),
            Denoise::Rounds(0) | Denoise::Off => None,
            Denoise::Rounds(rounds) => Some(options.with_rounds(rounds)),
        }
    }
}

/// The denoised mesh and what the fairing found.
#[derive(Clone, Debug)]
pub struct Denoised {
    pub mesh: TriMesh,
    /// The fairing's report (the noise estimate, the rounds kept, the sharp edges).
    pub report: FairReport,
}

/// Runs the first stage on a copy of `mesh` (`topology` built from it), reporting to
/// `progress`: `Ok(None)` when `options` ask for no stage ([`Denoise::Off`], no rounds),
/// [`Cancelled`] when `progress` cancelled it.
pub fn denoise(
    mesh: &TriMesh,
    topology: &Topology,
    options: &DenoiseOptions,
    progress: &mut dyn Progress,
) -> Result<Option<Denoised>, Cancelled> {
    let Some(fair_options) = options.fair_options() else {
        progress.check(1.0)?;
        return Ok(None);
    };
    let mut denoised = mesh.clone();
    let report = fair_constrained_with_progress(&mut denoised, topology, &fair_options, progress)?;
    Ok(Some(Denoised {
        mesh: denoised,
        report,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::fair_constrained;
    use crate::mesh::fixtures::irregular_sphere;
    use crate::noise::{add_noise, NoiseOptions};

    #[test]
    fn the_first_stage_is_the_automatic_default_and_off_is_nothing() {
        let mut noisy = irregular_sphere();
        add_noise(&mut noisy, &NoiseOptions::default());
        let topology = Topology::build(&noisy);
        let options = DenoiseOptions::default();
        let denoised = denoise(&noisy, &topology, &options, &mut crate::NoProgress)
            .expect("not cancelled")
            .expect("a stage was asked for");
        let mut default = noisy.clone();
        let report = fair_constrained(&mut default, &topology, &FairOptions::default());
        assert_eq!(denoised.mesh.positions, default.positions);
        assert_eq!(denoised.report.rounds_run, report.rounds_run);
        assert!(report.rounds_run > 0, "the noisy sphere is faired");
        for off in [Denoise::Off, Denoise::Rounds(0)] {
            let options = DenoiseOptions {
                denoise: off,
                ..DenoiseOptions::default()
            };
            let none = denoise(&noisy, &topology, &options, &mut crate::NoProgress);
            assert!(matches!(none, Ok(None)), "{off:?}");
        }
        let two = DenoiseOptions {
            denoise: Denoise::Rounds(2),
            ..DenoiseOptions::default()
        };
        let fixed = denoise(&noisy, &topology, &two, &mut crate::NoProgress)
            .expect("not cancelled")
            .expect("two rounds");
        assert_eq!(fixed.report.rounds_run, 2);
        let cancelled = denoise(&noisy, &topology, &options, &mut |_: f32| false);
        assert_eq!(cancelled.err(), Some(Cancelled));
    }
}
