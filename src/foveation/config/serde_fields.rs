//! The functions serde's attributes on [`super::Layer`] and the config file name: defaults,
//! skip tests, and whole-number fields read with a message that says what they take.

use super::limits::{
    DEFAULT_BLEND_DEG, DEFAULT_DENOISE_SIGMA, DEFAULT_SPP, MAX_LAYER_SPP, MAX_SPACING,
};

/// serde's `skip_serializing_if = "..."` needs a function path.
pub(super) fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// serde's `skip_serializing_if = "..."` needs a function path.
pub(super) fn is_one(n: &u32) -> bool {
    *n == 1
}

/// serde's `default = "..."` needs a function path.
pub(super) fn one() -> u32 {
    1
}

/// serde's `skip_serializing_if = "..."` needs a function path.
pub(super) fn is_zero_f32(x: &f32) -> bool {
    *x == 0.0
}

/// serde's `default = "..."` needs a function path.
pub(super) fn default_denoise_sigma() -> f32 {
    DEFAULT_DENOISE_SIGMA
}

/// serde's `skip_serializing_if = "..."` needs a function path.
pub(super) fn is_default_denoise_sigma(x: &f32) -> bool {
    *x == DEFAULT_DENOISE_SIGMA
}

/// A layer's whole-number field, read with a message that says what it takes (serde's own
/// says "expected u32" for `spacing = -1` or `spp = 1.5`). The range is checked by `validate`.
#[derive(Clone, Copy)]
enum WholeNumber {
    Spacing,
    Spp,
}

impl serde::de::Visitor<'_> for WholeNumber {
    type Value = u32;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            WholeNumber::Spacing => write!(f, "a whole number of pixels from 1 to {MAX_SPACING}"),
            WholeNumber::Spp => write!(
                f,
                "a whole number of samples per target pixel from 1 to {MAX_LAYER_SPP}"
            ),
        }
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<u32, E> {
        u32::try_from(v).map_err(|_| E::invalid_value(serde::de::Unexpected::Signed(v), &self))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<u32, E> {
        u32::try_from(v).map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(v), &self))
    }
}

/// serde's `deserialize_with = "..."` needs a function path.
pub(super) fn deserialize_spacing<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    d.deserialize_u32(WholeNumber::Spacing)
}

/// serde's `deserialize_with = "..."` needs a function path.
pub(super) fn deserialize_spp<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    d.deserialize_u32(WholeNumber::Spp)
}

/// serde's `default = "..."` needs a function path.
pub(super) fn default_spp() -> u32 {
    DEFAULT_SPP
}

/// serde's `default = "..."` needs a function path.
pub(super) fn default_blend_deg() -> f32 {
    DEFAULT_BLEND_DEG
}
