//! One spelling per enum value, on every surface: the serde representation of a unit
//! variant (every enum of a plan says `#[serde(rename_all = "snake_case")]`), read back here
//! for `as_str`, `Display` and `FromStr`, so that JSON, MCAP, Parquet, CSV, the CLI's text
//! and Python cannot drift apart. docs/cli.md lists every enum with its values.

use serde::de::{DeserializeOwned, IntoDeserializer, value::StrDeserializer};
use serde::ser::{self, Impossible, Serialize};

/// A value of an enum whose variants carry no data, with every value listed.
pub trait Spelled: Serialize + DeserializeOwned + Copy + PartialEq + 'static {
    /// Every value, in declaration order.
    const ALL: &'static [Self];
    /// What the values are, for error messages: "space", "variable", ...
    const WHAT: &'static str;
}

/// The spelling of `value`: its serde name.
///
/// # Panics
/// Never for a [`Spelled`] enum: serde writes each of its values as a unit variant, which
/// `VariantName` reads; anything else is a bug in the enum's derive, caught by the
/// spelling tests of every enum.
pub fn spelling<T: Spelled>(value: T) -> &'static str {
    match value.serialize(VariantName) {
        Ok(name) => name,
        Err(NotAUnitVariant) => unreachable!("{} is not a unit-variant enum", T::WHAT),
    }
}

/// Every spelling of `T`, in declaration order.
pub fn spellings<T: Spelled>() -> Vec<&'static str> {
    T::ALL.iter().map(|v| spelling(*v)).collect()
}

/// The value spelled `text`.
///
/// # Errors
/// [`UnknownSpelling`], naming what was expected.
pub fn parse<T: Spelled>(text: &str) -> Result<T, UnknownSpelling> {
    let deserializer: StrDeserializer<'_, serde::de::value::Error> = text.into_deserializer();
    T::deserialize(deserializer).map_err(|_| UnknownSpelling {
        what: T::WHAT,
        text: text.to_owned(),
        expected: spellings::<T>().join(", "),
    })
}

/// A text that spells no value of an enum.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{text}` (expected one of: {expected})")]
pub struct UnknownSpelling {
    /// What kind of value was expected.
    pub what: &'static str,
    /// The text given.
    pub text: String,
    /// The spellings, comma separated.
    pub expected: String,
}

/// `as_str`, `Display` and `FromStr` of a [`Spelled`] enum from its serde spelling, its
/// values listed in brackets or named by the enum's own array of them (`Variable::ALL`), so
/// that the list is written once.
macro_rules! spelled {
    (@impl $type:ty, $what:literal, $all:expr) => {
        impl $crate::spelling::Spelled for $type {
            const ALL: &'static [Self] = &$all;
            const WHAT: &'static str = $what;
        }

        impl $type {
            /// The one spelling of the value (its serde name), on every surface.
            pub fn as_str(self) -> &'static str {
                $crate::spelling::spelling(self)
            }
        }

        impl ::std::fmt::Display for $type {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.as_str())
            }
        }

        impl ::std::str::FromStr for $type {
            type Err = $crate::spelling::UnknownSpelling;

            fn from_str(text: &str) -> Result<Self, Self::Err> {
                $crate::spelling::parse(text)
            }
        }
    };
    ($type:ty, $what:literal, [$($value:expr),+ $(,)?]) => {
        $crate::spelling::spelled!(@impl $type, $what, [$($value),+]);
    };
    ($type:ty, $what:literal, $all:path) => {
        $crate::spelling::spelled!(@impl $type, $what, $all);
    };
}
pub(crate) use spelled;

/// A serializer that accepts a unit variant only and returns its (renamed) name.
struct VariantName;

#[derive(Debug)]
struct NotAUnitVariant;

impl std::fmt::Display for NotAUnitVariant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("not a unit variant")
    }
}

impl std::error::Error for NotAUnitVariant {}

impl ser::Error for NotAUnitVariant {
    fn custom<M: std::fmt::Display>(_: M) -> Self {
        NotAUnitVariant
    }
}

macro_rules! refuse {
    ($($method:ident($($arg:ty),*)),+ $(,)?) => {
        $(fn $method(self, $(_: $arg),*) -> Result<&'static str, NotAUnitVariant> {
            Err(NotAUnitVariant)
        })+
    };
}

impl ser::Serializer for VariantName {
    type Ok = &'static str;
    type Error = NotAUnitVariant;
    type SerializeSeq = Impossible<&'static str, NotAUnitVariant>;
    type SerializeTuple = Impossible<&'static str, NotAUnitVariant>;
    type SerializeTupleStruct = Impossible<&'static str, NotAUnitVariant>;
    type SerializeTupleVariant = Impossible<&'static str, NotAUnitVariant>;
    type SerializeMap = Impossible<&'static str, NotAUnitVariant>;
    type SerializeStruct = Impossible<&'static str, NotAUnitVariant>;
    type SerializeStructVariant = Impossible<&'static str, NotAUnitVariant>;

    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<&'static str, NotAUnitVariant> {
        Ok(variant)
    }

    refuse!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_f32(f32),
        serialize_f64(f64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_none(),
        serialize_unit(),
        serialize_unit_struct(&'static str),
    );

    fn serialize_some<T: ?Sized + Serialize>(self, _: &T) -> Result<&'static str, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStruct, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, NotAUnitVariant> {
        Err(NotAUnitVariant)
    }
}

/// Every enum spelled on a plan's surfaces, with its values: what docs/cli.md tabulates and
/// the surface tests check against.
pub fn catalogue() -> Vec<(&'static str, Vec<&'static str>)> {
    use crate::decompose::{ActionType, SegmentPattern};
    use crate::language::{PositionFrame, SolverChoice, Space, Variable};
    use crate::solve::{Fallback, WarningKind, qp::ClarabelStatus};
    fn entry<T: Spelled>() -> (&'static str, Vec<&'static str>) {
        (T::WHAT, spellings::<T>())
    }
    vec![
        entry::<Space>(),
        entry::<Variable>(),
        entry::<ActionType>(),
        entry::<SegmentPattern>(),
        entry::<SolverChoice>(),
        entry::<Fallback>(),
        entry::<WarningKind>(),
        entry::<ClarabelStatus>(),
        entry::<PositionFrame>(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_value_has_one_snake_case_spelling_that_reads_back() {
        for (what, values) in catalogue() {
            assert!(!values.is_empty(), "{what}");
            for (i, v) in values.iter().enumerate() {
                assert!(
                    v.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                        && v.starts_with(|c: char| c.is_ascii_lowercase()),
                    "{what}: `{v}` is not snake_case"
                );
                assert!(!values[..i].contains(v), "{what}: `{v}` twice");
            }
        }
        let types = spellings::<crate::decompose::ActionType>();
        assert_eq!(types, ["i", "ii", "iii", "iv", "v", "vi", "vii"]);
        let variables = spellings::<crate::language::Variable>();
        assert_eq!(variables, ["pw", "ow", "swivel", "shoulder_frame", "elbow"]);
        let space: crate::language::Space = "hat".parse().expect("`hat` is a space");
        assert_eq!(space.to_string(), "hat");
        assert_eq!(serde_json::to_string(&space).expect("a space serializes"), "\"hat\"");
        let e = "HAT".parse::<crate::language::Space>().expect_err("spellings are lower case");
        assert_eq!(e.to_string(), "unknown space `HAT` (expected one of: cpsa, hat)");
    }
}
