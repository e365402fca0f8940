//! Writes element trees back to XML text: how `hindsight convert` saves a lowered model as plain SCXML.

use crate::model::xml::{Element, Node};

/// The XML text of `root` and everything below it, indented by four spaces per level,
/// with an XML declaration and a final newline.
///
/// Attribute values and comments are escaped so that reading the text back gives the
/// same tree; character data (which plain SCXML does not use) is dropped.
pub fn to_xml(root: &Element) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    write_element(root, 0, &mut out);
    out
}

fn indent(depth: usize, out: &mut String) {
    for _ in 0..depth {
        out.push_str("    ");
    }
}

fn write_element(el: &Element, depth: usize, out: &mut String) {
    indent(depth, out);
    out.push('<');
    out.push_str(&el.name);
    for a in &el.attrs {
        out.push(' ');
        out.push_str(&a.name);
        out.push_str("=\"");
        escape_into(&a.value, out);
        out.push('"');
    }
    let children: Vec<&Node> = el
        .children
        .iter()
        .filter(|n| !matches!(n, Node::Text(_)))
        .collect();
    if children.is_empty() {
        out.push_str("/>\n");
        return;
    }
    out.push_str(">\n");
    for child in children {
        match child {
            Node::Element(e) => write_element(e, depth + 1, out),
            Node::Comment(text, _) => {
                indent(depth + 1, out);
                out.push_str("<!--");
                // `--` may not appear inside a comment.
                out.push_str(&text.replace("--", "- -"));
                out.push_str("-->\n");
            }
            Node::Text(_) => {}
        }
    }
    indent(depth, out);
    out.push_str("</");
    out.push_str(&el.name);
    out.push_str(">\n");
}

/// Appends `text` escaped for an attribute value in double quotes.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::source::{FileId, SourceMap, Span};
    use crate::model::xml;

    fn reparse(text: &str) -> Element {
        let mut sm = SourceMap::new();
        let id = sm.add("t.scxml", text.to_string());
        xml::parse(&sm, id).expect("written XML parses")
    }

    #[test]
    fn round_trip_keeps_names_values_and_comments() {
        let at = Span {
            file: FileId(0),
            offset: 0,
        };
        let mut root = Element::new("scxml", at).with_attr("name", "M");
        let mut dm = Element::new("datamodel", at);
        dm.push_comment(" TYPE x:int32 ");
        dm.push(
            Element::new("data", at)
                .with_attr("id", "x")
                .with_attr("expr", "a < 3 && b > \"q\"\n"),
        );
        root.push(dm);
        let text = to_xml(&root);
        let back = reparse(&text);
        assert_eq!(back.name, "scxml");
        assert_eq!(back.attr_value("name"), Some("M"));
        let dm = back.elements().next().expect("datamodel");
        assert!(matches!(&dm.children[0], Node::Comment(c, _) if c == " TYPE x:int32 "));
        let data = dm.elements().next().expect("data");
        assert_eq!(data.attr_value("expr"), Some("a < 3 && b > \"q\"\n"));
    }

    #[test]
    fn double_dash_in_comment_stays_a_comment() {
        let at = Span {
            file: FileId(0),
            offset: 0,
        };
        let mut root = Element::new("scxml", at);
        root.push_comment("a -- b");
        let back = reparse(&to_xml(&root));
        assert!(matches!(&back.children[0], Node::Comment(c, _) if c == "a - - b"));
    }
}
