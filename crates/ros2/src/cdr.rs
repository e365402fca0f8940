//! The CDR reader: ROS 2's serialised messages (OMG CDR, XCDR version 1, as the ROS 2
//! middlewares write it), decoded against a [`Schema`] while reading only the fields a
//! property asks for.
//!
//! # Encoding
//!
//! A message starts with a 4-byte encapsulation header: `0x00 0x00` (big endian) or
//! `0x00 0x01` (little endian) and two option bytes. Each primitive is aligned to its own
//! size (1, 2, 4 or 8 bytes) counted from the end of that header; `bool` is one byte;
//! a string is a `uint32` length that counts its terminating NUL, then its bytes; a
//! sequence (`T[]`, `T[<=N]`) is a `uint32` count then its elements; a fixed array
//! `T[N]` is its elements; a nested message is its fields in order (no alignment of
//! its own). Source: OMG DDS-XTypes 1.3, section 7.4.3.4 ("XCDR stream format", version
//! 1), and ROS 2's `rosidl_typesupport_fastrtps_cpp` (the generated `cdr_serialize`).
//!
//! # Bounded work
//!
//! A decoder never allocates for a length it reads: strings are borrowed from the
//! message, sequences are walked in place, and a count is checked against the bytes left
//! (every element takes at least one byte) before it is walked, so a 4 GB length prefix
//! in a 20-byte message is an error at once. Nesting is bounded by the schema
//! ([`crate::schema::MAX_DEPTH`]).

use std::collections::HashMap;

use monitor_core::{Ty, Value};

use crate::interface::{ArraySize, Primitive};
use crate::schema::{Elem, SType, Schema};

mod error;

pub use error::{CdrError, FieldError};

fn err<T>(e: CdrError) -> Result<T, CdrError> {
    Err(e)
}

/// A position in a message's body (after the encapsulation header).
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    be: bool,
}

impl<'a> Cursor<'a> {
    /// The body of a message whose first 4 bytes are the encapsulation header.
    fn open(bytes: &'a [u8]) -> Result<Cursor<'a>, CdrError> {
        if bytes.len() < 4 {
            return err(CdrError::NoHeader { len: bytes.len() });
        }
        let be = match (bytes[0], bytes[1]) {
            (0, 0) => true,
            (0, 1) => false,
            (a, b) => return err(CdrError::Encapsulation { kind: [a, b] }),
        };
        Ok(Cursor {
            data: &bytes[4..],
            pos: 0,
            be,
        })
    }

    fn left(&self) -> usize {
        self.data.len() - self.pos
    }

    #[inline]
    fn take(&mut self, n: usize, align: usize) -> Result<&'a [u8], CdrError> {
        let start = (self.pos + align - 1) & !(align - 1);
        match start.checked_add(n) {
            Some(end) if end <= self.data.len() => {
                self.pos = end;
                Ok(&self.data[start..end])
            }
            _ => err(CdrError::Truncated {
                end: self.data.len() + 4,
                need: n,
                at: start.min(self.data.len()) + 4,
            }),
        }
    }

    #[inline]
    fn u32(&mut self) -> Result<u32, CdrError> {
        let b = self.take(4, 4)?;
        let a = [b[0], b[1], b[2], b[3]];
        Ok(if self.be {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        })
    }

    /// The number of elements of a sequence, checked against the bytes left.
    fn count(&mut self, min_size: usize) -> Result<usize, CdrError> {
        let n = self.u32()? as usize;
        if n.saturating_mul(min_size.max(1)) > self.left() {
            return err(CdrError::Count {
                count: n,
                left: self.left(),
            });
        }
        Ok(n)
    }

