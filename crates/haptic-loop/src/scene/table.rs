//! Reading one table of a scene file by its key, keeping the TOML reader's positions, so an
//! error inside a world's table still points at its line and column.

use haptic_engine::check::SceneError;
use serde::Deserialize;
use serde::de::{DeserializeOwned, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, Visitor};
use std::fmt;
use std::marker::PhantomData;

fn syntax(e: toml::de::Error) -> SceneError {
    SceneError::Syntax {
        message: e.message().trim().to_string(),
        offset: e.span().map(|s| s.start),
    }
}

/// Parses the whole text as `T`.
pub fn parse<T: DeserializeOwned>(text: &str) -> Result<T, SceneError> {
    toml::from_str(text).map_err(syntax)
}

/// Reads the top-level table `key` of `text` as `T` (`None`: no such table). Errors inside the
/// table carry the position of the offending value.
pub fn pick<T: DeserializeOwned>(text: &str, key: &str) -> Result<Option<T>, SceneError> {
    let de = toml::Deserializer::parse(text).map_err(syntax)?;
    de.deserialize_any(Pick::<T> {
        key,
        marker: PhantomData,
    })
    .map_err(syntax)
}

/// Refuses a top-level key not in `allowed`, at the key's position, with serde's wording.
pub fn check_keys(text: &str, allowed: &[&str]) -> Result<(), SceneError> {
    let de = toml::Deserializer::parse(text).map_err(syntax)?;
    de.deserialize_any(Keys { allowed }).map_err(syntax)
}

struct Pick<'k, T> {
    key: &'k str,
    marker: PhantomData<T>,
}

impl<'de, T: DeserializeOwned> Visitor<'de> for Pick<'_, T> {
    type Value = Option<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a table")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Option<T>, A::Error> {
        let mut out = None;
        while let Some(k) = map.next_key::<String>()? {
            if k == self.key {
                out = Some(map.next_value::<T>()?);
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        Ok(out)
    }
}

struct Keys<'a> {
    allowed: &'a [&'a str],
}

impl<'de> Visitor<'de> for Keys<'_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a table")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while map.next_key_seed(KnownKey(self.allowed))?.is_some() {
            map.next_value::<IgnoredAny>()?;
        }
        Ok(())
    }
}

/// A key that must be one of a list (checked while the key is read, so the error has the key's
/// position).
struct KnownKey<'a>(&'a [&'a str]);

impl<'de> DeserializeSeed<'de> for KnownKey<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let key = String::deserialize(d)?;
        if self.0.contains(&key.as_str()) {
            Ok(())
        } else {
            let list: Vec<String> = self.0.iter().map(|k| format!("`{k}`")).collect();
            Err(serde::de::Error::custom(format!(
                "unknown field `{key}`, expected one of {}",
                list.join(", ")
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct W {
        k: f64,
    }

    #[test]
    fn a_table_is_read_with_the_position_of_its_errors() {
        let text = "[a]\nx = 1\n[w]\nk = 2.5\n";
        assert_eq!(pick::<W>(text, "w").unwrap(), Some(W { k: 2.5 }));
        assert_eq!(pick::<W>(text, "v").unwrap(), None);
        let bad = "[a]\nx = 1\n[w]\nk = \"two\"\n";
        match pick::<W>(bad, "w") {
            Err(SceneError::Syntax { message, offset }) => {
                assert_eq!(message, "invalid type: string \"two\", expected f64");
                assert_eq!(offset, Some(bad.find("\"two\"").unwrap()));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_unknown_table_is_named_at_its_key() {
        let text = "[a]\nx = 1\n[moon]\nk = 2.5\n";
        match check_keys(text, &["a", "w"]) {
            Err(SceneError::Syntax { message, offset }) => {
                assert_eq!(message, "unknown field `moon`, expected one of `a`, `w`");
                assert_eq!(offset, Some(text.find("moon").unwrap()));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(check_keys(text, &["a", "moon"]), Ok(()));
    }
}
