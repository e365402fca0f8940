//! ROS 2 interface definitions (`.msg`, `.srv`, `.action`): read with positions, the standard
//! packages built in, and flattened into the leaf fields the ROS lowering sends.
//!
//! # Main types
//!
//! - [`InterfaceDef`]: one parsed interface file: its package, name, kind and its parts
//!   (one for a message, request/response for a service, goal/result/feedback for an
//!   action), each a [`MessageDef`] of [`Field`]s and [`Constant`]s.
//! - [`Interfaces`]: every known interface, from [`Interfaces::with_builtins`] (our own field
//!   lists, [`builtin`]) plus the packages found for a model by [`Interfaces::discover_with`]
//!   ([`discover`] gives the search order). It implements [`InterfaceLookup`].
//!
//! # Files
//!
//! The parsed types, the file format and the built-in packages are the `hindsight-ros2`
//! crate's (`crates/ros2/src/interface/`, re-exported here), shared with recordings;
//! `discover.rs` is where packages are looked for, and this file the store: lookups,
//! checks and flattening.
//!
//! # The file format
//!
//! One field or constant a line, `#` starts a comment (outside quotes), `---` separates the
//! parts of a service (2 parts) or an action (3 parts):
//!
//! ```text
//! int8 MODE_FAST=1                 # a constant
//! int32 count 5                    # a field with a default value
//! string<=10 name "robot"          # a bounded string
//! float64[3] xyz [0.0, 1.0, 2.0]   # a fixed array
//! int32[<=5] few                   # a bounded array
//! geometry_msgs/Point[] points     # an unbounded array of another package's messages
//! Internal inner                   # a message of the same package
//! ```
//!
//! # Flattening
//!
//! A nested message becomes its leaf fields, with paths `inner.i`, `inner.text` (AS2FM's
//! `ros_fields__inner__i`). An array of messages becomes one array per leaf field (a
//! struct of arrays, as AS2FM lowers arrays of data structs): `Internal[] i_arr` gives
//! `i_arr.i: int32[]` and `i_arr.text: string[]`; array dimensions are written outermost
//! first (`Polygon[] p` of `Point[] points` of `float64 x` gives `p.points.x: float64[][]`).
//!
//! Types are spelled as the SCXML reader reads them: ROS's primitive names (`int8` ...
//! `uint64`, `float32`, `float64`, `bool`, `string`); `byte` and `char` become `uint8`,
//! `wstring` becomes `string`, `string<=N` becomes `string`; a fixed array `T[3]` is `T[3]`,
//! a bounded one `T[<=5]` is `T[5]` (a maximum length), an unbounded one `T[]`.

pub mod discover;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

pub use discover::Search;
/// The built-in packages: `hindsight-ros2`'s, the one `.msg` reader the project has.
pub use ros2::interface::builtin;
pub use ros2::interface::*;

use super::types::{ActionFields, FlatField, InterfaceLookup, LookupError, ServiceFields};
use crate::model::source::{Diagnostic, SourceMap};

/// Deepest nesting of messages followed when flattening (a deeper chain is a cycle).
const MAX_NESTING: usize = 32;

/// Most leaf fields one flattened message may have.
const MAX_LEAVES: usize = 10_000;

/// Every known ROS interface, by package, kind and name.
#[derive(Clone, Debug, Default)]
pub struct Interfaces {
    defs: BTreeMap<(String, InterfaceKind, String), InterfaceDef>,
    /// The folder each package read from disk came from (built-in packages are absent).
    origins: BTreeMap<String, PathBuf>,
    /// The places [`Interfaces::discover_with`] searched, in order: named when a type is
    /// missing.
    searched: Vec<String>,
    /// Packages of a sourced ROS workspace that did not read or resolve: their errors,
    /// given when a model uses the package (an unused broken package stops nothing).
    broken: BTreeMap<String, Vec<Diagnostic>>,
    /// Whether an error has listed `searched` already (the list is given once).
    searched_said: std::cell::Cell<bool>,
}

