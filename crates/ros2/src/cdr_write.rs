//! The CDR writer: a message value ([`Val`]) serialised against the same [`Schema`] the
//! reader ([`crate::cdr`]) decodes with, as the ROS 2 middlewares write it: little-endian
//! plain CDR (XCDR version 1) behind the 4-byte encapsulation header `0x00 0x01 0x00 0x00`.
//!
//! The rules are the reader's (OMG DDS-XTypes 1.3, section 7.4.3.4; ROS 2's
//! `rosidl_typesupport_fastrtps_cpp` generated `cdr_serialize`): each primitive aligned to
//! its size counted from the end of the header, `bool` one byte, a string a `uint32`
//! length counting its terminating NUL then its bytes and the NUL, a `wstring` a `uint32`
//! count of UTF-16 units then the units, a sequence a `uint32` count then its elements, a
//! fixed array its elements alone, a nested message its fields in order.
//!
//! A value is built from the type's zeros ([`Val::zero`]: `false`, 0, `""`, empty
//! sequences, fixed arrays of zeros) and set field by field ([`Val::set`], by the
//! reader's field paths). [`encode`] checks the value against the type: an integer out of
//! its field's range, a sequence or string past its bound, a fixed array of another
//! length or a value of another kind is an error naming the field, never a wrapped or
//! truncated number.

use crate::cdr::{parse_path, FieldError};
use crate::interface::{ArraySize, Primitive};
use crate::schema::{Elem, Schema};

/// A value that does not fit its type: every variant names the field path (`at`, the
/// root type's name for the whole message).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EncodeError {
    /// [`Val::set`] named a field the type does not have as asked (boxed: it is the
    /// largest variant, and results are passed around on every message).
    Field(Box<FieldError>),
    /// A message was expected (of type `ty`).
    NotAMessage {
        /// The field path.
        at: String,
        /// The message type.
        ty: String,
    },
    /// A message value with another number of fields than its type.
    FieldCount {
        /// The field path.
        at: String,
        /// The message type.
        ty: String,
        /// Fields of the type.
        want: usize,
        /// Fields of the value.
        got: usize,
    },
    /// An array or sequence was expected.
    NotAnArray {
        /// The field path.
        at: String,
    },
    /// A fixed array of `n` elements given `got`.
    FixedLength {
        /// The field path.
        at: String,
        /// Its size.
        n: u32,
        /// The value's.
        got: usize,
    },
    /// A bounded sequence or string past its bound (`len` elements, bytes or UTF-16
    /// units).
    PastBound {
        /// The field path.
        at: String,
        /// The value's length.
        len: usize,
        /// The bound.
        bound: u32,
        /// `elements`, `bytes` or `UTF-16 units`.
        unit: &'static str,
    },
    /// A sequence or string longer than CDR's `uint32` length holds.
    TooLong {
        /// The field path.
        at: String,
    },
    /// A value of another kind than the primitive field (`what` says which).
    Kind {
        /// The field path.
        at: String,
        /// The field's `.msg` type.
        prim: &'static str,
        /// What the value is not (`is not a bool`, ...).
        what: &'static str,
    },
    /// A string with a NUL byte (CDR ends strings with one).
    Nul {
        /// The field path.
        at: String,
    },
    /// An integer out of its field's range.
    Range {
        /// The field path.
        at: String,
        /// The field's `.msg` type.
        prim: &'static str,
        /// The value.
        value: i128,
    },
}

impl std::fmt::Display for EncodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EncodeError::Field(e) => write!(f, "{e}"),
            EncodeError::NotAMessage { at, ty } => write!(f, "`{at}`: expected a `{ty}` message"),
            EncodeError::FieldCount { at, ty, want, got } => {
                write!(f, "`{at}`: a `{ty}` has {want} field(s), the value {got}")
            }
            EncodeError::NotAnArray { at } => write!(f, "`{at}`: expected an array"),
            EncodeError::FixedLength { at, n, got } => {
                write!(f, "`{at}`: a fixed array of {n}, the value has {got}")
            }
            EncodeError::PastBound {
                at,
                len,
                bound,
                unit,
            } => write!(f, "`{at}`: {len} {unit}, past the bound {bound}"),
            EncodeError::TooLong { at } => write!(f, "`{at}`: too long for CDR"),
            EncodeError::Kind { at, prim, what } => {
                write!(f, "`{at}` is a {prim}, the value {what}")
            }
            EncodeError::Nul { at } => write!(f, "`{at}`: a string holds no NUL byte"),
            EncodeError::Range { at, prim, value } => {
                write!(f, "`{at}` is a {prim}, which does not hold {value}")
            }
        }
    }
}

