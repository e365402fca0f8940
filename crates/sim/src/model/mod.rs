//! Reading plain SCXML models as SCAN takes them: a folder of `.scxml` files or a `model.xml` list.
//!
//! # Pipeline
//!
//! 1. [`load`] reads a folder (every `.scxml` below it, sorted by path, plus
//!    `types.xml` and `properties.xml` when present) or a SCAN main file
//!    (`<specification><model><processList><process id moc="fsm" path/>...`,
//!    `<types path/>`, `<properties path/>`).
//! 2. Each file is parsed into an element tree (with byte spans) and then
//!    into an [`ast::Machine`]; `<!-- TYPE name:type -->` comments type the
//!    next `<data>` or `<param>` of that name.
//! 3. The result is a [`ModelSource`]: machines, named types, the properties
//!    file's path (read by the property layer) and a [`SourceMap`] that turns
//!    any span into file, line and column.
//!
//! Expressions are kept as text here; [`crate::sim::CompiledModel::compile`]
//! parses, type-checks and compiles them. All errors are [`Diagnostics`].

pub mod ast;
pub mod json;
mod scxml;
pub mod source;
pub mod types;
pub mod xml;

pub use ast::Machine;
pub use source::{about_file, Diagnostic, Diagnostics, FileId, SourceMap, Span};
pub use types::{BaseType, TypeDef, TypeDefs, TypeExpr};

use std::path::{Component, Path, PathBuf};

/// A model as read from disk, before compilation.
#[derive(Clone, Debug, Default)]
pub struct ModelSource {
    /// Text of every file read, for diagnostics.
    pub sources: SourceMap,
    /// The state machines, in the order they were listed (folder: sorted by path).
    pub machines: Vec<Machine>,
    /// Named types from `types.xml`.
    pub types: TypeDefs,
    /// The properties file named by `model.xml`, or `properties.xml` in a model folder.
    pub properties: Option<PathBuf>,
    /// The length of one model time unit in nanoseconds, when known (`--time-unit`, a
    /// robot model's timers): it converts the durations of `<send delay="1.5s">` and
    /// `delayexpr="e + 'ms'"` into units. Without it, such a delay is an error.
    pub time_unit_ns: Option<u64>,
}

impl ModelSource {
    /// A model built from in-memory SCXML texts `(file name, text)`; for tests and tools.
    pub fn from_texts<'a>(
        files: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Result<ModelSource, Diagnostics> {
        let mut m = ModelSource::default();
        let mut errs = Diagnostics::default();
        for (name, text) in files {
            let id = m.sources.add(name, text.to_string());
            m.add_machine(id, &mut errs);
        }
        m.check_names(&mut errs);
        errs.into_result(m)
    }

    fn add_machine(&mut self, id: FileId, errs: &mut Diagnostics) {
        match scxml::read_machine(&self.sources, id) {
            Ok(machine) => self.machines.push(machine),
            Err(ds) => errs.0.extend(ds),
        }
    }

    /// Adds a machine given as an element tree (a lowered robot model); errors go to `errs`.
    pub fn add_machine_tree(&mut self, root: &xml::Element, file: FileId, errs: &mut Diagnostics) {
        match scxml::read_machine_tree(&self.sources, root, file) {
            Ok(machine) => self.machines.push(machine),
            Err(ds) => errs.0.extend(ds),
        }
    }

    /// Errors for machine names used twice.
    pub fn check_names(&self, errs: &mut Diagnostics) {
        for (i, m) in self.machines.iter().enumerate() {
            if let Some(first) = self.machines[..i]
                .iter()
                .find(|o| o.name.name == m.name.name)
            {
                let at = self.sources.diag(first.name.span, "");
                errs.push(self.sources.diag(
                    m.name.span,
                    format!(
                        "machine name `{}` is used twice (also at {}:{}:{})",
                        m.name.name, at.file, at.line, at.col
                    ),
                ));
            }
        }
    }

    fn read_types(&mut self, path: &Path, errs: &mut Diagnostics) {
        match codegen::diag::read_source(path) {
            Ok(text) => {
                let id = self.sources.add(path, text);
                if let Err(ds) = self.types.read(&self.sources, id) {
                    errs.0.extend(ds);
                }
            }
            Err(d) => errs.push(d),
        }
    }
}

/// Reads a model: a folder of `.scxml` files, or a SCAN main file (`model.xml`).
pub fn load(path: &Path) -> Result<ModelSource, Diagnostics> {
    if path.is_dir() {
        load_dir(path)
    } else if path.extension().is_some_and(|e| e == "scxml") {
        let mut m = ModelSource::default();
        let mut errs = Diagnostics::default();
        read_scxml_file(&mut m, path, &mut errs);
        m.check_names(&mut errs);
        errs.into_result(m)
    } else {
        load_spec(path)
    }
}

fn read_scxml_file(m: &mut ModelSource, path: &Path, errs: &mut Diagnostics) {
    match codegen::diag::read_source(path) {
        Ok(text) => {
            let id = m.sources.add(path, text);
            m.add_machine(id, errs);
        }
        Err(d) => errs.push(d),
    }
}

fn collect_scxml(dir: &Path, out: &mut Vec<PathBuf>, errs: &mut Diagnostics, depth: usize) {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) => {
            errs.push(crate::model::about_file(
                dir,
                format!("cannot read folder: {e}"),
            ));
            return;
        }
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            if depth < 16 {
                collect_scxml(&p, out, errs, depth + 1);
            }
        } else if p.extension().is_some_and(|e| e == "scxml") {
            out.push(p);
        }
    }
}

