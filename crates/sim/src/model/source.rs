//! What reading XML adds to the source foundation: the entity decoder and the map
//! from an unescaped attribute value back to its file.
//!
//! The model reader keeps the text of every file it read in codegen's [`SourceMap`]
//! (the project's one, shared with the formula compiler); parsed items carry a
//! [`Span`] whose `source` is the file's [`FileId`]. Line and column are computed only
//! when a [`Diagnostic`] is made. Spans, lines, columns, the diagnostic and its
//! rendering are codegen's ([`codegen::diag`]); they are re-exported here so the
//! readers name one module.

use std::path::Path;

/// The map of every file read for a model, its ids and spans, and the project's one
/// diagnostic: an error (or warning) about a model (line 0: about a whole file, such
/// as a missing one); one or more of them, [`Diagnostics`], are the error type of
/// loading and compiling a model.
pub use codegen::diag::{Diagnostic, Diagnostics, FileId, SourceMap, Span};

/// A diagnostic about the whole file at `path` (no line or column).
pub fn about_file(path: impl AsRef<Path>, message: impl Into<String>) -> Diagnostic {
    Diagnostic::about_file(path.as_ref().display().to_string(), message.into())
}

/// The span of byte `k` of an attribute value whose raw (escaped) text starts at `span`.
///
/// Expressions are parsed from the unescaped value; this maps an offset in
/// the unescaped text back to the file (`&amp;` counts as one character).
pub fn unescaped_offset(sm: &SourceMap, span: Span, k: u32) -> Span {
    let Some(f) = sm.source(FileId::of(span)) else {
        return span;
    };
    let raw = f.text();
    let mut raw_pos = codegen::diag::floor_boundary(raw, span.lo as usize);
    let mut out = 0u32;
    while out < k && raw_pos < raw.len() {
        let rest = &raw[raw_pos..];
        let (produced, consumed) = match (normalised_space(rest), reference(rest)) {
            (Some(consumed), _) => (1, consumed),
            (None, Some(Ok((c, consumed)))) => (c.len_utf8(), consumed),
            _ => {
                let c = rest.chars().next().map_or(1, char::len_utf8);
                (c, c)
            }
        };
        out = out.saturating_add(produced as u32);
        raw_pos += consumed;
    }
    FileId::of(span).at(raw_pos as u32)
}

/// The reference at the start of `rest`, when it starts with `&`: the character it
/// stands for and the bytes it takes (`&lt;` is 4), or what is wrong with it; `None`
/// when `rest` does not start with `&`. The one scanner of references, used by the
/// XML tree (`model::xml`, attribute values of every XML file read), by the property
/// reader's position-keeping unescaping (formulas, element text) and by
/// [`unescaped_offset`]; names are decoded by `resolve_entity`.
pub fn reference(rest: &str) -> Option<Result<(char, usize), BadReference>> {
    let after = rest.strip_prefix('&')?;
    // A name longer than any entity or reasonable character reference is taken as a
    // stray `&`, so the message does not quote half a line.
    let Some(end) = after.find(';').filter(|&end| end <= 12) else {
        return Some(Err(BadReference::Stray));
    };
    let name = &after[..end];
    Some(match resolve_entity(name) {
        Some(c) => Ok((c, end + 2)),
        None => Err(BadReference::Unknown(name.to_string())),
    })
}

/// What is wrong with a reference in XML text ([`reference()`], [`unescape`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BadReference {
    /// An `&` that starts no reference (no `;` close after it).
    Stray,
    /// A name no entity or character reference has (the name, without `&` and `;`).
    Unknown(String),
}

impl std::fmt::Display for BadReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BadReference::Stray => {
                f.write_str("`&` that does not start a reference (write `&amp;`)")
            }
            BadReference::Unknown(name) => write!(f, "unknown reference `&{name};`"),
        }
    }
}

impl std::error::Error for BadReference {}

/// The character an XML entity name (without `&` and `;`) stands for: the five
/// predefined entities and character references (`&#65;`, `&#x41;`). `&#0;` is `None`:
/// U+0000 is not an XML character (XML 1.0, production `Char`). The one entity decoder.
pub(crate) fn resolve_entity(name: &str) -> Option<char> {
    match name {
        "lt" => Some('<'),
        "gt" => Some('>'),
        "amp" => Some('&'),
        "apos" => Some('\''),
        "quot" => Some('"'),
        _ => {
            let num = name.strip_prefix('#')?;
            let code = match num.strip_prefix('x') {
                Some(hex) => u32::from_str_radix(hex, 16).ok()?,
                None => num.parse::<u32>().ok()?,
            };
            char::from_u32(code).filter(|&c| c != '\0')
        }
    }
}

/// The characters attribute-value normalisation turns into a space (a `\r\n` pair is
/// one line break, so one space).
const ATTR_WHITESPACE: [char; 3] = ['\t', '\n', '\r'];