    /// A primitive's value.
    #[inline]
    fn prim(&mut self, p: Primitive) -> Result<Leaf<'a>, CdrError> {
        let size = prim_size(p);
        if p == Primitive::String {
            return self.string().map(Leaf::Str);
        }
        if p == Primitive::WString {
            let n = self.count(2)?;
            let b = self.take(n * 2, 2)?;
            return Ok(Leaf::WStr(b));
        }
        let b = self.take(size, size)?;
        let be = self.be;
        macro_rules! num {
            ($t:ty) => {{
                let mut a = [0u8; std::mem::size_of::<$t>()];
                a.copy_from_slice(b);
                if be {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }
            }};
        }
        Ok(match p {
            Primitive::Bool => match b[0] {
                0 => Leaf::Bool(false),
                1 => Leaf::Bool(true),
                v => return err(CdrError::Bool(v)),
            },
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => Leaf::UInt(b[0] as u64),
            Primitive::Int8 => Leaf::Int(b[0] as i8 as i64),
            Primitive::Int16 => Leaf::Int(num!(i16) as i64),
            Primitive::UInt16 => Leaf::UInt(num!(u16) as u64),
            Primitive::Int32 => Leaf::Int(num!(i32) as i64),
            Primitive::UInt32 => Leaf::UInt(num!(u32) as u64),
            Primitive::Int64 => Leaf::Int(num!(i64)),
            Primitive::UInt64 => Leaf::UInt(num!(u64)),
            Primitive::Float32 => Leaf::Float(num!(f32) as f64),
            Primitive::Float64 => Leaf::Float(num!(f64)),
            Primitive::String | Primitive::WString => unreachable!("handled above"),
        })
    }

    fn string(&mut self) -> Result<&'a [u8], CdrError> {
        let n = self.count(1)?;
        let b = self.take(n, 1)?;
        // The length counts the terminating NUL (a length of 0 is read as "").
        Ok(match b.split_last() {
            Some((0, s)) => s,
            Some(_) => return err(CdrError::NoNul),
            None => b,
        })
    }

    fn skip_prim(&mut self, p: Primitive, n: usize) -> Result<(), CdrError> {
        match p {
            Primitive::String => {
                for _ in 0..n {
                    self.string()?;
                }
            }
            Primitive::WString => {
                for _ in 0..n {
                    let k = self.count(2)?;
                    self.take(k * 2, 2)?;
                }
            }
            p => {
                let size = prim_size(p);
                if p == Primitive::Bool {
                    for b in self.take(n, 1)? {
                        if *b > 1 {
                            return err(CdrError::Bool(*b));
                        }
                    }
                } else {
                    // n <= left here (checked by `count` or bounded by the schema).
                    self.take(n.saturating_mul(size), if n == 0 { 1 } else { size })?;
                }
            }
        }
        Ok(())
    }
}

/// Size (and alignment) of a fixed-size primitive.
fn prim_size(p: Primitive) -> usize {
    match p {
        Primitive::Bool
        | Primitive::Byte
        | Primitive::Char
        | Primitive::Int8
        | Primitive::UInt8 => 1,
        Primitive::Int16 | Primitive::UInt16 => 2,
        Primitive::Int32 | Primitive::UInt32 | Primitive::Float32 => 4,
        Primitive::Int64 | Primitive::UInt64 | Primitive::Float64 => 8,
        Primitive::String | Primitive::WString => 4,
    }
}

/// A primitive value read from a message.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Leaf<'a> {
    Bool(bool),
    Int(i64),
    UInt(u64),
    Float(f64),
    Str(&'a [u8]),
    WStr(&'a [u8]),
}

/// One step of a field path: a field, then optionally an element.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PathStep {
    /// The field's name.
    pub field: String,
    /// `[i]` after it.
    pub index: Option<u32>,
}

