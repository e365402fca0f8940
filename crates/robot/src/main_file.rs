//! The main file of a robot model: AS2FM's `<roaml>` (and the older `<convince_mc_tc>`), which
//! names the behavior tree, its plugins, the node models, data types and properties, and the
//! run parameters.
//!
//! ```xml
//! <roaml>
//!     <parameters>
//!         <max_time value="100" unit="s" />          <!-- ns, us, ms, s or min -->
//!         <max_array_size value="10" />
//!         <bt_tick_rate value="5.0" />               <!-- Hz -->
//!         <bt_tick_if_not_running value="true" />
//!     </parameters>
//!     <data_declarations> <input type="xml" src="./types.xml" /> </data_declarations>
//!     <behavior_tree>
//!         <input type="bt.cpp-xml" src="./bt.xml" />
//!         <input type="bt-plugin-ascxml" src="./plugin.ascxml" />
//!     </behavior_tree>
//!     <node_models> <input type="node-ascxml" src="./node.ascxml" /> </node_models>
//!     <properties> <input type="jani" src="./properties.jani" /> </properties>
//! </roaml>
//! ```
//!
//! The older form is `<convince_mc_tc>` with `<mc_parameters>`, plugins of type
//! `bt-plugin-ros-scxml` and node models of type `ros-scxml` (`.scxml` files with ROS tags).
//! Either parameter element is accepted in either form. Paths are relative to the main file.
//! `<parameters>` with `<max_time>` is required, as AS2FM requires it. AS2FM reads whole
//! numbers of `s`, `ms`, `us` or `ns`; decimals (`2.5`, converted exactly) and `min` are
//! accepted too (the units of `codegen::duration`; `h` is an error, as everywhere). Several property inputs, `xml` and `hspec` ones, and no `<properties>`
//! at all are extensions (AS2FM wants exactly one `jani`).
//!
//! # What is accepted, ignored and refused
//!
//! Everything AS2FM's reader accepts is accepted (`RoamlMain` and the `Roaml*` classes of
//! `jani_generator/scxml_helpers/roaml_model.py`). Where that reader errors, so do we: a
//! section given twice, an unknown parameter, a child of a section that is not `<input>`,
//! an unknown input type, a missing `value`, `unit`, `type` or `src`. What it ignores (it
//! looks sections up by name and reads only the attributes it knows) is ignored here with
//! a warning at its position ([`MainFile::warnings`]): an unknown element of the root, an
//! attribute it does not read, text, elements inside a parameter or an `<input>`,
//! `<mc_parameters>` beside `<parameters>` (AS2FM reads `<parameters>` then). Two are
//! ignored without a warning: `id` on `<input>` (a label, used by UC3's main files) and
//! `xmlns` attributes. An unknown name close to one that is read (`<node_model>`, `scr=`)
//! is an error with "did you mean": a misspelling would otherwise drop a section silently.

use std::path::{Path, PathBuf};

use crate::model::source::{Diagnostic, FileId, SourceMap, Span};
use crate::model::xml::{self, Element, Node};
use crate::rate::{self, RateError, RatePeriod};
use codegen::duration;

use super::main_ignored::{close_to, Notes, PARAMETERS, SECTIONS};

/// The BT tick rate AS2FM uses when `bt_tick_rate` is absent, in Hz.
pub(crate) const DEFAULT_BT_TICK_RATE_HZ: f64 = 1.0;

/// Whether AS2FM ticks a finished tree again when `bt_tick_if_not_running` is absent.
pub(crate) const DEFAULT_BT_TICK_IF_NOT_RUNNING: bool = false;

/// The length bound of unbounded arrays AS2FM uses when `max_array_size` is absent.
pub(crate) const DEFAULT_MAX_ARRAY_SIZE: u32 = 100;

/// Which of the two main file formats a file is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MainForm {
    /// `<roaml>`.
    Roaml,
    /// The older `<convince_mc_tc>`.
    ConvinceMcTc,
}

