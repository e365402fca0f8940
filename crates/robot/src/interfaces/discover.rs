//! Where a model's interface packages are looked for, and which one wins on a clash.
//!
//! # Search order
//!
//! 1. Each `--interfaces DIR` ([`Search::dirs`]), in the order given: `DIR` itself when it
//!    is a package, else the packages below it (up to three folders deep).
//! 2. The packages directly in the main file's folder.
//! 3. Interface folders (`ros_support_interfaces/`, `interfaces/`, `Interfaces/`) and the
//!    packages below them (up to three folders deep), in the main file's folder and then in
//!    every folder above it, nearest first, up to and including the root of the repository
//!    that holds the model (the first folder with a `.git`), or else the file system's root.
//! 4. The packages of a sourced ROS workspace ([`Search::ament_prefixes`], from
//!    `AMENT_PREFIX_PATH`): `<prefix>/share/<pkg>/msg|srv|action`, prefixes in order.
//! 5. The built-in packages ([`super::builtin`]).
//!
//! A package is a folder with a `msg/`, `srv/` or `action/` subfolder; its name is the
//! folder's. When several places hold a package of the same name, the first in this order
//! wins, whole (the others are not read), as an overlay workspace hides the one beneath it.
//! A package read from disk replaces a built-in package of the same name type by type: its
//! files win, built-in types it does not define stay.
//!
//! Errors in the files of places 1 to 3 are errors. A package of the sourced workspace that
//! does not read (a syntax this reader does not know) is only an error for a model that
//! uses it: a whole ROS installation should not stop a model that needs one package of it.

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

use super::{InterfaceKind, Interfaces};
use crate::model::source::{Diagnostic, SourceMap};

/// The folder names that hold interface packages, looked for beside and above a model.
pub(crate) const INTERFACE_FOLDERS: &[&str] =
    &["ros_support_interfaces", "interfaces", "Interfaces"];

/// How deep below a searched folder packages are looked for
/// (`ros_support_interfaces/uc3_interfaces/<pkg>/srv/X.srv` is two).
const PACKAGE_DEPTH: usize = 3;

/// Most folders walked up from a model (a guard against a cycle of links).
const MAX_LEVELS_UP: usize = 256;

/// Where to look for interface packages besides the model's own folders.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Search {
    /// `--interfaces DIR` folders, in the order given: each a package or a folder of them.
    pub dirs: Vec<PathBuf>,
    /// The install prefixes of a sourced ROS workspace, in order (`AMENT_PREFIX_PATH`).
    pub ament_prefixes: Vec<PathBuf>,
}

impl Search {
    /// `dirs`, and no ROS workspace.
    pub fn new(dirs: Vec<PathBuf>) -> Search {
        Search {
            dirs,
            ament_prefixes: Vec::new(),
        }
    }

    /// `dirs`, and the prefixes of the `AMENT_PREFIX_PATH` environment variable.
    pub fn from_env(dirs: Vec<PathBuf>) -> Search {
        let ament = std::env::var_os("AMENT_PREFIX_PATH")
            .map(|v| std::env::split_paths(&v).collect::<Vec<_>>())
            .unwrap_or_default();
        Search {
            dirs,
            ament_prefixes: ament
                .into_iter()
                .filter(|p| !p.as_os_str().is_empty())
                .collect(),
        }
    }
}

/// A package folder found, and whether it comes from the sourced workspace.
struct Found {
    name: String,
    path: PathBuf,
    workspace: bool,
}

impl Interfaces {
    /// [`Interfaces::discover_with`] with `extra` as the `--interfaces` folders and no ROS
    /// workspace.
    pub fn discover(
        sm: &mut SourceMap,
        main_file: &Path,
        extra: &[PathBuf],
    ) -> Result<Interfaces, Vec<Diagnostic>> {
        Self::discover_with(sm, main_file, &Search::new(extra.to_vec()))
    }

