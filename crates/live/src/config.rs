//! The sidecar's config file: which iceoryx2 services to tap or proxy and how their bytes map to spec variables.
//!
//! A TOML file, checked against the compiled spec; every error names `file:line:col`.
//!
//! ```toml
//! [clock]
//! heartbeat = 1        # a point with no sample every N ticks of the spec's unit (0: never)
//! speed = 1            # the system runs this many times faster than real time (`run --speed`)
//! from_first_message = false   # true: no heartbeat before the first sample or request
//!
//! [verdicts]
//! service = "museum/verdicts"   # also publish each verdict line on this service
//!
//! [[topic]]                      # a publish-subscribe service, tapped
//! service = "museum/battery"
//! size = 16                      # payload bytes; a sample of another size is malformed
//! event = "battery_published"    # event variable true at each sample (optional)
//! seq = { offset = 8, type = "u64" }   # optional counter, +1 per sample: gaps are lost samples
//! [[topic.field]]
//! name = "level"                 # the payload's field name (documentation)
//! var = "battery_level"          # the spec variable (default: `name`)
//! offset = 0
//! type = "i32"                   # bool, i8..i64, u8..u64, f32, f64; little-endian
//!
//! [[service]]                    # a request-response service, proxied
//! service = "museum/select_poi"  # the monitor serves this name ...
//! real = "museum/select_poi.real"   # ... and forwards to this one (default: NAME.real)
//! action = "filter"              # or "log"
//! size = 8                       # request payload bytes
//! event = "poi_requested"
//! properties = ["poi_response"]  # which properties a request may not falsify (default: all)
//! error = [0xff]                 # the reply to a blocked request (default: an empty payload)
//! [[service.field]]
//! var = "poi1_selected"
//! offset = 0
//! type = "bool"
//! ```

use std::ops::Range;

use codegen::diag::{Diagnostic, Diagnostics, FileId, SourceMap};

use codegen::Compiled;
use monitor_core::{Ty, Value, VarKind};
use serde::Deserialize;
use toml::Spanned;

/// The type of one payload field (little-endian, no padding assumed): a scalar of the
/// one table of type names ([`codegen::scalar::Scalar`]), never `string` (a layout
/// reads fixed-size fields only). A bool is one byte, 0 or 1; a `u64` above `i64::MAX`,
/// a NaN or an infinity makes the sample malformed.
pub type FieldTy = crate::model::types::Scalar;

/// Parses a layout's field type (the spec language's names: `i32`, `f64`, ...; not
/// `string`).
fn parse_field_ty(s: &str) -> Option<FieldTy> {
    FieldTy::from_spec_name(s).filter(|t| *t != FieldTy::Str)
}

/// A payload field's size and decoding.
pub trait Wire: Copy {
    /// Size in bytes (0 for `string`, which no layout holds).
    fn size(self) -> usize;
    /// Whether it holds an integer.
    fn is_int(self) -> bool;
    /// Reads the field at `offset`; `None` when out of range or not a valid value.
    fn read(self, bytes: &[u8], offset: usize) -> Option<Value>;
}

impl Wire for FieldTy {
    fn size(self) -> usize {
        match self {
            FieldTy::Bool | FieldTy::I8 | FieldTy::U8 => 1,
            FieldTy::I16 | FieldTy::U16 => 2,
            FieldTy::I32 | FieldTy::U32 | FieldTy::F32 => 4,
            FieldTy::I64 | FieldTy::U64 | FieldTy::F64 => 8,
            FieldTy::Str => 0,
        }
    }

    fn is_int(self) -> bool {
        self.int_range().is_some()
    }

    fn read(self, bytes: &[u8], offset: usize) -> Option<Value> {
        let b = bytes.get(offset..offset.checked_add(self.size())?)?;
        let mut w = [0u8; 8];
        w[..b.len()].copy_from_slice(b);
        let u = u64::from_le_bytes(w);
        Some(match self {
            FieldTy::Bool => match u {
                0 => Value::Bool(false),
                1 => Value::Bool(true),
                _ => return None,
            },
            FieldTy::I8 => Value::Int(u as u8 as i8 as i64),
            FieldTy::I16 => Value::Int(u as u16 as i16 as i64),
            FieldTy::I32 => Value::Int(u as u32 as i32 as i64),
            FieldTy::I64 => Value::Int(u as i64),
            FieldTy::U8 | FieldTy::U16 | FieldTy::U32 => Value::Int(u as i64),
            FieldTy::U64 => Value::Int(i64::try_from(u).ok()?),
            FieldTy::F32 => {
                let f = f32::from_bits(u as u32) as f64;
                if !f.is_finite() {
                    return None;
                }
                Value::Float(f)
            }
            FieldTy::F64 => {
                let f = f64::from_bits(u);
                if !f.is_finite() {
                    return None;
                }
                Value::Float(f)
            }
            FieldTy::Str => return None,
        })
    }
}

