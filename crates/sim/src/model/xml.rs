//! The one XML element tree of the project, with byte spans, built with quick-xml: the
//! model, robot and property-file readers all walk it.
//!
//! Reading into a tree first (with an explicit stack, so nesting depth cannot
//! overflow the call stack) keeps the readers simple: each one walks elements and
//! reports errors at exact positions. Attribute values are unescaped once, by the one
//! entity decoder (`source::reference`); the spans of raw values and text cover their
//! raw range in the file, for readers that map decoded text back to the file
//! character by character (property formulas).

use std::fmt;

use super::source::{unescape, Diagnostic, FileId, SourceMap, Span};
use quick_xml::events::Event;
use quick_xml::Reader;

/// Deepest element nesting accepted (real models nest fewer than 20 levels).
pub(crate) const MAX_DEPTH: usize = 256;

/// An attribute: its name and its unescaped value, with spans of both.
#[derive(Clone, Debug)]
pub struct Attr {
    /// The attribute's name.
    pub name: String,
    /// Span of the name's first byte.
    pub name_span: Span,
    /// The unescaped value.
    pub value: String,
    /// Span of the raw (escaped) value in the file, between the quotes (empty for a
    /// generated attribute).
    pub value_span: Span,
}

/// A child of an element.
#[derive(Clone, Debug)]
pub enum Node {
    /// A child element.
    Element(Element),
    /// A comment's text (between `<!--` and `-->`).
    Comment(String, Span),
    /// Non-blank character data (text from its first non-blank byte, CDATA or a
    /// reference), spanning its raw text in the file.
    Text(Span),
}

/// An element with its attributes and children.
#[derive(Clone, Debug)]
pub struct Element {
    /// The tag name.
    pub name: String,
    /// Span of the `<` that opens the element.
    pub span: Span,
    /// Attributes in document order.
    pub attrs: Vec<Attr>,
    /// Children in document order.
    pub children: Vec<Node>,
}

impl Element {
    /// A new element with no attributes or children; `span` is where it comes from
    /// (for a generated element, the source element that produced it).
    pub fn new(name: impl Into<String>, span: Span) -> Element {
        Element {
            name: name.into(),
            span,
            attrs: Vec::new(),
            children: Vec::new(),
        }
    }

    /// Sets attribute `name` to `value` (replacing it if present); its spans are the element's.
    pub fn set_attr(&mut self, name: &str, value: impl Into<String>) {
        self.set_attr_at(name, value, self.span);
    }

    /// Sets attribute `name` to `value` with `span` as the value's position (errors about the
    /// value point there, for example at the source attribute it was rewritten from).
    pub fn set_attr_at(&mut self, name: &str, value: impl Into<String>, span: Span) {
        let value = value.into();
        match self.attrs.iter_mut().find(|a| a.name == name) {
            Some(a) => {
                a.value = value;
                a.value_span = span;
            }
            None => self.attrs.push(Attr {
                name: name.to_string(),
                name_span: span,
                value,
                value_span: span,
            }),
        }
    }

    /// The element with attribute `name` set to `value`.
    pub fn with_attr(mut self, name: &str, value: impl Into<String>) -> Element {
        self.set_attr(name, value);
        self
    }

    /// Removes attribute `name`; returns it if it was present.
    pub fn remove_attr(&mut self, name: &str) -> Option<Attr> {
        let i = self.attrs.iter().position(|a| a.name == name)?;
        Some(self.attrs.remove(i))
    }

    /// The value of attribute `name`, if present.
    pub fn attr_value(&self, name: &str) -> Option<&str> {
        self.attr(name).map(|a| a.value.as_str())
    }

    /// Appends a child element.
    pub fn push(&mut self, child: Element) {
        self.children.push(Node::Element(child));
    }

    /// The element with `child` appended.
    pub fn with_child(mut self, child: Element) -> Element {
        self.push(child);
        self
    }

    /// Appends a comment (for example `TYPE x:int32`, which types the next `<data>`/`<param>`).
    pub fn push_comment(&mut self, text: impl Into<String>) {
        self.children.push(Node::Comment(text.into(), self.span));
    }

    /// Child elements, mutably, skipping comments and text.
    pub fn elements_mut(&mut self) -> impl Iterator<Item = &mut Element> {
        self.children.iter_mut().filter_map(|n| match n {
            Node::Element(e) => Some(e),
            _ => None,
        })
    }

