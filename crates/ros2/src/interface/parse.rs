//! The `.msg` / `.srv` / `.action` file format read with positions: one field or constant a
//! line, `---` between the parts of a service or an action.

use super::def::*;
use codegen::diag::{Diagnostic, FileId, SourceMap, Span};

/// Largest fixed array length accepted (its default literal is written out in full).
const MAX_FIXED_LEN: u32 = 4096;

/// Parses the text of interface file `file` (already in `sm`) as `package/kind/name`.
///
/// Message types named without a package are looked for in `package`. Whether the named
/// types exist is checked later, by the caller (`hindsight`'s `Interfaces::check`, or
/// [`crate::schema::Schema::resolve`]).
pub fn parse_interface(
    sm: &SourceMap,
    file: FileId,
    package: &str,
    name: &str,
    kind: InterfaceKind,
) -> Result<InterfaceDef, Vec<Diagnostic>> {
    let Some(src) = sm.source(file) else {
        return Err(vec![Diagnostic::about_file(
            "<unknown>",
            "internal error: interface file not in the source map".to_string(),
        )]);
    };
    let text = src.text();
    let at = |offset: usize| file.at(offset as u32);
    let mut errs = Vec::new();
    let mut parts = vec![MessageDef::default()];
    // A byte-order mark is not part of the first line.
    let mut line_start = if text.starts_with('\u{feff}') { 3 } else { 0 };
    for raw_line in text[line_start..].split_inclusive('\n') {
        let start = line_start;
        line_start += raw_line.len();
        let line = strip_comment(raw_line.trim_end_matches(['\n', '\r']));
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        let indent = line.len() - line.trim_start().len();
        let line_span = at(start + indent);
        if trimmed == "---" {
            if parts.len() >= kind.parts() {
                errs.push(sm.diag(
                    line_span,
                    format!(
                        "too many `---` separators: a {} has {} part{}",
                        kind.noun(),
                        kind.parts(),
                        if kind.parts() == 1 { "" } else { "s" }
                    ),
                ));
            } else {
                parts.push(MessageDef::default());
            }
            continue;
        }
        match parse_line(trimmed, start + indent, package) {
            Ok(Item::Field(mut f)) => {
                f.span = at(f.span.lo as usize);
                let part = parts.last_mut().expect("at least one part");
                if part.fields.iter().any(|g| g.name == f.name)
                    || part.constants.iter().any(|c| c.name == f.name)
                {
                    errs.push(sm.diag(line_span, format!("`{}` is declared twice", f.name)));
                } else {
                    part.fields.push(f);
                }
            }
            Ok(Item::Constant(mut c)) => {
                c.span = line_span;
                let part = parts.last_mut().expect("at least one part");
                if part.fields.iter().any(|g| g.name == c.name)
                    || part.constants.iter().any(|d| d.name == c.name)
                {
                    errs.push(sm.diag(line_span, format!("`{}` is declared twice", c.name)));
                } else {
                    part.constants.push(c);
                }
            }
            Err(e) => errs.push(sm.diag(at(e.offset), e.message)),
        }
    }
    if parts.len() < kind.parts() && errs.is_empty() {
        let end = at(text.len());
        errs.push(sm.diag(
            end,
            format!(
                "a {} needs {} parts separated by `---`, found {}",
                kind.noun(),
                kind.parts(),
                parts.len()
            ),
        ));
    }
    if errs.is_empty() {
        Ok(InterfaceDef {
            package: package.to_string(),
            name: name.to_string(),
            kind,
            parts,
            file: Some(file),
        })
    } else {
        Err(errs)
    }
}

/// The line without its comment (a `#` outside quotes starts one).
fn strip_comment(line: &str) -> &str {
    match unquoted(line).find(|&(_, c)| c == '#') {
        Some((i, _)) => &line[..i],
        None => line,
    }
}

/// The characters of `text` outside quoted strings (`"..."` or `'...'`, with `\`
/// escapes inside), with their byte offsets.
fn unquoted(text: &str) -> impl Iterator<Item = (usize, char)> + '_ {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    text.char_indices().filter(move |&(_, c)| {
        if escaped {
            escaped = false;
            return false;
        }
        match (quote, c) {
            (Some(_), '\\') => escaped = true,
            (Some(q), c) if c == q => quote = None,
            (None, '"') | (None, '\'') => quote = Some(c),
            (None, _) => return true,
            _ => {}
        }
        false
    })
}

