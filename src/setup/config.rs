//! The TOML run configuration: parsing, defaults and validation.
//!
//! Every list-valued field is a sweep; [`crate::setup::cases`] expands the configuration into the
//! cartesian product of cases. Validation names the field, the value and what is allowed.

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

/// A field that takes one value or a list of values (a sweep). A list is a sweep, so
/// `alpha = [0.5, 1.0]` is two isotropic roughnesses and one anisotropic roughness is written
/// `[[0.5, 1.0]]`; it is always serialized as a list, so configs round-trip.
#[derive(Clone, Debug)]
pub enum OneOrMany<T> {
    Many(Vec<T>),
    One(T),
}

/// Decides by the input's shape (a list or one value) and hands it to `T`, so that an error
/// of `T` (an unknown variant, a missing field) reaches the user with its field and value
/// instead of serde's "did not match any variant of untagged enum".
impl<'de, T: Deserialize<'de>> Deserialize<'de> for OneOrMany<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::IntoDeserializer;
        use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
        struct Visitor<T>(std::marker::PhantomData<T>);
        macro_rules! one {
            ($($visit:ident: $t:ty),*) => {$(
                fn $visit<E: serde::de::Error>(self, v: $t) -> Result<Self::Value, E> {
                    T::deserialize(v.into_deserializer()).map(OneOrMany::One)
                }
            )*};
        }
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visitor<T> {
            type Value = OneOrMany<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("one value or a list of values")
            }
            one!(visit_bool: bool, visit_i64: i64, visit_u64: u64, visit_f64: f64, visit_str: &str);
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                Vec::<T>::deserialize(SeqAccessDeserializer::new(seq)).map(OneOrMany::Many)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                T::deserialize(MapAccessDeserializer::new(map)).map(OneOrMany::One)
            }
        }
        d.deserialize_any(Visitor(std::marker::PhantomData))
    }
}

/// Deserializes a number or a list of exactly `N` numbers (`what` says which, for errors).
fn number_or_list<'de, D: serde::Deserializer<'de>, const N: usize>(
    d: D,
    what: &'static str,
) -> Result<Result<f64, [f64; N]>, D::Error> {
    struct Visitor<const N: usize>(&'static str);
    impl<'de, const N: usize> serde::de::Visitor<'de> for Visitor<N> {
        type Value = Result<f64, [f64; N]>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str(self.0)
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
            Ok(Ok(v))
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
            Ok(Ok(v as f64))
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
            Ok(Ok(v as f64))
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut values = Vec::new();
            while let Some(v) = seq.next_element::<f64>()? {
                values.push(v);
            }
            let n = values.len();
            values.try_into().map(Err).map_err(|_| serde::de::Error::invalid_length(n, &self))
        }
    }
    d.deserialize_any(Visitor::<N>(what))
}

impl<T: Serialize> Serialize for OneOrMany<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.as_slice())
    }
}

impl<T> OneOrMany<T> {
    pub fn as_slice(&self) -> &[T] {
        match self {
            OneOrMany::One(v) => std::slice::from_ref(v),
            OneOrMany::Many(v) => v,
        }
    }
}

impl<T: Clone> OneOrMany<T> {
    pub fn values(&self) -> Vec<T> {
        self.as_slice().to_vec()
    }
}

/// Equal when they hold the same values: `x` and `[x]` are the same sweep.
impl<T: PartialEq> PartialEq for OneOrMany<T> {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

/// A roughness entry: `0.5` (isotropic) or `[alpha_x, alpha_y]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Alpha {
    Isotropic(f64),
    Anisotropic([f64; 2]),
}

impl<'de> Deserialize<'de> for Alpha {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let what = "a roughness alpha or an anisotropic pair [alpha_x, alpha_y]";
        Ok(number_or_list::<D, 2>(d, what)?.map_or_else(Alpha::Anisotropic, Alpha::Isotropic))
    }
}

