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

use crate::cdr::parse_path;
use crate::interface::{ArraySize, Primitive};
use crate::schema::{Elem, Schema};

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
    pub fn set(&mut self, schema: &Schema, path: &str, v: Val) -> Result<(), String> {
        let steps = parse_path(path)?;
        let mut t = 0usize;
        let mut here: &mut Val = self;
        for (k, step) in steps.iter().enumerate() {
            let last = k + 1 == steps.len();
            let st = &schema.types[t];
            let Some(fi) = st.fields.iter().position(|f| f.name == step.field) else {
                return Err(format!(
                    "message `{}` has no field `{}` (field path `{path}`)",
                    st.name, step.field
                ));
            };
            let f = &st.fields[fi];
            let Val::Msg(fields) = here else {
                return Err(format!("`{path}`: `{}` is not a message value", st.name));
            };
            let mut slot = &mut fields[fi];
            if let Some(i) = step.index {
                let i = i as usize;
                let Val::Seq(items) = slot else {
                    return Err(format!(
                        "`{path}` indexes field `{}` of `{}`, which is not an array",
                        f.name, st.name
                    ));
                };
                let max = match f.array {
                    ArraySize::Scalar => 0,
                    ArraySize::Fixed(n) | ArraySize::Bounded(n) => n as usize,
                    ArraySize::Unbounded => usize::MAX,
                };
                if i >= max {
                    return Err(format!(
                        "`{path}`: field `{}` of `{}` has at most {max} element(s)",
                        f.name, st.name
                    ));
                }
                while items.len() <= i {
                    items.push(match f.elem {
                        Elem::Prim(p) => prim_zero(p),
                        Elem::Msg(m) => Val::zero(schema, m),
                    });
                }
                slot = &mut items[i];
            } else if f.array != ArraySize::Scalar && !last {
                return Err(format!(
                    "`{path}`: field `{}` of `{}` is an array: name one element",
                    f.name, st.name
                ));
            }
            match f.elem {
                Elem::Msg(m) if !last => {
                    t = m;
                    here = slot;
                }
                Elem::Prim(p) if !last => {
                    return Err(format!(
                        "`{path}`: field `{}` of `{}` is a {}, it has no fields",
                        f.name,
                        st.name,
                        p.msg_name()
                    ))
                }
                _ => {
                    *slot = v;
                    return Ok(());
                }
            }
        }
        Err(format!("`{path}`: empty field path"))
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
pub fn encode(schema: &Schema, v: &Val) -> Result<Vec<u8>, String> {
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

    fn msg(&mut self, schema: &Schema, t: usize, v: &Val, at: &str) -> Result<(), String> {
        let st = &schema.types[t];
        let Val::Msg(fields) = v else {
            return Err(format!("`{at}`: expected a `{}` message", st.name));
        };
        if fields.len() != st.fields.len() {
            return Err(format!(
                "`{at}`: a `{}` has {} field(s), the value {}",
                st.name,
                st.fields.len(),
                fields.len()
            ));
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
                return Err(format!("`{path}`: expected an array"));
            };
            match f.array {
                ArraySize::Fixed(n) if items.len() != n as usize => {
                    return Err(format!(
                        "`{path}`: a fixed array of {n}, the value has {}",
                        items.len()
                    ))
                }
                ArraySize::Fixed(_) => {}
                ArraySize::Bounded(b) if items.len() > b as usize => {
                    return Err(format!(
                        "`{path}`: {} elements, past the bound {b}",
                        items.len()
                    ))
                }
                _ => {
                    let n = u32::try_from(items.len())
                        .map_err(|_| format!("`{path}`: too many elements"))?;
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
    ) -> Result<(), String> {
        let kind = |what: &str| Err(format!("`{path}` is a {}, the value {what}", p.msg_name()));
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
                        return Err(format!("`{path}`: a string holds no NUL byte"));
                    }
                    if bound.is_some_and(|b| s.len() > b as usize) {
                        return Err(format!(
                            "`{path}`: {} bytes, past the bound {}",
                            s.len(),
                            bound.unwrap_or(0)
                        ));
                    }
                    let n = u32::try_from(s.len() + 1)
                        .map_err(|_| format!("`{path}`: string too long"))?;
                    self.u32(n);
                    self.out.extend_from_slice(s.as_bytes());
                    self.out.push(0);
                } else {
                    let units: Vec<u16> = s.encode_utf16().collect();
                    if bound.is_some_and(|b| units.len() > b as usize) {
                        return Err(format!("`{path}`: past the bound"));
                    }
                    let n = u32::try_from(units.len())
                        .map_err(|_| format!("`{path}`: string too long"))?;
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
                    return Err(format!(
                        "`{path}` is a {}, which does not hold {n}",
                        p.msg_name()
                    ));
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
        assert!(encode(&s, &v).unwrap_err().contains("`data` is a int32"));
        v.set(&s, "data", Val::Bool(true)).unwrap();
        assert!(encode(&s, &v).unwrap_err().contains("not an integer"));
        assert!(v.set(&s, "dat", Val::Int(1)).unwrap_err().contains("`dat`"));
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
            .contains("at most 1"));
        v.set(&s, "info.client_gid", Val::Seq(vec![Val::Int(1)]))
            .unwrap();
        assert!(encode(&s, &v).unwrap_err().contains("fixed array of 16"));
        v.set(&s, "info.client_gid", Val::zero(&s, 0)).unwrap();
        assert!(encode(&s, &v).unwrap_err().contains("expected an array"));
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
