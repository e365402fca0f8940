//! A small element tree over a property file, built with quick-xml, that keeps the
//! location of every element and attribute.

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use super::error::PropsErrorKind;
use super::source::{LineIndex, Location};

/// An attribute: its name, where it is, and its raw (still escaped) value.
#[derive(Clone, Debug)]
pub(crate) struct Attr<'a> {
    pub(crate) name: &'a str,
    /// Location of the attribute's name.
    pub(crate) at: Location,
    /// The raw value, between the quotes.
    pub(crate) raw: &'a str,
    /// Byte offset of the raw value in the file.
    pub(crate) offset: usize,
}

/// An element with its attributes and child elements.
#[derive(Clone, Debug)]
pub(crate) struct Element<'a> {
    pub(crate) name: &'a str,
    /// Location of the `<` that opens the element.
    pub(crate) at: Location,
    pub(crate) attrs: Vec<Attr<'a>>,
    pub(crate) children: Vec<Element<'a>>,
    /// Location of the first non-blank text (or CDATA, or reference) directly inside.
    pub(crate) text: Option<Location>,
    /// The raw (still escaped) text directly inside, from the first non-blank chunk to
    /// the end of the last one, with its byte offset in the file.
    pub(crate) raw_text: Option<(&'a str, usize)>,
}

type XmlError = (Location, PropsErrorKind);

/// The part of `text` that `slice` (a sub-slice of it) covers, with its offset.
fn borrow<'a>(text: &'a str, lines: &LineIndex<'a>, slice: &[u8]) -> Option<(&'a str, usize)> {
    let offset = lines.offset_of(slice)?;
    text.get(offset..offset + slice.len())
        .map(|part| (part, offset))
}

fn element<'a>(
    text: &'a str,
    lines: &LineIndex<'a>,
    start: &BytesStart<'_>,
    fallback: usize,
) -> Result<Element<'a>, XmlError> {
    let name_bytes = start.name().into_inner();
    let (name, name_offset) = borrow(text, lines, name_bytes.as_bytes()).ok_or_else(|| {
        (
            lines.location(fallback),
            PropsErrorKind::Xml("element name not found in the input".to_owned()),
        )
    })?;
    let at = lines.location(name_offset.saturating_sub(1));
    let mut attrs = Vec::new();
    for attribute in start.attributes() {
        let attribute = attribute.map_err(|error| (at, PropsErrorKind::Xml(error.to_string())))?;
        let key = borrow(text, lines, attribute.key.into_inner().as_bytes());
        let value = borrow(text, lines, attribute.value.as_bytes());
        let (Some((name, key_offset)), Some((raw, offset))) = (key, value) else {
            return Err((
                at,
                PropsErrorKind::Xml("attribute not found in the input".to_owned()),
            ));
        };
        attrs.push(Attr {
            name,
            at: lines.location(key_offset),
            raw,
            offset,
        });
    }
    Ok(Element {
        name,
        at,
        attrs,
        children: Vec::new(),
        text: None,
        raw_text: None,
    })
}

/// Parses the whole document into its root element. Comments, the XML declaration,
/// processing instructions and the document type are skipped.
pub(crate) fn parse_document<'a>(
    text: &'a str,
    lines: &LineIndex<'a>,
) -> Result<Element<'a>, XmlError> {
    let mut reader = Reader::from_str(text);
    let mut stack: Vec<Element<'a>> = Vec::new();
    let mut root: Option<Element<'a>> = None;
    loop {
        let before = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
        let event = reader.read_event().map_err(|error| {
            let at = usize::try_from(reader.error_position()).unwrap_or(usize::MAX);
            (lines.location(at), PropsErrorKind::Xml(error.to_string()))
        })?;
        let mut finished: Option<Element<'a>> = None;
        let mut content = false;
        match event {
            Event::Start(start) => stack.push(element(text, lines, &start, before)?),
            Event::Empty(start) => finished = Some(element(text, lines, &start, before)?),
            Event::End(_) => finished = stack.pop(),
            Event::Text(chunk) => {
                content = !chunk
                    .as_bytes()
                    .iter()
                    .all(|b| matches!(b, b' ' | b'\t' | b'\r' | b'\n'));
            }
            Event::CData(_) | Event::GeneralRef(_) => content = true,
            Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_) => {}
            Event::Eof => break,
        }
        if content {
            // Skip leading blanks to point at the text itself.
            let skip = text
                .get(before..)
                .map_or(0, |rest| rest.len() - rest.trim_start().len());
            let at = lines.location(before + skip);
            let after = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
            match stack.last_mut() {
                Some(parent) => {
                    parent.text.get_or_insert(at);
                    let start = parent.raw_text.map_or(before + skip, |(_, o)| o);
                    if let Some(raw) = text.get(start..after) {
                        parent.raw_text = Some((raw.trim_end(), start));
                    }
                }
                None => {
                    return Err((
                        at,
                        PropsErrorKind::Xml("text outside the root element".to_owned()),
                    ))
                }
            }
        }
        if let Some(done) = finished {
            match stack.last_mut() {
                Some(parent) => parent.children.push(done),
                None if root.is_none() => root = Some(done),
                None => {
                    return Err((
                        done.at,
                        PropsErrorKind::Xml("a second root element".to_owned()),
                    ))
                }
            }
        }
    }
    if let Some(open) = stack.last() {
        return Err((
            open.at,
            PropsErrorKind::Xml(format!("<{}> is never closed", open.name)),
        ));
    }
    root.ok_or_else(|| {
        (
            lines.location(text.len()),
            PropsErrorKind::Xml("no root element".to_owned()),
        )
    })
}
