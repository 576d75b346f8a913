//! The values a configuration field holds: one value or a list (a sweep), roughnesses and
//! per-channel parameters.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::error::{ConfigError, invalid};

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
pub(super) fn number_or_list<'de, D: serde::Deserializer<'de>, const N: usize>(
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

pub(super) fn non_empty<T: Clone>(field: &str, v: &OneOrMany<T>) -> Result<(), ConfigError> {
    if v.values().is_empty() {
        return Err(invalid(field, "[]", "at least one value (an empty list expands to no cases)"));
    }
    Ok(())
}

pub(super) fn check_channels(
    field: String,
    c: Channels,
    ok: impl Fn(f64) -> bool,
    allowed: &str,
) -> Result<(), ConfigError> {
    for v in c.values() {
        if !(v.is_finite() && ok(v)) {
            return Err(invalid(field, c, allowed.to_string()));
        }
    }
    Ok(())
}

/// `names` as a list in words: `"a"`, `"a" or "b"`, `"a", "b" or "c"`, each quoted as TOML does.
pub(crate) fn either(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
    match quoted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Deserializes one of `variants` from its name (a string), as its `Serialize` writes it. Any
/// other value is refused with the names, in the user's terms, instead of serde's "unknown
/// variant" or "expected enum".
pub(crate) fn deserialize_named<'de, D: serde::Deserializer<'de>, T: Copy + Serialize>(
    d: D,
    variants: &[T],
) -> Result<T, D::Error> {
    struct Visitor<'a, T>(&'a [T], String);
    impl<'de, T: Copy + Serialize> serde::de::Visitor<'de> for Visitor<'_, T> {
        type Value = T;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str(&self.1)
        }
        fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<T, E> {
            self.0.iter().copied().find(|t| name(t) == v).ok_or_else(|| E::custom(&self.1))
        }
    }
    let names: Vec<String> = variants.iter().map(name).collect();
    d.deserialize_str(Visitor(variants, either(&names)))
}

/// Implements `Deserialize` for a unit enum by [`deserialize_named`] over all its variants.
macro_rules! deserialize_by_name {
    ($t:ty: [$($variant:expr),+ $(,)?]) => {
        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                $crate::setup::config::values::deserialize_named(d, &[$($variant),+])
            }
        }
    };
}
pub(crate) use deserialize_by_name;

/// The serde name of a config enum value (`"ggx"`, `"hammon-rejection"`, ...), as configs
/// spell it and the tables write it.
pub(crate) fn name<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}
