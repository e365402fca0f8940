//! The standard interface packages every model may use without shipping them: our own
//! field lists (facts of a current ROS 2 release, Jazzy) in `builtin/<package>.txt`.
//!
//! A data file holds one package: lines before the first `@ kind/Name` line are comments,
//! and each `@ msg/Name`, `@ srv/Name` or `@ action/Name` line starts a definition in the
//! ordinary `.msg` / `.srv` / `.action` format that runs to the next `@` line.

use super::parse::parse_interface;
use super::{InterfaceDef, InterfaceKind};
use codegen::diag::SourceMap;

/// `(package, data file)`, in the order listed in README.
pub const PACKAGES: &[(&str, &str)] = &[
    (
        "builtin_interfaces",
        include_str!("builtin/builtin_interfaces.txt"),
    ),
    (
        "unique_identifier_msgs",
        include_str!("builtin/unique_identifier_msgs.txt"),
    ),
    ("service_msgs", include_str!("builtin/service_msgs.txt")),
    ("std_msgs", include_str!("builtin/std_msgs.txt")),
    ("std_srvs", include_str!("builtin/std_srvs.txt")),
    (
        "example_interfaces",
        include_str!("builtin/example_interfaces.txt"),
    ),
    ("action_msgs", include_str!("builtin/action_msgs.txt")),
    ("geometry_msgs", include_str!("builtin/geometry_msgs.txt")),
    ("sensor_msgs", include_str!("builtin/sensor_msgs.txt")),
    ("nav_msgs", include_str!("builtin/nav_msgs.txt")),
    (
        "diagnostic_msgs",
        include_str!("builtin/diagnostic_msgs.txt"),
    ),
    ("shape_msgs", include_str!("builtin/shape_msgs.txt")),
    (
        "trajectory_msgs",
        include_str!("builtin/trajectory_msgs.txt"),
    ),
    (
        "visualization_msgs",
        include_str!("builtin/visualization_msgs.txt"),
    ),
];

/// One definition of a data file: `(kind, name, text)`.
pub fn split(data: &str) -> Vec<(Option<InterfaceKind>, &str, String)> {
    let mut out: Vec<(Option<InterfaceKind>, &str, String)> = Vec::new();
    for line in data.lines() {
        if let Some(head) = line.strip_prefix('@') {
            let (kind, name) = head.trim().split_once('/').unwrap_or(("", head.trim()));
            out.push((InterfaceKind::from_dir(kind), name, String::new()));
        } else if let Some((_, _, text)) = out.last_mut() {
            text.push_str(line);
            text.push('\n');
        }
    }
    out
}

/// Every built-in definition, parsed (with no file: [`InterfaceDef::file`] is `None`).
/// The data files are ours and tested to parse and resolve (`every_builtin_parses`);
/// one that did not would be left out here and fail that test.
pub fn definitions() -> Vec<InterfaceDef> {
    let mut sm = SourceMap::new();
    let mut out = Vec::new();
    for (pkg, data) in PACKAGES {
        for (kind, name, text) in split(data) {
            let Some(kind) = kind else { continue };
            let file = sm.add(format!("<built-in {pkg}/{}/{name}>", kind.dir()), text);
            if let Ok(mut def) = parse_interface(&sm, file, pkg, name, kind) {
                def.file = None;
                out.push(def);
            }
        }
    }
    out
}

/// The names of the built-in packages.
pub fn package_names() -> impl Iterator<Item = &'static str> {
    PACKAGES.iter().map(|(p, _)| *p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every definition of every data file parses (nothing is left out silently), and
    /// there is no definition twice.
    #[test]
    fn every_builtin_parses() {
        let mut sm = SourceMap::new();
        let mut seen = std::collections::BTreeSet::new();
        let mut n = 0;
        for (pkg, data) in PACKAGES {
            for (kind, name, text) in split(data) {
                let kind = kind.unwrap_or_else(|| panic!("{pkg}/{name}: no kind"));
                assert!(seen.insert((pkg, kind, name)), "{pkg}/{name} twice");
                let file = sm.add(format!("{pkg}/{name}"), text);
                parse_interface(&sm, file, pkg, name, kind)
                    .unwrap_or_else(|e| panic!("{pkg}/{name}: {e:?}"));
                n += 1;
            }
        }
        assert_eq!(definitions().len(), n);
        assert!(n > 150, "{n} built-in definitions");
    }
}
