//! Fixed-length arrays read strictly: `#[serde(deserialize_with = "world_form::exact::array")]`
//! on a `[f64; N]` field (and [`vec_of_arrays`] on a `Vec<[f64; N]>`).
//!
//! serde reads a `[f64; N]` by taking N elements of the sequence; whether it refuses more is
//! up to the format: JSON (and so the Python dicts of the wheel) does, TOML does not, so a
//! scene file's `normal = [0, 0, 1, 5]` would lose its fourth element without a word. These
//! helpers read the whole sequence and refuse any other length with serde's
//! `invalid length` error, which each format places at the value (TOML: its line and column).

use serde::de::{Deserialize, Deserializer, Error, Expected};
use std::fmt;

struct Numbers(usize);

impl Expected for Numbers {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of {} numbers", self.0)
    }
}

fn exact<E: Error, const N: usize>(v: Vec<f64>) -> Result<[f64; N], E> {
    <[f64; N]>::try_from(v.as_slice()).map_err(|_| E::invalid_length(v.len(), &Numbers(N)))
}

/// A `[f64; N]` that must have exactly N elements.
pub fn array<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
    exact(Vec::<f64>::deserialize(d)?)
}

/// An optional `[f64; N]` (absent or `None`), exactly N elements when present.
pub fn option_array<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<Option<[f64; N]>, D::Error> {
    Option::<Vec<f64>>::deserialize(d)?.map(exact).transpose()
}

/// A `Vec<[f64; N]>` whose every element has exactly N numbers.
pub fn vec_of_arrays<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<Vec<[f64; N]>, D::Error> {
    Vec::<Vec<f64>>::deserialize(d)?
        .into_iter()
        .map(exact)
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    #[derive(Debug, serde::Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct T {
        #[serde(deserialize_with = "super::array")]
        normal: [f64; 3],
        #[serde(default, deserialize_with = "super::vec_of_arrays")]
        slots: Vec<[f64; 2]>,
    }

    #[test]
    fn toml_refuses_other_lengths_at_the_value() {
        let ok: T = toml::from_str("normal = [0.0, 0.0, 1.0]\nslots = [[1.0, 2.0]]\n").unwrap();
        assert_eq!(ok.normal, [0.0, 0.0, 1.0]);
        assert_eq!(ok.slots, vec![[1.0, 2.0]]);
        let e = toml::from_str::<T>("normal = [0.0, 0.0, 1.0, 5.0]\n").unwrap_err();
        assert_eq!(
            e.message().trim(),
            "invalid length 4, expected an array of 3 numbers"
        );
        assert_eq!(e.span(), Some(9..29));
        let e = toml::from_str::<T>("normal = [0.0, 1.0]\n").unwrap_err();
        assert_eq!(
            e.message().trim(),
            "invalid length 2, expected an array of 3 numbers"
        );
        let e = toml::from_str::<T>("normal = [0.0, 0.0, 1.0]\nslots = [[1.0, 2.0, 3.0]]\n")
            .unwrap_err();
        assert_eq!(
            e.message().trim(),
            "invalid length 3, expected an array of 2 numbers"
        );
    }
}