/// What an `<input>` is, from its `type` attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    /// `bt.cpp-xml`: a BehaviorTree.cpp XML tree (in `<behavior_tree>`).
    BtCppXml,
    /// `bt-plugin-ascxml`: a BT leaf plugin as `.ascxml` (in `<behavior_tree>`).
    BtPluginAscxml,
    /// `bt-plugin-ros-scxml`: a BT leaf plugin as `.scxml` with ROS tags, older form.
    BtPluginRosScxml,
    /// `node-ascxml`: a node model as `.ascxml` (in `<node_models>`).
    NodeAscxml,
    /// `ros-scxml`: a node model as `.scxml` with ROS tags, older form.
    RosScxml,
    /// `jani`: JANI properties (in `<properties>`).
    Jani,
    /// `xml` in `<properties>`: SCAN-format XML properties over ROS names.
    PropertiesXml,
    /// `hspec`: hindsight's own property file (in `<properties>`).
    Hspec,
    /// `xml` in `<data_declarations>`: `<types>` of `<struct>`s.
    DataXml,
    /// `json` in `<data_declarations>`: a JSON schema.
    DataJson,
}

impl InputKind {
    /// The `type` attribute value this kind is written as.
    pub fn type_name(self) -> &'static str {
        match self {
            InputKind::BtCppXml => "bt.cpp-xml",
            InputKind::BtPluginAscxml => "bt-plugin-ascxml",
            InputKind::BtPluginRosScxml => "bt-plugin-ros-scxml",
            InputKind::NodeAscxml => "node-ascxml",
            InputKind::RosScxml => "ros-scxml",
            InputKind::Jani => "jani",
            InputKind::PropertiesXml | InputKind::DataXml => "xml",
            InputKind::Hspec => "hspec",
            InputKind::DataJson => "json",
        }
    }
}

/// One `<input type src>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Input {
    /// What the file is.
    pub kind: InputKind,
    /// The `src` attribute as written.
    pub src: String,
    /// `src` resolved against the main file's folder.
    pub path: PathBuf,
    /// Where the `src` value is written (errors about the file point here).
    pub span: Span,
    /// Where the `<input>` element starts.
    pub element: Span,
}

/// A parameter's value and where it is written.
#[derive(Clone, Debug, PartialEq)]
pub struct Param<T> {
    /// The value.
    pub value: T,
    /// Where the `value` attribute's value is written.
    pub span: Span,
}

/// The BT tick rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickRate {
    /// Ticks per second, as written.
    pub hz: f64,
    /// The tick period in nanoseconds, rounded to the nearest nanosecond.
    pub period_ns: u64,
    /// True when `period_ns` is exactly `1e9 / hz`: always, since a rate whose period is
    /// not a whole number of nanoseconds (`3`) is refused where it is written.
    pub exact: bool,
}

/// The run parameters. `max_time` is required (as AS2FM requires it); the others are `None`
/// where the file does not set them, and their accessors give AS2FM's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    /// `max_time`, converted exactly to nanoseconds.
    pub max_time_ns: Param<u64>,
    /// `max_array_size`: the length bound of unbounded arrays.
    pub max_array_size: Option<Param<u32>>,
    /// `bt_tick_rate` (default `DEFAULT_BT_TICK_RATE_HZ`).
    pub bt_tick_rate: Option<Param<TickRate>>,
    /// `bt_tick_if_not_running` (default `DEFAULT_BT_TICK_IF_NOT_RUNNING`).
    pub bt_tick_if_not_running: Option<Param<bool>>,
    /// Where the parameters element starts.
    pub span: Span,
}

impl Parameters {
    /// The length bound of unbounded arrays, or the default.
    pub fn max_array_size_or_default(&self) -> u32 {
        self.max_array_size
            .as_ref()
            .map_or(DEFAULT_MAX_ARRAY_SIZE, |p| p.value)
    }