/// Reads every `.scxml` file under `dir` (sorted by path), `types.xml` and `properties.xml`.
pub(crate) fn load_dir(dir: &Path) -> Result<ModelSource, Diagnostics> {
    let mut m = ModelSource::default();
    let mut errs = Diagnostics::default();
    let mut files = Vec::new();
    collect_scxml(dir, &mut files, &mut errs, 0);
    if files.is_empty() && errs.is_empty() {
        errs.push(crate::model::about_file(
            dir,
            "no .scxml file in this folder",
        ));
    }
    let types = dir.join("types.xml");
    if types.is_file() {
        m.read_types(&types, &mut errs);
    }
    for f in &files {
        read_scxml_file(&mut m, f, &mut errs);
    }
    let props = dir.join("properties.xml");
    if props.is_file() {
        m.properties = Some(props);
    }
    m.check_names(&mut errs);
    errs.into_result(m)
}

/// Reads a SCAN main file: `<specification>` with a process list, types and properties.
pub(crate) fn load_spec(path: &Path) -> Result<ModelSource, Diagnostics> {
    let mut m = ModelSource::default();
    let mut errs = Diagnostics::default();
    let text = codegen::diag::read_source(path)?;
    let spec_id = m.sources.add(path, text);
    let root = xml::parse(&m.sources, spec_id)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let sm = m.sources.clone();
    if root.name != "specification" {
        // Another file of a model given as the model: say which and what to give.
        let what = match root.name.as_str() {
            "root" => {
                ": this is a BehaviorTree.CPP tree; give the robot model's main file \
                       (main.xml), which names it"
            }
            "properties" => ": this is a property file; give the model first, then it",
            _ => {
                " (a SCAN model.xml; or give a folder of .scxml files, one .scxml file, \
                  or a robot model's main.xml)"
            }
        };
        return Err(sm
            .diag(
                root.span,
                format!("expected <specification>, found <{}>{what}", root.name),
            )
            .into());
    }
    let mut es = Vec::new();
    root.check_attrs(&sm, &[], &mut es);
    let mut processes: Vec<(String, PathBuf, Span)> = Vec::new();
    for el in root.elements() {
        match el.name.as_str() {
            "model" => {
                el.check_attrs(&sm, &[], &mut es);
                for pl in el.elements() {
                    if pl.name != "processList" {
                        es.push(sm.diag(pl.span, format!("unexpected <{}> in <model>", pl.name)));
                        continue;
                    }
                    for p in pl.elements() {
                        if p.name != "process" {
                            es.push(
                                sm.diag(
                                    p.span,
                                    format!("unexpected <{}> in <processList>", p.name),
                                ),
                            );
                            continue;
                        }
                        p.check_attrs(&sm, &["id", "moc", "path"], &mut es);
                        if let Some(moc) = p.attr("moc") {
                            if moc.value != "fsm" {
                                es.push(sm.diag(
                                    moc.value_span,
                                    format!("unsupported model of computation `{}`", moc.value),
                                ));
                            }
                        }
                        match (p.required(&sm, "id"), p.required(&sm, "path")) {
                            (Ok(id), Ok(pa)) => processes.push((
                                id.value.clone(),
                                join_clean(base, &pa.value),
                                pa.value_span,
                            )),
                            (Err(d), _) | (_, Err(d)) => es.push(d),
                        }
                    }
                }
            }
            "types" | "properties" => {
                el.check_attrs(&sm, &["path"], &mut es);
                match el.required(&sm, "path") {
                    Ok(a) => {
                        let p = join_clean(base, &a.value);
                        if !p.is_file() {
                            es.push(
                                sm.diag(a.value_span, format!("no such file `{}`", p.display())),
                            );
                        } else if el.name == "types" {
                            m.read_types(&p, &mut errs);
                        } else {
                            m.properties = Some(p);
                        }
                    }
                    Err(d) => es.push(d),
                }
            }
            other => es.push(sm.diag(el.span, format!("unexpected <{other}> in <specification>"))),
        }
    }
    errs.0.extend(es);
    for (id, p, span) in &processes {
        if !p.is_file() {
            errs.push(sm.diag(*span, format!("no such file `{}`", p.display())));
            continue;
        }
        let before = m.machines.len();
        read_scxml_file(&mut m, p, &mut errs);
        if let Some(machine) = m.machines.get(before) {
            if machine.name.name != *id {
                errs.push(sm.diag(
                    *span,
                    format!(
                        "process `{id}` names a machine called `{}`; they must match",
                        machine.name.name
                    ),
                ));
            }
        }
    }
    if processes.is_empty() && errs.is_empty() {
        errs.push(sm.diag(root.span, "the specification lists no process"));
    }
    m.check_names(&mut errs);
    errs.into_result(m)
}

/// `base` joined with a path `rel` that a model file names, without `rel`'s `.`
/// components: `./policy.xml` is read, and named in messages, as `policy.xml` of the
/// model's folder (a main file's inputs, a SCAN `model.xml`'s processes and files).
pub fn join_clean(base: &Path, rel: &str) -> PathBuf {
    let mut path = base.to_path_buf();
    for c in Path::new(rel).components() {
        if c != Component::CurDir {
            path.push(c);
        }
    }
    path
}

#[cfg(test)]
mod join_tests {
    use super::*;

    #[test]
    fn model_paths_are_named_without_dot_components() {
        let base = Path::new("m");
        assert_eq!(join_clean(base, "./policy.xml"), Path::new("m/policy.xml"));
        assert_eq!(join_clean(base, "./a/./b.scxml"), Path::new("m/a/b.scxml"));
        // `..` is kept (the folder may be a link), and an absolute path wins, as in `join`.
        assert_eq!(join_clean(base, "../x.xml"), Path::new("m/../x.xml"));
        assert_eq!(join_clean(base, "/abs/x.xml"), Path::new("/abs/x.xml"));
    }
}