impl Interfaces {
    /// No interfaces at all.
    pub fn new() -> Self {
        Self::default()
    }

    /// The built-in packages ([`builtin::PACKAGES`]): std_msgs, std_srvs, example_interfaces,
    /// action_msgs, builtin_interfaces, unique_identifier_msgs and ROS 2's common interfaces
    /// (geometry_msgs, sensor_msgs, nav_msgs, diagnostic_msgs, shape_msgs, trajectory_msgs,
    /// visualization_msgs).
    pub fn with_builtins() -> Self {
        let mut me = Interfaces::new();
        for def in builtin::definitions() {
            me.insert(def);
        }
        me
    }

    /// Adds the text of one interface file as `package/kind/name` (replacing an earlier
    /// definition of that name). Named types are not checked here: call
    /// [`Interfaces::check`] once everything is added.
    pub fn add_text(
        &mut self,
        sm: &mut SourceMap,
        path: &Path,
        text: String,
        package: &str,
        kind: InterfaceKind,
        name: &str,
    ) -> Result<(), Vec<Diagnostic>> {
        let file = sm.add(path, text);
        if !ros2::interface::valid_type_name(name) {
            return Err(vec![crate::model::about_file(
                path,
                format!("`{name}` is not a valid interface name (it must start with an upper-case letter and have only letters and digits)"),
            )]);
        }
        let def = parse_interface(sm, file, package, name, kind)?;
        self.insert(def);
        Ok(())
    }

    fn insert(&mut self, def: InterfaceDef) {
        self.defs
            .insert((def.package.clone(), def.kind, def.name.clone()), def);
    }

    /// Checks that every message type a field names exists and that no message contains
    /// itself; errors point at the field.
    pub fn check(&self, sm: &SourceMap) -> Result<(), Vec<Diagnostic>> {
        let errs = self.check_packages(sm, |_| true);
        if errs.is_empty() {
            Ok(())
        } else {
            Err(errs)
        }
    }

    /// [`Interfaces::check`] of the definitions whose package `keep` accepts.
    fn check_packages(&self, sm: &SourceMap, keep: impl Fn(&str) -> bool) -> Vec<Diagnostic> {
        let mut errs = Vec::new();
        for def in self.defs.values().filter(|d| keep(&d.package)) {
            for part in &def.parts {
                for f in &part.fields {
                    let BaseType::Message { package, name } = &f.ty.base else {
                        continue;
                    };
                    let key = (package.clone(), InterfaceKind::Message, name.clone());
                    let msg = if self.defs.contains_key(&key) {
                        if self.contains_cycle(&key) {
                            Some(format!(
                                "message `{package}/{name}` contains itself, so it has no finite layout"
                            ))
                        } else {
                            None
                        }
                    } else {
                        Some(
                            self.unknown(&format!("{package}/{name}"), InterfaceKind::Message)
                                .to_string(),
                        )
                    };
                    if let Some(m) = msg {
                        let d = match def.file {
                            Some(_) => sm.diag(f.span, m),
                            None => crate::model::about_file(
                                format!("<built-in {}>", def.full_name()),
                                m,
                            ),
                        };
                        errs.push(d);
                    }
                }
            }
        }
        errs
    }

    /// True when message `start` can reach itself through its fields.
    fn contains_cycle(&self, start: &(String, InterfaceKind, String)) -> bool {
        let mut seen = BTreeSet::new();
        let mut stack = vec![start.clone()];
        while let Some(key) = stack.pop() {
            if !seen.insert(key.clone()) {
                continue;
            }
            let Some(def) = self.defs.get(&key) else {
                continue;
            };
            for f in def.parts.iter().flat_map(|p| &p.fields) {
                if let BaseType::Message { package, name } = &f.ty.base {
                    let k = (package.clone(), InterfaceKind::Message, name.clone());
                    if k == *start {
                        return true;
                    }
                    stack.push(k);
                }
            }
        }
        false
    }