    /// The built-ins plus every interface package found for the model `main_file`, in the
    /// order of this module's documentation. Every file read is added to `sm` and parsed,
    /// and every type a field names is checked ([`Interfaces::check`]). The places
    /// searched are kept: an error about a missing package names them all.
    pub fn discover_with(
        sm: &mut SourceMap,
        main_file: &Path,
        search: &Search,
    ) -> Result<Interfaces, Vec<Diagnostic>> {
        let mut me = Interfaces::with_builtins();
        let mut found: Vec<Found> = Vec::new();
        let mut errs = Vec::new();
        let add = |dir: &Path, depth: usize, workspace: bool, found: &mut Vec<Found>| {
            let mut v = Vec::new();
            find_packages(dir, depth, &mut v);
            found.extend(v.into_iter().map(|(name, path)| Found {
                name,
                path,
                workspace,
            }));
        };
        for path in &search.dirs {
            if !path.is_dir() {
                errs.push(crate::model::about_file(
                    path,
                    "--interfaces: the interface folder does not exist or is not a folder",
                ));
                continue;
            }
            me.searched.push(format!("--interfaces {}", path.display()));
            add(path, PACKAGE_DEPTH, false, &mut found);
        }
        let dir = match main_file.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        me.searched.push(format!(
            "packages in {} (the main file's folder)",
            dir.display()
        ));
        for child in sorted_dirs(dir) {
            if is_package(&child) {
                found.push(Found {
                    name: dir_name(&child),
                    path: child,
                    workspace: false,
                });
            }
        }
        // Folders above the main file, written relative to it (`dir/..`) when `dir` runs
        // out of components, so relative paths keep working above the current folder.
        let folders = INTERFACE_FOLDERS
            .iter()
            .map(|f| format!("{f}/"))
            .collect::<Vec<_>>()
            .join(", ");
        let mut anc = dir.to_path_buf();
        let mut last: Option<PathBuf> = None;
        for _ in 0..MAX_LEVELS_UP {
            let canon = anc.canonicalize().ok();
            if canon.is_some() && canon == last {
                break; // above the file system's root
            }
            for child in sorted_dirs(&anc) {
                if INTERFACE_FOLDERS.contains(&dir_name(&child).as_str()) {
                    add(&child, PACKAGE_DEPTH, false, &mut found);
                }
            }
            let repo_root = anc.join(".git").exists();
            me.searched.push(format!(
                "{folders} in {}{}",
                anc.display(),
                if repo_root {
                    " (the repository's root)"
                } else {
                    ""
                }
            ));
            if repo_root {
                break;
            }
            last = canon;
            anc = up(&anc);
        }
        for prefix in &search.ament_prefixes {
            let share = prefix.join("share");
            me.searched.push(format!(
                "AMENT_PREFIX_PATH: {}/<pkg>/msg|srv|action",
                share.display()
            ));
            for child in sorted_dirs(&share) {
                if is_package(&child) {
                    found.push(Found {
                        name: dir_name(&child),
                        path: child,
                        workspace: true,
                    });
                }
            }
        }
        if search.ament_prefixes.is_empty() {
            me.searched
                .push("AMENT_PREFIX_PATH: no sourced ROS workspace".to_string());
        }
        let mut seen = BTreeSet::new();
        let mut workspace_pkgs = BTreeSet::new();
        for f in found {
            if !seen.insert(f.name.clone()) {
                continue;
            }
            if f.workspace {
                // Read apart, merged only when the whole package reads.
                let mut alone = Interfaces::new();
                match alone.add_package_dir(sm, &f.path, &f.name) {
                    Ok(_) => {
                        me.defs.append(&mut alone.defs);
                        workspace_pkgs.insert(f.name.clone());
                    }
                    Err(e) => {
                        me.broken.insert(f.name.clone(), e);
                    }
                }
            } else if let Err(e) = me.add_package_dir(sm, &f.path, &f.name) {
                errs.extend(e);
            }
            me.origins.insert(f.name, f.path);
        }
        // A workspace package naming a type nothing defines is broken, not an error.
        for pkg in &workspace_pkgs {
            let e = me.check_packages(sm, |p| p == pkg);
            if !e.is_empty() {
                // Back to the built-in package of that name, if there is one.
                me.defs.retain(|(p, _, _), _| p != pkg);
                for def in super::builtin::definitions() {
                    if &def.package == pkg {
                        me.insert(def);
                    }
                }
                me.broken.insert(pkg.clone(), e);
            }
        }
        errs.extend(me.check_packages(sm, |p| !me.broken.contains_key(p)));
        if errs.is_empty() {
            Ok(me)
        } else {
            Err(errs)
        }
    }

    /// Reads every `msg/*.msg`, `srv/*.srv` and `action/*.action` of the package folder
    /// `dir` as package `package`; returns how many interfaces were added.
    pub(crate) fn add_package_dir(
        &mut self,
        sm: &mut SourceMap,
        dir: &Path,
        package: &str,
    ) -> Result<usize, Vec<Diagnostic>> {
        let mut errs = Vec::new();
        let mut added = 0;
        for kind in [
            InterfaceKind::Message,
            InterfaceKind::Service,
            InterfaceKind::Action,
        ] {
            let sub = dir.join(kind.dir());
            let Ok(rd) = std::fs::read_dir(&sub) else {
                continue;
            };
            let mut files: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().and_then(|e| e.to_str()) == Some(kind.dir()))
                .collect();
            files.sort();
            for path in files {
                let Some(name) = path
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .map(str::to_string)
                else {
                    continue;
                };
                let text = match codegen::diag::read_source(&path) {
                    Ok(t) => t,
                    Err(d) => {
                        errs.push(d);
                        continue;
                    }
                };
                match self.add_text(sm, &path, text, package, kind, &name) {
                    Ok(()) => added += 1,
                    Err(e) => errs.extend(e),
                }
            }
        }
        if errs.is_empty() {
            Ok(added)
        } else {
            Err(errs)
        }
    }
}

fn sorted_dirs(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    v.sort();
    v
}

/// The folder above `p`: its lexical parent while it has one, `p/..` after that.
fn up(p: &Path) -> PathBuf {
    match p.components().next_back() {
        Some(Component::Normal(_)) => match p.parent() {
            Some(q) if q.as_os_str().is_empty() => PathBuf::from("."),
            Some(q) => q.to_path_buf(),
            None => p.join(".."),
        },
        _ => p.join(".."),
    }
}

fn dir_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn is_package(dir: &Path) -> bool {
    ["msg", "srv", "action"]
        .iter()
        .any(|k| dir.join(k).is_dir())
}

fn find_packages(dir: &Path, depth: usize, out: &mut Vec<(String, PathBuf)>) {
    if is_package(dir) {
        out.push((dir_name(dir), dir.to_path_buf()));
        return;
    }
    if depth == 0 {
        return;
    }
    for child in sorted_dirs(dir) {
        find_packages(&child, depth - 1, out);
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_above() {
        assert_eq!(up(Path::new("a/b")), Path::new("a"));
        assert_eq!(up(Path::new("a")), Path::new("."));
        assert_eq!(up(Path::new(".")), Path::new("./.."));
        assert_eq!(up(Path::new("./..")), Path::new("./../.."));
        assert_eq!(up(Path::new("/")), Path::new("/.."));
    }
}