    /// The tick rate in Hz, or the default.
    pub(crate) fn bt_tick_rate_hz(&self) -> f64 {
        self.bt_tick_rate
            .as_ref()
            .map_or(DEFAULT_BT_TICK_RATE_HZ, |p| p.value.hz)
    }

    /// Whether a finished tree is ticked again, or the default.
    pub fn tick_if_not_running(&self) -> bool {
        self.bt_tick_if_not_running
            .as_ref()
            .map_or(DEFAULT_BT_TICK_IF_NOT_RUNNING, |p| p.value)
    }
}

/// Parameters as read, before `max_time` is known to be there.
#[derive(Default)]
struct RawParams {
    max_time_ns: Option<Param<u64>>,
    max_array_size: Option<Param<u32>>,
    bt_tick_rate: Option<Param<TickRate>>,
    bt_tick_if_not_running: Option<Param<bool>>,
}

/// The `<behavior_tree>` section.
#[derive(Clone, Debug, PartialEq)]
pub struct BehaviorTree {
    /// The one `bt.cpp-xml` tree.
    pub tree: Input,
    /// The plugins, in the order written.
    pub plugins: Vec<Input>,
    /// Where `<behavior_tree>` starts.
    pub span: Span,
}

/// A main file, read.
#[derive(Clone, Debug, PartialEq)]
pub struct MainFile {
    /// The main file's path as given.
    pub path: PathBuf,
    /// The main file in the source map.
    pub file: FileId,
    /// Which format it is written in.
    pub form: MainForm,
    /// The run parameters.
    pub params: Parameters,
    /// `<data_declarations>` inputs.
    pub data_declarations: Vec<Input>,
    /// The behavior tree and its plugins, if any.
    pub behavior_tree: Option<BehaviorTree>,
    /// `<node_models>` inputs.
    pub node_models: Vec<Input>,
    /// `<properties>` inputs.
    pub properties: Vec<Input>,
    /// What was ignored, as AS2FM ignores it (see the module documentation).
    pub warnings: Vec<Diagnostic>,
}

impl MainFile {
    /// Reads the main file at `path` and checks that every file it names exists
    /// ([`MainFile::parse`] then [`MainFile::missing_files`]).
    pub fn read(sm: &mut SourceMap, path: &Path) -> Result<MainFile, Vec<Diagnostic>> {
        let m = MainFile::parse(sm, path)?;
        let missing = m.missing_files(sm);
        if missing.is_empty() {
            Ok(m)
        } else {
            Err(missing)
        }
    }

    /// Reads the main file at `path` without looking at the files it names (for a caller
    /// that replaces some of them, such as the properties).
    pub fn parse(sm: &mut SourceMap, path: &Path) -> Result<MainFile, Vec<Diagnostic>> {
        let text = codegen::diag::read_source(path).map_err(|d| vec![d])?;
        let file = sm.add(path, text);
        MainFile::parse_file(sm, file, path)
    }

