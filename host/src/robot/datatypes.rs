//! AS2FM data declaration files (`<data_declarations>` of a main file): struct types written
//! as XML (`<types>` of `<struct id>` with `<member id type>`) or as a JSON schema, read into
//! the model's [`TypeDefs`].
//!
//! XML:
//!
//! ```xml
//! <types>
//!     <struct id="Point2D">
//!         <member id="frame" type="string" />
//!         <member id="x" type="float32" />
//!     </struct>
//!     <struct id="Polygon"> <member id="points" type="Point2D[]" /> </struct>
//! </types>
//! ```
//!
//! JSON schema: the top-level object (named by its `title`) and every entry of `$defs` is a
//! struct; property types are `"string"`, `"boolean"`, `"integer"` (read as `int32`),
//! `"number"` (read as `float32`, as AS2FM does), `"array"` with `items` (and an optional
//! `maxItems` bound) and `{"$ref": "#/$defs/Name"}`. Properties keep their written order.
//!
//! Every type a member names must be declared in one of the files given together.

use super::main_file::{InputKind, MainFile};
use crate::model::source::{Diagnostic, FileId, SourceMap, Span};
use crate::model::types::{TypeDef, TypeDefs, TypeExpr};
use crate::model::xml::{self, Node};
use std::path::Path;

/// Which format a declaration file is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataFormat {
    /// `<types>` XML.
    Xml,
    /// A JSON schema.
    Json,
}

/// Reads the declaration files `files` (path and format, as a main file lists them) into one
/// set of types, checking that every named member type is declared.
pub fn read_data_declarations(
    sm: &mut SourceMap,
    files: &[(&Path, DataFormat)],
) -> Result<TypeDefs, Vec<Diagnostic>> {
    let mut defs = TypeDefs::default();
    // Where each member's type was written, to report undeclared names.
    let mut uses: Vec<(TypeExpr, Span)> = Vec::new();
    let mut errs = Vec::new();
    for (path, format) in files {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => {
                errs.push(Diagnostic::file(*path, format!("cannot read: {e}")));
                continue;
            }
        };
        let file = sm.add(*path, text);
        let r = match format {
            DataFormat::Xml => read_xml(sm, file, &mut defs, &mut uses),
            DataFormat::Json => read_json(sm, file, &mut defs, &mut uses),
        };
        if let Err(e) = r {
            errs.extend(e);
        }
    }
    for (ty, span) in &uses {
        let mut t = ty;
        while let TypeExpr::Array(inner, _) = t {
            t = inner;
        }
        if let TypeExpr::Named(n) = t {
            match defs.get(n) {
                Some(TypeDef::Struct { .. }) | Some(TypeDef::Enumeration { .. }) => {}
                None => {
                    let known: Vec<&str> = defs.defs.iter().map(|(n, _, _)| n.as_str()).collect();
                    errs.push(sm.diag(
                        *span,
                        format!(
                            "type `{n}` is not declared (declared: {})",
                            if known.is_empty() {
                                "none".to_string()
                            } else {
                                known.join(", ")
                            }
                        ),
                    ));
                }
            }
        }
    }
    if errs.is_empty() {
        Ok(defs)
    } else {
        Err(errs)
    }
}

/// Reads the `<data_declarations>` of a main file ([`read_data_declarations`] on its inputs);
/// no declarations give no types.
pub fn read_main_declarations(
    sm: &mut SourceMap,
    main: &MainFile,
) -> Result<TypeDefs, Vec<Diagnostic>> {
    let files: Vec<(&Path, DataFormat)> = main
        .data_declarations
        .iter()
        .map(|i| {
            let format = if i.kind == InputKind::DataJson {
                DataFormat::Json
            } else {
                DataFormat::Xml
            };
            (i.path.as_path(), format)
        })
        .collect();
    read_data_declarations(sm, &files)
}

fn declare(
    sm: &SourceMap,
    defs: &mut TypeDefs,
    name: &str,
    fields: Vec<(String, TypeExpr)>,
    span: Span,
    errs: &mut Vec<Diagnostic>,
) {
    if defs.get(name).is_some() {
        errs.push(sm.diag(span, format!("type `{name}` is declared twice")));
    } else {
        defs.defs
            .push((name.to_string(), TypeDef::Struct { fields }, span));
    }
}