/// The characters an attribute value's decoding stops at: a reference, or whitespace
/// to normalise.
pub const ATTR_SPECIAL: [char; 4] = ['&', '\t', '\n', '\r'];

/// The bytes of raw attribute text at the start of `rest` that normalise to one space
/// (`\r\n` is 2), or `None` when `rest` does not start with a line break or tab.
pub fn normalised_space(rest: &str) -> Option<usize> {
    if rest.starts_with("\r\n") {
        Some(2)
    } else if rest.starts_with(ATTR_WHITESPACE) {
        Some(1)
    } else {
        None
    }
}

/// An XML attribute value as an XML processor gives it to the application: references
/// replaced, and every literal tab, line break (`\r\n`, `\r` or `\n`) turned into one
/// space. A character reference is kept as written (`&#10;` is a line break). This is
/// XML 1.0's attribute-value normalisation for CDATA attributes (sections 2.11 and
/// 3.3.3), which AS2FM gets from lxml: an `expr` written over two lines reads the same
/// in both tools. `Err` gives the byte offset of a bad reference and what is wrong.
pub fn unescape(raw: &str) -> Result<std::borrow::Cow<'_, str>, (usize, BadReference)> {
    if !raw.contains(ATTR_SPECIAL) {
        return Ok(std::borrow::Cow::Borrowed(raw));
    }
    let mut out = String::with_capacity(raw.len());
    let mut pos = 0usize;
    while let Some(i) = raw[pos..].find(ATTR_SPECIAL) {
        out.push_str(&raw[pos..pos + i]);
        pos += i;
        let rest = &raw[pos..];
        if let Some(consumed) = normalised_space(rest) {
            out.push(' ');
            pos += consumed;
            continue;
        }
        // `ATTR_SPECIAL` is `&` or a space `normalised_space` takes: here, an `&`.
        match reference(rest).unwrap_or(Err(BadReference::Stray)) {
            Ok((c, consumed)) => {
                out.push(c);
                pos += consumed;
            }
            Err(e) => return Err((pos, e)),
        }
    }
    out.push_str(&raw[pos..]);
    Ok(std::borrow::Cow::Owned(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unescaped_offsets_map_back() {
        let mut sm = SourceMap::new();
        let text = r#"<if cond="a &amp;&amp; b.c"/>"#;
        let f = sm.add("x", text.to_string());
        let start = text.find("a &").unwrap() as u32;
        let span = f.at(start);
        let raw = &text[start as usize..text.rfind('"').unwrap()];
        let un = unescape(raw).unwrap();
        assert_eq!(un, "a && b.c");
        let k = un.find('b').unwrap() as u32;
        let mapped = unescaped_offset(&sm, span, k);
        assert_eq!(&text[mapped.lo as usize..mapped.lo as usize + 1], "b");
    }

    #[test]
    fn attribute_whitespace_is_normalised_but_references_are_not() {
        assert_eq!(unescape("a\tb\nc\rd\r\ne").unwrap(), "a b c d e");
        assert_eq!(unescape("a&#10;b&#9;c").unwrap(), "a\nb\tc");
        assert_eq!(unescape("x &lt;\r\ny").unwrap(), "x < y");
        // Offsets after a normalised `\r\n` still land on the right byte of the file.
        let mut sm = SourceMap::new();
        let text = "<a expr=\"x &lt;\r\n  y\"/>";
        let f = sm.add("x", text.to_string());
        let start = text.find("x &").unwrap() as u32;
        let raw = &text[start as usize..text.rfind('"').unwrap()];
        let un = unescape(raw).unwrap();
        assert_eq!(un, "x <   y");
        let k = un.find('y').unwrap() as u32;
        let mapped = unescaped_offset(&sm, f.at(start), k);
        assert_eq!(&text[mapped.lo as usize..mapped.lo as usize + 1], "y");
    }

    #[test]
    fn bad_entity_is_an_error() {
        assert_eq!(unescape("a &bogus; b").unwrap_err().0, 2);
        assert_eq!(unescape("a & b").unwrap_err().0, 2);
        assert_eq!(unescape("&#x41;&lt;").unwrap(), "A<");
        assert_eq!(
            unescape("a&#0;").unwrap_err(),
            (1, BadReference::Unknown("#0".to_owned()))
        );
        assert_eq!(unescape("&#x0;").unwrap_err().0, 0);
        assert_eq!(unescape("x &#233;!").unwrap(), "x é!");
        assert_eq!(
            reference("&nbsp; b"),
            Some(Err(BadReference::Unknown("nbsp".to_owned())))
        );
        assert_eq!(reference("&amp;&lt;"), Some(Ok(('&', 5))));
        assert!(
            matches!(reference("&a b c d e f g h i;"), Some(Err(m)) if m.to_string().contains("write `&amp;`"))
        );
        assert_eq!(reference("a"), None);
    }
}
