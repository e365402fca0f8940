//! The JSON reader that keeps the position of every value: JANI property files and
//! JSON-schema data declarations (where positions are not needed, serde_json reads).
//!
//! It accepts RFC 8259 JSON (objects, arrays, strings with escapes, numbers, `true`,
//! `false`, `null`) and reports the first syntax error with its byte offset.

/// A JSON value and the byte offset where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Byte offset of the value's first character.
    pub offset: usize,
    /// The value.
    pub value: Json,
}

/// A JSON value.
#[derive(Clone, Debug, PartialEq)]
pub enum Json {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number, as written (so `10` and `10.0` stay apart).
    Number(String),
    /// A string, unescaped.
    Str(String),
    /// An array's elements.
    Array(Vec<Node>),
    /// Members in file order: key, key offset, value.
    Object(Vec<(String, usize, Node)>),
}

impl Node {
    /// The member `key` of an object.
    pub fn get(&self, key: &str) -> Option<&Node> {
        match &self.value {
            Json::Object(members) => members.iter().find(|(k, _, _)| k == key).map(|m| &m.2),
            _ => None,
        }
    }

    /// The number's value, if this is a number.
    pub fn as_f64(&self) -> Option<f64> {
        match &self.value {
            Json::Number(n) => n.parse().ok(),
            _ => None,
        }
    }

    /// The string value, if this is a string.
    pub fn as_str(&self) -> Option<&str> {
        match &self.value {
            Json::Str(s) => Some(s),
            _ => None,
        }
    }
}

/// Nesting limit, so deep input cannot overflow the stack.
const MAX_DEPTH: usize = 256;

struct Parser<'a> {
    text: &'a str,
    pos: usize,
}