impl std::error::Error for EncodeError {}

impl From<FieldError> for EncodeError {
    fn from(e: FieldError) -> Self {
        EncodeError::Field(Box::new(e))
    }
}

/// A message value, shaped like its type.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    /// A `bool`.
    Bool(bool),
    /// A signed integer (any width; checked against the field's range).
    Int(i64),
    /// An unsigned integer past `i64` (a `uint64` field).
    UInt(u64),
    /// A float (`float32` fields round it to the nearest `f32`).
    Float(f64),
    /// A string (`string` or `wstring`).
    Str(String),
    /// A message: one value per field of its type, in order.
    Msg(Vec<Val>),
    /// An array or a sequence: its elements.
    Seq(Vec<Val>),
}

impl Val {
    /// The zero of type `t` of `schema` (an index into [`Schema::types`]; 0 is the root).
    pub fn zero(schema: &Schema, t: usize) -> Val {
        Val::Msg(
            schema.types[t]
                .fields
                .iter()
                .map(|f| {
                    let one = || match f.elem {
                        Elem::Prim(p) => prim_zero(p),
                        Elem::Msg(m) => Val::zero(schema, m),
                    };
                    match f.array {
                        ArraySize::Scalar => one(),
                        ArraySize::Fixed(n) => Val::Seq((0..n).map(|_| one()).collect()),
                        ArraySize::Bounded(_) | ArraySize::Unbounded => Val::Seq(Vec::new()),
                    }
                })
                .collect(),
        )
    }

    /// Sets field `path` (`data`, `header.stamp.sec`, `cell_voltage[1]`, or a whole array
    /// `cell_voltage` to a [`Val::Seq`]) of this value of the root type of `schema` to `v`.
    /// A sequence too short for an index grows with zeros (up to its bound). An error
    /// names the path when the type has no such field or `v` is not of its kind (checked
    /// in full by [`encode`]).
    pub fn set(&mut self, schema: &Schema, path: &str, v: Val) -> Result<(), EncodeError> {
        let steps = parse_path(path)?;
        let mut t = 0usize;
        let mut here: &mut Val = self;
        for (k, step) in steps.iter().enumerate() {
            let last = k + 1 == steps.len();
            let st = &schema.types[t];
            let upto = || {
                steps[..=k]
                    .iter()
                    .map(|s| match s.index {
                        Some(i) => format!("{}[{i}]", s.field),
                        None => s.field.clone(),
                    })
                    .collect::<Vec<_>>()
                    .join(".")
            };
            let Some(fi) = st.fields.iter().position(|f| f.name == step.field) else {
                return Err(FieldError::NoField {
                    ty: st.name.clone(),
                    field: step.field.clone(),
                    path: path.to_string(),
                    root: schema.root().name.clone(),
                    known: st.fields.iter().map(|f| f.name.clone()).collect(),
                }
                .into());
            };
            let f = &st.fields[fi];
            let Val::Msg(fields) = here else {
                return Err(EncodeError::NotAMessage {
                    at: path.to_string(),
                    ty: st.name.clone(),
                });
            };
            let mut slot = &mut fields[fi];
            if let Some(i) = step.index {
                let i = i as usize;
                let Val::Seq(items) = slot else {
                    return Err(FieldError::NotAnArray {
                        here: upto(),
                        field: f.name.clone(),
                        ty: st.name.clone(),
                    }
                    .into());
                };
                let max = match f.array {
                    ArraySize::Scalar => 0,
                    ArraySize::Fixed(n) | ArraySize::Bounded(n) => n as usize,
                    ArraySize::Unbounded => usize::MAX,
                };
                if i >= max {
                    return Err(FieldError::PastBound {
                        here: upto(),
                        field: f.name.clone(),
                        ty: st.name.clone(),
                        bound: max,
                    }
                    .into());
                }
                while items.len() <= i {
                    items.push(match f.elem {
                        Elem::Prim(p) => prim_zero(p),
                        Elem::Msg(m) => Val::zero(schema, m),
                    });
                }
                slot = &mut items[i];
            } else if f.array != ArraySize::Scalar && !last {
                return Err(FieldError::IsAnArray {
                    here: upto(),
                    field: f.name.clone(),
                    ty: st.name.clone(),
                }
                .into());
            }
            match f.elem {
                Elem::Msg(m) if !last => {
                    t = m;
                    here = slot;
                }
                Elem::Prim(p) if !last => {
                    return Err(FieldError::NoFields {
                        here: upto(),
                        prim: p.msg_name(),
                        ty: st.name.clone(),
                    }
                    .into())
                }
                _ => {
                    *slot = v;
                    return Ok(());
                }
            }
        }
        // `parse_path` gives at least one step (an empty path is a step with no name).
        Err(FieldError::Syntax {
            path: path.to_string(),
            why: "it is empty",
        }
        .into())
    }
}

