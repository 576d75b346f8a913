//! The TOML run configuration: parsing, defaults and validation, one table a module.
//!
//! Every list-valued field is a sweep; [`crate::setup::cases`] expands the configuration into the
//! cartesian product of cases, turning each into physics values. Validation names the field,
//! the value and what is allowed.

mod compare;
mod detector;
mod energy;
mod error;
mod incident;
mod material;
pub mod physics;
mod precision;
mod reading;
mod surface;
pub(crate) mod values;

use std::path::Path;

use serde::{Deserialize, Serialize};

pub use compare::{CompareConfig, Model};
pub use detector::{DEFAULT_MAX_ORDER, DetectorConfig};
pub use energy::EnergyConfig;
pub use error::ConfigError;
pub(crate) use error::invalid;
use error::missing;
pub use incident::{IncidentConfig, IncidentSide};
pub use material::{FresnelKind, MaterialConfig};
use microsurface::ndf::Roughness;
pub use physics::MAX_ALPHA;
pub use precision::PrecisionConfig;
pub use reading::{RUN_TABLES, Supplied, locate, parse_toml, parse_toml_supplied, shorten};
use reading::{VALUE_CHARS, allowed_value, parse_toml_with};
pub use surface::{HeightKind, NdfKind, NormalsKind, SmithKind, SurfaceConfig};
pub(crate) use values::deserialize_by_name;
use values::non_empty;
pub use values::{Alpha, Channels, OneOrMany};

/// A whole run configuration.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Photons per case.
    pub paths: u64,
    #[serde(default = "default_seed")]
    pub seed: u64,
    pub surface: SurfaceConfig,
    pub material: OneOrMany<MaterialConfig>,
    pub incident: IncidentConfig,
    #[serde(default)]
    pub detector: DetectorConfig,
    #[serde(default)]
    pub energy: EnergyConfig,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precision: Option<PrecisionConfig>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare: Option<CompareConfig>,
}

/// The most photons per case.
pub const MAX_PATHS: u64 = 1_000_000_000_000_000;

/// The most cases a sweep may expand to.
pub const MAX_CASES: u64 = 1_000_000;

/// The longest material `name`, in characters: a label for tables, figures and the report.
pub const MAX_NAME_CHARS: usize = 100;

fn default_seed() -> u64 {
    1
}

/// Refuses a table config (`smithwalk lut`, which has a `table` key) read as a run config.
fn not_a_table_config(document: &toml::Table) -> Result<(), ConfigError> {
    match document.get("table") {
        Some(table) => Err(invalid(
            "table",
            shorten(&table.to_string(), VALUE_CHARS),
            "this is a table config for `smithwalk lut`; `smithwalk run` reads a run config, with the tables \
             [surface], [material] and [incident] (configs/quickstart.toml, README.md)",
        )),
        None => Ok(()),
    }
}