/// Parses a field path: `data`, `header.stamp.sec`, `cell_voltage[0]`, `a[2].b`.
pub(crate) fn parse_path(path: &str) -> Result<Vec<PathStep>, FieldError> {
    let bad = |why: &'static str| FieldError::Syntax {
        path: path.to_string(),
        why,
    };
    let mut out = Vec::new();
    for part in path.split('.') {
        let (field, index) = match part.split_once('[') {
            None => (part, None),
            Some((f, rest)) => {
                let Some(n) = rest.strip_suffix(']') else {
                    return Err(bad("`[` without `]` at the end of a step"));
                };
                let n: u32 = n
                    .parse()
                    .map_err(|_| bad("an index is a non-negative integer"))?;
                (f, Some(n))
            }
        };
        if field.is_empty() || !field.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad("each step is a field name, optionally `[N]`"));
        }
        out.push(PathStep {
            field: field.to_string(),
            index,
        });
    }
    Ok(out)
}

/// The steps of a resolved path, into the walk's selection.
#[derive(Clone, Debug, Default)]
struct MsgSel {
    /// `(field index, what is read there)`, by field index.
    fields: Vec<(usize, FieldSel)>,
}

#[derive(Clone, Debug)]
enum FieldSel {
    /// The field (a primitive) goes to a slot.
    Leaf(usize),
    /// Fields of the nested message.
    Sub(MsgSel),
    /// Elements of the array, by index.
    Elems(Vec<(u32, ElemSel)>),
}

#[derive(Clone, Debug)]
enum ElemSel {
    Leaf(usize),
    Sub(MsgSel),
}

/// Reads chosen fields of one message type, each into a slot as a monitor value.
#[derive(Clone, Debug)]
pub struct Decoder {
    schema: Schema,
    sel: MsgSel,
    /// The type each slot holds.
    slot_ty: Vec<Ty>,
    /// The path of each slot, for errors.
    slot_path: Vec<String>,
    /// Spec string constants by their bytes (other strings equal none).
    strings: HashMap<Vec<u8>, u32>,
}

impl Decoder {
    /// A decoder of `schema` reading no field yet; `strings` are the spec's string
    /// constants (a string field's value is its index there, or one past all of them).
    pub fn new(schema: Schema, strings: &[String]) -> Decoder {
        Decoder {
            schema,
            sel: MsgSel::default(),
            slot_ty: Vec::new(),
            slot_path: Vec::new(),
            strings: strings
                .iter()
                .enumerate()
                .map(|(i, s)| (s.as_bytes().to_vec(), i as u32))
                .collect(),
        }
    }

    /// The schema decoded.
    pub fn schema(&self) -> &Schema {
        &self.schema
    }

    /// The number of slots [`Decoder::decode`] fills.
    pub fn slots(&self) -> usize {
        self.slot_ty.len()
    }

    /// Adds field `path` read as a value of type `ty`; returns its slot. An error names
    /// the path and the message type when the message has no such field, the field is
    /// not a primitive, or its type does not convert to `ty` (integers to `int` or
    /// `float`, floats to `float`, `bool` to `bool`, strings to `string`).
    pub fn add(&mut self, path: &str, ty: Ty) -> Result<usize, FieldError> {
        // A failed path leaves the selection as it was.
        let mut sel = std::mem::take(&mut self.sel);
        let before = sel.clone();
        let r = self.add_into(&mut sel, path, ty);
        self.sel = if r.is_ok() { sel } else { before };
        r
    }