enum Item {
    Field(Field),
    Constant(Constant),
}

/// A fault in one line: the byte offset in the file it points at, and what is wrong.
struct LineError {
    offset: usize,
    message: String,
}

impl LineError {
    fn at(offset: usize, message: String) -> LineError {
        LineError { offset, message }
    }
}

/// Parses one non-empty, comment-free, trimmed line that starts at byte `base` of the file.
/// Spans in the result hold absolute offsets with a placeholder file.
fn parse_line(line: &str, base: usize, package: &str) -> Result<Item, LineError> {
    let ty_end = line.find(char::is_whitespace).unwrap_or(line.len());
    let ty_text = &line[..ty_end];
    let rest_full = &line[ty_end..];
    let rest = rest_full.trim_start();
    let name_off = base + ty_end + (rest_full.len() - rest.len());
    if rest.is_empty() {
        return Err(LineError::at(
            base + ty_end,
            format!("expected a field name after the type `{ty_text}`"),
        ));
    }
    let ty = parse_type(ty_text, base, package)?;
    let name_end = rest
        .find(|c: char| c.is_whitespace() || c == '=')
        .unwrap_or(rest.len());
    let name = &rest[..name_end];
    let after = rest[name_end..].trim_start();
    let after_off = name_off + name_end + (rest[name_end..].len() - after.len());
    if name.is_empty() {
        return Err(LineError::at(
            name_off,
            "expected a field or constant name".into(),
        ));
    }
    if let Some(value) = after.strip_prefix('=') {
        // A constant.
        if !valid_constant_name(name) {
            return Err(LineError::at(
                name_off,
                format!("`{name}` is not a valid constant name (upper-case letters, digits and `_`, starting with a letter)"),
            ));
        }
        let prim = match (&ty.base, ty.array) {
            (BaseType::Primitive { prim, .. }, ArraySize::Scalar) => *prim,
            _ => {
                return Err(LineError::at(
                    base,
                    "a constant must have a primitive, non-array type".into(),
                ))
            }
        };
        let v = value.trim();
        let v_off = after_off + 1 + (value.len() - value.trim_start().len());
        if v.is_empty() {
            return Err(LineError::at(
                after_off,
                format!("constant `{name}` has no value"),
            ));
        }
        let value = parse_scalar(prim, string_bound(&ty), v, v_off, true)?;
        return Ok(Item::Constant(Constant {
            name: name.to_string(),
            prim,
            value,
            span: placeholder(base),
        }));
    }
    if !valid_field_name(name) {
        return Err(LineError::at(
            name_off,
            format!(
                "`{name}` is not a valid field name (lower-case letters, digits and single `_`, starting with a letter)"
            ),
        ));
    }
    let default = if after.is_empty() {
        None
    } else {
        Some(parse_default(&ty, after, after_off)?)
    };
    Ok(Item::Field(Field {
        name: name.to_string(),
        ty,
        default,
        span: placeholder(base),
    }))
}

fn placeholder(offset: usize) -> Span {
    FileId(0).at(offset as u32)
}

fn string_bound(ty: &FieldType) -> Option<u32> {
    match ty.base {
        BaseType::Primitive { string_bound, .. } => string_bound,
        BaseType::Message { .. } => None,
    }
}

/// `[a-z][a-z0-9_]*`, no `__`, no trailing `_` (ROS 2's rule; `__` would also clash with the
/// flattened names).
fn valid_field_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !name.contains("__")
        && !name.ends_with('_')
}

fn valid_constant_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_uppercase())
        && name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

/// A valid interface (file) name: an upper-case letter, then letters and digits.
pub fn valid_type_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_uppercase())
        && name.chars().all(|c| c.is_ascii_alphanumeric())
}