/// One payload field mapped to a spec variable.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// The spec variable it sets (index into the spec's variables).
    pub var: usize,
    /// Byte offset in the payload.
    pub offset: usize,
    /// Wire type.
    pub ty: FieldTy,
    /// Convert an integer field to a float variable.
    pub to_float: bool,
}

/// A fixed payload layout: its size and the fields it carries.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Exact payload size in bytes.
    pub size: usize,
    /// Event variable set true at every sample, if any.
    pub event: Option<usize>,
    /// The fields, in file order.
    pub fields: Vec<Field>,
}

/// Why a payload could not be read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Malformed {
    /// The payload has the wrong number of bytes.
    Size {
        /// Bytes expected.
        expected: usize,
        /// Bytes received.
        found: usize,
    },
    /// A field holds no valid value (a bool other than 0/1, a NaN, a u64 above i64::MAX).
    Field {
        /// The field's byte offset.
        offset: usize,
    },
}

impl std::fmt::Display for Malformed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Malformed::Size { expected, found } => {
                write!(f, "payload of {found} bytes, the layout has {expected}")
            }
            Malformed::Field { offset } => write!(f, "no valid value at byte {offset}"),
        }
    }
}

impl Layout {
    /// Decodes `bytes` into `(variable, value)` sets (the event first), or says why not.
    pub fn decode(&self, bytes: &[u8], sets: &mut Vec<(usize, Value)>) -> Result<(), Malformed> {
        sets.clear();
        if bytes.len() != self.size {
            return Err(Malformed::Size {
                expected: self.size,
                found: bytes.len(),
            });
        }
        if let Some(e) = self.event {
            sets.push((e, Value::Bool(true)));
        }
        for f in &self.fields {
            let v =
                f.ty.read(bytes, f.offset)
                    .ok_or(Malformed::Field { offset: f.offset })?;
            let v = match (v, f.to_float) {
                (Value::Int(i), true) => Value::Float(i as f64),
                (v, _) => v,
            };
            sets.push((f.var, v));
        }
        Ok(())
    }

    /// Every variable this layout sets.
    pub fn vars(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.event.into_iter().collect();
        v.extend(self.fields.iter().map(|f| f.var));
        v.sort_unstable();
        v.dedup();
        v
    }
}

/// A sequence counter in the payload: +1 per sample from one publisher.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Seq {
    /// Byte offset.
    pub offset: usize,
    /// An unsigned integer type.
    pub ty: FieldTy,
}

/// A tapped publish-subscribe service.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// The iceoryx2 service name.
    pub service: String,
    /// How a sample's bytes map to variables.
    pub layout: Layout,
    /// Optional sequence counter for exact loss counts.
    pub seq: Option<Seq>,
    /// The subscriber buffer asked for when the monitor creates the service.
    pub buffer: usize,
}

/// What the proxy does with a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Judge and forward every request.
    Log,
    /// Answer a request that would falsify a property with the error reply; do not forward it.
    Filter,
}

/// A proxied request-response service.
#[derive(Clone, Debug, PartialEq)]
pub struct Service {
    /// The name clients call (the monitor serves it).
    pub service: String,
    /// The name the real server was renamed to (the monitor forwards to it).
    pub real: String,
    /// `log` or `filter`.
    pub action: Action,
    /// How a request's bytes map to variables.
    pub layout: Layout,
    /// Properties a request may not falsify (indices), for `filter`.
    pub properties: Vec<usize>,
    /// The reply sent for a blocked or undeliverable request.
    pub error: Vec<u8>,
}

