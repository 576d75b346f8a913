//! The `[material]` tables: a facet material and its parameters, tagged by `kind`.

use std::fmt;

use serde::de::{Error, MapAccess};
use serde::{Deserialize, Serialize};

use super::values::{Channels, deserialize_by_name, number_or_list};

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FresnelKind {
    None,
    Schlick,
    Exact,
}

deserialize_by_name!(FresnelKind: [FresnelKind::None, FresnelKind::Schlick, FresnelKind::Exact]);

/// A facet material (`[material]` or `[[material]]` entries), tagged by `kind`. It is read key
/// by key ([`MaterialConfig::deserialize`]), so that an error names the key and its value, where
/// serde's internally tagged enums read the table whole and report it as a whole.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum MaterialConfig {
    Conductor {
        fresnel: FresnelKind,
        #[serde(skip_serializing_if = "Option::is_none")]
        f0: Option<Channels>,
        #[serde(skip_serializing_if = "Option::is_none")]
        eta: Option<Channels>,
        #[serde(skip_serializing_if = "Option::is_none")]
        k: Option<Channels>,
        #[serde(skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Dielectric {
        eta: f64,
        #[serde(skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Diffuse {
        albedo: Channels,
        #[serde(skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
    Hammon {
        f0: Channels,
        albedo: Channels,
        #[serde(skip_serializing_if = "Option::is_none")]
        name: Option<String>,
    },
}

/// The `kind` of a material.
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum Kind {
    Conductor,
    Dielectric,
    Diffuse,
    Hammon,
}

deserialize_by_name!(Kind: [Kind::Conductor, Kind::Dielectric, Kind::Diffuse, Kind::Hammon]);

impl Kind {
    /// The keys a material of this kind takes.
    fn keys(self) -> &'static [&'static str] {
        match self {
            Kind::Conductor => &["kind", "fresnel", "f0", "eta", "k", "name"],
            Kind::Dielectric => &["kind", "eta", "name"],
            Kind::Diffuse => &["kind", "albedo", "name"],
            Kind::Hammon => &["kind", "f0", "albedo", "name"],
        }
    }
}

/// Every key of some kind of material.
const KEYS: [&str; 7] = ["kind", "fresnel", "f0", "eta", "k", "albedo", "name"];

/// The prefix of an error about the value of `key` in a table read whole (a material), which
/// serde's path stops short of: `key `eta`: ...`. Reading a config
/// ([`super::reading`]) puts the key on the path and the message after the value.
pub(super) const KEY_ERROR: &str = "key `";

fn key_error<E: Error>(key: &str, message: &str) -> E {
    E::custom(format_args!("{KEY_ERROR}{key}`: {message}"))
}

/// What a dielectric's `eta` is: one number.
const RELATIVE_INDEX: &str = "one number, the relative index n_inside / n_outside of every channel (an index per channel, \
                              dispersion, is not modelled)";

impl<'de> Deserialize<'de> for MaterialConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = MaterialConfig;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a table with `kind` = \"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<MaterialConfig, A::Error> {
                let mut kind = None;
                let mut fresnel = None;
                let [mut f0, mut eta, mut k, mut albedo] = [None; 4];
                let mut name = None;
                let mut unknown = None;
                while let Some(key) = map.next_key::<String>()? {
                    // Each value is read where it stands, so that its errors carry its key and place.
                    match key.as_str() {
                        "kind" if kind.is_none() => kind = Some(map.next_value::<Kind>()?),
                        "fresnel" if fresnel.is_none() => fresnel = Some(map.next_value::<FresnelKind>()?),
                        "eta" if eta.is_none() && kind == Some(Kind::Dielectric) => {
                            eta = Some(Channels::Mono(map.next_value::<RelativeIndex>()?.0))
                        }
                        "f0" if f0.is_none() => f0 = Some(map.next_value::<Channels>()?),
                        "eta" if eta.is_none() => eta = Some(map.next_value::<Channels>()?),
                        "k" if k.is_none() => k = Some(map.next_value::<Channels>()?),
                        "albedo" if albedo.is_none() => albedo = Some(map.next_value::<Channels>()?),
                        "name" if name.is_none() => name = Some(map.next_value::<String>()?),
                        key if KEYS.contains(&key) => return Err(key_error(key, "a key given once")),
                        // Reported once the kind, which says the keys allowed, is known.
                        _ => {
                            map.next_value::<serde::de::IgnoredAny>()?;
                            unknown.get_or_insert(key);
                        }
                    }
                }
                if let Some(key) = unknown {
                    return Err(Error::unknown_field(&key, kind.map_or(&KEYS[..], Kind::keys)));
                }
                let kind = kind.ok_or_else(|| Error::missing_field("kind"))?;
                let given = [
                    ("fresnel", fresnel.is_some()),
                    ("f0", f0.is_some()),
                    ("eta", eta.is_some()),
                    ("k", k.is_some()),
                    ("albedo", albedo.is_some()),
                ];
                if let Some((key, _)) = given.iter().find(|(key, given)| *given && !kind.keys().contains(key)) {
                    return Err(Error::unknown_field(key, kind.keys()));
                }
                Ok(match kind {
                    Kind::Conductor => {
                        MaterialConfig::Conductor { fresnel: fresnel.unwrap_or(FresnelKind::None), f0, eta, k, name }
                    }
                    Kind::Dielectric => match eta {
                        Some(Channels::Mono(eta)) => MaterialConfig::Dielectric { eta, name },
                        Some(Channels::Rgb(_)) => return Err(key_error("eta", RELATIVE_INDEX)),
                        None => return Err(Error::missing_field("eta")),
                    },
                    Kind::Diffuse => MaterialConfig::Diffuse { albedo: albedo.unwrap_or(unit_channels()), name },
                    Kind::Hammon => MaterialConfig::Hammon {
                        f0: f0.unwrap_or(hammon_f0()),
                        albedo: albedo.unwrap_or(unit_channels()),
                        name,
                    },
                })
            }
        }
        d.deserialize_map(Visitor)
    }
}

/// A dielectric's `eta`: one number, so that a list gets an error that says why.
struct RelativeIndex(f64);

impl<'de> Deserialize<'de> for RelativeIndex {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        number_or_list::<D, 3>(d, RELATIVE_INDEX)?.map(RelativeIndex).map_err(|_| Error::custom(RELATIVE_INDEX))
    }
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