    /// All interfaces, ordered by package, kind and name.
    pub fn iter(&self) -> impl Iterator<Item = &InterfaceDef> {
        self.defs.values()
    }

    /// The interface that `type_name` (`pkg/Type` or `pkg/msg/Type`) names, of kind `kind`.
    pub fn get(&self, type_name: &str, kind: InterfaceKind) -> Result<&InterfaceDef, LookupError> {
        let parts: Vec<&str> = type_name.trim().split('/').collect();
        let not_a_name = |suggestion| LookupError::NotATypeName {
            type_name: type_name.to_string(),
            dir: kind.dir(),
            suggestion,
        };
        let wrong_kind = |found: InterfaceKind, by_folder| LookupError::WrongKind {
            type_name: type_name.to_string(),
            found: found.noun(),
            wanted: kind.noun(),
            by_folder,
        };
        let (pkg, name) = match parts.as_slice() {
            [pkg, name] => (*pkg, *name),
            [pkg, mid, name] => match InterfaceKind::from_dir(mid) {
                Some(k) if k == kind => (*pkg, *name),
                Some(k) => return Err(wrong_kind(k, true)),
                None => return Err(not_a_name(None)),
            },
            _ => return Err(not_a_name(Some(self.suggest(type_name, kind)))),
        };
        let key = (pkg.to_string(), kind, name.to_string());
        if let Some(d) = self.defs.get(&key) {
            return Ok(d);
        }
        for other in [
            InterfaceKind::Message,
            InterfaceKind::Service,
            InterfaceKind::Action,
        ] {
            if other != kind
                && self
                    .defs
                    .contains_key(&(pkg.to_string(), other, name.to_string()))
            {
                return Err(wrong_kind(other, false));
            }
        }
        Err(self.unknown(&format!("{pkg}/{name}"), kind))
    }

    fn unknown(&self, type_name: &str, kind: InterfaceKind) -> LookupError {
        let pkg = type_name.split('/').next().unwrap_or("");
        let unknown = |why| LookupError::Unknown {
            type_name: type_name.to_string(),
            kind: kind.noun(),
            why,
        };
        if let Some(errs) = self.broken.get(pkg) {
            let first = errs.first().map(|d| d.to_string()).unwrap_or_default();
            return unknown(format!(
                "package `{pkg}` of the sourced ROS workspace did not read ({} error(s), first: {first})",
                errs.len()
            ));
        }
        let known_pkg = self.defs.keys().any(|(p, _, _)| p == pkg);
        let place = match (known_pkg, self.origins.get(pkg)) {
            (true, Some(dir)) => format!(
                "package `{pkg}` (found in {}) has no {}/ file of that name",
                dir.display(),
                kind.dir()
            ),
            (true, None) => format!("the built-in package `{pkg}` has no such {}", kind.noun()),
            (false, _) => format!("no package `{pkg}` was found"),
        };
        let suggestion = if known_pkg || self.close_package(pkg) {
            format!("; {}", self.suggest(type_name, kind))
        } else {
            String::new()
        };
        let mut why = format!("{place}{suggestion}");
        if !known_pkg {
            if self.searched_said.replace(true) {
                why.push_str(" (the places searched are listed above)");
            } else {
                why.push_str(&self.searched_text());
            }
        }
        unknown(why)
    }

    /// Whether a known package's name is one or two edits from `pkg` (a misspelt package:
    /// then close type names are worth suggesting).
    fn close_package(&self, pkg: &str) -> bool {
        self.defs
            .keys()
            .any(|(p, _, _)| edit_distance(&pkg.to_ascii_lowercase(), &p.to_ascii_lowercase()) <= 2)
    }