fn read_xml(
    sm: &SourceMap,
    file: FileId,
    defs: &mut TypeDefs,
    uses: &mut Vec<(TypeExpr, Span)>,
) -> Result<(), Vec<Diagnostic>> {
    let root = xml::parse(sm, file).map_err(|d| vec![d])?;
    if root.name != "types" {
        return Err(vec![sm.diag(
            root.span,
            format!("expected <types>, found <{}>", root.name),
        )]);
    }
    let mut errs = Vec::new();
    root.check_attrs(sm, &[], &mut errs);
    for node in &root.children {
        let el = match node {
            Node::Element(el) => el,
            Node::Text(span) => {
                errs.push(sm.diag(*span, "unexpected text in <types>"));
                continue;
            }
            Node::Comment(..) => continue,
        };
        if el.name != "struct" {
            errs.push(sm.diag(
                el.span,
                format!("unexpected <{}> in <types> (expected <struct>)", el.name),
            ));
            continue;
        }
        el.check_attrs(sm, &["id"], &mut errs);
        let id = match el.required(sm, "id") {
            Ok(a) => a.value.clone(),
            Err(d) => {
                errs.push(d);
                continue;
            }
        };
        let mut fields: Vec<(String, TypeExpr)> = Vec::new();
        for node in &el.children {
            let m = match node {
                Node::Element(m) => m,
                Node::Text(span) => {
                    errs.push(sm.diag(*span, "unexpected text in <struct>"));
                    continue;
                }
                Node::Comment(..) => continue,
            };
            if m.name != "member" && m.name != "field" {
                errs.push(sm.diag(
                    m.span,
                    format!("unexpected <{}> in <struct> (expected <member>)", m.name),
                ));
                continue;
            }
            m.check_attrs(sm, &["id", "type"], &mut errs);
            let (fid, fty) = match (m.required(sm, "id"), m.required(sm, "type")) {
                (Ok(a), Ok(b)) => (a, b),
                (Err(d), _) | (_, Err(d)) => {
                    errs.push(d);
                    continue;
                }
            };
            if fields.iter().any(|(n, _)| *n == fid.value) {
                errs.push(sm.diag(
                    fid.value_span,
                    format!("member `{}` is declared twice", fid.value),
                ));
                continue;
            }
            match TypeExpr::parse(&fty.value) {
                Ok(t) => {
                    uses.push((t.clone(), fty.value_span));
                    fields.push((fid.value.clone(), t));
                }
                Err(msg) => errs.push(sm.diag(fty.value_span, msg)),
            }
        }
        declare(sm, defs, &id, fields, el.span, &mut errs);
    }
    if errs.is_empty() {
        Ok(())
    } else {
        Err(errs)
    }
}

/// A JSON value with the byte offset where it starts; objects keep their key order.
#[derive(Clone, Debug, PartialEq)]
enum Json {
    Null,
    Bool(bool),
    Num(f64),
    Str(String),
    Arr(Vec<(Json, usize)>),
    Obj(Vec<(String, usize, Json, usize)>),
}

impl Json {
    fn get(&self, key: &str) -> Option<(&Json, usize)> {
        match self {
            Json::Obj(entries) => entries
                .iter()
                .find(|(k, _, _, _)| k == key)
                .map(|(_, _, v, at)| (v, *at)),
            _ => None,
        }
    }
}

struct JsonParser<'a> {
    s: &'a [u8],
    pos: usize,
}

type JsonError = (usize, String);

