//! The compiled specification: an owned [`monitor_core::Program`] plus what emitters and hosts need to know.

use std::collections::BTreeSet;
use std::sync::Mutex;

use monitor_core::table::TABLE_VERSION;
use monitor_core::{
    Atom, Instr, Monitor, Node, NodeId, Program, Property, StepError, TableError, Var,
};

use crate::ast::{self, CheckedSpec, VarDecl};
use crate::diag::Diagnostics;
use crate::lower::Net;

/// Names and strings handed out as `&'static str`, each distinct text leaked once.
///
/// [`Program`] borrows its names (`&'a str`), so an owned [`Compiled`] that
/// returns a `Program<'_>` needs them to outlive it; interning bounds the
/// memory to the distinct texts ever compiled in the process.
fn intern(s: &str) -> &'static str {
    static POOL: Mutex<BTreeSet<&'static str>> = Mutex::new(BTreeSet::new());
    let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&k) = pool.get(s) {
        return k;
    }
    let k: &'static str = Box::leak(s.to_string().into_boxed_str());
    pool.insert(k);
    k
}

/// One compiled property.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PropertyInfo {
    /// The property's name.
    pub name: String,
    /// First node of its network in [`Program::nodes`].
    pub first: NodeId,
    /// Its root node (the last of its network).
    pub root: NodeId,
    /// Bytes of state owned by its nodes (the shared header, atom bits and
    /// value bits are counted only in [`Compiled::state_bytes`]).
    pub state_bytes: usize,
}

/// A compiled specification: everything owned, ready to run, serialise or emit.
///
/// Invariant: [`Compiled::program`] passes [`Monitor::try_new`] (checked when
/// it is built), and [`Compiled::to_table_bytes`] loads with
/// `monitor_core::table::Table::from_bytes`.
///
/// The names and string constants that `program()` lends out are interned
/// for the life of the process (each distinct text once), since a
/// [`Program`] borrows them as `&str`.
#[derive(Clone, Debug)]
pub struct Compiled {
    checked: CheckedSpec,
    core_vars: Vec<Var<'static>>,
    strings: Vec<&'static str>,
    instrs: Vec<Instr>,
    atoms: Vec<Atom>,
    atom_exprs: Vec<ast::Expr>,
    nodes: Vec<Node>,
    node_words: Vec<u64>,
    core_props: Vec<Property<'static>>,
    props: Vec<PropertyInfo>,
    state_bytes: usize,
    warnings: Diagnostics,
}

/// Why [`Compiled::build`] refused a laid-out network: a compiler bug, never bad input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum BuildError {
    /// The monitor refused the program.
    Refused(TableError),
    /// The compiler and the monitor disagree on the state size (bytes).
    StateSize { compiler: usize, monitor: usize },
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BuildError::Refused(e) => write!(f, "{e}"),
            BuildError::StateSize { compiler, monitor } => write!(
                f,
                "state size mismatch: compiler {compiler} bytes, monitor {monitor} bytes"
            ),
        }
    }
}

impl Compiled {
    /// Packages a laid-out network; `Err` carries the monitor's complaint (a compiler bug).
    pub(crate) fn build(
        checked: CheckedSpec,
        net: Net,
        warnings: Diagnostics,
    ) -> Result<Compiled, BuildError> {
        let strings: Vec<&'static str> = checked.strings.iter().map(|s| intern(s)).collect();
        let core_vars = checked
            .vars
            .iter()
            .map(|v| Var {
                name: intern(&v.name),
                ty: v.ty,
                kind: v.kind,
                init: v.init,
            })
            .collect();
        let core_props = net
            .props
            .iter()
            .map(|p| Property {
                name: intern(&p.name),
                first: p.first,
                root: p.root,
            })
            .collect();
        let props = net
            .props
            .iter()
            .map(|p| PropertyInfo {
                name: p.name.clone(),
                first: p.first,
                root: p.root,
                state_bytes: (p.words * 8) as usize,
            })
            .collect();
        let c = Compiled {
            checked,
            core_vars,
            strings,
            instrs: net.instrs,
            atoms: net.atoms,
            atom_exprs: net.atom_exprs,
            nodes: net.nodes,
            node_words: net.node_words,
            core_props,
            props,
            state_bytes: (net.state_words * 8) as usize,
            warnings,
        };
        let m = Monitor::try_new(c.program()).map_err(BuildError::Refused)?;
        if m.state_bytes() != c.state_bytes {
            return Err(BuildError::StateSize {
                compiler: c.state_bytes,
                monitor: m.state_bytes(),
            });
        }
        Ok(c)
    }

