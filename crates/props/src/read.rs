//! Reads the element tree of a property file into a [`PropertyFile`]: both SCAN formats,
//! and the conversion of the older tree form into Rye formula text.

use std::collections::HashMap;
use std::path::Path;

use super::error::{PropsError, PropsErrorKind};
use super::source::{unescape_attribute, Location, SourceFile, SourceText};
use super::{Port, PortKind, Property, PropertyFile};
use crate::model::source::Span;
use crate::model::xml::{Attr, Element, Node};

mod tree;
use tree::Converter;

/// Value types of state variables, predicates and constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ty {
    Bool,
    Int,
    Float,
    Str,
}

impl Ty {
    fn of(declared: &str) -> Option<Ty> {
        use crate::model::types::{BaseType, Scalar};
        Some(match BaseType::from(Scalar::from_name(declared)?) {
            BaseType::Bool => Ty::Bool,
            BaseType::Int => Ty::Int,
            BaseType::Float => Ty::Float,
            BaseType::Str => Ty::Str,
        })
    }

    fn numeric(self) -> bool {
        matches!(self, Ty::Int | Ty::Float)
    }

    fn with_article(self) -> &'static str {
        match self {
            Ty::Bool => "a boolean",
            Ty::Int => "an integer",
            Ty::Float => "a float",
            Ty::Str => "a string",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Ty::Bool => "boolean",
            Ty::Int => "integer",
            Ty::Float => "float",
            Ty::Str => "string",
        }
    }
}

/// The declared type names, for error messages.
const TYPES: &str = "one of bool, boolean, int, int8..int64, uint8..uint64, float, double, \
                     float32, float64, string";

pub(crate) struct FileReader<'p, 'a> {
    path: &'p Path,
    lines: &'p SourceFile<'a>,
    errors: Vec<PropsError>,
    /// The ROS types ports name, in file order.
    pub(super) ros_types: Vec<super::RosTypeUse>,
}

impl<'p, 'a> FileReader<'p, 'a> {
    pub(crate) fn new(path: &'p Path, lines: &'p SourceFile<'a>) -> FileReader<'p, 'a> {
        FileReader {
            path,
            lines,
            errors: Vec::new(),
            ros_types: Vec::new(),
        }
    }

    pub(crate) fn into_errors(self) -> Vec<PropsError> {
        self.errors
    }

    pub(super) fn error(&mut self, at: Location, kind: PropsErrorKind) {
        self.errors
            .push(super::error::error_at(self.path, self.lines, at, kind));
    }

    /// The file location of `span`.
    pub(super) fn at(&self, span: Span) -> Location {
        self.lines.location(span.lo as usize)
    }