    /// The attribute called `name`, if present.
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }

    /// Child elements, skipping comments and text.
    pub fn elements(&self) -> impl Iterator<Item = &Element> {
        self.children.iter().filter_map(|n| match n {
            Node::Element(e) => Some(e),
            _ => None,
        })
    }

    /// Errors for attributes not in `allowed` (names starting with `xmlns` are always allowed).
    pub fn check_attrs(&self, sm: &SourceMap, allowed: &[&str], out: &mut Vec<Diagnostic>) {
        for a in &self.attrs {
            if !allowed.contains(&a.name.as_str()) && !a.name.starts_with("xmlns") {
                let expected = if allowed.is_empty() {
                    "it takes none".to_string()
                } else {
                    format!("expected one of: {}", allowed.join(", "))
                };
                out.push(sm.diag(
                    a.name_span,
                    format!(
                        "unknown attribute `{}` on <{}> ({expected})",
                        a.name, self.name
                    ),
                ));
            }
        }
    }

    /// The attribute called `name`, or an error at the element when it is missing.
    pub fn required(&self, sm: &SourceMap, name: &str) -> Result<&Attr, Diagnostic> {
        self.attr(name).ok_or_else(|| {
            sm.diag(
                self.span,
                format!(
                    "<{}> is missing the required attribute `{}`",
                    self.name, name
                ),
            )
        })
    }
}

fn offset_in(src: &str, part: &[u8]) -> Option<u32> {
    let s = src.as_ptr() as usize;
    let p = part.as_ptr() as usize;
    if p >= s && p + part.len() <= s + src.len() {
        Some((p - s) as u32)
    } else {
        None
    }
}

/// Parses the text of file `file` into its root element.
pub fn parse(sm: &SourceMap, file: FileId) -> Result<Element, Diagnostic> {
    let Some(f) = sm.source(file) else {
        return Err(crate::model::about_file(
            "<unknown>",
            "internal error: file not in source map",
        ));
    };
    // A file that does not even start like XML is not the source it was named as
    // (`src="/proc/self/environ"`, a path that reaches `/etc/passwd`): say so about the
    // whole file, and show none of its text, which may be a secret.
    // (At 1:1, with no excerpt; an empty file is "no root element" as before.)
    let start = f.text().trim_start_matches('\u{feff}').trim_start();
    if !start.is_empty() && !start.starts_with('<') {
        return Err(Diagnostic::error(
            f.path().display().to_string(),
            (1, 1),
            "not an XML file: it does not start with `<` (its text is not shown)".to_owned(),
        ));
    }
    parse_text(f.text(), file).map_err(|e| sm.diag(file.at(e.offset), e.to_string()))
}

/// Why a text is not one well-formed element tree, and the byte offset where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct XmlError {
    /// Byte offset in the text.
    pub offset: u32,
    /// What is wrong (without the `malformed XML: ` that [`fmt::Display`] puts first).
    pub message: String,
}

impl fmt::Display for XmlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "malformed XML: {}", self.message)
    }
}

/// Parses `src` (the text of file `file`) into its root element: the one XML reader
/// of models, robot models and property files. Attribute values are unescaped by the
/// one entity decoder ([`unescape`]); a bad reference, like any malformed XML, stops
/// the reading.
pub fn parse_text(src: &str, file: FileId) -> Result<Element, XmlError> {
    let fail = |offset: u64, message: String| XmlError {
        offset: offset.min(u32::MAX as u64) as u32,
        message,
    };
    let at = |offset: u64| file.at(offset.min(u32::MAX as u64) as u32);
    let mut reader = Reader::from_str(src);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let start = reader.buffer_position();
        let ev = match reader.read_event() {
            Ok(ev) => ev,
            Err(e) => return Err(fail(reader.error_position(), e.to_string())),
        };
        match ev {
            ev @ (Event::Start(_) | Event::Empty(_)) => {
                let (e, is_empty) = match ev {
                    Event::Start(e) => (e, false),
                    Event::Empty(e) => (e, true),
                    _ => continue,
                };
                let name = e.name().as_ref().to_string();
                let mut attrs = Vec::new();
                for a in e.attributes() {
                    let a = a.map_err(|err| fail(start, err.to_string()))?;
                    let key = a.key.as_ref();
                    let key_off = offset_in(src, key.as_bytes()).unwrap_or(start as u32);
                    let raw: &str = &a.value;
                    let val_off = offset_in(src, raw.as_bytes()).unwrap_or(key_off);
                    let value = match unescape(raw) {
                        Ok(v) => v.into_owned(),
                        Err((k, message)) => {
                            return Err(fail(u64::from(val_off) + k as u64, message.to_string()));
                        }
                    };
                    attrs.push(Attr {
                        name: key.to_string(),
                        name_span: at(u64::from(key_off)),
                        value,
                        value_span: Span {
                            hi: val_off.saturating_add(raw.len() as u32),
                            ..at(u64::from(val_off))
                        },
                    });
                }
                let el = Element {
                    name,
                    span: at(start),
                    attrs,
                    children: Vec::new(),
                };
                if is_empty {
                    attach(&mut stack, &mut root, el)?;
                } else {
                    if stack.len() >= MAX_DEPTH {
                        return Err(fail(start, "elements nested too deeply".to_owned()));
                    }
                    stack.push(el);
                }
            }
            Event::End(_) => {
                let Some(el) = stack.pop() else {
                    return Err(fail(start, "unexpected closing tag".to_owned()));
                };
                attach(&mut stack, &mut root, el)?;
            }
            Event::Comment(c) => {
                if let Some(top) = stack.last_mut() {
                    let text = c.as_ref().to_string();
                    top.children.push(Node::Comment(text, at(start)));
                }
            }
            ev @ (Event::Text(_) | Event::CData(_) | Event::GeneralRef(_)) => {
                // Text, CDATA and references are content; blank text is not.
                let off = match &ev {
                    Event::Text(t) => {
                        let raw: &str = t.as_ref();
                        match raw.bytes().position(|b| !b.is_ascii_whitespace()) {
                            Some(off) => off as u64,
                            None => continue,
                        }
                    }
                    _ => 0,
                };
                let end = reader.buffer_position().min(u32::MAX as u64) as u32;
                match stack.last_mut() {
                    Some(top) => top.children.push(Node::Text(Span {
                        hi: end,
                        ..at(start + off)
                    })),
                    None => {
                        return Err(fail(
                            start + off,
                            "text outside the root element".to_owned(),
                        ))
                    }
                }
            }
            Event::Decl(_) | Event::PI(_) | Event::DocType(_) => {}
            Event::Eof => break,
        }
    }
    if let Some(open) = stack.last() {
        return Err(fail(
            u64::from(open.span.lo),
            format!("<{}> is never closed", open.name),
        ));
    }
    root.ok_or_else(|| fail(0, "no root element".to_owned()))
}