    fn add_into(&mut self, top: &mut MsgSel, path: &str, ty: Ty) -> Result<usize, FieldError> {
        let steps = parse_path(path)?;
        let slot = self.slot_ty.len();
        let mut ty_index = 0usize;
        let mut sel = top;
        let root = self.schema.root().name.clone();
        for (k, step) in steps.iter().enumerate() {
            let last = k + 1 == steps.len();
            let st: &SType = &self.schema.types[ty_index];
            let Some(fi) = st.fields.iter().position(|f| f.name == step.field) else {
                return Err(FieldError::NoField {
                    ty: st.name.clone(),
                    field: step.field.clone(),
                    path: path.to_string(),
                    root,
                    known: st.fields.iter().map(|f| f.name.clone()).collect(),
                });
            };
            let f = st.fields[fi].clone();
            let pos = match sel.fields.binary_search_by_key(&fi, |(i, _)| *i) {
                Ok(p) => p,
                Err(p) => {
                    let fresh = match (step.index, f.elem) {
                        (Some(_), _) => FieldSel::Elems(Vec::new()),
                        (None, Elem::Msg(_)) => FieldSel::Sub(MsgSel::default()),
                        (None, Elem::Prim(_)) => FieldSel::Leaf(usize::MAX),
                    };
                    sel.fields.insert(p, (fi, fresh));
                    p
                }
            };
            let here = &steps[..=k]
                .iter()
                .map(|s| match s.index {
                    Some(i) => format!("{}[{i}]", s.field),
                    None => s.field.clone(),
                })
                .collect::<Vec<_>>()
                .join(".");
            if let Some(i) = step.index {
                match f.array {
                    ArraySize::Scalar => {
                        return Err(FieldError::NotAnArray {
                            here: here.clone(),
                            field: step.field.clone(),
                            ty: st.name.clone(),
                        })
                    }
                    ArraySize::Fixed(n) | ArraySize::Bounded(n) if i >= n => {
                        return Err(FieldError::PastBound {
                            here: here.clone(),
                            field: step.field.clone(),
                            ty: st.name.clone(),
                            bound: n as usize,
                        })
                    }
                    _ => {}
                }
            } else if f.array != ArraySize::Scalar {
                return Err(FieldError::IsAnArray {
                    here: here.clone(),
                    field: step.field.clone(),
                    ty: st.name.clone(),
                });
            }
            let leaf_or_sub = match &mut sel.fields[pos].1 {
                FieldSel::Leaf(s) => Err(s),
                FieldSel::Sub(sub) => Ok(sub),
                FieldSel::Elems(elems) => {
                    let i = step.index.unwrap_or(0);
                    let epos = match elems.binary_search_by_key(&i, |(j, _)| *j) {
                        Ok(p) => p,
                        Err(p) => {
                            let fresh = match f.elem {
                                Elem::Msg(_) => ElemSel::Sub(MsgSel::default()),
                                Elem::Prim(_) => ElemSel::Leaf(usize::MAX),
                            };
                            elems.insert(p, (i, fresh));
                            p
                        }
                    };
                    match &mut elems[epos].1 {
                        ElemSel::Leaf(s) => Err(s),
                        ElemSel::Sub(sub) => Ok(sub),
                    }
                }
            };
            match (leaf_or_sub, f.elem) {
                (Err(s), Elem::Prim(p)) => {
                    if !last {
                        return Err(FieldError::NoFields {
                            here: here.clone(),
                            prim: p.msg_name(),
                            ty: st.name.clone(),
                        });
                    }
                    check_convert(p, ty, path, &root)?;
                    if *s != usize::MAX {
                        return Ok(*s);
                    }
                    *s = slot;
                    self.slot_ty.push(ty);
                    self.slot_path.push(path.to_string());
                    return Ok(slot);
                }
                (Ok(sub), Elem::Msg(t)) => {
                    if last {
                        return Err(FieldError::IsAMessage {
                            here: here.clone(),
                            ty: self.schema.types[t].name.clone(),
                        });
                    }
                    ty_index = t;
                    sel = sub;
                }
                _ => unreachable!("a selection follows its field's element type"),
            }
        }
        // `parse_path` gives at least one step (an empty path is a step with no name).
        Err(FieldError::Syntax {
            path: path.to_string(),
            why: "it is empty",
        })
    }