    /// The raw (still escaped) value of an attribute read from the file.
    pub(super) fn raw(&self, attr: &Attr) -> &'a str {
        let span = attr.value_span;
        self.lines
            .text()
            .get(span.lo as usize..span.hi as usize)
            .unwrap_or_default()
    }

    /// The text, CDATA and references directly inside `element`.
    fn texts(element: &Element) -> impl DoubleEndedIterator<Item = Span> + '_ {
        element.children.iter().filter_map(|node| match node {
            Node::Text(span) => Some(*span),
            _ => None,
        })
    }

    /// Reports unknown attributes and text content; returns nothing.
    pub(super) fn check_attrs(&mut self, element: &Element, allowed: &[&str]) {
        self.check_attrs_allow_text(element, allowed);
        if let Some(span) = Self::texts(element).next() {
            self.error(
                self.at(span),
                PropsErrorKind::UnexpectedText {
                    element: element.name.clone(),
                },
            );
        }
    }

    /// Reports unknown attributes of an element whose text is its content.
    pub(super) fn check_attrs_allow_text(&mut self, element: &Element, allowed: &[&str]) {
        for attr in &element.attrs {
            if !allowed.contains(&attr.name.as_str()) {
                self.error(
                    self.at(attr.name_span),
                    PropsErrorKind::UnknownAttribute {
                        element: element.name.clone(),
                        name: attr.name.clone(),
                    },
                );
            }
        }
    }

    /// The unescaped text content of an element (`None`, with an error, if it has none):
    /// its raw text from the first non-blank chunk to the end of the last one.
    pub(super) fn element_text(&mut self, element: &Element) -> Option<SourceText> {
        let (first, last) = (
            Self::texts(element).next(),
            Self::texts(element).next_back(),
        );
        let raw = first.zip(last).and_then(|(first, last)| {
            let start = first.lo as usize;
            let raw = self.lines.text().get(start..last.hi as usize)?;
            Some((raw.trim_end(), start))
        });
        let Some((raw, offset)) = raw else {
            self.error(
                self.at(element.span),
                PropsErrorKind::BadValue {
                    attribute: format!("<{}> text", element.name),
                    value: String::new(),
                    expected: "an expression".to_owned(),
                },
            );
            return None;
        };
        self.value(raw, offset)
    }

    pub(super) fn attr<'e>(element: &'e Element, name: &str) -> Option<&'e Attr> {
        element.attr(name)
    }

    /// The unescaped value of the raw text `raw` at byte `offset` of the file, its
    /// tabs and line breaks normalised to spaces.
    fn value(&mut self, raw: &str, offset: usize) -> Option<SourceText> {
        match unescape_attribute(raw, offset, self.lines) {
            Ok(value) => Some(value),
            Err((offset, bad)) => {
                let at = self.lines.location(offset);
                self.error(at, PropsErrorKind::Xml(bad.to_string()));
                None
            }
        }
    }

    pub(super) fn optional(
        &mut self,
        element: &Element,
        name: &str,
    ) -> Option<(SourceText, Location)> {
        let attr = Self::attr(element, name)?;
        let at = self.at(attr.name_span);
        let raw = self.raw(attr);
        self.value(raw, attr.value_span.lo as usize)
            .map(|value| (value, at))
    }

    pub(super) fn required(
        &mut self,
        element: &Element,
        name: &'static str,
    ) -> Option<(SourceText, Location)> {
        if Self::attr(element, name).is_none() {
            self.error(
                self.at(element.span),
                PropsErrorKind::MissingAttribute {
                    element: element.name.to_owned(),
                    name,
                },
            );
            return None;
        }
        self.optional(element, name)
    }

    /// A required attribute that names something: non-empty, no surrounding blanks.
    pub(super) fn required_name(
        &mut self,
        element: &Element,
        name: &'static str,
    ) -> Option<String> {
        let (value, at) = self.required(element, name)?;
        let text = value.as_str();
        if text.is_empty() || text.trim() != text {
            self.error(
                at,
                PropsErrorKind::BadValue {
                    attribute: name.to_owned(),
                    value: text.to_owned(),
                    expected: "a non-empty name without surrounding blanks".to_owned(),
                },
            );
            return None;
        }
        Some(text.to_owned())
    }

    /// The id `name` declares (`id` of a property or port), checked against the id
    /// rule ([`super::is_valid_id`]) at the attribute.
    pub(super) fn required_id(&mut self, element: &Element) -> Option<String> {
        let id = self.required_name(element, "id")?;
        if !super::is_valid_id(&id) {
            let (_, at) = self.required(element, "id")?;
            self.error(
                at,
                PropsErrorKind::BadValue {
                    attribute: "id".to_owned(),
                    value: id,
                    expected: super::ID_RULE.to_owned(),
                },
            );
            return None;
        }
        Some(id)
    }

    pub(super) fn unknown_child(
        &mut self,
        child: &Element,
        parent: &Element,
        expected: &'static str,
    ) {
        self.error(
            self.at(child.span),
            PropsErrorKind::UnknownElement {
                name: child.name.to_owned(),
                parent: parent.name.to_owned(),
                expected,
            },
        );
    }

    pub(super) fn declared_type(&mut self, element: &Element) -> Option<(String, Ty)> {
        let (value, at) = self.required(element, "type")?;
        match Ty::of(value.as_str()) {
            Some(ty) => Some((value.as_str().to_owned(), ty)),
            None => {
                self.error(
                    at,
                    PropsErrorKind::BadValue {
                        attribute: "type".to_owned(),
                        value: value.as_str().to_owned(),
                        expected: TYPES.to_owned(),
                    },
                );
                None
            }
        }
    }

    /// Reads the root element.
    pub(crate) fn read(&mut self, root: &Element) -> PropertyFile {
        let mut file = PropertyFile {
            path: self.path.to_path_buf(),
            ports: Vec::new(),
            guarantees: Vec::new(),
            assumptions: Vec::new(),
            ros_types: Vec::new(),
        };
        if root.name != "properties" {
            self.error(
                self.at(root.span),
                PropsErrorKind::UnknownElement {
                    name: root.name.to_owned(),
                    parent: String::new(),
                    expected: "<properties>",
                },
            );
            return file;
        }
        self.check_attrs(root, &[]);
        let mut predicates: Vec<&Element> = Vec::new();
        let mut tree_guarantees: Vec<&Element> = Vec::new();
        let mut tree_assumptions: Vec<&Element> = Vec::new();
        for section in root.elements() {
            self.check_attrs(section, &[]);
            match section.name.as_str() {
                "ports" => {
                    for port in section.elements() {
                        match port.name.as_str() {
                            "scxml_event_send" => self.event_send(port, &mut file.ports),
                            "port" => self.tree_port(port, &mut file.ports),
                            "ros_topic" => self.ros_topic(port, &mut file.ports),
                            "ros_service" => self.ros_service(port, &mut file.ports),
                            _ => self.unknown_child(
                                port,
                                section,
                                "<scxml_event_send>, <ros_topic>, <ros_service> or <port>",
                            ),
                        }
                    }
                }
                "predicates" => {
                    for predicate in section.elements() {
                        if predicate.name == "predicate" {
                            predicates.push(predicate);
                        } else {
                            self.unknown_child(predicate, section, "<predicate>");
                        }
                    }
                }
                "guarantees" | "assumes" => {
                    let guarantees = section.name == "guarantees";
                    let tree_name = if guarantees { "guarantee" } else { "assume" };
                    for property in section.elements() {
                        if property.name == "property" {
                            let read = if Self::attr(property, "pattern").is_some() {
                                self.pattern_property(property)
                            } else {
                                self.text_property(property)
                            };
                            if let Some(property) = read {
                                if guarantees {
                                    file.guarantees.push(property);
                                } else {
                                    file.assumptions.push(property);
                                }
                            }
                        } else if property.name == tree_name {
                            if guarantees {
                                tree_guarantees.push(property);
                            } else {
                                tree_assumptions.push(property);
                            }
                        } else {
                            let expected = if guarantees {
                                "<property> or <guarantee>"
                            } else {
                                "<property> or <assume>"
                            };
                            self.unknown_child(property, section, expected);
                        }
                    }
                }
                _ => self.unknown_child(
                    section,
                    root,
                    "<ports>, <predicates>, <guarantees> or <assumes>",
                ),
            }
        }
        self.check_unique_variables(&file.ports);

        let mut converter = Converter::new(self, &file.ports, &predicates);
        let guarantees: Vec<Property> = tree_guarantees
            .iter()
            .filter_map(|element| converter.tree_property(element))
            .collect();
        let assumptions: Vec<Property> = tree_assumptions
            .iter()
            .filter_map(|element| converter.tree_property(element))
            .collect();
        converter.finish();
        file.guarantees.extend(guarantees);
        file.assumptions.extend(assumptions);
        file.guarantees.sort_by_key(|p| p.at);
        file.assumptions.sort_by_key(|p| p.at);
        let mut ids: HashMap<String, Location> = HashMap::new();
        for property in file.guarantees.iter().chain(&file.assumptions) {
            if let Some(&first) = ids.get(&property.id) {
                self.error(
                    property.at,
                    PropsErrorKind::Duplicate {
                        what: "property",
                        id: property.id.clone(),
                        first,
                    },
                );
            } else {
                ids.insert(property.id.clone(), property.at);
            }
        }
        file
    }

    fn check_unique_variables(&mut self, ports: &[Port]) {
        let mut seen: HashMap<&str, Location> = HashMap::new();
        for port in ports {
            if let Some(&first) = seen.get(port.id.as_str()) {
                self.error(
                    port.at,
                    PropsErrorKind::Duplicate {
                        what: "variable",
                        id: port.id.clone(),
                        first,
                    },
                );
            } else {
                seen.insert(&port.id, port.at);
            }
        }
    }

    /// `<scxml_event_send event origin target>` with `<state_var>` / `<event_var>`.
    fn event_send(&mut self, element: &Element, ports: &mut Vec<Port>) {
        self.check_attrs(element, &["event", "origin", "target"]);
        let event = self.required_name(element, "event");
        let origin = self.required_name(element, "origin");
        let target = self.required_name(element, "target");
        for var in element.elements() {
            let Some(kind) = self.port_variable(element, var, "param", |param| param) else {
                continue;
            };
            let id = self.required_id(var);
            if let (Some(id), Some(kind), Some(event), Some(origin), Some(target)) =
                (id, kind, &event, &origin, &target)
            {
                ports.push(Port {
                    id,
                    kind,
                    event: event.clone(),
                    origin: origin.clone(),
                    target: target.clone(),
                    at: self.at(var.span),
                });
            }
        }
    }

    /// The kind of port variable `var`, a child of `element`: a `<state_var id type expr>`
    /// whose attribute `param` names the event parameter (`param_name` of its value) or
    /// an `<event_var id>`; `Some(None)` when one is incomplete, `None` for any other
    /// element (each reported).
    pub(super) fn port_variable(
        &mut self,
        element: &Element,
        var: &Element,
        param: &'static str,
        param_name: impl FnOnce(String) -> String,
    ) -> Option<Option<PortKind>> {
        match var.name.as_str() {
            "state_var" => {
                self.check_attrs(var, &["id", param, "type", "expr"]);
                let name = self.required_name(var, param);
                let ty = self.declared_type(var);
                let init = self.required(var, "expr");
                Some(match (name, ty, init) {
                    (Some(name), Some((ty, _)), Some((init, _))) => Some(PortKind::State {
                        param: param_name(name),
                        ty,
                        init,
                    }),
                    _ => None,
                })
            }
            "event_var" => {
                self.check_attrs(var, &["id"]);
                Some(Some(PortKind::Event))
            }
            _ => {
                self.unknown_child(var, element, "<state_var> or <event_var>");
                None
            }
        }
    }

    /// The single child `<name>` of a tree-form port.
    fn single_child<'e>(
        &mut self,
        element: &'e Element,
        name: &'static str,
    ) -> Option<&'e Element> {
        let mut found = element.elements().filter(|child| child.name == name);
        let first = found.next();
        if let Some(again) = found.next() {
            self.error(
                self.at(again.span),
                PropsErrorKind::RepeatedElement {
                    element: element.name.to_owned(),
                    name: name.to_owned(),
                },
            );
        }
        if first.is_none() {
            self.error(
                self.at(element.span),
                PropsErrorKind::MissingElement {
                    element: element.name.to_owned(),
                    name,
                },
            );
        }
        first
    }

    /// The older `<port id type>` with `<origin refid>`, `<target refid>` and
    /// `<message event [param_name expr]>`.
    fn tree_port(&mut self, element: &Element, ports: &mut Vec<Port>) {
        self.check_attrs(element, &["id", "type"]);
        let id = self.required_id(element);
        let ty = self.declared_type(element);
        for child in element.elements() {
            if !matches!(child.name.as_str(), "origin" | "target" | "message") {
                self.unknown_child(child, element, "<origin>, <target> or <message>");
            }
        }
        let endpoint = |this: &mut Self, name| {
            let child = this.single_child(element, name)?;
            this.check_attrs(child, &["refid"]);
            this.required_name(child, "refid")
        };
        let origin = endpoint(self, "origin");
        let target = endpoint(self, "target");
        let message = self.single_child(element, "message");
        let (Some(id), Some((ty_name, ty)), Some(origin), Some(target), Some(message)) =
            (id, ty, origin, target, message)
        else {
            return;
        };
        self.check_attrs(message, &["event", "param_name", "expr"]);
        let Some(event) = self.required_name(message, "event") else {
            return;
        };
        let kind = if Self::attr(message, "param_name").is_some() {
            let param = self.required_name(message, "param_name");
            let init = self.required(message, "expr");
            let (Some(param), Some((init, _))) = (param, init) else {
                return;
            };
            PortKind::State {
                param,
                ty: ty_name,
                init,
            }
        } else {
            if let Some(attr) = Self::attr(message, "expr") {
                self.error(
                    self.at(attr.name_span),
                    PropsErrorKind::Type {
                        message: "`expr` (an initial value) needs `param_name`: a port without \
                                  it is an event variable"
                            .to_owned(),
                    },
                );
                return;
            }
            if ty != Ty::Bool {
                self.error(
                    self.at(element.span),
                    PropsErrorKind::Type {
                        message: format!(
                            "port `{id}` has no `param_name`, so it is an event variable and \
                             must have type boolean, not {ty_name}"
                        ),
                    },
                );
                return;
            }
            PortKind::Event
        };
        ports.push(Port {
            id,
            kind,
            event,
            origin,
            target,
            at: self.at(element.span),
        });
    }

    /// `<property id [logic="pmtl"] expr>`.
    fn text_property(&mut self, element: &Element) -> Option<Property> {
        self.check_attrs(element, &["id", "logic", "expr"]);
        if element.elements().next().is_some() {
            for child in element.elements() {
                self.unknown_child(child, element, "no child elements (the formula is `expr`)");
            }
        }
        if let Some((logic, at)) = self.optional(element, "logic") {
            if logic.as_str() != "pmtl" {
                self.error(
                    at,
                    PropsErrorKind::BadValue {
                        attribute: "logic".to_owned(),
                        value: logic.as_str().to_owned(),
                        expected: "\"pmtl\"".to_owned(),
                    },
                );
            }
        }
        let id = self.required_id(element);
        let formula = self.required(element, "expr");
        let (id, (formula, _)) = (id?, formula?);
        if formula.as_str().trim().is_empty() {
            self.error(
                self.at(element.span),
                PropsErrorKind::BadValue {
                    attribute: "expr".to_owned(),
                    value: String::new(),
                    expected: "a Past-MTL formula".to_owned(),
                },
            );
            return None;
        }
        Some(Property {
            id,
            formula,
            at: self.at(element.span),
            converted: false,
        })
    }
}
