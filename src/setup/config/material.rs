//! The `[material]` tables: a facet material and its parameters, tagged by `kind`.

use serde::{Deserialize, Serialize};

use super::values::{Channels, number_or_list};

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FresnelKind {
    None,
    Schlick,
    Exact,
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
    /// The user's `name`, if given.
    pub fn name(&self) -> Option<&str> {
        match self {
            MaterialConfig::Conductor { name, .. }
            | MaterialConfig::Dielectric { name, .. }
            | MaterialConfig::Diffuse { name, .. }
            | MaterialConfig::Hammon { name, .. } => name.as_deref(),
        }
    }

    /// A short label for tables: the user's `name`, or the kind and its parameters.
    pub fn label(&self) -> String {
        if let Some(name) = self.name() {
            return name.to_string();
        }
        match self {
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

pub(super) fn fresnel_name(f: FresnelKind) -> &'static str {
    match f {
        FresnelKind::None => "none",
        FresnelKind::Schlick => "schlick",
        FresnelKind::Exact => "exact",
    }
}