    /// Reads a main file already added to `sm` as `file`; `path` is where it lives (inputs
    /// are resolved against its folder).
    pub fn parse_file(
        sm: &SourceMap,
        file: FileId,
        path: &Path,
    ) -> Result<MainFile, Vec<Diagnostic>> {
        let root = xml::parse(sm, file).map_err(|d| vec![d])?;
        let form = match root.name.as_str() {
            "roaml" => MainForm::Roaml,
            "convince_mc_tc" => MainForm::ConvinceMcTc,
            other => {
                return Err(vec![sm.diag(
                    root.span,
                    format!("expected a main file (<roaml> or <convince_mc_tc>), found <{other}>"),
                )])
            }
        };
        let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let mut r = Reader {
            sm,
            base,
            errs: Vec::new(),
            warnings: Vec::new(),
        };
        r.attrs(&root, &[]);
        // AS2FM looks `<mc_parameters>` up only when there is no `<parameters>`
        // (`RoamlParameters.from_roaml_xml`).
        let has_parameters = root.elements().any(|e| e.name == "parameters");
        let mut params: Option<(RawParams, Span)> = None;
        let mut seen: Vec<(String, Span)> = Vec::new();
        let mut data_declarations = Vec::new();
        let mut behavior_tree = None;
        let mut node_models = Vec::new();
        let mut properties = Vec::new();
        for el in r.children(&root) {
            if el.name == "mc_parameters" && has_parameters {
                r.warn(
                    el.span,
                    "<mc_parameters> is ignored: <parameters> is given, and AS2FM reads only that",
                );
                continue;
            }
            let section = match el.name.as_str() {
                "parameters" | "mc_parameters" => "parameters",
                other => other,
            };
            if let Some((_, first)) = seen.iter().find(|(n, _)| n == section) {
                let (line, _) = sm
                    .source(FileId::of(*first))
                    .map_or((0, 0), |f| f.line_col(first.lo));
                r.errs.push(sm.diag(
                    el.span,
                    format!("<{}> is given twice (first on line {line})", el.name),
                ));
                continue;
            }
            seen.push((section.to_string(), el.span));
            match section {
                "parameters" => params = Some((r.parameters(el), el.span)),
                "data_declarations" => {
                    data_declarations = r.inputs(
                        el,
                        &[("xml", InputKind::DataXml), ("json", InputKind::DataJson)],
                    )
                }
                "behavior_tree" => {
                    let inputs = r.inputs(
                        el,
                        &[
                            ("bt.cpp-xml", InputKind::BtCppXml),
                            ("bt-plugin-ascxml", InputKind::BtPluginAscxml),
                            ("bt-plugin-ros-scxml", InputKind::BtPluginRosScxml),
                        ],
                    );
                    behavior_tree = r.behavior_tree(el, inputs);
                }
                "node_models" => {
                    node_models = r.inputs(
                        el,
                        &[
                            ("node-ascxml", InputKind::NodeAscxml),
                            ("ros-scxml", InputKind::RosScxml),
                        ],
                    )
                }
                "properties" => {
                    properties = r.inputs(
                        el,
                        &[
                            ("jani", InputKind::Jani),
                            ("xml", InputKind::PropertiesXml),
                            ("hspec", InputKind::Hspec),
                        ],
                    )
                }
                _ => {
                    // AS2FM finds sections by name: any other element is never read.
                    r.unknown_element(el, &root.name, SECTIONS);
                    continue;
                }
            }
            r.attrs(el, &[]);
        }
        let params = match params {
            Some((
                RawParams {
                    max_time_ns: Some(max_time_ns),
                    max_array_size,
                    bt_tick_rate,
                    bt_tick_if_not_running,
                },
                span,
            )) => Some(Parameters {
                max_time_ns,
                max_array_size,
                bt_tick_rate,
                bt_tick_if_not_running,
                span,
            }),
            Some((_, span)) => {
                if r.errs.is_empty() {
                    r.errs.push(sm.diag(
                        span,
                        "the parameters need <max_time value=... unit=...>: how long a run lasts",
                    ));
                }
                None
            }
            None => {
                r.errs.push(sm.diag(
                    root.span,
                    format!(
                        "<{}> needs <parameters> with <max_time value=... unit=...>",
                        root.name
                    ),
                ));
                None
            }
        };
        match params {
            Some(params) if r.errs.is_empty() => Ok(MainFile {
                path: path.to_path_buf(),
                file,
                form,
                params,
                data_declarations,
                behavior_tree,
                node_models,
                properties,
                warnings: r.warnings,
            }),
            _ => Err(r.errs),
        }
    }

