//! Writes element trees back to XML text: how `hindsight convert` saves a lowered model as plain SCXML.

use crate::model::source::FileId;
use crate::model::types::{BaseType, TypeDef, TypeDefs, TypeExpr};
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

/// A model's declared types as a SCAN `types.xml` (`<dataTypeList>` of `<struct id>` with
/// `<field id type>`, and `<enumeration id>` with `<label id>`), which the plain reader
/// takes back from a model folder: the types a converted robot model's machines name.
pub fn types_xml(defs: &TypeDefs) -> String {
    let at = FileId(0).at(0);
    let mut root = Element::new("dataTypeList", at);
    for (name, def, _) in &defs.defs {
        match def {
            TypeDef::Struct { fields } => {
                let mut st = Element::new("struct", at).with_attr("id", name.as_str());
                for (f, t) in fields {
                    st.push(
                        Element::new("field", at)
                            .with_attr("id", f.as_str())
                            .with_attr("type", type_text(t)),
                    );
                }
                root.push(st);
            }
            TypeDef::Enumeration { labels } => {
                let mut en = Element::new("enumeration", at).with_attr("id", name.as_str());
                for l in labels {
                    en.push(Element::new("label", at).with_attr("id", l.as_str()));
                }
                root.push(en);
            }
        }
    }
    to_xml(&root)
}

/// A type as a type attribute spells it (widths as stored: 64 bits).
fn type_text(t: &TypeExpr) -> String {
    match t {
        TypeExpr::Base(BaseType::Bool) => "bool".into(),
        TypeExpr::Base(BaseType::Int) => "int64".into(),
        TypeExpr::Base(BaseType::Float) => "float64".into(),
        TypeExpr::Base(BaseType::Str) => "string".into(),
        TypeExpr::Named(n) => n.clone(),
        // `T[2][3]` is 2 arrays of 3: the outermost dimension is written first.
        TypeExpr::Array(..) => {
            let mut dims = String::new();
            let mut t = t;
            while let TypeExpr::Array(inner, n) = t {
                match n {
                    Some(n) => dims.push_str(&format!("[{n}]")),
                    None => dims.push_str("[]"),
                }
                t = inner;
            }
            format!("{}{dims}", type_text(t))
        }
    }
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

pub use crate::model::xml::escape_into;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::source::{FileId, SourceMap};
    use crate::model::xml;

    fn reparse(text: &str) -> Element {
        let mut sm = SourceMap::new();
        let id = sm.add("t.scxml", text.to_string());
        xml::parse(&sm, id).expect("written XML parses")
    }

    #[test]
    fn round_trip_keeps_names_values_and_comments() {
        let at = FileId(0).at(0);
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
    fn types_round_trip_through_types_xml() {
        let mut sm = SourceMap::new();
        let src = r#"<dataTypeList>
            <struct id="Poly"><field id="points" type="Point[]"/><field id="m" type="int32[2][]"/></struct>
            <struct id="Point"><field id="frame" type="string"/><field id="x" type="float32"/><field id="ok" type="bool"/></struct>
            <enumeration id="Color"><label id="RED"/><label id="GREEN"/></enumeration>
        </dataTypeList>"#;
        let f = sm.add("types.xml", src.to_string());
        let mut defs = TypeDefs::default();
        defs.read(&sm, f).unwrap();
        let text = types_xml(&defs);
        assert!(
            text.contains("<field id=\"m\" type=\"int64[2][]\"/>"),
            "{text}"
        );
        let g = sm.add("again.xml", text);
        let mut back = TypeDefs::default();
        back.read(&sm, g).unwrap();
        let show = |d: &TypeDefs| {
            format!(
                "{:?}",
                d.defs.iter().map(|(n, t, _)| (n, t)).collect::<Vec<_>>()
            )
        };
        assert_eq!(show(&defs), show(&back));
    }

    #[test]
    fn double_dash_in_comment_stays_a_comment() {
        let at = FileId(0).at(0);
        let mut root = Element::new("scxml", at);
        root.push_comment("a -- b");
        let back = reparse(&to_xml(&root));
        assert!(matches!(&back.children[0], Node::Comment(c, _) if c == "a - - b"));
    }
}