/// A type name as written in a field's type: [`valid_type_name`], or the names rosidl
/// generates for the parts of services and actions and that embedded definitions (MCAP's
/// `ros2msg` schemas) spell out: `AddTwoInts_Request`, `AddTwoInts_Event`,
/// `Fibonacci_SendGoal_Request`, each `_`-separated part a valid type name.
pub fn valid_generated_type_name(name: &str) -> bool {
    name.split('_').all(valid_type_name)
}

fn valid_package_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Parses a type token (`int32`, `string<=5[<=3]`, `pkg/Type[4]`) starting at byte `base`.
fn parse_type(text: &str, base: usize, package: &str) -> Result<FieldType, LineError> {
    let (elem, array_text, array_off) = match text.find('[') {
        Some(i) => (&text[..i], &text[i..], base + i),
        None => (text, "", base + text.len()),
    };
    let array = if array_text.is_empty() {
        ArraySize::Scalar
    } else {
        let Some(inner) = array_text
            .strip_prefix('[')
            .and_then(|s| s.strip_suffix(']'))
        else {
            return Err(LineError::at(
                array_off,
                format!("malformed array size `{array_text}` (expected `[]`, `[N]` or `[<=N]`)"),
            ));
        };
        if inner.contains('[') || inner.contains(']') {
            return Err(LineError::at(
                array_off,
                "arrays of arrays are not allowed".into(),
            ));
        }
        if inner.is_empty() {
            ArraySize::Unbounded
        } else if let Some(n) = inner.strip_prefix("<=") {
            ArraySize::Bounded(parse_len(n, array_off)?)
        } else {
            let n = parse_len(inner, array_off)?;
            if n > MAX_FIXED_LEN {
                return Err(LineError::at(
                    array_off,
                    format!("fixed array length {n} is larger than {MAX_FIXED_LEN}"),
                ));
            }
            ArraySize::Fixed(n)
        }
    };
    let (elem_name, string_bound) = match elem.split_once("<=") {
        Some((e, n)) => {
            if e != "string" && e != "wstring" {
                return Err(LineError::at(
                    base,
                    format!("only strings can be bounded with `<=`, not `{e}`"),
                ));
            }
            (e, Some(parse_len(n, base + e.len())?))
        }
        None => (elem, None),
    };
    if elem_name.is_empty() {
        return Err(LineError::at(base, "missing type name".into()));
    }
    if let Some(prim) = Primitive::from_name(elem_name) {
        return Ok(FieldType {
            base: BaseType::Primitive { prim, string_bound },
            array,
        });
    }
    let parts: Vec<&str> = elem_name.split('/').collect();
    let (pkg, name) = match parts.as_slice() {
        [name] => {
            // ROS 2 reads a bare `Header` as std_msgs's.
            if *name == "Header" && package != "std_msgs" {
                ("std_msgs", *name)
            } else {
                (package, *name)
            }
        }
        [pkg, name] => (*pkg, *name),
        [pkg, "msg", name] => (*pkg, *name),
        _ => {
            return Err(LineError::at(
                base,
                format!(
                    "`{elem_name}` is not a type (expected a primitive, `Type` or `package/Type`)"
                ),
            ))
        }
    };
    if !valid_generated_type_name(name) || !valid_package_name(pkg) {
        return Err(LineError::at(
            base,
            format!("`{elem_name}` is not a primitive type or a message name (`package/Type`, the type starting with an upper-case letter)"),
        ));
    }
    Ok(FieldType {
        base: BaseType::Message {
            package: pkg.to_string(),
            name: name.to_string(),
        },
        array,
    })
}

fn parse_len(text: &str, offset: usize) -> Result<u32, LineError> {
    text.trim()
        .parse::<u32>()
        .map_err(|_| LineError::at(offset, format!("`{text}` is not an array or string length")))
}