    /// Every input, in file order of sections: data declarations, tree, plugins, node
    /// models, properties.
    pub fn inputs(&self) -> impl Iterator<Item = &Input> {
        let bt = self
            .behavior_tree
            .iter()
            .flat_map(|b| std::iter::once(&b.tree).chain(b.plugins.iter()));
        self.data_declarations
            .iter()
            .chain(bt)
            .chain(self.node_models.iter())
            .chain(self.properties.iter())
    }

    /// An error at each `src` that names no regular file: missing, a folder, a FIFO, a
    /// device (`codegen::diag::not_a_source_file`, which never opens it).
    pub fn missing_files(&self, sm: &SourceMap) -> Vec<Diagnostic> {
        self.inputs()
            .filter_map(|i| {
                let why = codegen::diag::not_a_source_file(&i.path)?;
                Some(sm.diag(
                    i.span,
                    format!("{} file `{}` {why}", i.kind.type_name(), i.path.display()),
                ))
            })
            .collect()
    }
}

struct Reader<'a> {
    sm: &'a SourceMap,
    base: PathBuf,
    errs: Vec<Diagnostic>,
    warnings: Vec<Diagnostic>,
}

impl Notes for Reader<'_> {
    fn sm(&self) -> &SourceMap {
        self.sm
    }
    fn errs(&mut self) -> &mut Vec<Diagnostic> {
        &mut self.errs
    }
    fn warnings(&mut self) -> &mut Vec<Diagnostic> {
        &mut self.warnings
    }
}