impl Alpha {
    pub fn xy(self) -> (f64, f64) {
        match self {
            Alpha::Isotropic(a) => (a, a),
            Alpha::Anisotropic([x, y]) => (x, y),
        }
    }
}

/// A per-channel parameter: one value for all channels or `[r, g, b]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Channels {
    Mono(f64),
    Rgb([f64; 3]),
}

impl<'de> Deserialize<'de> for Channels {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let what = "one value for all channels or three values [r, g, b]";
        Ok(number_or_list::<D, 3>(d, what)?.map_or_else(Channels::Rgb, Channels::Mono))
    }
}

impl Channels {
    pub fn is_rgb(self) -> bool {
        matches!(self, Channels::Rgb(_))
    }

    /// The values for `C` channels (a mono value is repeated).
    pub fn to_array<const C: usize>(self) -> [f64; C] {
        match self {
            Channels::Mono(v) => [v; C],
            Channels::Rgb(rgb) => std::array::from_fn(|i| rgb[i.min(2)]),
        }
    }

    /// The value of channel `channel` (0 = r, 1 = g, 2 = b; a mono value is every channel's).
    pub fn channel(self, channel: usize) -> f64 {
        self.to_array::<3>()[channel]
    }

    fn values(self) -> Vec<f64> {
        match self {
            Channels::Mono(v) => vec![v],
            Channels::Rgb(rgb) => rgb.to_vec(),
        }
    }
}