    /// The program, borrowed: run it with [`Monitor::try_new`].
    pub fn program(&self) -> Program<'_> {
        Program {
            tick_ns: self.checked.tick_ns,
            vars: &self.core_vars,
            strings: &self.strings,
            instrs: &self.instrs,
            atoms: &self.atoms,
            nodes: &self.nodes,
            props: &self.core_props,
        }
    }

    /// The postcard table: `(TABLE_VERSION, program)`, for `monitor_core::table::Table::from_bytes`.
    pub fn to_table_bytes(&self) -> Vec<u8> {
        // Serialising plain data into a Vec cannot fail; an empty table would fail to load.
        postcard::to_allocvec(&(TABLE_VERSION, self.program())).unwrap_or_default()
    }

    /// Length of one tick (the spec's time unit) in nanoseconds.
    pub fn tick_ns(&self) -> u64 {
        self.checked.tick_ns
    }

    /// Total monitor state in bytes: [`Monitor::state_bytes`] of this program.
    pub fn state_bytes(&self) -> usize {
        self.state_bytes
    }

    /// The properties, in declaration order (verdict `k` is property `k`).
    pub fn properties(&self) -> &[PropertyInfo] {
        &self.props
    }

    /// The property names, in declaration order.
    pub fn property_names(&self) -> impl Iterator<Item = &str> {
        self.props.iter().map(|p| p.name.as_str())
    }

    /// The declared variables: name, [`monitor_core::Ty`], kind, initial value and type as written.
    pub fn vars(&self) -> &[VarDecl] {
        &self.checked.vars
    }

    /// The index of variable `name` (the position of its value in `try_step`'s slice).
    pub fn var_index(&self, name: &str) -> Option<usize> {
        self.checked.vars.iter().position(|v| v.name == name)
    }

    /// The interned string constants; `Value::Str(i)` is `strings()[i]`.
    pub fn strings(&self) -> &[String] {
        &self.checked.strings
    }

    /// The id of string constant `s`, for building `Value::Str` inputs.
    /// A string that no atom or initial value mentions equals no constant:
    /// pass any id at or past `strings().len()`.
    pub fn string_id(&self, s: &str) -> Option<u32> {
        self.checked
            .strings
            .iter()
            .position(|x| x == s)
            .map(|i| i as u32)
    }

    /// The checked AST this program was compiled from.
    pub fn checked(&self) -> &CheckedSpec {
        &self.checked
    }

    /// The expression of each atom, in atom order (after deduplication).
    pub(crate) fn atom_exprs(&self) -> &[ast::Expr] {
        &self.atom_exprs
    }

    /// The number of state words each node owns, in node order.
    pub fn node_words(&self) -> &[u64] {
        &self.node_words
    }

    /// Warnings found while compiling (empty when there were none).
    pub fn warnings(&self) -> &Diagnostics {
        &self.warnings
    }

    /// A step error as its reader needs it: an atom by its text and a variable by
    /// its name and type, where [`StepError`]'s own text gives their indices.
    pub fn describe(&self, e: &StepError) -> String {
        match *e {
            StepError::Arithmetic { atom } => match self.atom_exprs.get(atom as usize) {
                Some(x) => format!(
                    "atom `{{{}}}`: integer overflow or division by zero",
                    crate::print::expr(x, &self.checked)
                ),
                None => e.to_string(),
            },
            StepError::VarType { var } => match self.vars().get(var as usize) {
                Some(d) => format!(
                    "variable `{}`: a value that is not of its type `{}`",
                    d.name, d.type_name
                ),
                None => e.to_string(),
            },
            _ => e.to_string(),
        }
    }
}