impl<'a> Reader<'a> {
    /// Child elements. Text is ignored with a warning (AS2FM reads only elements).
    fn children<'e>(&mut self, el: &'e Element) -> Vec<&'e Element> {
        let mut out = Vec::new();
        for n in &el.children {
            match n {
                Node::Element(e) => out.push(e),
                Node::Text(span) => self.warn(
                    *span,
                    format!(
                        "text in <{}> is ignored (AS2FM reads only elements)",
                        el.name
                    ),
                ),
                Node::Comment(..) => {}
            }
        }
        out
    }

    fn parameters(&mut self, el: &Element) -> RawParams {
        let sm = self.sm;
        let mut p = RawParams::default();
        for c in self.children(el) {
            let allowed: &[&str] = if c.name == "max_time" {
                &["value", "unit"]
            } else {
                &["value"]
            };
            if !PARAMETERS.contains(&c.name.as_str()) {
                // AS2FM refuses an unknown parameter (`_parse_parameters`).
                let hint = close_to(&c.name, PARAMETERS)
                    .map(|k| format!("did you mean <{k}>? "))
                    .unwrap_or_default();
                self.errs.push(sm.diag(
                    c.span,
                    format!(
                        "unknown parameter <{}>; {hint}(expected <max_time>, <max_array_size>, <bt_tick_rate> or <bt_tick_if_not_running>)",
                        c.name
                    ),
                ));
                continue;
            }
            self.attrs(c, allowed);
            self.ignored_children(c);
            let value = match c.required(sm, "value") {
                Ok(a) => a,
                Err(d) => {
                    self.errs.push(d);
                    continue;
                }
            };
            let v = value.value.trim();
            let span = value.value_span;
            match c.name.as_str() {
                "max_time" => {
                    let unit = match c.required(sm, "unit") {
                        Ok(u) => u,
                        Err(_) => {
                            self.errs.push(sm.diag(
                                c.span,
                                format!("<max_time> needs a `unit` ({})", duration::UNITS_TEXT),
                            ));
                            continue;
                        }
                    };
                    if p.max_time_ns.is_some() {
                        self.errs.push(sm.diag(c.span, "<max_time> is given twice"));
                        continue;
                    }
                    match duration::TimeUnit::from_suffix(unit.value.trim()) {
                        None => self.errs.push(sm.diag(
                            unit.value_span,
                            format!(
                                "unknown time unit `{}` (expected {})",
                                unit.value,
                                duration::UNITS_TEXT
                            ),
                        )),
                        Some(unit) => match duration::decimal_times(v, unit.nanos()) {
                            // As `--max-time 0` is: a run would end before its timers
                            // fire, every property judged on the first instant alone.
                            Ok(0) => self.errs.push(sm.diag(
                                span,
                                "max_time must be positive: a run of length 0 ends before \
                                 any timer fires",
                            )),
                            Ok(ns) => p.max_time_ns = Some(Param { value: ns, span }),
                            Err(m) => self.errs.push(sm.diag(span, m.to_string())),
                        },
                    }
                }
                "max_array_size" => {
                    if p.max_array_size.is_some() {
                        self.errs
                            .push(sm.diag(c.span, "<max_array_size> is given twice"));
                        continue;
                    }
                    match v.parse::<u32>() {
                        Ok(n) if n > 0 => p.max_array_size = Some(Param { value: n, span }),
                        _ => self.errs.push(sm.diag(
                            span,
                            format!("max_array_size must be a positive whole number, not `{v}`"),
                        )),
                    }
                }
                "bt_tick_rate" => {
                    if p.bt_tick_rate.is_some() {
                        self.errs
                            .push(sm.diag(c.span, "<bt_tick_rate> is given twice"));
                        continue;
                    }
                    match tick_rate(v) {
                        Ok(t) => p.bt_tick_rate = Some(Param { value: t, span }),
                        Err(e) => self.errs.push(sm.diag(span, e.to_string())),
                    }
                }
                _ => {
                    if p.bt_tick_if_not_running.is_some() {
                        self.errs
                            .push(sm.diag(c.span, "<bt_tick_if_not_running> is given twice"));
                        continue;
                    }
                    let b = match v.to_ascii_lowercase().as_str() {
                        "true" | "1" => Some(true),
                        "false" | "0" => Some(false),
                        _ => None,
                    };
                    match b {
                        Some(b) => p.bt_tick_if_not_running = Some(Param { value: b, span }),
                        None => self.errs.push(sm.diag(
                            span,
                            format!("bt_tick_if_not_running must be true or false, not `{v}`"),
                        )),
                    }
                }
            }
        }
        p
    }

    fn inputs(&mut self, el: &Element, kinds: &[(&str, InputKind)]) -> Vec<Input> {
        let sm = self.sm;
        let mut out = Vec::new();
        let expected = || kinds.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ");
        for c in self.children(el) {
            if c.name != "input" {
                self.errs.push(sm.diag(
                    c.span,
                    format!(
                        "unexpected <{}> in <{}> (expected <input type src>)",
                        c.name, el.name
                    ),
                ));
                continue;
            }
            self.attrs(c, &["type", "src"]);
            self.ignored_children(c);
            let (ty, src) = match (c.required(sm, "type"), c.required(sm, "src")) {
                (Ok(t), Ok(s)) => (t, s),
                (Err(d), _) | (_, Err(d)) => {
                    self.errs.push(d);
                    continue;
                }
            };
            let Some((_, kind)) = kinds.iter().find(|(n, _)| *n == ty.value.trim()) else {
                self.errs.push(sm.diag(
                    ty.value_span,
                    format!(
                        "unknown input type `{}` in <{}> (expected {})",
                        ty.value,
                        el.name,
                        expected()
                    ),
                ));
                continue;
            };
            let s = src.value.trim();
            if s.is_empty() {
                self.errs.push(sm.diag(src.value_span, "empty `src`"));
                continue;
            }
            out.push(Input {
                kind: *kind,
                src: src.value.clone(),
                path: crate::model::join_clean(&self.base, s),
                span: src.value_span,
                element: c.span,
            });
        }
        out
    }

    fn behavior_tree(&mut self, el: &Element, inputs: Vec<Input>) -> Option<BehaviorTree> {
        let sm = self.sm;
        let mut tree: Option<Input> = None;
        let mut plugins = Vec::new();
        for i in inputs {
            if i.kind == InputKind::BtCppXml {
                if tree.is_some() {
                    self.errs.push(sm.diag(
                        i.element,
                        "a behavior tree has exactly one bt.cpp-xml input (SubTrees go in the same file)",
                    ));
                } else {
                    tree = Some(i);
                }
            } else {
                plugins.push(i);
            }
        }
        match tree {
            Some(tree) => Some(BehaviorTree {
                tree,
                plugins,
                span: el.span,
            }),
            None => {
                self.errs.push(sm.diag(
                    el.span,
                    "<behavior_tree> needs one <input type=\"bt.cpp-xml\" src=...>",
                ));
                None
            }
        }
    }
}

