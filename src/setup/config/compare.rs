//! The `[compare]` table: the models `smithwalk compare` judges the run against.

use serde::{Deserialize, Serialize};

/// The analytic models `smithwalk compare` can judge a run against (`crate::analysis::compare`
/// evaluates them; the configuration only names them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    Single,
    HammonFit,
    HeitzNee,
    WangCorrelated,
    WangUncorrelated,
    ExactPositionFree,
    /// Cui et al. 2023 as its released code computes it, conductors (docs/theory.md §7.3).
    CuiReleased,
    /// Energy compensation of Kulla & Conty 2017, all orders (`analysis::compensation`).
    KullaConty,
    /// Energy compensation of Turquin 2019, all orders.
    Turquin,
    /// Energy compensation of Fdez-Agüera 2019, all orders.
    FdezAguera,
    /// MaterialX's GGX energy compensation (Turquin's form with its albedo fit), all orders.
    MaterialX,
    /// Lee et al. 2018's symmetric specular V-grooves, conductors, per order (docs/theory.md §14):
    /// another microsurface than Smith's.
    Lee2018,
    /// A user's own model read from a file (`smithwalk compare --external`); not in [`Model::ALL`].
    External,
}

impl Model {
    pub const ALL: [Model; 12] = [
        Model::Single,
        Model::HammonFit,
        Model::HeitzNee,
        Model::WangCorrelated,
        Model::WangUncorrelated,
        Model::ExactPositionFree,
        Model::CuiReleased,
        Model::KullaConty,
        Model::Turquin,
        Model::FdezAguera,
        Model::MaterialX,
        Model::Lee2018,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Model::Single => "single",
            Model::HammonFit => "hammon-fit",
            Model::HeitzNee => "heitz-nee",
            Model::WangCorrelated => "wang-correlated",
            Model::WangUncorrelated => "wang-uncorrelated",
            Model::ExactPositionFree => "exact-position-free",
            Model::CuiReleased => "cui2023-released",
            Model::KullaConty => "kulla-conty",
            Model::Turquin => "turquin",
            Model::FdezAguera => "fdez-aguera",
            Model::MaterialX => "materialx",
            Model::Lee2018 => "lee2018",
            Model::External => "external",
        }
    }

    /// Why the model cannot judge a run walked with Russian roulette below `threshold`
    /// (`energy.threshold`), if it cannot: the exact position-free chain (§7.1), and Cui's
    /// released model which carries the same weight (§7.3), end only by that roulette once
    /// their weight is small, so with no threshold their chains run on through weights that no
    /// longer change the lobes.
    pub fn refuses_threshold(self, threshold: f64) -> Option<String> {
        (matches!(self, Model::ExactPositionFree | Model::CuiReleased) && threshold <= 0.0).then(|| {
            format!(
                "{} needs energy.threshold > 0 (its chains end only by Russian roulette below it), \
                 and the run's is {threshold}: walk it with a threshold (0.1 is the default)",
                self.name()
            )
        })
    }

    pub fn parse(text: &str) -> Result<Self, String> {
        Model::ALL.into_iter().find(|m| m.name() == text).ok_or_else(|| {
            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
            format!("{text:?} is not a model; allowed: {}", names.join(", "))
        })
    }
}

/// Models to compare the run with when it finishes (`smithwalk compare` on its output).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CompareConfig {
    /// Model names: `single`, `hammon-fit`, `heitz-nee`, `exact-position-free`, `wang-correlated`,
    /// `wang-uncorrelated`, `cui2023-released`, `kulla-conty`, `turquin`, `fdez-aguera`, `materialx`, `lee2018`.
    pub models: Vec<String>,
    /// Photons per case for the Monte Carlo models (default: the run's `paths`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paths: Option<u64>,
}
