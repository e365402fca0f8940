//! Scalar type names: the one table of `int8` ... `uint64`, `float32`, `float64`, `bool`,
//! `string` as models, property files and interfaces write them, and their names in the
//! spec language (`i8` ... `u64`, `f32`, `f64`, `bool`, `string`).
//!
//! The host's SCXML data declarations, property-file port types, the judge's spec types
//! and the sidecar's layouts read names here; the formula checker reads spec names here.

/// A scalar type by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    /// `bool` / `boolean`; spec `bool`.
    Bool,
    /// `int8`; spec `i8`.
    I8,
    /// `int16`; spec `i16`.
    I16,
    /// `int32` / `int`; spec `i32`.
    I32,
    /// `int64`; spec `i64`.
    I64,
    /// `uint8`; spec `u8`.
    U8,
    /// `uint16`; spec `u16`.
    U16,
    /// `uint32`; spec `u32`.
    U32,
    /// `uint64`; spec `u64`.
    U64,
    /// `float32` / `float`; spec `f32`.
    F32,
    /// `float64` / `double`; spec `f64`.
    F64,
    /// `string`; spec `string`.
    Str,
}

impl Scalar {
    /// Every scalar.
    pub const ALL: [Scalar; 12] = [
        Scalar::Bool,
        Scalar::I8,
        Scalar::I16,
        Scalar::I32,
        Scalar::I64,
        Scalar::U8,
        Scalar::U16,
        Scalar::U32,
        Scalar::U64,
        Scalar::F32,
        Scalar::F64,
        Scalar::Str,
    ];

    /// The scalar a model or property file names: `bool`, `boolean`, `int`, `int8` ...
    /// `int64`, `uint8` ... `uint64`, `float`, `float32`, `double`, `float64`, `string`.
    pub fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "boolean" => Scalar::Bool,
            "int" => Scalar::I32,
            "float" => Scalar::F32,
            "double" => Scalar::F64,
            _ => return Scalar::from_exact_name(name),
        })
    }

    /// The scalar whose [`name`](Scalar::name) is exactly `name`, without the other
    /// spellings `from_name` takes (`int`, `float`, `double`, `boolean`): the names ROS
    /// interfaces and behavior-tree ports use.
    pub fn from_exact_name(name: &str) -> Option<Scalar> {
        Scalar::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The scalar the spec language (and a sidecar layout) names: `bool`, `i8` ...
    /// `u64`, `f32`, `f64`, `string`.
    pub fn from_spec_name(name: &str) -> Option<Scalar> {
        Scalar::ALL.into_iter().find(|s| s.spec_name() == name)
    }

    /// The name as a model writes it: `bool`, `int8`, ..., `float64`, `string`.
    pub fn name(self) -> &'static str {
        match self {
            Scalar::Bool => "bool",
            Scalar::I8 => "int8",
            Scalar::I16 => "int16",
            Scalar::I32 => "int32",
            Scalar::I64 => "int64",
            Scalar::U8 => "uint8",
            Scalar::U16 => "uint16",
            Scalar::U32 => "uint32",
            Scalar::U64 => "uint64",
            Scalar::F32 => "float32",
            Scalar::F64 => "float64",
            Scalar::Str => "string",
        }
    }

    /// The name in the spec language: `bool`, `i8`, ..., `f64`, `string`.
    pub fn spec_name(self) -> &'static str {
        match self {
            Scalar::Bool => "bool",
            Scalar::I8 => "i8",
            Scalar::I16 => "i16",
            Scalar::I32 => "i32",
            Scalar::I64 => "i64",
            Scalar::U8 => "u8",
            Scalar::U16 => "u16",
            Scalar::U32 => "u32",
            Scalar::U64 => "u64",
            Scalar::F32 => "f32",
            Scalar::F64 => "f64",
            Scalar::Str => "string",
        }
    }
}

impl Scalar {
    /// The values an integer scalar holds, `None` for the others.
    pub fn int_range(self) -> Option<(i128, i128)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::I64 => (i64::MIN.into(), i64::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::U64 => (0, u64::MAX.into()),
            Scalar::Bool | Scalar::F32 | Scalar::F64 | Scalar::Str => return None,
        })
    }

    /// What the scalar holds, whatever its width: how the formula checker and the
    /// simulator store it.
    pub fn kind(self) -> ScalarKind {
        match self {
            Scalar::Bool => ScalarKind::Bool,
            Scalar::F32 | Scalar::F64 => ScalarKind::Float,
            Scalar::Str => ScalarKind::Str,
            Scalar::I8
            | Scalar::I16
            | Scalar::I32
            | Scalar::I64
            | Scalar::U8
            | Scalar::U16
            | Scalar::U32
            | Scalar::U64 => ScalarKind::Int,
        }
    }
}

/// What a [`Scalar`] holds, whatever its width ([`Scalar::kind`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScalarKind {
    /// `bool`.
    Bool,
    /// A signed or unsigned integer of any width.
    Int,
    /// `float32` or `float64`.
    Float,
    /// `string`.
    Str,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for s in Scalar::ALL {
            assert_eq!(Scalar::from_name(s.name()), Some(s));
            assert_eq!(Scalar::from_spec_name(s.spec_name()), Some(s));
        }
        assert_eq!(Scalar::from_name("int"), Some(Scalar::I32));
        assert_eq!(Scalar::from_name("double"), Some(Scalar::F64));
        assert_eq!(Scalar::from_name("integer"), None);
        assert_eq!(Scalar::from_exact_name("float64"), Some(Scalar::F64));
        assert_eq!(Scalar::from_exact_name("double"), None);
        assert_eq!(Scalar::from_spec_name("int32"), None);
        assert_eq!(Scalar::U8.int_range(), Some((0, 255)));
        assert_eq!(Scalar::F32.int_range(), None);
    }
}