fn tick_rate(text: &str) -> Result<TickRate, TickRateError> {
    let refuse = |why| TickRateError {
        text: text.to_string(),
        why,
    };
    match rate::period(text) {
        Ok(RatePeriod {
            hz,
            period_ns,
            exact: true,
        }) => Ok(TickRate {
            hz,
            period_ns,
            exact: true,
        }),
        // The model's time step is the greatest common divisor of its periods: a period
        // rounded to the nanosecond would make it 1 ns, and every run would end at the
        // step limit with no verdict. Refused here, at the attribute, instead.
        Ok(p) => Err(refuse(TickRateWhy::Fraction(p.hz))),
        Err(e) => Err(refuse(TickRateWhy::Rate(e))),
    }
}

/// A `bt_tick_rate` refused: the text, and why.
#[derive(Clone, Debug, PartialEq)]
struct TickRateError {
    text: String,
    why: TickRateWhy,
}

/// Why a `bt_tick_rate` was refused.
#[derive(Clone, Debug, PartialEq)]
enum TickRateWhy {
    /// The rate reader's error.
    Rate(RateError),
    /// The rate, in hertz, of a period that is not a whole number of nanoseconds.
    Fraction(f64),
}

impl std::fmt::Display for TickRateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = &self.text;
        match self.why {
            TickRateWhy::Fraction(hz) => write!(
                f,
                "bt_tick_rate `{text}` ticks every {:.3} ns, not a whole number of \
                 nanoseconds: the model's time step would shrink to 1 ns and every run would \
                 stop at the step limit; use a rate whose period is whole, such as 2, 4, 5, \
                 10 or 0.5 ticks per second",
                1e9 / hz
            ),
            TickRateWhy::Rate(RateError::NotPositive) => write!(
                f,
                "bt_tick_rate must be a positive number of ticks per second, not `{text}`"
            ),
            TickRateWhy::Rate(RateError::FasterThanNs) => write!(
                f,
                "bt_tick_rate `{text}` is faster than one tick per nanosecond"
            ),
            TickRateWhy::Rate(RateError::TooSlow) => write!(
                f,
                "bt_tick_rate `{text}` is slower than the slowest rate hindsight can time \
                 (one tick per 2^64 ns, about 584 years)"
            ),
        }
    }
}

impl std::error::Error for TickRateError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_rates() {
        let t = tick_rate("10.0").unwrap();
        assert_eq!((t.period_ns, t.exact), (100_000_000, true));
        let t = tick_rate("0.5").unwrap();
        assert_eq!((t.period_ns, t.exact), (2_000_000_000, true));
        let t = tick_rate("1e1").unwrap();
        assert_eq!((t.period_ns, t.exact), (100_000_000, true));
        // A period that is no whole number of nanoseconds, or does not fit in 64 bits.
        assert!(tick_rate("3")
            .unwrap_err()
            .to_string()
            .contains("333333333.333 ns"));
        assert!(tick_rate("1e-12")
            .unwrap_err()
            .to_string()
            .contains("584 years"));
        assert!(tick_rate("0").is_err());
        assert!(tick_rate("-1").is_err());
        assert!(tick_rate("fast").is_err());
        assert!(tick_rate("inf").is_err());
    }
}