impl JsonParser<'_> {
    fn ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn expect(&mut self, b: u8) -> Result<(), JsonError> {
        self.ws();
        if self.s.get(self.pos) == Some(&b) {
            self.pos += 1;
            Ok(())
        } else {
            Err((self.pos, format!("expected `{}`", b as char)))
        }
    }

    fn value(&mut self, depth: usize) -> Result<(Json, usize), JsonError> {
        self.ws();
        let at = self.pos;
        if depth > 128 {
            return Err((at, "JSON nested too deeply".into()));
        }
        let v = match self.s.get(self.pos) {
            None => return Err((at, "unexpected end of the file".into())),
            Some(b'{') => {
                self.pos += 1;
                let mut entries = Vec::new();
                self.ws();
                if self.s.get(self.pos) == Some(&b'}') {
                    self.pos += 1;
                } else {
                    loop {
                        self.ws();
                        let kat = self.pos;
                        let Some(b'"') = self.s.get(self.pos) else {
                            return Err((kat, "expected a key in double quotes".into()));
                        };
                        let k = self.string()?;
                        self.expect(b':')?;
                        let (v, vat) = self.value(depth + 1)?;
                        if entries.iter().any(|(e, _, _, _)| *e == k) {
                            return Err((kat, format!("key `{k}` appears twice")));
                        }
                        entries.push((k, kat, v, vat));
                        self.ws();
                        match self.s.get(self.pos) {
                            Some(b',') => self.pos += 1,
                            Some(b'}') => {
                                self.pos += 1;
                                break;
                            }
                            _ => return Err((self.pos, "expected `,` or `}`".into())),
                        }
                    }
                }
                Json::Obj(entries)
            }
            Some(b'[') => {
                self.pos += 1;
                let mut items = Vec::new();
                self.ws();
                if self.s.get(self.pos) == Some(&b']') {
                    self.pos += 1;
                } else {
                    loop {
                        items.push(self.value(depth + 1)?);
                        self.ws();
                        match self.s.get(self.pos) {
                            Some(b',') => self.pos += 1,
                            Some(b']') => {
                                self.pos += 1;
                                break;
                            }
                            _ => return Err((self.pos, "expected `,` or `]`".into())),
                        }
                    }
                }
                Json::Arr(items)
            }
            Some(b'"') => Json::Str(self.string()?),
            Some(b't') if self.s[self.pos..].starts_with(b"true") => {
                self.pos += 4;
                Json::Bool(true)
            }
            Some(b'f') if self.s[self.pos..].starts_with(b"false") => {
                self.pos += 5;
                Json::Bool(false)
            }
            Some(b'n') if self.s[self.pos..].starts_with(b"null") => {
                self.pos += 4;
                Json::Null
            }
            Some(b) if *b == b'-' || b.is_ascii_digit() => {
                let start = self.pos;
                while self.pos < self.s.len()
                    && matches!(
                        self.s[self.pos],
                        b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E'
                    )
                {
                    self.pos += 1;
                }
                let t = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                Json::Num(
                    t.parse()
                        .map_err(|_| (start, format!("`{t}` is not a number")))?,
                )
            }
            Some(_) => return Err((at, "expected a JSON value".into())),
        };
        Ok((v, at))
    }

    /// A string starting at the current `"`.
    fn string(&mut self) -> Result<String, JsonError> {
        let start = self.pos;
        self.pos += 1;
        let mut out = Vec::new();
        loop {
            match self.s.get(self.pos) {
                None => return Err((start, "string is never closed".into())),
                Some(b'"') => {
                    self.pos += 1;
                    break;
                }
                Some(b'\\') => {
                    let esc = self.s.get(self.pos + 1).copied();
                    self.pos += 2;
                    let c = match esc {
                        Some(b'"') => '"',
                        Some(b'\\') => '\\',
                        Some(b'/') => '/',
                        Some(b'n') => '\n',
                        Some(b't') => '\t',
                        Some(b'r') => '\r',
                        Some(b'b') => '\u{8}',
                        Some(b'f') => '\u{c}',
                        Some(b'u') => {
                            let hex = self
                                .s
                                .get(self.pos..self.pos + 4)
                                .and_then(|h| std::str::from_utf8(h).ok())
                                .and_then(|h| u32::from_str_radix(h, 16).ok())
                                .and_then(char::from_u32)
                                .ok_or((self.pos - 2, "bad \\u escape".to_string()))?;
                            self.pos += 4;
                            hex
                        }
                        _ => return Err((self.pos - 2, "bad escape in string".into())),
                    };
                    let mut buf = [0u8; 4];
                    out.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
                }
                Some(b) => {
                    out.push(*b);
                    self.pos += 1;
                }
            }
        }
        String::from_utf8(out).map_err(|_| (start, "string is not UTF-8".into()))
    }
}

fn read_json(
    sm: &SourceMap,
    file: FileId,
    defs: &mut TypeDefs,
    uses: &mut Vec<(TypeExpr, Span)>,
) -> Result<(), Vec<Diagnostic>> {
    let text = sm.file(file).map(|f| f.text()).unwrap_or("");
    let at = |offset: usize| Span {
        file,
        offset: offset as u32,
    };
    let mut p = JsonParser {
        s: text.as_bytes(),
        pos: 0,
    };
    let (root, root_at) = p.value(0).map_err(|(o, m)| vec![sm.diag(at(o), m)])?;
    p.ws();
    if p.pos < text.len() {
        return Err(vec![sm.diag(at(p.pos), "text after the JSON value")]);
    }
    let mut errs = Vec::new();
    let mut structs: Vec<(String, &Json, usize)> = Vec::new();
    match root.get("title") {
        Some((Json::Str(t), _)) => structs.push((t.clone(), &root, root_at)),
        Some((_, o)) => errs.push(sm.diag(at(o), "`title` must be a string")),
        None if root.get("properties").is_some() => errs.push(sm.diag(
            at(root_at),
            "the top-level object needs a `title`: the name of its struct type",
        )),
        None => {}
    }
    match root.get("$defs") {
        Some((Json::Obj(entries), _)) => {
            for (k, _, v, vat) in entries {
                structs.push((k.clone(), v, *vat));
            }
        }
        Some((_, o)) => errs.push(sm.diag(at(o), "`$defs` must be an object")),
        None => {}
    }
    for (name, obj, oat) in structs {
        match obj.get("type") {
            Some((Json::Str(t), _)) if t == "object" => {}
            Some((_, o)) => {
                errs.push(sm.diag(at(o), format!("`{name}` must have \"type\": \"object\"")));
                continue;
            }
            None => {
                errs.push(sm.diag(at(oat), format!("`{name}` has no \"type\"")));
                continue;
            }
        }
        let mut fields = Vec::new();
        match obj.get("properties") {
            Some((Json::Obj(props), _)) => {
                for (k, _, v, vat) in props {
                    match json_type(v, *vat) {
                        Ok(t) => {
                            uses.push((t.clone(), at(*vat)));
                            fields.push((k.clone(), t));
                        }
                        Err((o, m)) => errs.push(sm.diag(at(o), m)),
                    }
                }
            }
            Some((_, o)) => errs.push(sm.diag(at(o), "`properties` must be an object")),
            None => {}
        }
        declare(sm, defs, &name, fields, at(oat), &mut errs);
    }
    if errs.is_empty() {
        Ok(())
    } else {
        Err(errs)
    }
}