fn prim_zero(p: Primitive) -> Val {
    match p {
        Primitive::Bool => Val::Bool(false),
        Primitive::Float32 | Primitive::Float64 => Val::Float(0.0),
        Primitive::String | Primitive::WString => Val::Str(String::new()),
        _ => Val::Int(0),
    }
}

/// Serialises `v`, a value of the root type of `schema`: the 4-byte little-endian header,
/// then the body.
pub fn encode(schema: &Schema, v: &Val) -> Result<Vec<u8>, EncodeError> {
    let mut w = Writer {
        out: vec![0, 1, 0, 0],
    };
    w.msg(schema, 0, v, &schema.root().name)?;
    Ok(w.out)
}

struct Writer {
    out: Vec<u8>,
}

impl Writer {
    /// Pads to `align` counted from the end of the header.
    fn align(&mut self, align: usize) {
        while (self.out.len() - 4) % align != 0 {
            self.out.push(0);
        }
    }

    fn u32(&mut self, n: u32) {
        self.align(4);
        self.out.extend_from_slice(&n.to_le_bytes());
    }

    fn msg(&mut self, schema: &Schema, t: usize, v: &Val, at: &str) -> Result<(), EncodeError> {
        let st = &schema.types[t];
        let Val::Msg(fields) = v else {
            return Err(EncodeError::NotAMessage {
                at: at.to_string(),
                ty: st.name.clone(),
            });
        };
        if fields.len() != st.fields.len() {
            return Err(EncodeError::FieldCount {
                at: at.to_string(),
                ty: st.name.clone(),
                want: st.fields.len(),
                got: fields.len(),
            });
        }
        for (f, fv) in st.fields.iter().zip(fields) {
            let path = if at == st.name || at.is_empty() {
                f.name.clone()
            } else {
                format!("{at}.{}", f.name)
            };
            let one = |w: &mut Writer, x: &Val, path: &str| match f.elem {
                Elem::Prim(p) => w.prim(p, f.string_bound, x, path),
                Elem::Msg(m) => w.msg(schema, m, x, path),
            };
            if f.array == ArraySize::Scalar {
                one(self, fv, &path)?;
                continue;
            }
            let Val::Seq(items) = fv else {
                return Err(EncodeError::NotAnArray { at: path });
            };
            match f.array {
                ArraySize::Fixed(n) if items.len() != n as usize => {
                    return Err(EncodeError::FixedLength {
                        at: path,
                        n,
                        got: items.len(),
                    })
                }
                ArraySize::Fixed(_) => {}
                ArraySize::Bounded(b) if items.len() > b as usize => {
                    return Err(EncodeError::PastBound {
                        at: path,
                        len: items.len(),
                        bound: b,
                        unit: "elements",
                    })
                }
                _ => {
                    let n = u32::try_from(items.len())
                        .map_err(|_| EncodeError::TooLong { at: path.clone() })?;
                    self.u32(n);
                }
            }
            for (i, x) in items.iter().enumerate() {
                one(self, x, &format!("{path}[{i}]"))?;
            }
        }
        Ok(())
    }

