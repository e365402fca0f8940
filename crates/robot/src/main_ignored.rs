//! What AS2FM's main-file reader ignores, and how we say so: an element or attribute it
//! never reads is ignored with a warning at its position, one that looks like a misspelt
//! name it reads is an error with "did you mean" (see `main_file`'s documentation).

use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::xml::{Element, Node};

/// The sections of a main file, as AS2FM names them.
pub(super) const SECTIONS: &[&str] = &[
    "parameters",
    "mc_parameters",
    "data_declarations",
    "behavior_tree",
    "node_models",
    "properties",
];

/// The parameters AS2FM reads (`RoamlParameters._parse_parameters`).
pub(super) const PARAMETERS: &[&str] = &[
    "max_time",
    "max_array_size",
    "bt_tick_rate",
    "bt_tick_if_not_running",
];

/// Attributes of `<input>` read without a warning though nothing uses them.
pub(super) const QUIET_INPUT_ATTRS: &[&str] = &["id"];

/// The name in `known` that `name` is probably a misspelling of.
pub(super) fn close_to<'k>(name: &str, known: &[&'k str]) -> Option<&'k str> {
    let lower = name.to_ascii_lowercase();
    known
        .iter()
        .map(|k| (crate::interfaces::edit_distance(&lower, k), *k))
        .filter(|(d, k)| name != *k && *d <= (k.len() / 3 + 1).min(3))
        .min()
        .map(|(_, k)| k)
}

/// A reader that collects errors and warnings; the checks below are provided.
pub(super) trait Notes {
    /// The sources positions refer to.
    fn sm(&self) -> &SourceMap;
    /// Errors found so far.
    fn errs(&mut self) -> &mut Vec<Diagnostic>;
    /// Warnings found so far.
    fn warnings(&mut self) -> &mut Vec<Diagnostic>;

    /// A warning at `span`.
    fn warn(&mut self, span: Span, message: impl Into<String>) {
        let d = self.sm().diag(span, message.into());
        self.warnings().push(d);
    }

    /// An error at `span`.
    fn error(&mut self, span: Span, message: impl Into<String>) {
        let d = self.sm().diag(span, message.into());
        self.errs().push(d);
    }

    /// Checks `el`'s attributes against those read (`allowed`): an unknown one is ignored
    /// with a warning, or is an error when it looks like a misspelt `allowed` one.
    fn attrs(&mut self, el: &Element, allowed: &[&str]) {
        for a in &el.attrs {
            let name = a.name.as_str();
            if allowed.contains(&name) || name.starts_with("xmlns") {
                continue;
            }
            if el.name == "input" && QUIET_INPUT_ATTRS.contains(&name) {
                continue;
            }
            match close_to(name, allowed) {
                Some(k) => self.error(
                    a.name_span,
                    format!(
                        "unknown attribute `{name}` on <{}>; did you mean `{k}`?",
                        el.name
                    ),
                ),
                None => self.warn(
                    a.name_span,
                    format!(
                        "attribute `{name}` on <{}> is ignored (AS2FM does not read it; {})",
                        el.name,
                        if allowed.is_empty() {
                            "it reads none here".to_string()
                        } else {
                            format!("it reads {}", allowed.join(", "))
                        }
                    ),
                ),
            }
        }
    }

    /// An element AS2FM never looks at: a warning, or an error when its name looks like a
    /// misspelt `known` one.
    fn unknown_element(&mut self, el: &Element, parent: &str, known: &[&str]) {
        let list = known
            .iter()
            .map(|k| format!("<{k}>"))
            .collect::<Vec<_>>()
            .join(", ");
        match close_to(&el.name, known) {
            Some(k) => self.error(
                el.span,
                format!(
                    "unknown element <{}> in <{parent}>; did you mean <{k}>? (expected {list})",
                    el.name
                ),
            ),
            None => self.warn(
                el.span,
                format!(
                    "element <{}> in <{parent}> is ignored (AS2FM reads only {list})",
                    el.name
                ),
            ),
        }
    }

    /// Elements inside an element whose children AS2FM never reads: warnings.
    fn ignored_children(&mut self, el: &Element) {
        let mut spans = Vec::new();
        for n in &el.children {
            match n {
                Node::Element(e) => spans.push((e.span, format!("<{}>", e.name))),
                Node::Text(span) => spans.push((*span, "text".to_string())),
                Node::Comment(..) => {}
            }
        }
        for (span, what) in spans {
            self.warn(
                span,
                format!(
                    "{what} in <{}> is ignored (AS2FM does not read it)",
                    el.name
                ),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misspellings() {
        assert_eq!(close_to("scr", &["type", "src"]), Some("src"));
        assert_eq!(close_to("typ", &["type", "src"]), Some("type"));
        assert_eq!(close_to("node_model", SECTIONS), Some("node_models"));
        assert_eq!(close_to("Properties", SECTIONS), Some("properties"));
        assert_eq!(close_to("max_tme", PARAMETERS), Some("max_time"));
        assert_eq!(close_to("id", &["type", "src"]), None);
        assert_eq!(close_to("version", &["type", "src"]), None);
        assert_eq!(close_to("description", SECTIONS), None);
        assert_eq!(close_to("src", &["type", "src"]), None);
    }
}
