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
use crate::model::json::{self, Json, Node as JsonNode};
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
        let text = match codegen::diag::read_source(path) {
            Ok(t) => t,
            Err(d) => {
                errs.push(d);
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
                Err(msg) => errs.push(sm.diag(fty.value_span, msg.to_string())),
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

type JsonError = (usize, String);

fn read_json(
    sm: &SourceMap,
    file: FileId,
    defs: &mut TypeDefs,
    uses: &mut Vec<(TypeExpr, Span)>,
) -> Result<(), Vec<Diagnostic>> {
    let text = sm.source(file).map(|f| f.text()).unwrap_or("");
    let at = |offset: usize| file.at(offset as u32);
    let root = json::parse(text).map_err(|(o, m)| vec![sm.diag(at(o), m)])?;
    let root_at = root.offset;
    let mut errs = Vec::new();
    let mut structs: Vec<(String, &JsonNode)> = Vec::new();
    match root.get("title") {
        Some(JsonNode {
            value: Json::Str(t),
            ..
        }) => structs.push((t.clone(), &root)),
        Some(t) => errs.push(sm.diag(at(t.offset), "`title` must be a string")),
        None if root.get("properties").is_some() => errs.push(sm.diag(
            at(root_at),
            "the top-level object needs a `title`: the name of its struct type",
        )),
        None => {}
    }
    match root.get("$defs") {
        Some(JsonNode {
            value: Json::Object(entries),
            ..
        }) => {
            for (k, _, v) in entries {
                structs.push((k.clone(), v));
            }
        }
        Some(d) => errs.push(sm.diag(at(d.offset), "`$defs` must be an object")),
        None => {}
    }
    for (name, obj) in structs {
        let oat = obj.offset;
        match obj.get("type") {
            Some(t) if t.as_str() == Some("object") => {}
            Some(t) => {
                errs.push(sm.diag(
                    at(t.offset),
                    format!("`{name}` must have \"type\": \"object\""),
                ));
                continue;
            }
            None => {
                errs.push(sm.diag(at(oat), format!("`{name}` has no \"type\"")));
                continue;
            }
        }
        let mut fields = Vec::new();
        match obj.get("properties") {
            Some(JsonNode {
                value: Json::Object(props),
                ..
            }) => {
                for (k, _, v) in props {
                    match json_type(v) {
                        Ok(t) => {
                            uses.push((t.clone(), at(v.offset)));
                            fields.push((k.clone(), t));
                        }
                        Err((o, m)) => errs.push(sm.diag(at(o), m)),
                    }
                }
            }
            Some(p) => errs.push(sm.diag(at(p.offset), "`properties` must be an object")),
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
fn json_type(v: &JsonNode) -> Result<TypeExpr, JsonError> {
    if let Some(r) = v.get("$ref") {
        return match r.as_str() {
            Some(s) => match s.strip_prefix("#/$defs/") {
                Some(n) if !n.is_empty() => Ok(TypeExpr::Named(n.to_string())),
                _ => Err((
                    r.offset,
                    format!("`{s}`: only references to `#/$defs/Name` are supported"),
                )),
            },
            None => Err((r.offset, "`$ref` must be a string".into())),
        };
    }
    let t = v.get("type").ok_or((
        v.offset,
        "the property has no \"type\" or \"$ref\"".to_string(),
    ))?;
    let tat = t.offset;
    let Some(t) = t.as_str() else {
        return Err((tat, "\"type\" must be a string".into()));
    };
    use crate::model::types::BaseType;
    Ok(match t {
        "string" => TypeExpr::Base(BaseType::Str),
        "boolean" => TypeExpr::Base(BaseType::Bool),
        "integer" => TypeExpr::parse("int32").map_err(|m| (tat, m.to_string()))?,
        "number" => TypeExpr::parse("float32").map_err(|m| (tat, m.to_string()))?,
        "array" => {
            let items = v
                .get("items")
                .ok_or((v.offset, "an array property needs `items`".to_string()))?;
            let inner = json_type(items)?;
            let bound = match v.get("maxItems") {
                None => None,
                Some(m) => match m.as_f64() {
                    Some(n) if n >= 0.0 && n.fract() == 0.0 && n <= u32::MAX as f64 => {
                        Some(n as u32)
                    }
                    _ => return Err((m.offset, "`maxItems` must be a whole number".into())),
                },
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

    fn parse(s: &str) -> Result<JsonNode, JsonError> {
        json::parse(s)
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
        let (mut oks, mut errs) = (0, 0);
        for text in crate::random_text::texts(&tokens, 0x2545_f491_4f6c_dd1du64, 12, 20_000) {
            match parse(&text) {
                Ok(v) => {
                    oks += 1;
                    let _ = json_type(&v);
                }
                Err(_) => errs += 1,
            }
        }
        assert!(oks > 500 && errs > 10_000, "{oks} parsed, {errs} rejected");
    }

    #[test]
    fn json_values() {
        let v = parse(" [1, -2.5e1, true, null] ").unwrap();
        let Json::Array(items) = &v.value else {
            panic!("{v:?}")
        };
        let at: Vec<usize> = items.iter().map(|n| n.offset).collect();
        assert_eq!(at, [2, 5, 13, 19]);
        assert_eq!(items[1].as_f64(), Some(-25.0));
        let o = parse(r#"{"b": "x\"\u0041", "a": {}}"#).unwrap();
        let Json::Object(e) = &o.value else { panic!() };
        assert_eq!(e[0].0, "b");
        assert_eq!(e[0].2.as_str(), Some("x\"A"));
        assert_eq!(e[1].0, "a");
        assert_eq!(parse("{\"a\" 1}").unwrap_err().0, 5);
        assert_eq!(parse("[1,").unwrap_err().0, 3);
        assert!(parse("\"abc").is_err());
        assert_eq!(parse("{\"a\":1,\"a\":2}").unwrap_err().0, 7);
        assert!(parse(&"[".repeat(500)).is_err());
    }
}