/// Parses a field's default value (after the name) into an ECMAScript literal.
fn parse_default(ty: &FieldType, text: &str, offset: usize) -> Result<String, LineError> {
    let (prim, sbound) = match &ty.base {
        BaseType::Primitive { prim, string_bound } => (*prim, *string_bound),
        BaseType::Message { .. } => {
            return Err(LineError::at(
                offset,
                "only fields of primitive types can have default values".into(),
            ))
        }
    };
    match ty.array {
        ArraySize::Scalar => parse_scalar(prim, sbound, text, offset, false),
        size => {
            let Some(inner) = text.strip_prefix('[').and_then(|s| s.strip_suffix(']')) else {
                return Err(LineError::at(
                    offset,
                    format!("an array default is written `[a, b, ...]`, found `{text}`"),
                ));
            };
            let items = split_items(inner);
            let mut out = Vec::new();
            for (k, item) in items {
                let t = item.trim();
                if t.is_empty() {
                    if inner.trim().is_empty() {
                        break;
                    }
                    return Err(LineError::at(offset + 1 + k, "empty array element".into()));
                }
                let lead = item.len() - item.trim_start().len();
                out.push(parse_scalar(prim, sbound, t, offset + 1 + k + lead, false)?);
            }
            match size {
                ArraySize::Fixed(n) if out.len() != n as usize => {
                    return Err(LineError::at(
                        offset,
                        format!(
                            "the default has {} elements, the array has exactly {n}",
                            out.len()
                        ),
                    ))
                }
                ArraySize::Bounded(n) if out.len() > n as usize => {
                    return Err(LineError::at(
                        offset,
                        format!(
                            "the default has {} elements, the array has at most {n}",
                            out.len()
                        ),
                    ))
                }
                _ => {}
            }
            Ok(format!("[{}]", out.join(", ")))
        }
    }
}

/// Splits `a, 'b,c', d` at top-level commas; each item with its byte offset in `text`.
fn split_items(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, _) in unquoted(text).filter(|&(_, c)| c == ',') {
        out.push((start, &text[start..i]));
        start = i + 1;
    }
    out.push((start, &text[start..]));
    out
}

/// Parses one primitive value into an ECMAScript literal. Unquoted strings are accepted
/// for constants (`string NAME=abc`), as ROS 2 does.
fn parse_scalar(
    prim: Primitive,
    string_bound: Option<u32>,
    text: &str,
    offset: usize,
    constant: bool,
) -> Result<String, LineError> {
    let bad = |what: &str| LineError::at(offset, format!("`{text}` is not {what}"));
    if prim.is_string() {
        let value = match unquote(text) {
            Some(Ok(v)) => v,
            Some(Err(())) => return Err(bad("a well-formed quoted string")),
            None if constant => text.to_string(),
            None => return Err(bad("a quoted string (write \"...\" or '...')")),
        };
        if let Some(n) = string_bound {
            if value.chars().count() > n as usize {
                return Err(LineError::at(
                    offset,
                    format!("the string is longer than its bound {n}"),
                ));
            }
        }
        return Ok(ecma_string(&value));
    }
    match prim {
        Primitive::Bool => match text {
            "true" | "True" | "1" => Ok("true".into()),
            "false" | "False" | "0" => Ok("false".into()),
            _ => Err(bad("a bool (true or false)")),
        },
        Primitive::Float32 | Primitive::Float64 => {
            let ok = !text.is_empty()
                && text
                    .chars()
                    .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
            match text.parse::<f64>() {
                Ok(v) if ok && v.is_finite() => Ok(format!("{v:?}")),
                _ => Err(bad("a finite number")),
            }
        }
        _ => {
            let (lo, hi) = prim.int_range().ok_or_else(|| bad("a value"))?;
            let v: i128 = text.parse().map_err(|_| bad("an integer"))?;
            if v < lo || v > hi {
                return Err(LineError::at(
                    offset,
                    format!(
                        "{v} is out of range for {} ({lo} to {hi})",
                        prim.scxml_name()
                    ),
                ));
            }
            Ok(v.to_string())
        }
    }
}

/// `"a\"b"` or `'a'` unquoted; `None` when not quoted; `Err` when malformed.
fn unquote(text: &str) -> Option<Result<String, ()>> {
    let q = text.chars().next()?;
    if q != '"' && q != '\'' {
        return None;
    }
    let body = &text[1..];
    let mut out = String::new();
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(c) => out.push(c),
                None => return Some(Err(())),
            }
        } else if c == q {
            return Some(if chars.as_str().is_empty() {
                Ok(out)
            } else {
                Err(())
            });
        } else {
            out.push(c);
        }
    }
    Some(Err(()))
}