    /// Decodes one serialised message (encapsulation header included), writing every
    /// slot into `out` and whether the message has it into `present` (both at least
    /// [`Decoder::slots`] long): a slot is absent when it is an element past the end of a
    /// sequence in this message. The whole message is walked, so a message shorter than
    /// its definition is an error even past the last field read.
    pub fn decode(
        &self,
        bytes: &[u8],
        out: &mut [Value],
        present: &mut [bool],
    ) -> Result<(), CdrError> {
        let mut c = Cursor::open(bytes)?;
        present[..self.slots()].fill(true);
        self.walk(&mut c, 0, Some(&self.sel), out, present)?;
        // Writers pad a message to a multiple of 4 bytes (or 8): more is not this type.
        if c.left() >= 8 {
            return err(CdrError::Trailing {
                left: c.left(),
                ty: self.schema.root().name.clone(),
            });
        }
        Ok(())
    }

    fn walk<'a>(
        &self,
        c: &mut Cursor<'a>,
        t: usize,
        sel: Option<&MsgSel>,
        out: &mut [Value],
        present: &mut [bool],
    ) -> Result<(), CdrError> {
        let st = &self.schema.types[t];
        let picks: &[(usize, FieldSel)] = sel.map_or(&[], |s| &s.fields);
        let mut next = 0;
        for (fi, f) in st.fields.iter().enumerate() {
            let pick = match picks.get(next) {
                Some((i, p)) if *i == fi => {
                    next += 1;
                    Some(p)
                }
                _ => None,
            };
            let n = match f.array {
                ArraySize::Scalar => {
                    match (f.elem, pick) {
                        (Elem::Prim(p), Some(FieldSel::Leaf(s))) => {
                            let v = c.prim(p)?;
                            self.store(*s, v, out)?;
                        }
                        (Elem::Prim(p), _) => c.skip_prim(p, 1)?,
                        (Elem::Msg(m), Some(FieldSel::Sub(sub))) => {
                            self.walk(c, m, Some(sub), out, present)?
                        }
                        (Elem::Msg(m), _) => self.walk(c, m, None, out, present)?,
                    }
                    continue;
                }
                ArraySize::Fixed(n) => n as usize,
                ArraySize::Bounded(b) => {
                    let n = c.count(1)?;
                    if n > b as usize {
                        return err(CdrError::PastBound {
                            field: f.name.clone(),
                            ty: st.name.clone(),
                            count: n,
                            bound: b,
                        });
                    }
                    n
                }
                ArraySize::Unbounded => c.count(1)?,
            };
            let elems: &[(u32, ElemSel)] = match pick {
                Some(FieldSel::Elems(e)) => e,
                _ => &[],
            };
            // Elements past the end of this message's array: their slots are absent.
            let mut cut = elems.len();
            while cut > 0 && elems[cut - 1].0 as usize >= n {
                cut -= 1;
                match &elems[cut].1 {
                    ElemSel::Leaf(s) => present[*s] = false,
                    ElemSel::Sub(m) => mark_absent(m, present),
                }
            }
            let elems = &elems[..cut];
            match f.elem {
                Elem::Prim(p) if elems.is_empty() => c.skip_prim(p, n)?,
                Elem::Prim(p) => {
                    let mut k = 0;
                    for i in 0..n {
                        match elems.get(k) {
                            Some((j, ElemSel::Leaf(s))) if *j as usize == i => {
                                k += 1;
                                let v = c.prim(p)?;
                                self.store(*s, v, out)?;
                            }
                            _ => c.skip_prim(p, 1)?,
                        }
                    }
                }
                Elem::Msg(m) => {
                    let mut k = 0;
                    for i in 0..n {
                        match elems.get(k) {
                            Some((j, ElemSel::Sub(sub))) if *j as usize == i => {
                                k += 1;
                                self.walk(c, m, Some(sub), out, present)?;
                            }
                            _ => self.walk(c, m, None, out, present)?,
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The field path slot `slot` reads.
    pub(crate) fn slot_path(&self, slot: usize) -> &str {
        &self.slot_path[slot]
    }

    #[inline]
    fn store(&self, slot: usize, v: Leaf<'_>, out: &mut [Value]) -> Result<(), CdrError> {
        let ty = self.slot_ty[slot];
        out[slot] = match (ty, v) {
            (Ty::Bool, Leaf::Bool(b)) => Value::Bool(b),
            (Ty::Int, Leaf::Int(i)) => Value::Int(i),
            (Ty::Int, Leaf::UInt(u)) => match i64::try_from(u) {
                Ok(i) => Value::Int(i),
                Err(_) => {
                    return err(CdrError::TooLarge {
                        path: self.slot_path[slot].clone(),
                        value: u,
                    })
                }
            },
            (Ty::Float, Leaf::Float(f)) => Value::Float(f),
            (Ty::Float, Leaf::Int(i)) => Value::Float(i as f64),
            (Ty::Float, Leaf::UInt(u)) => Value::Float(u as f64),
            (Ty::Str, Leaf::Str(s)) => Value::Str(self.strings.get(s).copied().unwrap_or(u32::MAX)),
            (Ty::Str, Leaf::WStr(s)) => {
                let units: Vec<u16> = s
                    .chunks_exact(2)
                    .map(|b| u16::from_le_bytes([b[0], b[1]]))
                    .collect();
                let text = String::from_utf16_lossy(&units);
                Value::Str(
                    self.strings
                        .get(text.as_bytes())
                        .copied()
                        .unwrap_or(u32::MAX),
                )
            }
            _ => {
                return err(CdrError::Mismatch {
                    path: self.slot_path[slot].clone(),
                })
            }
        };
        Ok(())
    }
}

/// Marks every slot under `sel` absent.
fn mark_absent(sel: &MsgSel, present: &mut [bool]) {
    for (_, f) in &sel.fields {
        match f {
            FieldSel::Leaf(s) => present[*s] = false,
            FieldSel::Sub(m) => mark_absent(m, present),
            FieldSel::Elems(e) => {
                for (_, e) in e {
                    match e {
                        ElemSel::Leaf(s) => present[*s] = false,
                        ElemSel::Sub(m) => mark_absent(m, present),
                    }
                }
            }
        }
    }
}

/// Whether a field of primitive `p` converts to a value of type `ty`.
fn check_convert(p: Primitive, ty: Ty, path: &str, root: &str) -> Result<(), FieldError> {
    let ok = match ty {
        Ty::Bool => p == Primitive::Bool,
        Ty::Int => p.int_range().is_some(),
        Ty::Float => {
            p.int_range().is_some() || matches!(p, Primitive::Float32 | Primitive::Float64)
        }
        Ty::Str => p.is_string(),
    };
    if ok {
        Ok(())
    } else {
        let want = match ty {
            Ty::Bool => "bool",
            Ty::Int => "an integer",
            Ty::Float => "a number",
            Ty::Str => "string",
        };
        Err(FieldError::Convert {
            path: path.to_string(),
            root: root.to_string(),
            prim: p.msg_name(),
            want,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::{BuiltinDefs, Schema};

    fn decoder(ty: &str) -> Decoder {
        Decoder::new(
            Schema::resolve(ty, &BuiltinDefs::new()).unwrap(),
            &["ok".to_string()],
        )
    }

    #[test]
    fn int32_in_both_byte_orders() {
        let mut d = decoder("std_msgs/msg/Int32");
        assert_eq!(d.add("data", Ty::Int).unwrap(), 0);
        let mut out = [Value::Int(0)];
        let mut p = [false];
        d.decode(&[0, 1, 0, 0, 0xfe, 0xff, 0xff, 0xff], &mut out, &mut p)
            .unwrap();
        assert_eq!((out[0], p[0]), (Value::Int(-2), true));
        d.decode(&[0, 0, 0, 0, 0, 0, 1, 0], &mut out, &mut p)
            .unwrap();
        assert_eq!(out[0], Value::Int(256));
        assert!(d.decode(&[0, 1, 0, 0, 1, 2], &mut out, &mut p).is_err());
        let e = d
            .decode(&[0, 2, 0, 0, 1, 2, 3, 4], &mut out, &mut p)
            .unwrap_err();
        assert_eq!(e, CdrError::Encapsulation { kind: [0, 2] });
        assert!(e.to_string().contains("encapsulation"));
    }

    #[test]
    fn paths_into_nested_fields_and_arrays() {
        // sensor_msgs/BatteryState: header (stamp sec, nanosec; frame_id), voltage ...
        let mut d = decoder("sensor_msgs/msg/BatteryState");
        let sec = d.add("header.stamp.sec", Ty::Int).unwrap();
        let frame = d.add("header.frame_id", Ty::Str).unwrap();
        let cell = d.add("cell_voltage[1]", Ty::Float).unwrap();
        let e = d.add("cell_voltag[0]", Ty::Float).unwrap_err();
        assert!(
            matches!(&e, FieldError::NoField { field, root, .. }
                if field == "cell_voltag" && root == "sensor_msgs/BatteryState"),
            "{e:?}"
        );
        assert!(e.to_string().contains("no field `cell_voltag`"));
        assert!(matches!(
            d.add("cell_voltage", Ty::Float).unwrap_err(),
            FieldError::IsAnArray { .. }
        ));
        assert!(matches!(
            d.add("voltage", Ty::Bool).unwrap_err(),
            FieldError::Convert {
                prim: "float32",
                want: "bool",
                ..
            }
        ));
        let mut m = vec![0, 1, 0, 0];
        m.extend(7i32.to_le_bytes()); // sec
        m.extend(0u32.to_le_bytes()); // nanosec
        m.extend(3u32.to_le_bytes()); // frame_id length with NUL
        m.extend(b"ok\0");
        m.push(0); // pad to 4
        for _ in 0..7 {
            m.extend(1.5f32.to_le_bytes()); // voltage .. percentage
        }
        m.extend([1, 2, 3, 1]); // status, health, technology, present
        m.extend(2u32.to_le_bytes()); // cell_voltage count
        m.extend(3.0f32.to_le_bytes());
        m.extend(4.0f32.to_le_bytes());
        m.extend(0u32.to_le_bytes()); // cell_temperature
        m.extend(1u32.to_le_bytes()); // location ""
        m.push(0);
        m.extend([0, 0, 0]);
        m.extend(1u32.to_le_bytes()); // serial_number ""
        m.push(0);
        let mut out = vec![Value::Int(0); d.slots()];
        let mut p = vec![false; d.slots()];
        d.decode(&m, &mut out, &mut p).unwrap();
        assert_eq!(out[sec], Value::Int(7));
        assert_eq!(out[frame], Value::Str(0));
        assert_eq!(out[cell], Value::Float(4.0));
        assert!(p.iter().all(|x| *x));
        // One cell only: `cell_voltage[1]` is absent from this message.
        let mut one = m.clone();
        let at = 4 + 12 + 4 + 28 + 4;
        one[at..at + 4].copy_from_slice(&1u32.to_le_bytes());
        one.drain(at + 8..at + 12);
        d.decode(&one, &mut out, &mut p).unwrap();
        assert!(!p[cell] && p[sec]);
        // A sequence that claims 4 G elements fails at once, without allocating.
        m[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = d.decode(&m, &mut out, &mut p).unwrap_err();
        assert!(
            matches!(
                e,
                CdrError::Count {
                    count: 4294967295,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("4294967295"), "{e}");
        // Truncated anywhere: an error, never a panic.
        m[at..at + 4].copy_from_slice(&2u32.to_le_bytes());
        for n in 0..m.len() - 3 {
            assert!(d.decode(&m[..n], &mut out, &mut p).is_err(), "{n}");
        }
    }

    #[test]
    fn paths_parse() {
        assert_eq!(parse_path("a.b[3]").unwrap()[1].index, Some(3));
        assert!(parse_path("a..b").is_err());
        assert!(parse_path("a[x]").is_err());
        assert!(parse_path("a[1").is_err());
    }
}