impl Config {
    /// Reads, parses and validates a TOML configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = crate::input::read_to_string(path, crate::input::MAX_CONFIG_BYTES)
            .map_err(|cause| ConfigError::Read { path: path.display().to_string(), cause })?;
        Self::parse(&text).map_err(|e| e.in_source(&path.display().to_string()))
    }

    /// Parses and validates TOML text; errors name it `<text>`.
    pub fn parse(text: &str) -> Result<Self, ConfigError> {
        if let Ok(document) = text.parse::<toml::Table>() {
            not_a_table_config(&document).map_err(|e| locate(e, text, true).in_source("<text>"))?;
        }
        let config: Config = parse_toml(text)?;
        config.validate().map_err(|e| locate(e, text, true).in_source("<text>"))?;
        Ok(config)
    }

    /// Parses and validates a configuration given as a table (the Python package's dict) with
    /// the checks of a file; errors name it `<dict>` and no lines, which a dict does not have.
    pub fn from_table(table: &toml::Table) -> Result<Self, ConfigError> {
        let in_dict = |e: ConfigError| e.in_source("<dict>");
        not_a_table_config(table).map_err(in_dict)?;
        let text = toml::to_string(table)
            .map_err(|e| in_dict(ConfigError::Parse { path: String::new(), message: e.to_string() }))?;
        let config: Config = parse_toml_with(&text, false).map_err(in_dict)?;
        config.validate().map_err(|e| in_dict(locate(e, &text, false)))?;
        Ok(config)
    }

    /// Checks every field against what the simulator supports.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if self.paths < 2 {
            return Err(invalid("paths", self.paths, "at least 2 photons per case (standard errors need two)"));
        }
        if self.paths > MAX_PATHS {
            return Err(invalid("paths", self.paths, "at most 10^15 photons per case (about 3 years at 10^7 paths/s)"));
        }
        let s = &self.surface;
        non_empty("surface.ndf", &s.ndf)?;
        non_empty("surface.height", &s.height)?;
        non_empty("surface.smith", &s.smith)?;
        non_empty("surface.normals", &s.normals)?;
        non_empty("surface.alpha", &s.alpha)?;
        for alpha in s.alpha.values() {
            physics::roughness(alpha)?;
        }
        // `gamma` is the shape of `student-t` and of nothing else: physics::ndf says which
        // combination is wrong, with `gamma` against the first NDF it does not fit.
        let student_t = s.ndf.values().contains(&NdfKind::StudentT);
        let unit = Roughness::isotropic(1.0);
        match &s.gamma {
            None if student_t => drop(physics::ndf(NdfKind::StudentT, unit, None)?),
            None => {}
            Some(gamma) => {
                non_empty("surface.gamma", gamma)?;
                let kind = if student_t { NdfKind::StudentT } else { s.ndf.values()[0] };
                for g in gamma.values() {
                    physics::ndf(kind, unit, Some(g))?;
                }
            }
        }
        let cases = self.cases();
        if cases > MAX_CASES {
            return Err(invalid(
                "the sweep (surface, material and incident lists)",
                format!("{cases} cases"),
                "at most 10^6 cases per run: split the sweep into several configs",
            ));
        }
        let materials = self.material.values();
        if materials.is_empty() {
            return Err(invalid("material", "[]", "at least one material"));
        }
        for (field, m) in self.material_fields() {
            physics::material(&field, m)?;
            if let Some(name) = m.name()
                && name.chars().count() > MAX_NAME_CHARS
            {
                return Err(invalid(
                    format!("{field}.name"),
                    format!("a name of {} characters", name.chars().count()),
                    format!("a label of at most {MAX_NAME_CHARS} characters (it heads table columns and figures)"),
                ));
            }
        }
        let i = &self.incident;
        if i.theta_deg.is_some() && i.theta_rad.is_some() {
            let [first, second] = ["incident.theta_deg", "incident.theta_rad"].map(String::from);
            return Err(ConfigError::Exclusive { first, second });
        }
        let (field, values, limit) = match (&i.theta_deg, &i.theta_rad) {
            (Some(d), _) => ("incident.theta_deg", d.values(), 90.0),
            (None, Some(r)) => ("incident.theta_rad", r.values(), std::f64::consts::FRAC_PI_2),
            (None, None) => {
                let allowed = allowed_value("incident.theta_deg").expect("described");
                return Err(missing("incident.theta_deg", allowed));
            }
        };
        if values.is_empty() {
            return Err(invalid(field, "[]", "at least one incident angle"));
        }
        for t in values {
            if !(t.is_finite() && (0.0..limit).contains(&t)) {
                return Err(invalid(field, t, format!("an angle in [0, {limit})")));
            }
        }
        non_empty("incident.phi_deg", &i.phi_deg)?;
        // One turn either way names every azimuth; a larger one (1e300) is a typo, not a direction.
        for p in i.phi_deg.values() {
            if !(p.is_finite() && (-360.0..=360.0).contains(&p)) {
                return Err(invalid("incident.phi_deg", p, "an azimuth in degrees in [-360, 360]"));
            }
        }
        non_empty("incident.side", &i.side)?;
        if i.side.values().contains(&IncidentSide::Inside)
            && let Some(m) = materials.iter().find(|m| !m.transmits())
        {
            return Err(invalid(
                "incident.side",
                "\"inside\"",
                format!("light from inside needs dielectric materials only, but a material is {}", m.kind()),
            ));
        }
        let d = &self.detector;
        if d.cos_theta_bins == 0 || d.cos_theta_bins > 4096 {
            return Err(invalid("detector.cos_theta_bins", d.cos_theta_bins, "an integer from 1 to 4096"));
        }
        if d.phi_bins == 0 || d.phi_bins > 4096 {
            return Err(invalid("detector.phi_bins", d.phi_bins, "an integer from 1 to 4096"));
        }
        if d.max_order == Some(0) {
            return Err(invalid("detector.max_order", 0, "an order >= 1 (left out: 64)"));
        }
        if let Some(p) = &self.precision {
            p.validate()?;
            if let Some(k) = d.max_order
                && p.orders > k as usize
            {
                return Err(invalid(
                    "precision.orders",
                    p.orders,
                    format!("at most detector.max_order = {k} (order slots above {k} do not exist)"),
                ));
            }
        }
        if let Some(c) = &self.compare {
            if c.models.is_empty() {
                return Err(invalid(
                    "compare.models",
                    "[]",
                    "at least one model, e.g. [\"single\"] (leave `[compare]` out to compare with none)",
                ));
            }
            for m in &c.models {
                let model = Model::parse(m).map_err(|allowed| invalid("compare.models", format!("{m:?}"), allowed))?;
                if let Some(reason) = model.refuses_threshold(self.energy.threshold) {
                    return Err(invalid("compare.models", format!("{m:?}"), reason));
                }
            }
            if let Some(p) = c.paths
                && !(2..=MAX_PATHS).contains(&p)
            {
                return Err(invalid("compare.paths", p, "from 2 to 10^15 photons per case"));
            }
        }
        let e = &self.energy;
        if !(e.threshold.is_finite() && (0.0..=1.0).contains(&e.threshold)) || (e.split && e.threshold == 0.0) {
            return Err(invalid(
                "energy.threshold",
                e.threshold,
                "a weight in (0, 1] when split = true (splitting stops below it), or in [0, 1] with split = false",
            ));
        }
        Ok(())
    }

    /// Every material with its name in errors: `material` for one table, `material[i]` in a
    /// list, as the text names it.
    pub fn material_fields(&self) -> impl Iterator<Item = (String, &MaterialConfig)> {
        self.material.as_slice().iter().enumerate().map(|(i, m)| match self.material {
            OneOrMany::One(_) => ("material".to_string(), m),
            OneOrMany::Many(_) => (format!("material[{i}]"), m),
        })
    }

    /// The number of cases of the sweep, without expanding it (saturating: a validated config
    /// has at most [`MAX_CASES`]).
    pub fn cases(&self) -> u64 {
        let s = &self.surface;
        let i = &self.incident;
        let thetas = i.theta_deg.as_ref().or(i.theta_rad.as_ref()).map_or(0, |t| t.as_slice().len());
        [
            s.ndf_shapes().len(),
            s.alpha.as_slice().len(),
            s.height.as_slice().len(),
            s.smith.as_slice().len(),
            s.normals.as_slice().len(),
            self.material.as_slice().len(),
            i.side.as_slice().len(),
            thetas,
            i.phi_deg.as_slice().len(),
        ]
        .into_iter()
        .fold(1u64, |n, len| n.saturating_mul(len as u64))
    }

    /// Whether the run carries three colour channels (any material parameter is `[r, g, b]`).
    pub fn is_rgb(&self) -> bool {
        self.material.values().iter().any(MaterialConfig::is_rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_run_tables_are_the_top_level_keys_of_a_run_config_but_paths_and_seed() {
        let config = Config::parse(
            "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n\
             [precision]\ntarget_stderr = 0.01\n[compare]\nmodels = [\"single\"]\n",
        )
        .unwrap();
        let document: toml::Table = toml::to_string(&config).unwrap().parse().unwrap();
        let mut keys: Vec<&str> =
            document.keys().map(String::as_str).filter(|k| !["paths", "seed"].contains(k)).collect();
        let mut tables = RUN_TABLES.to_vec();
        keys.sort_unstable();
        tables.sort_unstable();
        assert_eq!(keys, tables);
    }
}
