//! How [`Settings`] are stored: one flat record of named fields, as they were stored before the
//! settings were split into parts, so that what a user saved with any earlier version loads into
//! the same values (and what is saved now loads into an earlier version). eframe keeps the record
//! as RON (`(iterations:5,rounds:1,…)`); serde's `flatten` would write and read a map
//! (`{"iterations":5,…}`) instead and fail on every value stored before.
//!
//! Each part declares its fields with `settings_part!`, which names the stored field of each one
//! and lets the part write and read its own fields; [`STORED_FIELDS`] is the record's order.

use std::fmt;

use serde::de::{Deserialize, Deserializer, IgnoredAny, MapAccess, Visitor};
use serde::ser::{Serialize, SerializeStruct, Serializer};

use super::{Settings, UNVERSIONED};

/// Declares a part of the [`Settings`]: the struct, each field with the name it is stored under
/// (`pub sigma: f64 => "noise_sigma",`), and its [`StoredPart`] impl.
macro_rules! settings_part {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(
                $(#[$field_meta:meta])*
                pub $field:ident: $ty:ty => $key:literal,
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $name {
            $(
                $(#[$field_meta])*
                pub $field: $ty,
            )*
        }

        impl stored::StoredPart for $name {
            #[cfg(test)]
            const KEYS: &'static [&'static str] = &[$($key),*];

            fn write_field<S: serde::ser::SerializeStruct>(
                &self,
                key: &str,
                out: &mut S,
            ) -> Result<bool, S::Error> {
                match key {
                    $($key => out.serialize_field($key, &self.$field)?,)*
                    _ => return Ok(false),
                }
                Ok(true)
            }

            fn read_field<'de, A: serde::de::MapAccess<'de>>(
                &mut self,
                key: &str,
                map: &mut A,
            ) -> Result<bool, A::Error> {
                match key {
                    $($key => self.$field = map.next_value()?,)*
                    _ => return Ok(false),
                }
                Ok(true)
            }
        }
    };
}

/// A part of the settings as fields of the stored record.
pub(super) trait StoredPart {
    /// The stored names of the part's fields.
    #[cfg(test)]
    const KEYS: &'static [&'static str];

    /// Writes the field stored as `key`; `false` when the part has none.
    fn write_field<S: SerializeStruct>(&self, key: &str, out: &mut S) -> Result<bool, S::Error>;

    /// Reads the value of the field stored as `key`; `false` (nothing read) when the part has
    /// none.
    fn read_field<'de, A: MapAccess<'de>>(
        &mut self,
        key: &str,
        map: &mut A,
    ) -> Result<bool, A::Error>;
}

/// The stored record's fields, in the order they are written (the order of the one struct the
/// settings were before they had parts, so that what is written now reads the same).
pub(super) const STORED_FIELDS: &[&str] = &[
    "iterations",
    "rounds",
    "boundary",
    "fair_finest",
    "variant",
    "wireframe",
    "view_mode",
    "show_performance",
    "last_dir",
    "noise_sigma",
    "noise_seed",
    "noise_mode",
    "heat_map",
    "heat_reference",
    "compare",
    "split",
    "method",
    "baseline_iterations",
    "baseline_lambda",
    "levels_folder",
    "levels_from",
    "levels_to",
    "start_levels",
    "paint",
    "keep_sharp_edges",
    "sharp_edge_angle",
    "recent_files",
    "shading",
    "lighting",
    "clay",
    "denoise",
    "version",
];

/// The fields stored apart from the parts' own.
#[cfg(test)]
pub(super) const WHOLE_FIELDS: [&str; 2] = ["paint", "version"];

impl Serialize for Settings {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut out = serializer.serialize_struct("Settings", STORED_FIELDS.len())?;
        for &key in STORED_FIELDS {
            let written = self.fairing.write_field(key, &mut out)?
                || self.hierarchy.write_field(key, &mut out)?
                || self.noise.write_field(key, &mut out)?
                || self.view.write_field(key, &mut out)?
                || self.files.write_field(key, &mut out)?
                || self.level_chain.write_field(key, &mut out)?;
            match key {
                _ if written => {}
                "paint" => out.serialize_field("paint", &self.paint)?,
                "version" => out.serialize_field("version", &self.version)?,
                _ => {}
            }
        }
        out.end()
    }
}

impl<'de> Deserialize<'de> for Settings {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_struct("Settings", STORED_FIELDS, SettingsVisitor)
    }
}

/// Reads the stored record: a field missing takes its default (the version: [`UNVERSIONED`]),
/// a field no longer known is skipped.
struct SettingsVisitor;

impl<'de> Visitor<'de> for SettingsVisitor {
    type Value = Settings;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str("struct Settings")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Settings, A::Error> {
        let mut settings = Settings {
            version: UNVERSIONED,
            ..Settings::default()
        };
        while let Some(FieldName(key)) = map.next_key()? {
            let read = settings.fairing.read_field(&key, &mut map)?
                || settings.hierarchy.read_field(&key, &mut map)?
                || settings.noise.read_field(&key, &mut map)?
                || settings.view.read_field(&key, &mut map)?
                || settings.files.read_field(&key, &mut map)?
                || settings.level_chain.read_field(&key, &mut map)?;
            match key.as_str() {
                _ if read => {}
                "paint" => settings.paint = map.next_value()?,
                "version" => settings.version = map.next_value()?,
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(settings)
    }
}

/// A field's name in the stored record (an index, from a format that stores fields by their
/// place, names the field at that place in [`STORED_FIELDS`]).
struct FieldName(String);

impl<'de> Deserialize<'de> for FieldName {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_identifier(FieldNameVisitor)
    }
}

struct FieldNameVisitor;

impl Visitor<'_> for FieldNameVisitor {
    type Value = FieldName;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str("field identifier")
    }

    fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<FieldName, E> {
        Ok(FieldName(name.to_owned()))
    }

    fn visit_bytes<E: serde::de::Error>(self, name: &[u8]) -> Result<FieldName, E> {
        Ok(FieldName(String::from_utf8_lossy(name).into_owned()))
    }

    fn visit_u64<E: serde::de::Error>(self, index: u64) -> Result<FieldName, E> {
        let name = usize::try_from(index)
            .ok()
            .and_then(|index| STORED_FIELDS.get(index));
        Ok(FieldName(
            name.map_or_else(String::new, |&name| name.to_owned()),
        ))
    }
}