fn attach(stack: &mut [Element], root: &mut Option<Element>, el: Element) -> Result<(), XmlError> {
    match stack.last_mut() {
        Some(parent) => {
            parent.children.push(Node::Element(el));
            Ok(())
        }
        None => {
            if root.is_some() {
                return Err(XmlError {
                    offset: el.span.lo,
                    message: "more than one root element".to_owned(),
                });
            }
            *root = Some(el);
            Ok(())
        }
    }
}

/// Appends `text` escaped for markup: XML or HTML text, or an attribute value in double
/// quotes. `&`, `<`, `>` and `"` become entities; tab, line feed and carriage return
/// become character references, so that an attribute value keeps them (an XML reader
/// turns a literal one into a space: XML 1.0, 3.3.3 Attribute-Value Normalization). The
/// one markup escaper: `hindsight convert`'s XML, the report's HTML and SVG, the live page.
pub fn escape_into(text: &str, out: &mut String) {
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\n' => out.push_str("&#10;"),
            '\t' => out.push_str("&#9;"),
            '\r' => out.push_str("&#13;"),
            c => out.push(c),
        }
    }
}

/// `text` escaped by [`escape_into`].
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    escape_into(text, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's two escapers left line breaks and tabs as they were: in an SVG (XML)
    /// attribute a reader turns them into spaces. The one escaper keeps every character.
    #[test]
    fn escaped_text_reads_back_as_written() {
        let text = "a<b & c>\"d\" 'e'\nf\tg\r\nh";
        let e = escape(text);
        assert!(!e.contains(['<', '>', '"', '\n', '\t', '\r']), "{e}");
        let root = doc(&format!("<a v=\"{e}\">{e}</a>")).unwrap();
        assert_eq!(root.attr("v").unwrap().value, text);
        assert_eq!(escape("plain text"), "plain text");
        assert_eq!(escape("x&amp;"), "x&amp;amp;");
    }

    fn doc(text: &str) -> Result<Element, Diagnostic> {
        let mut sm = SourceMap::new();
        let f = sm.add("t.xml", text.to_string());
        parse(&sm, f)
    }

    #[test]
    fn tree_with_spans() {
        let text = "<a x=\"1 &lt; 2\">\n  <!-- TYPE v:int32 -->\n  <b/>\n  <c y='q'></c>\n</a>";
        let root = doc(text).unwrap();
        assert_eq!(root.name, "a");
        let x = root.attr("x").unwrap();
        assert_eq!(x.value, "1 < 2");
        assert_eq!(x.value_span.lo as usize, text.find("1 &lt;").unwrap());
        let kids: Vec<_> = root.elements().map(|e| e.name.as_str()).collect();
        assert_eq!(kids, ["b", "c"]);
        assert!(matches!(&root.children[0], Node::Comment(c, _) if c.contains("TYPE v:int32")));
        let b = root.elements().next().unwrap();
        assert_eq!(b.span.lo as usize, text.find("<b/>").unwrap());
    }

    #[test]
    fn malformed_is_an_error_not_a_panic() {
        for bad in [
            "<a>",
            "<a></b>",
            "</a>",
            "<a x=1/>",
            "<a x='&nope;'/>",
            "",
            "<a/><b/>",
            "text",
            "<a x='1' x='2'/>",
        ] {
            assert!(doc(bad).is_err(), "{bad:?} should be rejected");
        }
    }

    #[test]
    fn deep_nesting_is_an_error() {
        let text = "<a>".repeat(MAX_DEPTH + 5) + &"</a>".repeat(MAX_DEPTH + 5);
        let err = doc(&text).unwrap_err();
        assert!(err.message.contains("nested too deeply"));
    }
}
