//! What TOML may hold where a setting is a name or a table (`law`, `law.offset_free`,
//! `law.attitude_rate`, `null_space`): one reading for all of them.

use serde::{Deserialize, Serialize};

/// A name or a table, read so that the table's own errors (an unknown key, a bad kind) reach
/// the message with their path, which an untagged enum would replace by "no variant matched".
pub(crate) enum NameOr<T> {
    /// A name (or a string form the caller parses).
    Name(String),
    /// A table, read as `T`.
    Table(T),
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for NameOr<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visit<T> {
            type Value = NameOr<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a name or a table")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(NameOr::Name(v.into()))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<Self::Value, A::Error> {
                T::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(NameOr::Table)
            }
        }
        d.deserialize_any(Visit(std::marker::PhantomData))
    }
}

impl<T: Serialize> Serialize for NameOr<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            NameOr::Name(n) => s.serialize_str(n),
            NameOr::Table(t) => t.serialize(s),
        }
    }
}
