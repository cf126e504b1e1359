//! The choices `fairmesh fair` offers (and the Python package's `fair` as keyword arguments), and
//! the [`MethodOptions`] they stand for: one mapping, so that the command line and the package
//! fair alike bit for bit.

use super::creases::{CreaseOptions, DEFAULT_CREASE_ANGLE};
use super::{
    BoundaryMode, FairOptions, HcOptions, LaplacianOptions, Method, MethodOptions, Relaxation,
    TaubinOptions,
};

/// What a user picks for one fairing, by the command line's names (`fair --help`).
#[derive(Clone, Debug, PartialEq)]
pub struct MethodChoices {
    pub method: Method,
    /// Iterations (per round for constrained fairing).
    pub iterations: usize,
    /// Constrained: `None` is the automatic strength.
    pub rounds: Option<usize>,
    /// Constrained, normal-projected: the sharp-edge angle in degrees.
    pub crease_angle: f64,
    pub no_creases: bool,
    /// Constrained, normal-projected: this relaxation weight at every vertex (`None`: where
    /// needed).
    pub tangential: Option<f64>,
    pub no_volume_correction: bool,
    /// Constrained: in mean edge lengths, both the early stop and the settle rule of a round
    /// (`None`: [`FairOptions::default`]'s settle rule alone).
    pub tolerance: Option<f64>,
    pub boundary: BoundaryMode,
    /// Constrained: the paper's method exactly ([`FairOptions::paper`]).
    pub paper_variant: bool,
    /// Laplacian and Taubin: λ; Taubin: μ; HC: α and β (`None`: the method's default).
    pub lambda: Option<f64>,
    pub mu: Option<f64>,
    pub alpha: Option<f64>,
    pub beta: Option<f64>,
}

impl Default for MethodChoices {
    /// `fairmesh fair` with no option.
    fn default() -> Self {
        Self {
            method: Method::Constrained,
            iterations: 10,
            rounds: None,
            crease_angle: DEFAULT_CREASE_ANGLE,
            no_creases: false,
            tangential: None,
            no_volume_correction: false,
            tolerance: None,
            boundary: BoundaryMode::Curve,
            paper_variant: false,
            lambda: None,
            mu: None,
            alpha: None,
            beta: None,
        }
    }
}

impl MethodChoices {
    /// The options of the chosen method on a mesh of mean edge length `mean_edge_length`; the
    /// file's own sharp edges (`file_edges`, asked for only when creases are kept) are creases
    /// too. The paper's variant is the paper's method: one round, no creases, no relaxation, no
    /// volume correction (`crease_angle`, `no_creases`, `tangential`, `no_volume_correction` do
    /// not apply to it; `rounds` does).
    pub fn options(
        &self,
        mean_edge_length: f64,
        file_edges: impl FnOnce() -> Vec<[u32; 2]>,
    ) -> MethodOptions {
        let boundary = self.boundary;
        match self.method {
            Method::Laplacian => {
                let defaults = LaplacianOptions::default();
                MethodOptions::Laplacian(LaplacianOptions {
                    iterations: self.iterations,
                    lambda: self.lambda.unwrap_or(defaults.lambda),
                    boundary,
                })
            }
            Method::Taubin => {
                let defaults = TaubinOptions::default();
                MethodOptions::Taubin(TaubinOptions {
                    iterations: self.iterations,
                    lambda: self.lambda.unwrap_or(defaults.lambda),
                    mu: self.mu.unwrap_or(defaults.mu),
                    boundary,
                })
            }
            Method::Hc => {
                let defaults = HcOptions::default();
                MethodOptions::Hc(HcOptions {
                    iterations: self.iterations,
                    alpha: self.alpha.unwrap_or(defaults.alpha),
                    beta: self.beta.unwrap_or(defaults.beta),
                    boundary,
                })
            }
            Method::Constrained => {
                MethodOptions::Constrained(self.constrained(mean_edge_length, file_edges))
            }
        }
    }

    fn constrained(
        &self,
        mean_edge_length: f64,
        file_edges: impl FnOnce() -> Vec<[u32; 2]>,
    ) -> FairOptions {
        let base = if self.paper_variant {
            FairOptions::paper()
        } else {
            let options = FairOptions::default()
                .with_keep_volume(!self.no_volume_correction)
                .with_creases((!self.no_creases).then(|| {
                    CreaseOptions::default()
                        .with_angle_degrees(self.crease_angle)
                        .with_file_edges(file_edges())
                }));
            match self.tangential {
                Some(weight) => options
                    .with_tangential_relaxation(weight)
                    .with_relaxation(Relaxation::Everywhere),
                None => options,
            }
        };
        let mut options = base
            .with_iterations(self.iterations)
            .with_boundary(self.boundary);
        if let Some(tolerance) = self.tolerance {
            options = options
                .with_tolerance(tolerance * mean_edge_length)
                .with_settled(tolerance);
        }
        if let Some(rounds) = self.rounds {
            options = options.with_rounds(rounds);
        }
        options
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_choice_is_the_default_and_the_paper_variant_ignores_the_defaults_extras() {
        let MethodOptions::Constrained(options) = MethodChoices::default().options(1.0, Vec::new)
        else {
            panic!("constrained by default");
        };
        let mut expected = FairOptions::default();
        if let Some(creases) = &mut expected.creases {
            *creases = creases.clone().with_file_edges(Vec::new());
        }
        assert_eq!(format!("{options:?}"), format!("{expected:?}"));
        let paper = MethodChoices {
            paper_variant: true,
            no_creases: false,
            tangential: Some(0.5),
            ..MethodChoices::default()
        };
        let mut asked = false;
        let MethodOptions::Constrained(options) = paper.options(1.0, || {
            asked = true;
            Vec::new()
        }) else {
            panic!("constrained");
        };
        assert!(options.creases.is_none() && options.tangential_relaxation == 0.0);
        assert!(!asked, "no creases: the file's edges are not read");
    }
}