/// A single-quoted ECMAScript string literal.
fn ecma_string(s: &str) -> String {
    let mut out = String::from("'");
    for c in s.chars() {
        match c {
            '\'' => out.push_str("\\'"),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c => out.push(c),
        }
    }
    out.push('\'');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, kind: InterfaceKind) -> Result<InterfaceDef, Vec<Diagnostic>> {
        let mut sm = SourceMap::new();
        let f = sm.add("p/x", text.to_string());
        parse_interface(&sm, f, "p", "X", kind)
    }

    fn err(text: &str, kind: InterfaceKind) -> String {
        parse(text, kind).unwrap_err()[0].to_string()
    }

    #[test]
    fn lines_parse() {
        let d = parse(
            "# c\nint8 A=1 # x\nstring S = \"a#b\"\nint32 x 5\nfloat64[3] v [1, 2, 3.5]\nstring<=4[<=2] s ['ab', \"c,d\"]\nInternal i\nq/T[] ts\n",
            InterfaceKind::Message,
        )
        .unwrap();
        let p = &d.parts[0];
        assert_eq!(p.constants[0].value, "1");
        assert_eq!(p.constants[1].value, "'a#b'");
        assert_eq!(p.fields[0].default.as_deref(), Some("5"));
        assert_eq!(p.fields[1].default.as_deref(), Some("[1.0, 2.0, 3.5]"));
        assert_eq!(p.fields[1].ty.array, ArraySize::Fixed(3));
        assert_eq!(p.fields[2].ty.array, ArraySize::Bounded(2));
        assert_eq!(p.fields[2].default.as_deref(), Some("['ab', 'c,d']"));
        assert_eq!(
            p.fields[3].ty.base,
            BaseType::Message {
                package: "p".into(),
                name: "Internal".into()
            }
        );
        assert_eq!(p.fields[4].ty.array, ArraySize::Unbounded);
    }

    #[test]
    fn bad_lines() {
        assert!(err("int32", InterfaceKind::Message).contains("p/x:1:6"));
        assert!(err("int33 x", InterfaceKind::Message).contains("p/x:1:1"));
        assert!(err("int8 x 300", InterfaceKind::Message).contains("out of range"));
        assert!(err("int32[2] x [1]", InterfaceKind::Message).contains("exactly 2"));
        assert!(err("int32 Bad", InterfaceKind::Message).contains("p/x:1:7"));
        assert!(err("int32 x\n---\n", InterfaceKind::Message).contains("p/x:2:1"));
        assert!(err("int32 x\n", InterfaceKind::Service).contains("2 parts"));
        assert!(err("int32 x\nint32 x\n", InterfaceKind::Message).contains("twice"));
        assert!(err("string s abc", InterfaceKind::Message).contains("quoted"));
        assert!(err("int32[<=x] s", InterfaceKind::Message).contains("length"));
        assert!(err("int32[2][3] s", InterfaceKind::Message).contains("array"));
        assert!(err("int32<=3 s", InterfaceKind::Message).contains("bounded"));
    }

    #[test]
    fn no_input_panics() {
        let tokens = [
            "int32", "x", "X", "=", "[", "]", "[<=", "<=", "'", "\"", "é", "#", "---", " ", "\n",
            "3", "-1", "string", "p/T", "\\", ",", "\u{feff}", "1e999", "\r\n", "[]", "T",
        ];
        let (mut oks, mut errs) = (0, 0);
        for text in crate::interface::random_texts(&tokens, 0x9e37_79b9_7f4a_7c15u64, 9, 20_000) {
            for kind in [
                InterfaceKind::Message,
                InterfaceKind::Service,
                InterfaceKind::Action,
            ] {
                match parse(&text, kind) {
                    Ok(_) => oks += 1,
                    Err(_) => errs += 1,
                }
            }
        }
        assert!(
            oks > 1_000 && errs > 10_000,
            "{oks} parsed, {errs} rejected"
        );
        assert_eq!(
            parse(
                "\u{feff}int32 x\r\nstring<=3 s 'é'\r\n",
                InterfaceKind::Message
            )
            .unwrap()
            .parts[0]
                .fields
                .len(),
            2
        );
    }
}