/// The type of one schema property.
fn json_type(v: &Json, vat: usize) -> Result<TypeExpr, JsonError> {
    if let Some((r, rat)) = v.get("$ref") {
        return match r {
            Json::Str(s) => match s.strip_prefix("#/$defs/") {
                Some(n) if !n.is_empty() => Ok(TypeExpr::Named(n.to_string())),
                _ => Err((
                    rat,
                    format!("`{s}`: only references to `#/$defs/Name` are supported"),
                )),
            },
            _ => Err((rat, "`$ref` must be a string".into())),
        };
    }
    let (t, tat) = v
        .get("type")
        .ok_or((vat, "the property has no \"type\" or \"$ref\"".to_string()))?;
    let Json::Str(t) = t else {
        return Err((tat, "\"type\" must be a string".into()));
    };
    use crate::model::types::BaseType;
    Ok(match t.as_str() {
        "string" => TypeExpr::Base(BaseType::Str),
        "boolean" => TypeExpr::Base(BaseType::Bool),
        "integer" => TypeExpr::parse("int32").map_err(|m| (tat, m))?,
        "number" => TypeExpr::parse("float32").map_err(|m| (tat, m))?,
        "array" => {
            let (items, iat) = v
                .get("items")
                .ok_or((vat, "an array property needs `items`".to_string()))?;
            let inner = json_type(items, iat)?;
            let bound = match v.get("maxItems") {
                Some((Json::Num(n), _)) if *n >= 0.0 && n.fract() == 0.0 && *n <= u32::MAX as f64 => {
                    Some(*n as u32)
                }
                Some((_, o)) => return Err((o, "`maxItems` must be a whole number".into())),
                None => None,
            };
            TypeExpr::Array(Box::new(inner), bound)
        }
        other => {
            return Err((
                tat,
                format!(
                    "unsupported type `{other}` (expected string, boolean, integer, number, array or a $ref)"
                ),
            ))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Json, JsonError> {
        JsonParser {
            s: s.as_bytes(),
            pos: 0,
        }
        .value(0)
        .map(|(v, _)| v)
    }

    #[test]
    fn no_input_panics() {
        let tokens = [
            "{",
            "}",
            "[",
            "]",
            ":",
            ",",
            "\"",
            "\\",
            "u",
            "12",
            "-",
            "e",
            "true",
            "nul",
            "é",
            "\"$ref\"",
            "\"#/$defs/\"",
            "\"type\"",
            "\"array\"",
            "\"items\"",
            " ",
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let (mut oks, mut errs) = (0, 0);
        for _ in 0..20_000 {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state
            };
            let mut text = String::new();
            for _ in 0..(next() % 12) {
                text.push_str(tokens[(next() % tokens.len() as u64) as usize]);
            }
            match parse(&text) {
                Ok(v) => {
                    oks += 1;
                    let _ = json_type(&v, 0);
                }
                Err(_) => errs += 1,
            }
        }
        assert!(oks > 500 && errs > 10_000, "{oks} parsed, {errs} rejected");
    }

    #[test]
    fn json_values() {
        assert_eq!(parse(" [1, -2.5e1, true, null] ").unwrap(), {
            Json::Arr(vec![
                (Json::Num(1.0), 2),
                (Json::Num(-25.0), 5),
                (Json::Bool(true), 13),
                (Json::Null, 19),
            ])
        });
        let o = parse(r#"{"b": "x\"\u0041", "a": {}}"#).unwrap();
        let Json::Obj(e) = &o else { panic!() };
        assert_eq!(e[0].0, "b");
        assert_eq!(e[0].2, Json::Str("x\"A".into()));
        assert_eq!(e[1].0, "a");
        assert_eq!(parse("{\"a\" 1}").unwrap_err().0, 5);
        assert_eq!(parse("[1,").unwrap_err().0, 3);
        assert!(parse("\"abc").is_err());
        assert!(parse("{\"a\":1,\"a\":2}").is_err());
        assert!(parse(&"[".repeat(500)).is_err());
    }
}
