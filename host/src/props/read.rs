//! Reads the element tree of a property file into a [`PropertyFile`]: both SCAN formats,
//! and the conversion of the older tree form into Rye formula text.

use std::collections::HashMap;
use std::path::Path;

use super::error::{PropsError, PropsErrorKind};
use super::source::{unescape_attribute, LineIndex, Location, SourceText};
use super::xml::{Attr, Element};
use super::{Port, PortKind, Property, PropertyFile};

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
        Some(match declared {
            "bool" | "boolean" => Ty::Bool,
            "int" | "int8" | "int16" | "int32" | "int64" | "uint8" | "uint16" | "uint32"
            | "uint64" => Ty::Int,
            "float" | "double" | "float32" | "float64" => Ty::Float,
            "string" => Ty::Str,
            _ => return None,
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

/// A value-level expression of the tree form, as text.
struct Term {
    text: SourceText,
    ty: Ty,
    /// Whether the text needs parentheses when it is an operand.
    compound: bool,
}

impl Term {
    fn nested(&self) -> SourceText {
        if !self.compound {
            return self.text.clone();
        }
        let mut out = SourceText::empty();
        let at = self.text.location(0);
        out.push_generated("(", at);
        out.push_source(&self.text);
        out.push_generated(")", at);
        out
    }
}

/// What a variable id refers to.
#[derive(Clone, Copy)]
struct VarInfo {
    ty: Ty,
}

/// Where a predicate stands during conversion.
enum PredicateState<'e, 'a> {
    Pending(&'e Element<'a>),
    Converting,
    Done(Option<(SourceText, Ty, bool)>),
}

pub(crate) struct FileReader<'p, 'a> {
    path: &'p Path,
    lines: &'p LineIndex<'a>,
    errors: Vec<PropsError>,
}

impl<'p, 'a> FileReader<'p, 'a> {
    pub(crate) fn new(path: &'p Path, lines: &'p LineIndex<'a>) -> FileReader<'p, 'a> {
        FileReader {
            path,
            lines,
            errors: Vec::new(),
        }
    }

    pub(crate) fn into_errors(self) -> Vec<PropsError> {
        self.errors
    }

    pub(super) fn error(&mut self, at: Location, kind: PropsErrorKind) {
        self.errors.push(PropsError {
            path: self.path.to_path_buf(),
            at,
            kind,
        });
    }

    /// Reports unknown attributes and text content; returns nothing.
    pub(super) fn check_attrs(&mut self, element: &Element<'a>, allowed: &[&str]) {
        self.check_attrs_allow_text(element, allowed);
        if let Some(at) = element.text {
            self.error(
                at,
                PropsErrorKind::UnexpectedText {
                    element: element.name.to_owned(),
                },
            );
        }
    }

    /// Reports unknown attributes of an element whose text is its content.
    pub(super) fn check_attrs_allow_text(&mut self, element: &Element<'a>, allowed: &[&str]) {
        for attr in &element.attrs {
            if !allowed.contains(&attr.name) {
                self.error(
                    attr.at,
                    PropsErrorKind::UnknownAttribute {
                        element: element.name.to_owned(),
                        name: attr.name.to_owned(),
                    },
                );
            }
        }
    }

    /// The unescaped text content of an element (`None`, with an error, if it has none).
    pub(super) fn element_text(&mut self, element: &Element<'a>) -> Option<SourceText> {
        let Some((raw, offset)) = element.raw_text else {
            self.error(
                element.at,
                PropsErrorKind::BadValue {
                    attribute: format!("<{}> text", element.name),
                    value: String::new(),
                    expected: "an expression".to_owned(),
                },
            );
            return None;
        };
        let attr = Attr {
            name: element.name,
            at: element.at,
            raw,
            offset,
        };
        self.value(&attr)
    }

    pub(super) fn attr<'e>(element: &'e Element<'a>, name: &str) -> Option<&'e Attr<'a>> {
        element.attrs.iter().find(|attr| attr.name == name)
    }

    /// The unescaped value of an attribute.
    fn value(&mut self, attr: &Attr<'a>) -> Option<SourceText> {
        match unescape_attribute(attr.raw, attr.offset, self.lines) {
            Ok(value) => Some(value),
            Err((offset, message)) => {
                let at = self.lines.location(offset);
                self.error(at, PropsErrorKind::Xml(message));
                None
            }
        }
    }

    pub(super) fn optional(
        &mut self,
        element: &Element<'a>,
        name: &str,
    ) -> Option<(SourceText, Location)> {
        let attr = Self::attr(element, name)?;
        let at = attr.at;
        self.value(attr).map(|value| (value, at))
    }

    pub(super) fn required(
        &mut self,
        element: &Element<'a>,
        name: &'static str,
    ) -> Option<(SourceText, Location)> {
        if Self::attr(element, name).is_none() {
            self.error(
                element.at,
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
        element: &Element<'a>,
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

    pub(super) fn unknown_child(
        &mut self,
        child: &Element<'a>,
        parent: &Element<'a>,
        expected: &'static str,
    ) {
        self.error(
            child.at,
            PropsErrorKind::UnknownElement {
                name: child.name.to_owned(),
                parent: parent.name.to_owned(),
                expected,
            },
        );
    }

    pub(super) fn declared_type(&mut self, element: &Element<'a>) -> Option<(String, Ty)> {
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
    pub(crate) fn read(&mut self, root: &Element<'a>) -> PropertyFile {
        let mut file = PropertyFile {
            path: self.path.to_path_buf(),
            ports: Vec::new(),
            guarantees: Vec::new(),
            assumptions: Vec::new(),
        };
        if root.name != "properties" {
            self.error(
                root.at,
                PropsErrorKind::UnknownElement {
                    name: root.name.to_owned(),
                    parent: String::new(),
                    expected: "<properties>",
                },
            );
            return file;
        }
        self.check_attrs(root, &[]);
        let mut predicates: Vec<&Element<'a>> = Vec::new();
        let mut tree_guarantees: Vec<&Element<'a>> = Vec::new();
        let mut tree_assumptions: Vec<&Element<'a>> = Vec::new();
        for section in &root.children {
            self.check_attrs(section, &[]);
            match section.name {
                "ports" => {
                    for port in &section.children {
                        match port.name {
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
                    for predicate in &section.children {
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
                    for property in &section.children {
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
    fn event_send(&mut self, element: &Element<'a>, ports: &mut Vec<Port>) {
        self.check_attrs(element, &["event", "origin", "target"]);
        let event = self.required_name(element, "event");
        let origin = self.required_name(element, "origin");
        let target = self.required_name(element, "target");
        for var in &element.children {
            let kind = match var.name {
                "state_var" => {
                    self.check_attrs(var, &["id", "param", "type", "expr"]);
                    let param = self.required_name(var, "param");
                    let ty = self.declared_type(var);
                    let init = self.required(var, "expr");
                    match (param, ty, init) {
                        (Some(param), Some((ty, _)), Some((init, _))) => {
                            Some(PortKind::State { param, ty, init })
                        }
                        _ => None,
                    }
                }
                "event_var" => {
                    self.check_attrs(var, &["id"]);
                    Some(PortKind::Event)
                }
                _ => {
                    self.unknown_child(var, element, "<state_var> or <event_var>");
                    continue;
                }
            };
            let id = self.required_name(var, "id");
            if let (Some(id), Some(kind), Some(event), Some(origin), Some(target)) =
                (id, kind, &event, &origin, &target)
            {
                ports.push(Port {
                    id,
                    kind,
                    event: event.clone(),
                    origin: origin.clone(),
                    target: target.clone(),
                    at: var.at,
                });
            }
        }
    }

    /// The single child `<name>` of a tree-form port.
    fn single_child<'e>(
        &mut self,
        element: &'e Element<'a>,
        name: &'static str,
    ) -> Option<&'e Element<'a>> {
        let mut found = element.children.iter().filter(|child| child.name == name);
        let first = found.next();
        if let Some(again) = found.next() {
            self.error(
                again.at,
                PropsErrorKind::RepeatedElement {
                    element: element.name.to_owned(),
                    name: name.to_owned(),
                },
            );
        }
        if first.is_none() {
            self.error(
                element.at,
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
    fn tree_port(&mut self, element: &Element<'a>, ports: &mut Vec<Port>) {
        self.check_attrs(element, &["id", "type"]);
        let id = self.required_name(element, "id");
        let ty = self.declared_type(element);
        for child in &element.children {
            if !matches!(child.name, "origin" | "target" | "message") {
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
                    attr.at,
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
                    element.at,
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
            at: element.at,
        });
    }

    /// `<property id [logic="pmtl"] expr>`.
    fn text_property(&mut self, element: &Element<'a>) -> Option<Property> {
        self.check_attrs(element, &["id", "logic", "expr"]);
        if !element.children.is_empty() {
            for child in &element.children {
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
        let id = self.required_name(element, "id");
        let formula = self.required(element, "expr");
        let (id, (formula, _)) = (id?, formula?);
        if formula.as_str().trim().is_empty() {
            self.error(
                element.at,
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
            at: element.at,
            converted: false,
        })
    }
}

/// Converts tree-form formulas and predicates into Rye text.
struct Converter<'r, 'p, 'a, 'e> {
    reader: &'r mut FileReader<'p, 'a>,
    variables: HashMap<String, VarInfo>,
    predicates: HashMap<&'a str, PredicateState<'e, 'a>>,
    order: Vec<&'a str>,
}

impl<'r, 'p, 'a, 'e> Converter<'r, 'p, 'a, 'e> {
    fn new(
        reader: &'r mut FileReader<'p, 'a>,
        ports: &[Port],
        predicates: &[&'e Element<'a>],
    ) -> Self {
        let mut variables = HashMap::new();
        for port in ports {
            let ty = match &port.kind {
                PortKind::Event | PortKind::Sent => Ty::Bool,
                PortKind::State { ty, .. } | PortKind::Part { ty, .. } => {
                    Ty::of(ty).unwrap_or(Ty::Int)
                }
            };
            variables.entry(port.id.clone()).or_insert(VarInfo { ty });
        }
        let mut table: HashMap<&'a str, PredicateState<'e, 'a>> = HashMap::new();
        let mut order = Vec::new();
        let mut first_at: HashMap<&'a str, Location> = HashMap::new();
        for &predicate in predicates {
            reader.check_attrs(predicate, &["id"]);
            let Some(id_attr) = FileReader::attr(predicate, "id") else {
                reader.error(
                    predicate.at,
                    PropsErrorKind::MissingAttribute {
                        element: "predicate".to_owned(),
                        name: "id",
                    },
                );
                continue;
            };
            let id = id_attr.raw;
            if let Some(&first) = first_at.get(id) {
                reader.error(
                    predicate.at,
                    PropsErrorKind::Duplicate {
                        what: "predicate",
                        id: id.to_owned(),
                        first,
                    },
                );
                continue;
            }
            if variables.contains_key(id) {
                reader.error(
                    predicate.at,
                    PropsErrorKind::Type {
                        message: format!("predicate `{id}` has the name of a variable"),
                    },
                );
                continue;
            }
            first_at.insert(id, predicate.at);
            table.insert(id, PredicateState::Pending(predicate));
            order.push(id);
        }
        Converter {
            reader,
            variables,
            predicates: table,
            order,
        }
    }

    /// Converts the predicates no property used, so their errors are reported too.
    fn finish(&mut self) {
        for id in self.order.clone() {
            self.predicate(id);
        }
    }

    fn tree_property(&mut self, element: &'e Element<'a>) -> Option<Property> {
        self.reader.check_attrs(element, &["id"]);
        let id = self.reader.required_name(element, "id");
        let body = self.only_child(element)?;
        let mut formula = self.formula(body, element.name)?;
        // The top level needs no parentheses.
        formula = strip_outer(formula);
        Some(Property {
            id: id?,
            formula,
            at: element.at,
            converted: true,
        })
    }

    fn only_child(&mut self, element: &'e Element<'a>) -> Option<&'e Element<'a>> {
        if element.children.len() == 1 {
            element.children.first()
        } else {
            self.reader.error(
                element.at,
                PropsErrorKind::Arity {
                    element: element.name.to_owned(),
                    expected: "exactly one element",
                    found: element.children.len(),
                },
            );
            None
        }
    }

    fn operands(
        &mut self,
        element: &'e Element<'a>,
        expected: &'static str,
        ok: impl Fn(usize) -> bool,
    ) -> Option<&'e [Element<'a>]> {
        if ok(element.children.len()) {
            Some(&element.children)
        } else {
            self.reader.error(
                element.at,
                PropsErrorKind::Arity {
                    element: element.name.to_owned(),
                    expected,
                    found: element.children.len(),
                },
            );
            None
        }
    }

    /// The `[a:b]` interval of a temporal element's `lower_bound` / `upper_bound`.
    fn interval(&mut self, element: &'e Element<'a>) -> Option<String> {
        self.reader
            .check_attrs(element, &["lower_bound", "upper_bound"]);
        let mut bound = |name: &'static str| -> Result<Option<u64>, ()> {
            let Some((value, at)) = self.reader.optional(element, name) else {
                return Ok(None);
            };
            match value.as_str().trim().parse::<u64>() {
                Ok(number) => Ok(Some(number)),
                Err(_) => {
                    self.reader.error(
                        at,
                        PropsErrorKind::BadValue {
                            attribute: name.to_owned(),
                            value: value.as_str().to_owned(),
                            expected: "a non-negative integer (time units)".to_owned(),
                        },
                    );
                    Err(())
                }
            }
        };
        let lower = bound("lower_bound");
        let upper = bound("upper_bound");
        let (Ok(lower), Ok(upper)) = (lower, upper) else {
            return None;
        };
        if let (Some(lower), Some(upper)) = (lower, upper) {
            if lower > upper {
                let at = FileReader::attr(element, "upper_bound").map_or(element.at, |a| a.at);
                self.reader.error(
                    at,
                    PropsErrorKind::BadValue {
                        attribute: "upper_bound".to_owned(),
                        value: upper.to_string(),
                        expected: format!("at least lower_bound ({lower})"),
                    },
                );
                return None;
            }
        }
        Some(match (lower, upper) {
            (None, None) => String::new(),
            (Some(lower), None) => format!("[{lower}:]"),
            (None, Some(upper)) => format!("[:{upper}]"),
            (Some(lower), Some(upper)) => format!("[{lower}:{upper}]"),
        })
    }

    /// A formula: self-delimited Rye text (an atom, a constant, or in parentheses).
    fn formula(&mut self, element: &'e Element<'a>, parent: &str) -> Option<SourceText> {
        let at = element.at;
        let mut out = SourceText::empty();
        match element.name {
            "true" | "false" => {
                self.reader.check_attrs(element, &[]);
                self.operands(element, "no operands", |n| n == 0)?;
                out.push_generated(element.name, at);
            }
            "not" => {
                self.reader.check_attrs(element, &[]);
                let operand = self.only_child(element)?;
                let inner = self.formula(operand, element.name)?;
                out.push_generated("(!", at);
                out.push_source(&inner);
                out.push_generated(")", at);
            }
            "and" | "or" | "implies" => {
                self.reader.check_attrs(element, &[]);
                let (symbol, operands) = if element.name == "implies" {
                    (" -> ", self.operands(element, "two operands", |n| n == 2)?)
                } else {
                    let symbol = if element.name == "and" {
                        " && "
                    } else {
                        " || "
                    };
                    (
                        symbol,
                        self.operands(element, "at least one operand", |n| n >= 1)?,
                    )
                };
                let parts: Vec<Option<SourceText>> = operands
                    .iter()
                    .map(|child| self.formula(child, element.name))
                    .collect();
                let parts: Vec<SourceText> = parts.into_iter().collect::<Option<_>>()?;
                if let [only] = parts.as_slice() {
                    return Some(only.clone());
                }
                out.push_generated("(", at);
                for (i, part) in parts.iter().enumerate() {
                    if i > 0 {
                        out.push_generated(symbol, at);
                    }
                    out.push_source(part);
                }
                out.push_generated(")", at);
            }
            "historically" | "previously" | "once" => {
                let interval = self.interval(element);
                let operand = self.only_child(element);
                let inner = self.formula(operand?, element.name)?;
                let word = if element.name == "historically" {
                    "historically"
                } else {
                    "once"
                };
                out.push_generated(&format!("({word}{} ", interval?), at);
                out.push_source(&inner);
                out.push_generated(")", at);
            }
            "since" => {
                let interval = self.interval(element);
                let operands = self.operands(element, "two operands", |n| n == 2)?;
                let left = self.formula(&operands[0], element.name);
                let right = self.formula(&operands[1], element.name);
                let (interval, left, right) = (interval?, left?, right?);
                out.push_generated("(", at);
                out.push_source(&left);
                out.push_generated(&format!(" since{interval} "), at);
                out.push_source(&right);
                out.push_generated(")", at);
            }
            _ => {
                let term = self.term(element, parent)?;
                if term.ty != Ty::Bool {
                    self.reader.error(
                        at,
                        PropsErrorKind::Type {
                            message: format!(
                                "<{}> has {} type, but a formula needs a boolean",
                                element.name,
                                term.ty.name()
                            ),
                        },
                    );
                    return None;
                }
                out.push_generated("{", at);
                out.push_source(&term.text);
                out.push_generated("}", at);
            }
        }
        Some(out)
    }

    /// A predicate's converted text and type, converting it on first use.
    fn predicate(&mut self, id: &'a str) -> Option<(SourceText, Ty, bool)> {
        match self.predicates.get(id) {
            Some(PredicateState::Done(done)) => return done.clone(),
            Some(PredicateState::Converting) | None => return None,
            Some(PredicateState::Pending(_)) => {}
        }
        let Some(PredicateState::Pending(element)) =
            self.predicates.insert(id, PredicateState::Converting)
        else {
            return None;
        };
        let result = self.only_child(element).and_then(|body| {
            let term = self.term(body, element.name)?;
            Some((term.text, term.ty, term.compound))
        });
        self.predicates
            .insert(id, PredicateState::Done(result.clone()));
        result
    }

    /// A value-level expression.
    fn term(&mut self, element: &'e Element<'a>, parent: &str) -> Option<Term> {
        let at = element.at;
        let name = element.name;
        let mut text = SourceText::empty();
        match name {
            "var" => {
                self.reader.check_attrs(element, &["refid"]);
                self.operands(element, "no operands", |n| n == 0)?;
                let (refid, _) = self.reader.required(element, "refid")?;
                let id = refid.as_str().to_owned();
                if let Some(info) = self.variables.get(&id).copied() {
                    text.push_source(&refid);
                    return Some(Term {
                        text,
                        ty: info.ty,
                        compound: false,
                    });
                }
                let known = self.predicates.get_key_value(id.as_str()).map(|(k, _)| *k);
                let Some(key) = known else {
                    self.reader
                        .error(at, PropsErrorKind::UnknownReference { id });
                    return None;
                };
                if matches!(self.predicates.get(key), Some(PredicateState::Converting)) {
                    self.reader.error(at, PropsErrorKind::Cycle { id });
                    return None;
                }
                let (text, ty, compound) = self.predicate(key)?;
                return Some(Term { text, ty, compound });
            }
            "const" => {
                self.reader.check_attrs(element, &["type", "expr"]);
                self.operands(element, "no operands", |n| n == 0)?;
                let ty = self.reader.declared_type(element);
                let (value, _) = self.reader.required(element, "expr")?;
                let value_at = value.location(0);
                let (_, ty) = ty?;
                let raw = value.as_str().trim();
                let valid = match ty {
                    Ty::Bool => matches!(raw, "true" | "false"),
                    Ty::Int => raw.parse::<i64>().is_ok(),
                    Ty::Float => raw.parse::<f64>().is_ok_and(f64::is_finite),
                    Ty::Str => !value.as_str().contains(['\'', '\\']),
                };
                if !valid {
                    self.reader.error(
                        value_at,
                        PropsErrorKind::BadValue {
                            attribute: "expr".to_owned(),
                            value: value.as_str().to_owned(),
                            expected: format!("{} constant", ty.with_article()),
                        },
                    );
                    return None;
                }
                if ty == Ty::Str {
                    text.push_generated(&format!("'{}'", value.as_str()), value_at);
                } else {
                    text.push_generated(raw, value_at);
                }
                return Some(Term {
                    text,
                    ty,
                    compound: false,
                });
            }
            "true" | "false" => {
                self.reader.check_attrs(element, &[]);
                self.operands(element, "no operands", |n| n == 0)?;
                text.push_generated(name, at);
                return Some(Term {
                    text,
                    ty: Ty::Bool,
                    compound: false,
                });
            }
            _ => {}
        }
        self.reader.check_attrs(element, &[]);
        let (operands, symbol, compare) = match name {
            "equal" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " == ",
                true,
            ),
            "less" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " < ",
                true,
            ),
            "leq" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " <= ",
                true,
            ),
            "greater" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " > ",
                true,
            ),
            "geq" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " >= ",
                true,
            ),
            "sum" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " + ",
                false,
            ),
            "mult" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " * ",
                false,
            ),
            "and" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " && ",
                false,
            ),
            "or" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " || ",
                false,
            ),
            "implies" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " || ",
                false,
            ),
            "opposite" | "not" => {
                let operand = self.only_child(element)?;
                let inner = self.term(operand, element.name)?;
                let (symbol, ok) = if name == "not" {
                    ("!", inner.ty == Ty::Bool)
                } else {
                    ("-", inner.ty.numeric())
                };
                if !ok {
                    self.type_error(element, &[inner.ty]);
                    return None;
                }
                text.push_generated(symbol, at);
                text.push_source(&inner.nested());
                return Some(Term {
                    text,
                    ty: inner.ty,
                    compound: true,
                });
            }
            "historically" | "previously" | "once" | "since" => {
                self.reader.error(
                    at,
                    PropsErrorKind::Type {
                        message: format!(
                            "temporal operator <{name}> inside a predicate or arithmetic \
                             expression"
                        ),
                    },
                );
                return None;
            }
            _ => {
                self.reader.error(
                    at,
                    PropsErrorKind::UnknownElement {
                        name: name.to_owned(),
                        parent: parent.to_owned(),
                        expected: "an operator (not, and, or, implies, historically, \
                                   previously, once, since, equal, less, leq, greater, geq, \
                                   sum, mult, opposite) or <var>, <const>, <true>, <false>",
                    },
                );
                return None;
            }
        };
        let terms: Vec<Option<Term>> = operands
            .iter()
            .map(|child| self.term(child, element.name))
            .collect();
        let terms: Vec<Term> = terms.into_iter().collect::<Option<_>>()?;
        let types: Vec<Ty> = terms.iter().map(|t| t.ty).collect();
        let ty = match name {
            "equal" if types[0] == types[1] || (types[0].numeric() && types[1].numeric()) => {
                Some(Ty::Bool)
            }
            "less" | "leq" | "greater" | "geq" if types.iter().all(|t| t.numeric()) => {
                Some(Ty::Bool)
            }
            "sum" | "mult" if types.iter().all(|t| t.numeric()) => {
                Some(if types.contains(&Ty::Float) {
                    Ty::Float
                } else {
                    Ty::Int
                })
            }
            "and" | "or" | "implies" if types.iter().all(|&t| t == Ty::Bool) => Some(Ty::Bool),
            _ => None,
        };
        let Some(ty) = ty else {
            self.type_error(element, &types);
            return None;
        };
        if terms.len() == 1 && !compare {
            return terms.into_iter().next();
        }
        for (i, term) in terms.iter().enumerate() {
            if i > 0 {
                text.push_generated(symbol, at);
            }
            if name == "implies" && i == 0 {
                text.push_generated("!", at);
            }
            text.push_source(&term.nested());
        }
        Some(Term {
            text,
            ty,
            compound: true,
        })
    }

    fn type_error(&mut self, element: &Element<'a>, types: &[Ty]) {
        let found: Vec<&str> = types.iter().map(|t| t.name()).collect();
        self.reader.error(
            element.at,
            PropsErrorKind::Type {
                message: format!(
                    "<{}> cannot take operands of type {}",
                    element.name,
                    found.join(", ")
                ),
            },
        );
    }
}

/// Drops one pair of parentheses around the whole text, if there is one.
fn strip_outer(text: SourceText) -> SourceText {
    let s = text.as_str();
    if !(s.starts_with('(') && s.ends_with(')')) {
        return text;
    }
    // The first parenthesis must close at the very end.
    let mut depth = 0usize;
    let mut in_atom = false;
    for (i, c) in s.char_indices() {
        match c {
            '{' => in_atom = true,
            '}' => in_atom = false,
            '(' if !in_atom => depth += 1,
            ')' if !in_atom => {
                depth = depth.saturating_sub(1);
                if depth == 0 && i + 1 != s.len() {
                    return text;
                }
            }
            _ => {}
        }
    }
    text.slice(1, s.len() - 1)
}