impl fmt::Display for Channels {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Channels::Mono(v) => write!(f, "{v}"),
            Channels::Rgb([r, g, b]) => write!(f, "[{r}, {g}, {b}]"),
        }
    }
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum NdfKind {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum HeightKind {
    Uniform,
    Gaussian,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SmithKind {
    Exact,
    Symmetric,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum NormalsKind {
    Vndf,
    HammonRejection,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FresnelKind {
    None,
    Schlick,
    Exact,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum IncidentSide {
    Outside,
    Inside,
}

/// A facet material (`[material]` or `[[material]]` entries), tagged by `kind`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialConfig {
    Conductor {
        #[serde(default = "fresnel_none")]
        fresnel: FresnelKind,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        f0: Option<Channels>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<Channels>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        k: Option<Channels>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Dielectric {
        #[serde(deserialize_with = "relative_index")]
        eta: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Diffuse {
        #[serde(default = "unit_channels")]
        albedo: Channels,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Hammon {
        #[serde(default = "hammon_f0")]
        f0: Channels,
        #[serde(default = "unit_channels")]
        albedo: Channels,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
}

/// A dielectric's `eta`: one number, so that a list gets an error that says why.
fn relative_index<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let what = "one number, the relative index n_inside / n_outside of every channel (an index per channel, dispersion, is not modelled)";
    number_or_list::<D, 3>(d, what)?.map_err(|_| serde::de::Error::invalid_type(serde::de::Unexpected::Seq, &what))
}

fn fresnel_none() -> FresnelKind {
    FresnelKind::None
}
fn unit_channels() -> Channels {
    Channels::Mono(1.0)
}
/// Hammon 2017 uses F0 = 0.02 (water-like dielectric).
fn hammon_f0() -> Channels {
    Channels::Mono(0.02)
}

impl MaterialConfig {
    /// A short label for tables: the user's `name`, or the kind and its parameters.
    pub fn label(&self) -> String {
        match self {
            MaterialConfig::Conductor { name: Some(n), .. }
            | MaterialConfig::Dielectric { name: Some(n), .. }
            | MaterialConfig::Diffuse { name: Some(n), .. }
            | MaterialConfig::Hammon { name: Some(n), .. } => n.clone(),
            MaterialConfig::Conductor { fresnel, f0, eta, k, .. } => match fresnel {
                FresnelKind::None => "conductor F=1".into(),
                FresnelKind::Schlick => format!("conductor schlick f0={}", f0.unwrap_or(Channels::Mono(f64::NAN))),
                FresnelKind::Exact => format!(
                    "conductor eta={} k={}",
                    eta.unwrap_or(Channels::Mono(f64::NAN)),
                    k.unwrap_or(Channels::Mono(f64::NAN))
                ),
            },
            MaterialConfig::Dielectric { eta, .. } => format!("dielectric eta={eta}"),
            MaterialConfig::Diffuse { albedo, .. } => format!("diffuse albedo={albedo}"),
            MaterialConfig::Hammon { f0, albedo, .. } => format!("hammon f0={f0} albedo={albedo}"),
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            MaterialConfig::Conductor { .. } => "conductor",
            MaterialConfig::Dielectric { .. } => "dielectric",
            MaterialConfig::Diffuse { .. } => "diffuse",
            MaterialConfig::Hammon { .. } => "hammon",
        }
    }

    /// Whether light can pass to the other side (only dielectrics transmit).
    pub fn transmits(&self) -> bool {
        matches!(self, MaterialConfig::Dielectric { .. })
    }

    fn channel_params(&self) -> Vec<Channels> {
        match self {
            MaterialConfig::Conductor { f0, eta, k, .. } => [f0, eta, k].into_iter().flatten().copied().collect(),
            MaterialConfig::Dielectric { .. } => vec![],
            MaterialConfig::Diffuse { albedo, .. } => vec![*albedo],
            MaterialConfig::Hammon { f0, albedo, .. } => vec![*f0, *albedo],
        }
    }

    pub fn is_rgb(&self) -> bool {
        self.channel_params().iter().any(|c| c.is_rgb())
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceConfig {
    #[serde(default = "default_ndf")]
    pub ndf: OneOrMany<NdfKind>,
    pub alpha: OneOrMany<Alpha>,
    #[serde(default = "default_height")]
    pub height: OneOrMany<HeightKind>,
    #[serde(default = "default_smith")]
    pub smith: OneOrMany<SmithKind>,
    #[serde(default = "default_normals")]
    pub normals: OneOrMany<NormalsKind>,
}

fn default_ndf() -> OneOrMany<NdfKind> {
    OneOrMany::One(NdfKind::Ggx)
}
fn default_height() -> OneOrMany<HeightKind> {
    OneOrMany::One(HeightKind::Uniform)
}
fn default_smith() -> OneOrMany<SmithKind> {
    OneOrMany::One(SmithKind::Exact)
}
fn default_normals() -> OneOrMany<NormalsKind> {
    OneOrMany::One(NormalsKind::Vndf)
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IncidentConfig {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_deg: Option<OneOrMany<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_rad: Option<OneOrMany<f64>>,
    #[serde(default = "default_phi")]
    pub phi_deg: OneOrMany<f64>,
    #[serde(default = "default_side")]
    pub side: OneOrMany<IncidentSide>,
}

fn default_phi() -> OneOrMany<f64> {
    OneOrMany::One(0.0)
}
fn default_side() -> OneOrMany<IncidentSide> {
    OneOrMany::One(IncidentSide::Outside)
}

impl IncidentConfig {
    /// The incident polar angles in degrees, whichever unit the config used.
    pub fn theta_degrees(&self) -> Vec<f64> {
        match (&self.theta_deg, &self.theta_rad) {
            (Some(d), _) => d.values(),
            (None, Some(r)) => r.values().into_iter().map(f64::to_degrees).collect(),
            (None, None) => vec![],
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DetectorConfig {
    #[serde(default = "default_cos_bins")]
    pub cos_theta_bins: usize,
    #[serde(default = "default_phi_bins")]
    pub phi_bins: usize,
    /// Orders `>= max_order` are folded into the last order, "K+". The walk is not capped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_order: Option<u32>,
}

fn default_cos_bins() -> usize {
    32
}
fn default_phi_bins() -> usize {
    64
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self { cos_theta_bins: default_cos_bins(), phi_bins: default_phi_bins(), max_order: None }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EnergyConfig {
    #[serde(default = "default_split")]
    pub split: bool,
    #[serde(default = "default_threshold")]
    pub threshold: f64,
}

fn default_split() -> bool {
    true
}
fn default_threshold() -> f64 {
    0.1
}

impl Default for EnergyConfig {
    fn default() -> Self {
        Self { split: default_split(), threshold: default_threshold() }
    }
}

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
    /// Energy compensation of Kulla & Conty 2017, all orders (`analysis::compensation`).
    KullaConty,
    /// Energy compensation of Turquin 2019, all orders.
    Turquin,
    /// Energy compensation of Fdez-Agüera 2019, all orders.
    FdezAguera,
    /// A user's own model read from a file (`smithwalk compare --external`); not in [`Model::ALL`].
    External,
}

impl Model {
    pub const ALL: [Model; 9] = [
        Model::Single,
        Model::HammonFit,
        Model::HeitzNee,
        Model::WangCorrelated,
        Model::WangUncorrelated,
        Model::ExactPositionFree,
        Model::KullaConty,
        Model::Turquin,
        Model::FdezAguera,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Model::Single => "single",
            Model::HammonFit => "hammon-fit",
            Model::HeitzNee => "heitz-nee",
            Model::WangCorrelated => "wang-correlated",
            Model::WangUncorrelated => "wang-uncorrelated",
            Model::ExactPositionFree => "exact-position-free",
            Model::KullaConty => "kulla-conty",
            Model::Turquin => "turquin",
            Model::FdezAguera => "fdez-aguera",
            Model::External => "external",
        }
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
    /// `wang-uncorrelated`, `kulla-conty`, `turquin`, `fdez-aguera`.
    pub models: Vec<String>,
    /// Photons per case for the Monte Carlo models (default: the run's `paths`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paths: Option<u64>,
}

/// A precision target: a case stops at the first round of chunks after which every nonzero
/// albedo of order slots `0..=orders` (both hemispheres, channel 0) has a standard error of at
/// most `target_stderr` and a relative standard error of at most `target_rel_stderr` (each
/// when given; at least one must be); `paths` is then the maximum.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PrecisionConfig {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_rel_stderr: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_stderr: Option<f64>,
    #[serde(default = "default_precision_orders")]
    pub orders: usize,
}

fn default_precision_orders() -> usize {
    1
}

impl PrecisionConfig {
    fn validate(&self) -> Result<(), ConfigError> {
        if self.target_rel_stderr.is_none() && self.target_stderr.is_none() {
            return Err(invalid("precision", "{}", "a `target_rel_stderr` or a `target_stderr` (or both)"));
        }
        let targets =
            [("precision.target_rel_stderr", self.target_rel_stderr), ("precision.target_stderr", self.target_stderr)];
        for (field, target) in targets {
            if let Some(t) = target
                && !(t.is_finite() && t > 0.0)
            {
                return Err(invalid(field, t, "a standard error > 0"));
            }
        }
        Ok(())
    }
}

/// The most photons per case.
pub const MAX_PATHS: u64 = 1_000_000_000_000_000;

/// The roughest surface a walk supports. A walk makes about `alpha` bounces (order 1152 at
/// alpha 1e3, 105 770 at 1e5 at 60 deg, 64 photons): at 1e6, 14% of the energy passes the
/// 2^20-interaction cap and is lost as runaway, so 1e4 keeps a factor of 100 to it (measured,
/// docs/reliability.md).
pub const MAX_ALPHA: f64 = 1e4;

/// The tables of a run config (`smithwalk run`), every top-level key but `paths` and `seed`; a
/// table config (`smithwalk lut`) has none of them.
pub const RUN_TABLES: [&str; 7] = ["surface", "material", "incident", "detector", "energy", "precision", "compare"];

/// The most cases a sweep may expand to.
pub const MAX_CASES: u64 = 1_000_000;

fn default_seed() -> u64 {
    1
}

/// A configuration error: which field, which value, and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The cause is part of the message and not the error's `source`, so that a chain of
    /// errors (`{:#}`) prints it once.
    #[error("cannot read config {path}: {cause}")]
    Read { path: String, cause: std::io::Error },
    #[error("config {path} is not valid: {message}")]
    Parse { path: String, message: String },
    #[error("`{field}` = {value} is not allowed: {allowed}")]
    Invalid { field: String, value: String, allowed: String },
    /// A required table or key that is absent; `place` is empty or says where it belongs.
    #[error("`{field}` is missing{place}: {allowed}")]
    Missing { field: String, place: String, allowed: String },
    /// Two keys that say the same thing in different ways, of which one at most may be given.
    #[error("`{first}` and `{second}` are both given: give one of them")]
    Exclusive { first: String, second: String },
}

impl ConfigError {
    /// The error as found in the config `path` (a file, `<text>` or `<dict>`): errors of its
    /// text or values name it; an unreadable file already does.
    pub fn in_source(self, path: &str) -> Self {
        match self {
            ConfigError::Parse { message, .. } => ConfigError::Parse { path: path.into(), message },
            ConfigError::Read { .. } => self,
            _ => ConfigError::Parse { path: path.into(), message: self.to_string() },
        }
    }
}

impl ConfigError {
    /// The error as caused by the command-line `option` that overrode its field: a value the
    /// user typed on the command line is named as they typed it.
    pub fn from_option(self, option: &str) -> Self {
        match self {
            ConfigError::Invalid { value, allowed, .. } => {
                ConfigError::Invalid { field: option.into(), value, allowed }
            }
            e => e,
        }
    }
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

pub(crate) fn invalid(field: impl Into<String>, value: impl fmt::Display, allowed: impl Into<String>) -> ConfigError {
    ConfigError::Invalid { field: field.into(), value: value.to_string(), allowed: allowed.into() }
}

/// A required table or key that is absent, with what it should be.
fn missing(field: impl Into<String>, allowed: impl Into<String>) -> ConfigError {
    ConfigError::Missing { field: field.into(), place: String::new(), allowed: allowed.into() }
}

impl Config {
    /// Reads, parses and validates a TOML configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|cause| ConfigError::Read { path: path.display().to_string(), cause })?;
        Self::parse(&text).map_err(|e| e.in_source(&path.display().to_string()))
    }

    /// Parses and validates TOML text; errors name it `<text>`.
    pub fn parse(text: &str) -> Result<Self, ConfigError> {
        if let Ok(document) = text.parse::<toml::Table>() {
            not_a_table_config(&document).map_err(|e| e.in_source("<text>"))?;
        }
        let config: Config = parse_toml(text)?;
        config.validate().map_err(|e| e.in_source("<text>"))?;
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
        config.validate().map_err(in_dict)?;
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
        for a in s.alpha.values() {
            let (x, y) = a.xy();
            for v in [x, y] {
                if !(v.is_finite() && v > 0.0 && v <= MAX_ALPHA) {
                    return Err(invalid(
                        "surface.alpha",
                        v,
                        "a roughness > 0 and at most 1e4: a walk makes about alpha bounces, and from alpha ~1e6 on walks \
                         pass the 2^20-interaction cap and are lost (docs/reliability.md)",
                    ));
                }
            }
        }
        let cases = crate::setup::cases::count(self);
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
        for (i, m) in materials.iter().enumerate() {
            // Named as the text names it: `material` for one table, `material[i]` in a list.
            let field = match self.material {
                OneOrMany::One(_) => "material".to_string(),
                OneOrMany::Many(_) => format!("material[{i}]"),
            };
            validate_material(&field, m)?;
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
                let allowed = required("incident.theta_deg").expect("described");
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
        for p in i.phi_deg.values() {
            if !p.is_finite() {
                return Err(invalid("incident.phi_deg", p, "a finite azimuth in degrees"));
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
            return Err(invalid("detector.max_order", 0, "an order >= 1, or leave it out to keep every order"));
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
            for m in &c.models {
                Model::parse(m).map_err(|allowed| invalid("compare.models", format!("{m:?}"), allowed))?;
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

    /// Whether the run carries three colour channels (any material parameter is `[r, g, b]`).
    pub fn is_rgb(&self) -> bool {
        self.material.values().iter().any(MaterialConfig::is_rgb)
    }
}

/// Deserializes TOML text; an error is one line naming the field (its dotted path), the value
/// as written (shortened) and what is allowed, whatever the input's size.
pub fn parse_toml<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, ConfigError> {
    parse_toml_with(text, true)
}

/// [`parse_toml`], with the errors' line numbers only when `lines` (text made from a dict has
/// lines the user never saw).
fn parse_toml_with<T: serde::de::DeserializeOwned>(text: &str, lines: bool) -> Result<T, ConfigError> {
    let parse = |message: String| ConfigError::Parse { path: "<text>".into(), message };
    let shown = |line: Option<usize>| line.filter(|_| lines);
    let line_of =
        |e: &toml::de::Error| shown(e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1));
    let at = |e: &toml::de::Error| at_line(line_of(e));
    let deserializer = toml::de::Deserializer::parse(text)
        .map_err(|e| parse(format!("not TOML{}: {}", at(&e), shorten(e.message(), MESSAGE_CHARS))))?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.inner();
        let value = inner.span().and_then(|s| text.get(s)).map_or("?".to_string(), |v| shorten(v, VALUE_CHARS));
        let allowed = shorten(&in_user_terms(&field, inner.message()), MESSAGE_CHARS);
        // Keys inside a material (a table tagged by `kind`) are not on serde's path.
        let key = |prefix: &str| inner.message().strip_prefix(prefix).and_then(|m| m.split('`').next());
        let line = at(inner);
        match (key("unknown field `"), key("missing field `")) {
            (Some(k), _) => {
                let field = if field.ends_with(k) { field } else { format!("{field}.{k}") };
                parse(format!("`{field}` is not a known key{line}: {allowed}"))
            }
            // At the top level the span is the whole text: no line says where the key belongs.
            (None, Some(k)) if field == "." => {
                let field = if RUN_TABLES.contains(&k) { format!("[{k}]") } else { k.to_string() };
                let allowed = required(k).unwrap_or(allowed);
                parse(ConfigError::Missing { field, place: String::new(), allowed }.to_string())
            }
            (None, Some(k)) => {
                // The span of a table of `[[material]]` is that of the first one.
                let line = match material_index(&field) {
                    Some(Some(i)) => shown(material_header(&text.lines().collect::<Vec<_>>(), Some(i)).map(|h| h + 1)),
                    _ => line_of(inner),
                };
                let place = line.map_or(String::new(), |n| format!(" from the table at line {n}"));
                let allowed = required(&format!("{}.{k}", without_indices(&field))).unwrap_or(allowed);
                parse(ConfigError::Missing { field: format!("{field}.{k}"), place, allowed }.to_string())
            }
            _ if field == "." => parse(format!("{allowed}{line}")),
            _ => match material_culprit(text, &field, inner.message()) {
                Some(Culprit { key, value, line }) => {
                    let line = at_line(shown(line));
                    parse(format!("`{field}.{key}` = {value} is not allowed{line}: {allowed}"))
                }
                None => parse(format!("`{field}` = {value} is not allowed{line}: {allowed}")),
            },
        }
    })
}

/// serde's `message` about `field` with Rust's type names said in user terms: `expected u64`
/// is an integer in the field's range, `expected f64` a number.
fn in_user_terms(field: &str, message: &str) -> String {
    let integer = match without_indices(field).as_str() {
        "paths" | "compare.paths" => "an integer from 2 to 10^15, e.g. 1000000 or 1_000_000",
        "seed" => "an integer >= 0",
        "detector.cos_theta_bins" | "detector.phi_bins" => "an integer from 1 to 4096",
        _ => "an integer >= 1",
    };
    ["u64", "usize", "u32"]
        .into_iter()
        .fold(message.to_string(), |m, rust| m.replace(&format!("expected {rust}"), &format!("expected {integer}")))
        .replace("expected f64", "expected a number")
}

/// ` (line n)`, or nothing without a line.
fn at_line(line: Option<usize>) -> String {
    line.map_or(String::new(), |n| format!(" (line {n})"))
}

/// `field` without its list indices: `material[1].eta` is `material.eta`.
fn without_indices(field: &str) -> String {
    field.split('[').map(|part| part.split_once(']').map_or(part, |(_, rest)| rest)).collect()
}

/// What a required table or key (its dotted path without list indices) should be, for the
/// error that says it is missing.
fn required(key: &str) -> Option<String> {
    let kinds = "\"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"";
    Some(match key {
        "paths" => "photons per case, from 2 to 10^15".into(),
        "table" => "the table config's facet, \"conductor\", \"dielectric\" or \"hammon\"".into(),
        "surface" => "a table with `alpha`, the roughness".into(),
        "material" => format!("a table with `kind` = {kinds}, or several `[[material]]` tables"),
        "incident" => "a table with `theta_deg` or `theta_rad`, the incident polar angles".into(),
        "surface.alpha" => "a roughness > 0 and at most 1e4, a list of them (a sweep) or [[alpha_x, alpha_y]]".into(),
        "material.kind" => kinds.into(),
        "material.eta" => "the relative index n_inside / n_outside, > 0 and != 1".into(),
        "incident.theta_deg" => {
            "a polar angle in [0, 90) or a list of them (or `theta_rad`, in radians, in [0, pi/2))".into()
        }
        "compare.models" => {
            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
            format!("a list of models from {}", names.join(", "))
        }
        _ => return None,
    })
}

/// The key of a material table whose value is wrong, its value and its line.
struct Culprit {
    key: String,
    value: String,
    line: Option<usize>,
}

/// Which key of the material at `field` (`material` or `material[i]`) causes the error
/// `message`. Serde reports errors of values inside a material at the whole table, since the
/// table is tagged by `kind` and read as a whole before its keys are; the culprit is the key
/// whose removal makes the error go away or change. Its line is that of the key after the
/// table's header (none for an inline table).
fn material_culprit(text: &str, field: &str, message: &str) -> Option<Culprit> {
    let document: toml::Table = toml::from_str(text).ok()?;
    let index = material_index(field)?;
    let table = match (document.get("material")?, index) {
        (toml::Value::Table(t), None) => t,
        (toml::Value::Array(a), Some(i)) => a.get(i)?.as_table()?,
        _ => return None,
    };
    let key = table.keys().filter(|k| *k != "kind").find(|k| {
        let mut without = table.clone();
        without.remove(k.as_str());
        MaterialConfig::deserialize(toml::Value::Table(without)).map_or_else(|e| e.message() != message, |_| true)
    })?;
    let value = shorten(&table[key].to_string(), VALUE_CHARS);
    // The key's line: the first `key =` after the header of the material's table.
    let lines: Vec<&str> = text.lines().collect();
    let line = material_header(&lines, index).and_then(|h| {
        lines[h + 1..]
            .iter()
            .take_while(|l| !l.trim_start().starts_with('['))
            .position(|l| l.split('=').next().is_some_and(|k| k.trim() == key))
            .map(|n| h + 1 + n + 1)
    });
    Some(Culprit { key: key.clone(), value, line })
}

/// Which material `field` names: `Some(None)` for `material` (one table), `Some(Some(i))` for
/// `material[i]`, `None` for any other field.
fn material_index(field: &str) -> Option<Option<usize>> {
    match field.strip_prefix("material")? {
        "" => Some(None),
        rest => Some(Some(rest.strip_prefix('[')?.strip_suffix(']')?.parse::<usize>().ok()?)),
    }
}

/// The index (from 0) of the line of the header of material `index` (`[material]`, or the
/// `index`-th `[[material]]`); none for inline tables.
fn material_header(lines: &[&str], index: Option<usize>) -> Option<usize> {
    let is_header = |l: &str| {
        let l: String = l.chars().filter(|c| !c.is_whitespace()).collect();
        l == "[material]" || l == "[[material]]"
    };
    lines.iter().enumerate().filter(|(_, l)| is_header(l)).nth(index.unwrap_or(0)).map(|(n, _)| n)
}

/// Longest quoted value and message in a config error.
const VALUE_CHARS: usize = 60;
const MESSAGE_CHARS: usize = 300;

/// `text` on one line (runs of whitespace as one space), cut in the middle to at most `max`
/// characters: long inputs are quoted shortened, never echoed whole.
pub fn shorten(text: &str, max: usize) -> String {
    let one_line = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    if text.chars().nth(max).is_none() {
        return one_line(text);
    }
    let head: String = text.chars().take(max / 2).collect();
    let tail: String = text.chars().rev().take(max / 2).collect::<Vec<_>>().into_iter().rev().collect();
    format!("{} … {} ({} bytes)", one_line(&head), one_line(&tail), text.len())
}

fn non_empty<T: Clone>(field: &str, v: &OneOrMany<T>) -> Result<(), ConfigError> {
    if v.values().is_empty() {
        return Err(invalid(field, "[]", "at least one value (an empty list expands to no cases)"));
    }
    Ok(())
}

fn check_channels(field: String, c: Channels, ok: impl Fn(f64) -> bool, allowed: &str) -> Result<(), ConfigError> {
    for v in c.values() {
        if !(v.is_finite() && ok(v)) {
            return Err(invalid(field, c, allowed.to_string()));
        }
    }
    Ok(())
}

fn validate_material(field: &str, m: &MaterialConfig) -> Result<(), ConfigError> {
    let unit = |v: f64| (0.0..=1.0).contains(&v);
    match m {
        MaterialConfig::Conductor { fresnel, f0, eta, k, .. } => {
            // Each parameter: the Fresnel kind that uses it (and needs it), and its range.
            let params = [
                ("f0", f0, FresnelKind::Schlick, unit as fn(f64) -> bool, "a reflectance in [0, 1]"),
                ("eta", eta, FresnelKind::Exact, |v| v > 0.0, "the real part of the index, > 0"),
                ("k", k, FresnelKind::Exact, |v| v >= 0.0, "the extinction coefficient, >= 0"),
            ];
            for (name, value, user, ok, allowed) in params {
                let key = format!("{field}.{name}");
                let allowed = format!("{allowed}, or one per channel [r, g, b]");
                let (kind, user) = (fresnel_name(*fresnel), fresnel_name(user));
                match value {
                    None if kind == user => return Err(missing(key, format!("fresnel = \"{user}\" needs {allowed}"))),
                    Some(c) if kind != user => {
                        let allowed = format!("`{name}` is used only with fresnel = \"{user}\", not \"{kind}\"");
                        return Err(invalid(key, c, allowed));
                    }
                    Some(c) => check_channels(key, *c, ok, &allowed)?,
                    None => {}
                }
            }
        }
        MaterialConfig::Dielectric { eta, .. } => {
            if !(eta.is_finite() && *eta > 0.0 && *eta != 1.0) {
                return Err(invalid(
                    format!("{field}.eta"),
                    eta,
                    "a relative index n_inside / n_outside > 0 and != 1 (an index-matched interface is invisible)",
                ));
            }
        }
        MaterialConfig::Diffuse { albedo, .. } => {
            check_channels(format!("{field}.albedo"), *albedo, unit, "albedos in [0, 1]")?;
        }
        MaterialConfig::Hammon { f0, albedo, .. } => {
            check_channels(format!("{field}.f0"), *f0, unit, "reflectances in [0, 1]")?;
            check_channels(format!("{field}.albedo"), *albedo, unit, "albedos in [0, 1]")?;
        }
    }
    Ok(())
}

fn fresnel_name(f: FresnelKind) -> &'static str {
    match f {
        FresnelKind::None => "none",
        FresnelKind::Schlick => "schlick",
        FresnelKind::Exact => "exact",
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