    /// The places searched, one a line, for an error about a missing package.
    fn searched_text(&self) -> String {
        let mut out = String::from("\n  searched, in this order:");
        if self.searched.is_empty() {
            out.push_str("\n    (no folder: only the built-in packages)");
        }
        for s in &self.searched {
            out.push_str("\n    ");
            out.push_str(s);
        }
        out.push_str("\n    built in: ");
        out.push_str(&builtin::package_names().collect::<Vec<_>>().join(", "));
        out.push_str(
            "\n  hint: `--interfaces DIR` names a folder of interface packages (DIR/<pkg>/msg/*.msg)",
        );
        out
    }

    /// "did you mean ..." with up to five close names of the same kind.
    fn suggest(&self, type_name: &str, kind: InterfaceKind) -> String {
        let wanted = type_name.to_ascii_lowercase();
        let wanted_short = wanted.rsplit('/').next().unwrap_or(&wanted).to_string();
        let mut scored: Vec<(usize, String)> = self
            .defs
            .values()
            .filter(|d| d.kind == kind)
            .filter_map(|d| {
                let full = format!("{}/{}", d.package, d.name);
                let lower = full.to_ascii_lowercase();
                let dist = edit_distance(&wanted, &lower)
                    .min(edit_distance(&wanted_short, &d.name.to_ascii_lowercase()) + 1);
                let limit = 2.max(wanted.len() / 4);
                (dist <= limit).then_some((dist, full))
            })
            .collect();
        scored.sort();
        // Only the closest few: a near miss should not drown in far ones.
        if let Some(best) = scored.first().map(|(d, _)| *d) {
            scored.retain(|(d, _)| *d <= best + 1);
        }
        scored.truncate(5);
        if scored.is_empty() {
            let n = self.defs.values().filter(|d| d.kind == kind).count();
            format!("no close name among the {n} known {} types", kind.noun())
        } else {
            let names: Vec<String> = scored.into_iter().map(|(_, n)| n).collect();
            format!("did you mean {}?", names.join(", "))
        }
    }

    /// The constants of message `type_name`, as `(name, ECMAScript literal)`.
    pub fn constants(&self, type_name: &str) -> Result<Vec<(String, String)>, LookupError> {
        let def = self.get(type_name, InterfaceKind::Message)?;
        Ok(def.parts[0]
            .constants
            .iter()
            .map(|c| (c.name.clone(), c.value.clone()))
            .collect())
    }

    /// Flattens one part into leaf fields.
    fn flatten(&self, part: &MessageDef) -> Result<Vec<FlatField>, LookupError> {
        let mut out = Vec::new();
        let mut path = Vec::new();
        let mut dims = Vec::new();
        self.flatten_into(part, &mut path, &mut dims, &mut out, 0)?;
        Ok(out)
    }

    fn flatten_into(
        &self,
        part: &MessageDef,
        path: &mut Vec<String>,
        dims: &mut Vec<ArraySize>,
        out: &mut Vec<FlatField>,
        depth: usize,
    ) -> Result<(), LookupError> {
        if depth > MAX_NESTING {
            return Err(LookupError::TooDeep {
                at: path.join("."),
                limit: MAX_NESTING,
            });
        }
        for f in &part.fields {
            if out.len() >= MAX_LEAVES {
                return Err(LookupError::TooManyLeaves {
                    at: path.join("."),
                    limit: MAX_LEAVES,
                });
            }
            path.push(f.name.clone());
            match &f.ty.base {
                BaseType::Primitive { prim, .. } => {
                    let mut all = dims.clone();
                    if f.ty.array != ArraySize::Scalar {
                        all.push(f.ty.array);
                    }
                    let mut ty = prim.scxml_name().to_string();
                    for d in &all {
                        match d {
                            ArraySize::Fixed(n) | ArraySize::Bounded(n) => {
                                ty.push_str(&format!("[{n}]"))
                            }
                            _ => ty.push_str("[]"),
                        }
                    }
                    let default = match &f.default {
                        // An explicit default covers the field's own array (if any).
                        Some(d) => array_default(dims, d),
                        None => array_default(&all, prim.zero()),
                    };
                    out.push(FlatField {
                        path: path.clone(),
                        scxml_type: ty,
                        default,
                    });
                }
                BaseType::Message { package, name } => {
                    let key = (package.clone(), InterfaceKind::Message, name.clone());
                    let Some(def) = self.defs.get(&key) else {
                        return Err(
                            self.unknown(&format!("{package}/{name}"), InterfaceKind::Message)
                        );
                    };
                    let pushed = f.ty.array != ArraySize::Scalar;
                    if pushed {
                        dims.push(f.ty.array);
                    }
                    let r = self.flatten_into(&def.parts[0], path, dims, out, depth + 1);
                    if pushed {
                        dims.pop();
                    }
                    r?;
                }
            }
            path.pop();
        }
        Ok(())
    }
}