/// Parses a whole document; an error is `(byte offset, message)`.
pub fn parse(text: &str) -> Result<Node, (usize, String)> {
    let mut p = Parser { text, pos: 0 };
    p.ws();
    let node = p.value(0)?;
    p.ws();
    if p.pos < text.len() {
        return Err((p.pos, "unexpected text after the JSON value".into()));
    }
    Ok(node)
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.pos += 1;
        }
    }

    fn expect(&mut self, b: u8) -> Result<(), (usize, String)> {
        if self.peek() == Some(b) {
            self.pos += 1;
            Ok(())
        } else {
            Err((self.pos, format!("expected `{}`", b as char)))
        }
    }

    fn value(&mut self, depth: usize) -> Result<Node, (usize, String)> {
        if depth > MAX_DEPTH {
            return Err((self.pos, "nested too deeply".into()));
        }
        let offset = self.pos;
        let value = match self.peek() {
            Some(b'{') => {
                self.pos += 1;
                let mut members = Vec::new();
                self.ws();
                if self.peek() == Some(b'}') {
                    self.pos += 1;
                } else {
                    loop {
                        self.ws();
                        let key_at = self.pos;
                        if self.peek() != Some(b'"') {
                            return Err((self.pos, "expected a member name (a string)".into()));
                        }
                        let key = self.string()?;
                        if members.iter().any(|(k, _, _)| *k == key) {
                            return Err((key_at, format!("member `{key}` appears twice")));
                        }
                        self.ws();
                        self.expect(b':')?;
                        self.ws();
                        let v = self.value(depth + 1)?;
                        members.push((key, key_at, v));
                        self.ws();
                        match self.peek() {
                            Some(b',') => self.pos += 1,
                            Some(b'}') => {
                                self.pos += 1;
                                break;
                            }
                            _ => return Err((self.pos, "expected `,` or `}`".into())),
                        }
                    }
                }
                Json::Object(members)
            }
            Some(b'[') => {
                self.pos += 1;
                let mut items = Vec::new();
                self.ws();
                if self.peek() == Some(b']') {
                    self.pos += 1;
                } else {
                    loop {
                        self.ws();
                        items.push(self.value(depth + 1)?);
                        self.ws();
                        match self.peek() {
                            Some(b',') => self.pos += 1,
                            Some(b']') => {
                                self.pos += 1;
                                break;
                            }
                            _ => return Err((self.pos, "expected `,` or `]`".into())),
                        }
                    }
                }
                Json::Array(items)
            }
            Some(b'"') => Json::Str(self.string()?),
            Some(b't') => self.word("true", Json::Bool(true))?,
            Some(b'f') => self.word("false", Json::Bool(false))?,
            Some(b'n') => self.word("null", Json::Null)?,
            Some(b'-' | b'0'..=b'9') => self.number()?,
            Some(_) => return Err((self.pos, "expected a JSON value".into())),
            None => return Err((self.pos, "unexpected end of file".into())),
        };
        Ok(Node { offset, value })
    }

    fn word(&mut self, w: &str, v: Json) -> Result<Json, (usize, String)> {
        if self.text[self.pos..].starts_with(w) {
            self.pos += w.len();
            Ok(v)
        } else {
            Err((self.pos, "expected a JSON value".into()))
        }
    }

    fn number(&mut self) -> Result<Json, (usize, String)> {
        let start = self.pos;
        let digits = |p: &mut Self| {
            let s = p.pos;
            while matches!(p.peek(), Some(b'0'..=b'9')) {
                p.pos += 1;
            }
            p.pos > s
        };
        if self.peek() == Some(b'-') {
            self.pos += 1;
        }
        if !digits(self) {
            return Err((self.pos, "expected digits".into()));
        }
        if self.peek() == Some(b'.') {
            self.pos += 1;
            if !digits(self) {
                return Err((self.pos, "expected digits after `.`".into()));
            }
        }
        if matches!(self.peek(), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(self.peek(), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            if !digits(self) {
                return Err((self.pos, "expected exponent digits".into()));
            }
        }
        Ok(Json::Number(self.text[start..self.pos].to_owned()))
    }

    fn string(&mut self) -> Result<String, (usize, String)> {
        self.expect(b'"')?;
        let mut out = String::new();
        loop {
            let rest = &self.text[self.pos..];
            let Some(c) = rest.chars().next() else {
                return Err((self.pos, "unterminated string".into()));
            };
            match c {
                '"' => {
                    self.pos += 1;
                    return Ok(out);
                }
                '\\' => {
                    let at = self.pos;
                    self.pos += 1;
                    let Some(e) = self.peek() else {
                        return Err((at, "unterminated escape".into()));
                    };
                    self.pos += 1;
                    match e {
                        b'"' => out.push('"'),
                        b'\\' => out.push('\\'),
                        b'/' => out.push('/'),
                        b'b' => out.push('\u{8}'),
                        b'f' => out.push('\u{c}'),
                        b'n' => out.push('\n'),
                        b'r' => out.push('\r'),
                        b't' => out.push('\t'),
                        b'u' => {
                            let hex = self.text.get(self.pos..self.pos + 4).unwrap_or("");
                            let code = u32::from_str_radix(hex, 16)
                                .map_err(|_| (at, "bad `\\u` escape".to_string()))?;
                            self.pos += 4;
                            out.push(char::from_u32(code).unwrap_or('\u{fffd}'));
                        }
                        _ => return Err((at, "unknown escape".into())),
                    }
                }
                c if (c as u32) < 0x20 => {
                    return Err((self.pos, "control character in a string".into()))
                }
                c => {
                    out.push(c);
                    self.pos += c.len_utf8();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_offsets_and_number_text() {
        let n = parse(r#"{"a": [1, 2.0, "x\n"], "b": true}"#).unwrap();
        let a = n.get("a").unwrap();
        assert_eq!(a.offset, 6);
        let Json::Array(items) = &a.value else {
            panic!("array")
        };
        assert_eq!(items[1].value, Json::Number("2.0".into()));
        assert_eq!(items[2].as_str(), Some("x\n"));
        assert_eq!(n.get("b").unwrap().value, Json::Bool(true));
    }

    #[test]
    fn errors_have_offsets() {
        assert_eq!(parse("{\"a\" 1}").unwrap_err().0, 5);
        assert!(parse("[1,]").is_err());
        assert!(parse("\"abc").is_err());
        assert!(parse(&"[".repeat(1000)).is_err());
    }
}