/// A checked sidecar configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Tapped topics.
    pub topics: Vec<Topic>,
    /// Proxied services.
    pub services: Vec<Service>,
    /// A heartbeat point every this many ticks without a sample (0: none).
    pub heartbeat: u64,
    /// Publish verdict lines on this service too.
    pub verdict_service: Option<String>,
    /// The monitored system runs this many times faster than real time (1: real time),
    /// so the clock counts model time; see [`super::Clock`].
    pub speed: f64,
    /// No heartbeat before the first sample or request: a monitor started before the
    /// system judges nothing while it waits (its first point is the first message).
    pub from_first_message: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    clock: Option<RawClock>,
    verdicts: Option<RawVerdicts>,
    #[serde(default)]
    topic: Vec<RawTopic>,
    #[serde(default)]
    service: Vec<RawService>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawClock {
    heartbeat: Option<u64>,
    speed: Option<Spanned<f64>>,
    from_first_message: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVerdicts {
    service: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawField {
    name: Option<Spanned<String>>,
    var: Option<Spanned<String>>,
    offset: Spanned<usize>,
    #[serde(rename = "type")]
    ty: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSeq {
    offset: Spanned<usize>,
    #[serde(rename = "type")]
    ty: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTopic {
    service: Spanned<String>,
    size: Spanned<usize>,
    event: Option<Spanned<String>>,
    seq: Option<RawSeq>,
    buffer: Option<Spanned<usize>>,
    #[serde(default)]
    field: Vec<RawField>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawService {
    service: Spanned<String>,
    real: Option<Spanned<String>>,
    action: Spanned<String>,
    size: Spanned<usize>,
    event: Option<Spanned<String>>,
    properties: Option<Vec<Spanned<String>>>,
    error: Option<Vec<u8>>,
    #[serde(default)]
    field: Vec<RawField>,
}

struct Checker<'a> {
    /// The config file in the one source map, for positions and carets.
    map: SourceMap,
    id: FileId,
    spec: &'a Compiled,
    errors: Vec<Diagnostic>,
}

impl Checker<'_> {
    fn err(&mut self, span: Range<usize>, msg: String) {
        let at = self.id.at(u32::try_from(span.start).unwrap_or(u32::MAX));
        self.errors.push(self.map.diag(at, msg));
    }

    fn service_name(&mut self, s: &Spanned<String>) -> String {
        if s.get_ref().is_empty() || s.get_ref().len() > 255 {
            self.err(s.span(), "a service name has 1 to 255 bytes".into());
        }
        s.get_ref().clone()
    }

    fn event(&mut self, e: &Option<Spanned<String>>) -> Option<usize> {
        let e = e.as_ref()?;
        match self.spec.var_index(e.get_ref()) {
            Some(i) if self.spec.vars()[i].kind == VarKind::Event => Some(i),
            Some(_) => {
                self.err(
                    e.span(),
                    format!("`{}` is a state, not an event", e.get_ref()),
                );
                None
            }
            None => {
                self.err(
                    e.span(),
                    format!("`{}` is not a variable of the spec", e.get_ref()),
                );
                None
            }
        }
    }

    fn layout(
        &mut self,
        size: &Spanned<usize>,
        event: &Option<Spanned<String>>,
        raw: &[RawField],
    ) -> Layout {
        let size_v = *size.get_ref();
        if size_v == 0 {
            self.err(size.span(), "a payload has at least one byte".into());
        }
        let event = self.event(event);
        let mut fields = Vec::new();
        for f in raw {
            let Some(name) = f.var.as_ref().or(f.name.as_ref()) else {
                self.err(
                    f.offset.span(),
                    "a field needs `var` (or `name`, used as the variable)".into(),
                );
                continue;
            };
            let Some(ty) = parse_field_ty(f.ty.get_ref()) else {
                self.err(
                    f.ty.span(),
                    format!(
                        "unknown type `{}`: bool, i8, i16, i32, i64, u8, u16, u32, u64, f32 or f64",
                        f.ty.get_ref()
                    ),
                );
                continue;
            };
            let offset = *f.offset.get_ref();
            if offset.checked_add(ty.size()).is_none_or(|end| end > size_v) {
                self.err(
                    f.offset.span(),
                    format!(
                        "a {} at byte {offset} does not fit a {size_v}-byte payload",
                        f.ty.get_ref()
                    ),
                );
            }
            let Some(var) = self.spec.var_index(name.get_ref()) else {
                self.err(
                    name.span(),
                    format!("`{}` is not a variable of the spec", name.get_ref()),
                );
                continue;
            };
            let vty = self.spec.vars()[var].ty;
            let to_float = vty == Ty::Float && ty.is_int();
            let ok = match vty {
                Ty::Bool => ty == FieldTy::Bool,
                Ty::Int => ty.is_int(),
                Ty::Float => ty != FieldTy::Bool,
                Ty::Str => false,
            };
            if !ok {
                self.err(
                    f.ty.span(),
                    format!(
                        "a {} field cannot set `{}` of type {}",
                        f.ty.get_ref(),
                        name.get_ref(),
                        self.spec.vars()[var].type_name
                    ),
                );
                continue;
            }
            fields.push(Field {
                var,
                offset,
                ty,
                to_float,
            });
        }
        Layout {
            size: size_v,
            event,
            fields,
        }
    }
}

impl Config {
    /// Parses and checks `src` (named `file` in errors) against `spec`.
    /// Errors are every problem found, each at its `file:line:col`.
    pub fn parse(src: &str, file: &str, spec: &Compiled) -> Result<Config, Diagnostics> {
        let mut map = SourceMap::new();
        let id = map.add(file, src.to_owned());
        let raw: RawConfig = toml::from_str(src).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            map.diag(id.at(u32::try_from(at).unwrap_or(u32::MAX)), e.message())
        })?;
        let mut c = Checker {
            map,
            id,
            spec,
            errors: Vec::new(),
        };
        let mut names: Vec<(String, Range<usize>)> = Vec::new();
        let mut topics = Vec::new();
        for t in &raw.topic {
            let service = c.service_name(&t.service);
            names.push((service.clone(), t.service.span()));
            let layout = c.layout(&t.size, &t.event, &t.field);
            let seq = t.seq.as_ref().and_then(|s| {
                let ty = parse_field_ty(s.ty.get_ref()).filter(|t| {
                    matches!(t, FieldTy::U8 | FieldTy::U16 | FieldTy::U32 | FieldTy::U64)
                });
                let Some(ty) = ty else {
                    c.err(
                        s.ty.span(),
                        "a sequence counter is u8, u16, u32 or u64".into(),
                    );
                    return None;
                };
                let off = *s.offset.get_ref();
                if off.checked_add(ty.size()).is_none_or(|e| e > layout.size) {
                    c.err(
                        s.offset.span(),
                        "the sequence counter does not fit the payload".into(),
                    );
                }
                Some(Seq { offset: off, ty })
            });
            let buffer = t.buffer.as_ref().map_or(256, |b| *b.get_ref());
            if buffer == 0 {
                if let Some(b) = &t.buffer {
                    c.err(b.span(), "a buffer holds at least one sample".into());
                }
            }
            topics.push(Topic {
                service,
                layout,
                seq,
                buffer,
            });
        }
        let mut services = Vec::new();
        for s in &raw.service {
            let service = c.service_name(&s.service);
            names.push((service.clone(), s.service.span()));
            let real = match &s.real {
                Some(r) => c.service_name(r),
                None => format!("{service}.real"),
            };
            let action = match s.action.get_ref().as_str() {
                "log" => Action::Log,
                "filter" => Action::Filter,
                other => {
                    c.err(
                        s.action.span(),
                        format!("unknown action `{other}`: `log` or `filter`"),
                    );
                    Action::Log
                }
            };
            let layout = c.layout(&s.size, &s.event, &s.field);
            let properties = match &s.properties {
                None => (0..spec.properties().len()).collect(),
                Some(ps) => ps
                    .iter()
                    .filter_map(|p| {
                        let i = spec.property_names().position(|n| n == p.get_ref());
                        if i.is_none() {
                            c.err(
                                p.span(),
                                format!("`{}` is not a property of the spec", p.get_ref()),
                            );
                        }
                        i
                    })
                    .collect(),
            };
            services.push(Service {
                service,
                real,
                action,
                layout,
                properties,
                error: s.error.clone().unwrap_or_default(),
            });
        }
        let verdict_service = raw.verdicts.as_ref().map(|v| {
            names.push((v.service.get_ref().clone(), v.service.span()));
            c.service_name(&v.service)
        });
        for (i, (n, span)) in names.iter().enumerate() {
            if names[..i].iter().any(|(m, _)| m == n) {
                c.err(span.clone(), format!("service `{n}` is named twice"));
            }
        }
        if topics.is_empty() && services.is_empty() {
            c.err(
                0..0,
                "nothing to monitor: add a [[topic]] or a [[service]]".into(),
            );
        }
        let speed = match raw.clock.as_ref().and_then(|k| k.speed.as_ref()) {
            None => 1.0,
            Some(s) => super::check_speed(*s.get_ref()).unwrap_or_else(|m| {
                c.err(s.span(), m.to_string());
                1.0
            }),
        };
        if !c.errors.is_empty() {
            return Err(Diagnostics(c.errors));
        }
        Ok(Config {
            topics,
            services,
            heartbeat: raw.clock.as_ref().and_then(|c| c.heartbeat).unwrap_or(1),
            verdict_service,
            speed,
            from_first_message: raw
                .clock
                .as_ref()
                .and_then(|c| c.from_first_message)
                .unwrap_or(false),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_read_little_endian_and_reject_bad_values() {
        let b = [0xfe, 0xff, 0xff, 0xff, 2, 0, 0, 0];
        assert_eq!(FieldTy::I32.read(&b, 0), Some(Value::Int(-2)));
        assert_eq!(FieldTy::U16.read(&b, 4), Some(Value::Int(2)));
        assert_eq!(FieldTy::Bool.read(&b, 4), None);
        assert_eq!(FieldTy::I64.read(&b, 4), None);
        assert_eq!(FieldTy::F32.read(&f32::NAN.to_le_bytes(), 0), None);
    }
}