/// The default of a value nested in arrays `dims` (outermost first) whose leaf default is
/// `leaf`: fixed arrays are filled, others start empty.
fn array_default(dims: &[ArraySize], leaf: &str) -> String {
    match dims.first() {
        None => leaf.to_string(),
        Some(ArraySize::Fixed(n)) => {
            let inner = array_default(&dims[1..], leaf);
            let items: Vec<&str> = (0..*n).map(|_| inner.as_str()).collect();
            format!("[{}]", items.join(", "))
        }
        Some(_) => "[]".to_string(),
    }
}

/// The Levenshtein distance between `a` and `b` (in characters): how close a misspelt
/// name is to a known one, for "did you mean".
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

impl InterfaceLookup for Interfaces {
    fn message(&self, type_name: &str) -> Result<Vec<FlatField>, LookupError> {
        let def = self.get(type_name, InterfaceKind::Message)?;
        self.flatten(&def.parts[0])
    }

    fn service(&self, type_name: &str) -> Result<ServiceFields, LookupError> {
        let def = self.get(type_name, InterfaceKind::Service)?;
        Ok(ServiceFields {
            request: self.flatten(&def.parts[0])?,
            response: self.flatten(&def.parts[1])?,
        })
    }

    fn action(&self, type_name: &str) -> Result<ActionFields, LookupError> {
        let def = self.get(type_name, InterfaceKind::Action)?;
        Ok(ActionFields {
            goal: self.flatten(&def.parts[0])?,
            result: self.flatten(&def.parts[1])?,
            feedback: self.flatten(&def.parts[2])?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance("int32", "int33"), 1);
        assert_eq!(edit_distance("", "ab"), 2);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }

    #[test]
    fn defaults_of_nested_arrays() {
        assert_eq!(array_default(&[ArraySize::Fixed(2)], "0"), "[0, 0]");
        assert_eq!(
            array_default(&[ArraySize::Fixed(2), ArraySize::Unbounded], "0"),
            "[[], []]"
        );
        assert_eq!(array_default(&[ArraySize::Bounded(2)], "0"), "[]");
    }

    /// Every built-in type resolves and flattens into the leaf fields the lowering sends.
    #[test]
    fn every_builtin_flattens() {
        use crate::types::InterfaceLookup;
        use codegen::diag::SourceMap;
        let ifs = Interfaces::with_builtins();
        assert_eq!(ifs.iter().count(), builtin::definitions().len());
        assert_eq!(ifs.check(&SourceMap::new()), Ok(()));
        for d in ifs.iter() {
            let name = format!("{}/{}", d.package, d.name);
            let r = match d.kind {
                InterfaceKind::Message => ifs.message(&name).map(|f| f.len()),
                InterfaceKind::Service => ifs.service(&name).map(|s| s.request.len()),
                InterfaceKind::Action => ifs.action(&name).map(|a| a.goal.len()),
            };
            assert!(r.is_ok(), "{name}: {r:?}");
        }
        for pkg in [
            "sensor_msgs",
            "geometry_msgs",
            "nav_msgs",
            "diagnostic_msgs",
            "shape_msgs",
            "trajectory_msgs",
            "visualization_msgs",
            "unique_identifier_msgs",
        ] {
            assert!(ifs.iter().any(|d| d.package == pkg), "{pkg}");
        }
    }
}