    fn prim(
        &mut self,
        p: Primitive,
        bound: Option<u32>,
        v: &Val,
        path: &str,
    ) -> Result<(), EncodeError> {
        let kind = |what: &'static str| {
            Err(EncodeError::Kind {
                at: path.to_string(),
                prim: p.msg_name(),
                what,
            })
        };
        match p {
            Primitive::Bool => match v {
                Val::Bool(b) => self.out.push(u8::from(*b)),
                _ => return kind("is not a bool"),
            },
            Primitive::Float32 | Primitive::Float64 => {
                let x = match v {
                    Val::Float(x) => *x,
                    Val::Int(i) => *i as f64,
                    Val::UInt(u) => *u as f64,
                    _ => return kind("is not a number"),
                };
                if p == Primitive::Float32 {
                    self.align(4);
                    self.out.extend_from_slice(&(x as f32).to_le_bytes());
                } else {
                    self.align(8);
                    self.out.extend_from_slice(&x.to_le_bytes());
                }
            }
            Primitive::String | Primitive::WString => {
                let Val::Str(s) = v else {
                    return kind("is not a string");
                };
                if p == Primitive::String {
                    if s.as_bytes().contains(&0) {
                        return Err(EncodeError::Nul {
                            at: path.to_string(),
                        });
                    }
                    if let Some(b) = bound.filter(|b| s.len() > *b as usize) {
                        return Err(EncodeError::PastBound {
                            at: path.to_string(),
                            len: s.len(),
                            bound: b,
                            unit: "bytes",
                        });
                    }
                    let n = u32::try_from(s.len() + 1).map_err(|_| EncodeError::TooLong {
                        at: path.to_string(),
                    })?;
                    self.u32(n);
                    self.out.extend_from_slice(s.as_bytes());
                    self.out.push(0);
                } else {
                    let units: Vec<u16> = s.encode_utf16().collect();
                    if let Some(b) = bound.filter(|b| units.len() > *b as usize) {
                        return Err(EncodeError::PastBound {
                            at: path.to_string(),
                            len: units.len(),
                            bound: b,
                            unit: "UTF-16 units",
                        });
                    }
                    let n = u32::try_from(units.len()).map_err(|_| EncodeError::TooLong {
                        at: path.to_string(),
                    })?;
                    self.u32(n);
                    for u in units {
                        self.out.extend_from_slice(&u.to_le_bytes());
                    }
                }
            }
            _ => {
                let n: i128 = match v {
                    Val::Int(i) => i128::from(*i),
                    Val::UInt(u) => i128::from(*u),
                    _ => return kind("is not an integer"),
                };
                let (lo, hi) = p.int_range().unwrap_or((0, 0));
                if n < lo || n > hi {
                    return Err(EncodeError::Range {
                        at: path.to_string(),
                        prim: p.msg_name(),
                        value: n,
                    });
                }
                let size = match p {
                    Primitive::Int16 | Primitive::UInt16 => 2,
                    Primitive::Int32 | Primitive::UInt32 => 4,
                    Primitive::Int64 | Primitive::UInt64 => 8,
                    _ => 1,
                };
                self.align(size);
                // Two's complement little-endian: the low `size` bytes of the i128.
                self.out.extend_from_slice(&n.to_le_bytes()[..size]);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::Decoder;
    use crate::schema::BuiltinDefs;
    use monitor_core::{Ty, Value};

    fn schema(ty: &str) -> Schema {
        Schema::resolve(ty, &BuiltinDefs::new()).unwrap()
    }

    #[test]
    fn int32_and_bool_are_what_ros_writes() {
        let s = schema("std_msgs/msg/Int32");
        let mut v = Val::zero(&s, 0);
        v.set(&s, "data", Val::Int(-2)).unwrap();
        assert_eq!(
            encode(&s, &v).unwrap(),
            [0, 1, 0, 0, 0xfe, 0xff, 0xff, 0xff]
        );
        let b = schema("std_msgs/msg/Bool");
        let mut v = Val::zero(&b, 0);
        v.set(&b, "data", Val::Bool(true)).unwrap();
        assert_eq!(encode(&b, &v).unwrap(), [0, 1, 0, 0, 1]);
        // Out of range, of another kind, no such field: errors naming the field.
        let mut v = Val::zero(&s, 0);
        v.set(&s, "data", Val::Int(1 << 40)).unwrap();
        let e = encode(&s, &v).unwrap_err();
        assert!(e.to_string().contains("`data` is a int32"), "{e}");
        assert_eq!(
            e,
            EncodeError::Range {
                at: "data".into(),
                prim: "int32",
                value: 1 << 40
            }
        );
        v.set(&s, "data", Val::Bool(true)).unwrap();
        assert!(encode(&s, &v)
            .unwrap_err()
            .to_string()
            .contains("not an integer"));
        assert!(v
            .set(&s, "dat", Val::Int(1))
            .unwrap_err()
            .to_string()
            .contains("`dat`"));
    }

    /// Every field the writer writes, the reader reads back: nested, strings, sequences,
    /// fixed arrays, every width, in a message whose alignment padding falls everywhere.
    #[test]
    fn battery_state_round_trips_through_the_reader() {
        let s = schema("sensor_msgs/msg/BatteryState");
        let mut v = Val::zero(&s, 0);
        let sets: [(&str, Val); 12] = [
            ("header.stamp.sec", Val::Int(-7)),
            ("header.stamp.nanosec", Val::Int(4_000_000_000)),
            ("header.frame_id", Val::Str("ok".into())),
            ("voltage", Val::Float(12.5)),
            ("percentage", Val::Float(0.25)),
            ("power_supply_status", Val::Int(2)),
            ("present", Val::Bool(true)),
            ("cell_voltage[2]", Val::Float(3.75)),
            ("cell_temperature", Val::Seq(vec![Val::Float(20.0)])),
            ("location", Val::Str("slot".into())),
            ("serial_number", Val::Str("SN1".into())),
            ("capacity", Val::Int(3)),
        ];
        for (p, x) in sets.iter().cloned() {
            v.set(&s, p, x).unwrap();
        }
        let bytes = encode(&s, &v).unwrap();
        let strings = ["ok".to_string(), "slot".into(), "SN1".into()];
        let mut d = Decoder::new(s.clone(), &strings);
        let reads = [
            ("header.stamp.sec", Ty::Int, Value::Int(-7)),
            ("header.stamp.nanosec", Ty::Int, Value::Int(4_000_000_000)),
            ("header.frame_id", Ty::Str, Value::Str(0)),
            ("voltage", Ty::Float, Value::Float(12.5)),
            ("percentage", Ty::Float, Value::Float(0.25)),
            ("power_supply_status", Ty::Int, Value::Int(2)),
            ("present", Ty::Bool, Value::Bool(true)),
            ("cell_voltage[0]", Ty::Float, Value::Float(0.0)),
            ("cell_voltage[2]", Ty::Float, Value::Float(3.75)),
            ("cell_temperature[0]", Ty::Float, Value::Float(20.0)),
            ("location", Ty::Str, Value::Str(1)),
            ("serial_number", Ty::Str, Value::Str(2)),
            ("capacity", Ty::Float, Value::Float(3.0)),
        ];
        for (p, ty, _) in reads {
            d.add(p, ty).unwrap();
        }
        let mut out = vec![Value::Int(0); d.slots()];
        let mut present = vec![false; d.slots()];
        d.decode(&bytes, &mut out, &mut present).unwrap();
        for (i, (p, _, want)) in reads.iter().enumerate() {
            assert_eq!(out[i], *want, "{p}");
            assert!(present[i], "{p}");
        }
    }

    #[test]
    fn bounds_and_shapes_are_checked() {
        let s = schema("example_interfaces/srv/AddTwoInts_Event");
        let mut v = Val::zero(&s, 0);
        v.set(&s, "request[0].a", Val::Int(5)).unwrap();
        assert!(v
            .set(&s, "request[1].a", Val::Int(5))
            .unwrap_err()
            .to_string()
            .contains("at most 1"));
        v.set(&s, "info.client_gid", Val::Seq(vec![Val::Int(1)]))
            .unwrap();
        assert!(matches!(
            encode(&s, &v).unwrap_err(),
            EncodeError::FixedLength { n: 16, got: 1, .. }
        ));
        v.set(&s, "info.client_gid", Val::zero(&s, 0)).unwrap();
        assert!(encode(&s, &v)
            .unwrap_err()
            .to_string()
            .contains("expected an array"));
        let mut v = Val::zero(&s, 0);
        v.set(&s, "request[0].b", Val::Int(-9)).unwrap();
        v.set(&s, "info.event_type", Val::Int(1)).unwrap();
        let bytes = encode(&s, &v).unwrap();
        let mut d = Decoder::new(s.clone(), &[]);
        d.add("info.event_type", Ty::Int).unwrap();
        d.add("request[0].b", Ty::Int).unwrap();
        d.add("response[0].sum", Ty::Int).unwrap();
        let mut out = vec![Value::Int(0); 3];
        let mut present = vec![false; 3];
        d.decode(&bytes, &mut out, &mut present).unwrap();
        assert_eq!(&out[..2], &[Value::Int(1), Value::Int(-9)]);
        assert_eq!(present, [true, true, false]);
    }
}
