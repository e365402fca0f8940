//! Seeded random behavior trees and leaf scripts for the differential test: every node
//! kind the oracle knows, mixed at random depth and width, in `BTCPP_format` 3 and 4;
//! SubTrees remapped, shared or keeping an entry private; blackboard writes (constants
//! and copies) and reads of int, double, string and bool entries; leaves with and
//! without `<bt_halt>`; counts of -1. With [`Options::btcpp4_nodes`], also BT.CPP 4's
//! nodes that AS2FM has no model of; with [`Options::scripts`], BT.CPP 4's script
//! language (`Script`, `ScriptCondition`, `Precondition`) and pre/post conditions on
//! nodes, over the integer entries `x`, `y` and the boolean `f` (conditions also read the
//! texts SetBlackboard wrote to `k0`, `k1`, `p0`); with [`Options::time_nodes`]
//! and [`Options::try_catch`], Timeout, Delay, Sleep and TryCatch; with
//! [`Options::bb_nodes`], BT.CPP 4's blackboard nodes (UnsetBlackboard, the entry-updated
//! nodes, the Loop nodes).

use super::oracle::Scripts;
use super::tree::Status;
use rand_core::Rng;

/// A generated case: the tree XML, the scripts of its leaf types, how many root ticks.
#[derive(Clone, Debug)]
pub struct Case {
    /// The tree document.
    pub xml: String,
    /// The leaf types' scripts.
    pub scripts: Scripts,
    /// Root ticks to run.
    pub ticks: usize,
}

struct G<'r, R: Rng> {
    rng: &'r mut R,
    scripts: Scripts,
    /// Nodes left to place.
    budget: i64,
    /// SubTree definitions written so far (a tree only uses earlier ones).
    subtrees: Vec<String>,
    /// `BTCPP_format="3"`: v3 names and SubTree mapping.
    v3: bool,
    /// What else to generate.
    opts: Options,
    /// With scripts: which pre/post-condition attributes.
    conds: Conditions,
    /// Writing a SubTree's body (no UnsetBlackboard there).
    in_subtree: bool,
    /// The main tree has a leaf whose input port names `w` so far
    /// ([`Options::port_doubles`]): `w = ...` does not throw (the port created `w`).
    has_in: bool,
}

/// Which pre/post-condition attributes [`Options::scripts`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Conditions {
    /// None.
    Off,
    /// All but `_skipIf` and `_while` (no SKIPPED).
    WithoutSkip,
    /// All of them.
    All,
}

/// What the generator writes besides the nodes both AS2FM and BT.CPP have.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// BT.CPP 4's nodes AS2FM has no model of (AsyncSequence, AsyncFallback,
    /// ParallelAll, WhileDoElse, KeepRunningUntilFailure, RunOnce, Switch2-6), in
    /// format-4 trees: for the real-library test and the BT.CPP lowering's test
    /// (AS2FM's lowering refuses them).
    /// Off, the generator draws exactly what it drew before they existed.
    pub btcpp4_nodes: bool,
    /// Scripts (format-4 trees only): `Script` and `ScriptCondition` leaves,
    /// `Precondition`, and the `_failureIf` ... `_post` attributes (`_skipIf` and `_while`
    /// among them, so SKIPPED reaches every kind of parent) on any node but a SubTree (see
    /// [`Options::subtree_conds`]);
    /// children of sequences, fallbacks and parallels after the first get a second
    /// chance of `_skipIf` / `_while`. Scripts keep the integers
    /// small (no product of two entries), so nothing overflows. Off, the generator draws
    /// what it drew before.
    pub scripts: bool,
    /// BT.CPP 4's timed nodes (format-4 trees only): Timeout, Delay and Sleep, with
    /// durations that are multiples of half the oracle's default period (0 to 350 ms at
    /// 100 ms), so that timers fall between ticks and on them. Off, the generator draws
    /// what it drew before.
    pub time_nodes: bool,
    /// TryCatch (BT.CPP 4.10 only, not in the 4.8.2 library), with and without
    /// `catch_on_halt` (format-4 trees only). Off, the generator draws what it drew
    /// before.
    pub try_catch: bool,
    /// BT.CPP 4's blackboard nodes, with [`Options::scripts`] only (over the script
    /// entries `x`, `y`, `f`): UnsetBlackboard (in the main tree only), WasEntryUpdated,
    /// WaitValueUpdate, SkipUnlessUpdated (with [`Conditions::All`] only: it answers
    /// SKIPPED), and LoopInt, LoopBool, LoopDouble, LoopString over queues written in
    /// the tree (`if_empty="SKIPPED"` with [`Conditions::All`] only). Off, the generator
    /// draws what it drew before.
    pub bb_nodes: bool,
    /// UnsetBlackboard alone (of [`Options::bb_nodes`]), with [`Options::scripts`], in
    /// the main tree, over the script entries: what the lowering takes of the blackboard
    /// nodes. Off, the generator draws what it drew before.
    pub unset: bool,
    /// SKIPPED from the nodes that make it besides `_skipIf` / `_while`
    /// ([`Conditions::All`]): RunOnce with `then_skip` true (written, or left to its
    /// default) half the time, and Precondition with `else="SKIPPED"` among its `else`
    /// statuses. Off, the generator draws what it drew before.
    pub skipped: bool,
    /// Doubles in the scripts, with [`Options::scripts`]: the main tree creates `x` or
    /// `f` from a double now and then (`x:=0+0`, `f:=1>0`: BT.CPP keeps the type an entry
    /// was created with), and conditions use `/`, real literals, and arithmetic values
    /// cast to bool (a double is true unless 0 and throws when negative; an integer
    /// must be 0 or 1). Nothing stores a number that is not whole. Off, the generator
    /// draws what it drew before.
    pub reals: bool,
    /// A root that answers SKIPPED (format-4 trees, with [`Options::skipped`]): one tree
    /// in three has a RunOnce (its `then_skip` left to its default, true) over the main
    /// tree's Sequence, which answers SKIPPED at every tick after the Sequence first
    /// finished (4.10 `RunOnceNode::tick`), so the executor neither ticks again nor
    /// resets it (`Tree::tickRoot`). Drawn after everything else: the trees are those
    /// of the same seed without it, the root aside.
    pub root_skip: bool,
    /// With [`Options::scripts`]: the bit operators (`~ & | ^`), a double entry `r`
    /// (created by the main tree as `0.5`, `0+0` or `2.5`, remapped into every SubTree)
    /// that statements store numbers that are not whole in (`r := x / 2`, `r /= y`,
    /// `r := -r`), divisors that are entries or expressions (zero now and then, with
    /// either sign), and Script nodes that store a double into an integer entry (which
    /// throws unless it is whole). Off, the generator draws what it drew before.
    pub bits: bool,
    /// Strings in the scripts, with [`Options::scripts`]: the main tree creates `t` from
    /// a string (`t:='a'`, remapped into every SubTree); statements assign it literals,
    /// `k0`/`k1` (the texts a SetBlackboard wrote, some now written `01`, `00`, `10`) and
    /// `?:` over two literals; conditions compare strings with strings (byte order:
    /// `'B' < 'a'`, `'10' < '9'`, `'01' != '1'`) and, risky, with numbers (a text read as
    /// a number: `' 1'` and `'01'` are 1, `'a'` and `''` throw). Off, the generator
    /// draws what it drew before.
    pub strings: bool,
    /// Pre/post conditions on `<SubTree>` nodes too, with [`Options::scripts`] (format-4
    /// trees): three SubTree references in four get one (the node's conditions run in
    /// the caller's blackboard, where `x`, `y`, `f` are the caller's). Off, the generator
    /// draws what it drew before.
    pub subtree_conds: bool,
    /// With [`Options::bb_nodes`] and [`Options::strings`]: LoopString nodes (drawn
    /// more often) write their items, texts of [`LOOP_TEXTS`], into `t`, the string
    /// entry the scripts compare, now and then (BT.CPP 4 creates it as a `std::string`
    /// when it loads the tree, the Loop's `value` port typing it). Off, the generator
    /// draws what it drew before.
    pub loop_strings: bool,
    /// With [`Options::bb_nodes`] and [`Options::bits`]: LoopDouble nodes (drawn more
    /// often) write their items into `r`, the double entry the scripts store numbers in,
    /// two times in three, else into `ld`, which risky conditions compare (BT.CPP 4
    /// throws reading it before the first write: the Loop's port created it empty when
    /// the tree was loaded). Off, the generator draws what it drew before.
    pub loop_doubles: bool,
    /// With [`Options::bits`]: leaves with an output port `out` of type `float64`
    /// (types `O0`, `O1`, ...: `model::has_out`) writing `model::OUT_VALUES` into `v`,
    /// one leaf in eight, leaves with an input port `in` of type `float64` (`I0`, ...:
    /// `model::has_in`) naming `w`, one in eight, which statements write doubles into
    /// (`=` too: the port created the entry when the tree was loaded), and risky
    /// conditions comparing `v` and `w` (BT.CPP throws reading either before its first
    /// write: the port created it empty).
    /// The real library's harness has no leaves with ports: these trees go to the oracle
    /// and the lowering only. Off, the generator draws what it drew before.
    pub port_doubles: bool,
    /// With [`Options::strings`]: leaves with an input port `in` of type `string` naming
    /// `t` (types `T0`, `T1`, ...: `model::has_in_text`), one leaf in six, which answer
    /// SUCCESS while `t` holds `model::IN_TEXT` (`'a'`, the text the main tree starts `t`
    /// with) and their script otherwise, so what the scripts store in `t` reaches a
    /// plugin. Not under a count of -1 (the leaf must be able to stop it). No leaf of the
    /// real library's harness has ports: oracle and lowering only. Off, the generator
    /// draws what it drew before.
    pub port_strings: bool,
    /// Joins, with [`Options::strings`]: the main tree also creates `u` from a string
    /// (`u:=''`, remapped into every SubTree); statements store in `u` joins of `t`,
    /// literals and number literals (`t .. 'a'`, `t .. 3`, `t .. 1.5`, `t + 'b'`,
    /// `(f ? 'a' : 'b') .. t`, `u := t; u += '1'`), whose texts are bounded; conditions
    /// compare `u` and joins with strings, and, risky, join `k0`/`k1` (BT.CPP throws
    /// where they hold no value). Off, the generator draws what it drew before.
    pub joins: bool,
}

/// The items [`Options::loop_strings`] writes in LoopString queues: texts of
/// [`TEXTS`] that need no escaping in a queue (no empty part, no space).
const LOOP_TEXTS: [&str; 9] = ["b", "a", "ab", "B", "9", "10", "1", "01", "0"];

/// The texts [`Options::strings`] writes: letters (read as numbers they throw) and
/// whole numbers with spaces or leading zeros, in an order other than byte order.
const TEXTS: [&str; 11] = ["b", "a", "", "ab", "B", "9", "10", "1", "01", " 1", "0"];

/// The script entries: `x`, `y` integers, `f` a boolean, all written first by the main
/// tree and remapped into every SubTree.
const SCRIPT_INIT: &str = "x:=0; y:=1; f:=true";

/// The int entries. `p0` is never remapped: inside a SubTree it is the instance's own
/// (unless the whole blackboard is shared), which each SubTree body writes first.
const INTS: [&str; 3] = ["k0", "k1", "p0"];

impl<R: Rng> G<'_, R> {
    fn below(&mut self, n: u64) -> u64 {
        self.rng.next_u64() % n
    }

    fn status(&mut self) -> Status {
        match self.below(10) {
            0..=3 => Status::Success,
            4..=6 => Status::Failure,
            _ => Status::Running,
        }
    }

    /// A fresh leaf type; `N...` types have no `<bt_halt>` (see `model::plugin`). With
    /// `stop`, its script ends with it or RUNNING, so a count of -1 above it ends.
    fn leaf_with(&mut self, stop: Option<Status>) -> String {
        // 0: a leaf writing `v` (`out`), 1: one reading `w` (`in`).
        let port = if self.port_doubles_on() {
            self.below(8)
        } else {
            8
        };
        // A leaf reading `t` (`in`, a string).
        let text_in = port >= 2 && stop.is_none() && self.port_strings_on() && self.below(6) == 0;
        let tag = if port < 2 {
            ["O", "I"][port as usize]
        } else if text_in {
            "T"
        } else if self.below(4) == 0 {
            "N"
        } else {
            "L"
        };
        let name = format!("{tag}{}", self.scripts.len());
        let len = 1 + self.below(4) as usize;
        let mut script: Vec<Status> = (0..len).map(|_| self.status()).collect();
        if let Some(st) = stop {
            script[len - 1] = if self.below(3) == 0 {
                Status::Running
            } else {
                st
            };
        }
        self.scripts.insert(name.clone(), script);
        if port == 0 {
            format!("<{name} out=\"{{v}}\"/>")
        } else if port == 1 {
            self.has_in |= !self.in_subtree;
            format!("<{name} in=\"{{w}}\"/>")
        } else if text_in {
            format!("<{name} in=\"{{t}}\"/>")
        } else {
            format!("<{name}/>")
        }
    }

    fn leaf(&mut self) -> String {
        self.leaf_with(None)
    }

    fn pick<'s>(&mut self, xs: &[&'s str]) -> &'s str {
        xs[self.below(xs.len() as u64) as usize]
    }

    /// A write: an int constant or copy, or a constant of another type.
    fn set(&mut self) -> String {
        if self.opts.strings && self.scripts_on() && self.below(4) == 0 {
            // The same numbers written otherwise: equal as numbers, not as texts.
            let key = self.pick(&["k0", "k1"]);
            let value = self.pick(&["01", "00", "10", "1"]);
            return format!("<SetBlackboard output_key=\"{key}\" value=\"{value}\"/>");
        }
        let (key, value) = match self.below(7) {
            0 => ("d0", self.pick(&["0.5", "1.5", "1.50000005"]).to_string()),
            1 => ("s0", self.pick(&["a", "b"]).to_string()),
            2 => ("b0", self.pick(&["true", "false"]).to_string()),
            3 => (self.int_entry(), format!("{{{}}}", self.int_entry())),
            _ => (self.int_entry(), self.below(3).to_string()),
        };
        format!("<SetBlackboard output_key=\"{key}\" value=\"{value}\"/>")
    }

    fn int_entry(&mut self) -> &'static str {
        INTS[self.below(3) as usize]
    }

    /// A BlackboardCheck of some type over `child`.
    fn check(&mut self, child: String) -> String {
        let (tag, a, b) = match self.below(6) {
            0 => (
                "Double",
                "d0",
                self.pick(&["0.5", "1.5", "1.50000005", "{d0}"]).to_string(),
            ),
            1 => ("String", "s0", self.pick(&["a", "b", "{s0}"]).to_string()),
            2 => ("Bool", "b0", self.pick(&["true", "false"]).to_string()),
            _ => {
                let a = self.int_entry();
                let b = if self.below(2) == 0 {
                    format!("{{{}}}", self.int_entry())
                } else {
                    self.below(3).to_string()
                };
                ("Int", a, b)
            }
        };
        let st = self.status();
        let m = if self.below(2) == 0 {
            st.name().to_string()
        } else {
            st.code().to_string()
        };
        format!(
            "<BlackboardCheck{tag} value_A=\"{{{a}}}\" value_B=\"{b}\" return_on_mismatch=\"{m}\">{child}</BlackboardCheck{tag}>"
        )
    }

    /// LoopString nodes writing the scripts' string entry ([`Options::loop_strings`]).
    fn loop_strings_on(&self) -> bool {
        self.opts.loop_strings && self.opts.strings && self.scripts_on()
    }

    /// LoopDouble nodes writing the scripts' double entries ([`Options::loop_doubles`]).
    fn loop_doubles_on(&self) -> bool {
        self.opts.loop_doubles && self.opts.bits && self.opts.bb_nodes && self.scripts_on()
    }

    /// Leaves writing the double `v` through a port ([`Options::port_doubles`]).
    fn port_doubles_on(&self) -> bool {
        self.opts.port_doubles && self.opts.bits && self.scripts_on()
    }

    fn port_strings_on(&self) -> bool {
        self.opts.port_strings && self.opts.strings && self.scripts_on()
    }

    fn scripts_on(&self) -> bool {
        self.opts.scripts && !self.v3
    }

    /// An integer expression over `x` and `y`.
    fn int_expr(&mut self, d: u32) -> String {
        if d == 0 {
            return match self.below(5) {
                0 | 1 => self.pick(&["x", "y"]).to_string(),
                2 => format!("-{}", self.pick(&["x", "1"])),
                _ => self.below(4).to_string(),
            };
        }
        match self.below(6) {
            0 => format!("{} + {}", self.int_expr(d - 1), self.int_expr(d - 1)),
            1 => format!("{} - {}", self.int_expr(d - 1), self.int_expr(0)),
            2 => format!(
                "({}) * {}",
                self.int_expr(d - 1),
                self.pick(&["-1", "0", "1"])
            ),
            3 => format!(
                "({} ? {} : ({}))",
                self.bool_expr(0, false),
                self.int_expr(0),
                self.int_expr(0)
            ),
            _ => self.int_expr(0),
        }
    }

    /// A boolean expression (a value 0 or 1); `risky`: with now and then one that throws
    /// (`Implicit casting`, `Logic operators`) when `x` is not 0 or 1. Statements never
    /// throw (the real-library harness relies on it: `Tree::haltTree` runs every
    /// `_onHalted` script, and a throw from the tree's destructor aborts).
    fn bool_expr(&mut self, d: u32, risky: bool) -> String {
        if risky && self.port_doubles_on() && self.below(2) == 0 {
            return self.v_cond();
        }
        if self.opts.bits && self.below(4) == 0 {
            return self.bits_cond(risky);
        }
        if self.opts.reals && self.below(4) == 0 {
            return self.real_cond(risky);
        }
        if self.opts.strings && self.below(4) == 0 {
            return self.str_cond(risky);
        }
        // Now and then, in a condition (`risky`), an entry a SetBlackboard wrote (`k0`,
        // `k1`, `p0`): BT.CPP 4 holds its text, which a comparison reads as a number.
        // Not in statements: a SubTree's own `p0` does not exist until the SubTree runs,
        // and `Tree::haltTree` runs every `_onHalted`, ticked or not.
        let c = |g: &mut Self| {
            let op = g.pick(&["==", "!=", "<", "<=", ">", ">="]);
            let a = if risky && g.below(4) == 0 {
                g.int_entry().to_string()
            } else {
                g.int_expr(0)
            };
            format!("{a} {op} {}", g.int_expr(0))
        };
        if d == 0 {
            return match self.below(6) {
                0 => "f".into(),
                1 => "!f".into(),
                2 => self.pick(&["true", "false"]).into(),
                _ => c(self),
            };
        }
        // `!` and arithmetic do not mix in one expression (see `script.rs`): operands of
        // `&&` / `||` are parenthesized, except comparisons (which have no `!`).
        match self.below(8) {
            0 => format!(
                "({}) && ({})",
                self.bool_expr(d - 1, risky),
                self.bool_expr(d - 1, risky)
            ),
            1 => format!(
                "({}) || ({})",
                self.bool_expr(d - 1, risky),
                self.bool_expr(0, risky)
            ),
            2 => format!("{} && {} || f", c(self), c(self)),
            3 => format!("!({})", self.bool_expr(d - 1, risky)),
            4 => format!("({}) == f", c(self)),
            // A chain `a - b + c` in a condition, where BT.CPP's grouping (to the right)
            // shows in the node's answer.
            6 => {
                let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
                format!(
                    "{} - {} + {} {op} {}",
                    self.int_expr(0),
                    self.int_expr(0),
                    self.int_expr(0),
                    self.int_expr(0)
                )
            }
            // Arithmetic over a SetBlackboard's text throws ("Operation not permitted");
            // as the condition of `?:` it reads as a number.
            5 if risky && self.below(4) == 0 => match self.below(4) {
                0 => format!("{} + 1 > 0", self.int_entry()),
                1 => format!("({} ? 1 : 0) == 1", self.int_entry()),
                _ => "x".into(),
            },
            _ => self.bool_expr(0, risky),
        }
    }

    /// A condition over doubles ([`Options::reals`]); `risky`: with one that throws
    /// (a negative double or an integer other than 0 and 1 cast to bool).
    fn real_cond(&mut self, risky: bool) -> String {
        let lit = |g: &mut Self| g.pick(&["0.5", "1.5", "2.5e-1", "1e1", "0.0"]).to_string();
        // Divisors are literals other than 0 (the lowering refuses others: the sign of a
        // zero divisor shows in BT.CPP's doubles).
        let div = |g: &mut Self| g.pick(&["2", "3", "-2", "0.5", "4"]).to_string();
        let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
        match self.below(if risky { 8 } else { 5 }) {
            0 => format!("{} / {} {op} {}", self.int_expr(0), div(self), lit(self)),
            1 => format!(
                "{} * {} {op} {}",
                self.int_expr(0),
                lit(self),
                self.int_expr(0)
            ),
            2 => format!(
                "({} / {}) {op} ({} / {})",
                self.int_expr(1),
                div(self),
                self.int_expr(0),
                div(self)
            ),
            3 => format!("({} / {} ? 1 : 0) == 1", self.int_expr(0), div(self)),
            // inf, and NaN (`inf - inf`), on both sides of every ordering in BT.CPP.
            4 => format!(
                "{} * 1e308 * 10 {} 1e308 * 10 {op} {}",
                self.pick(&["x", "y", "1"]),
                self.pick(&["-", "+"]),
                self.int_expr(0)
            ),
            // An arithmetic value, or an entry, cast to bool.
            5 => format!(
                "{} {} {}",
                self.pick(&["x", "y"]),
                self.pick(&["+", "-"]),
                self.int_expr(0)
            ),
            6 => format!("{} / {}", self.pick(&["x", "y"]), div(self)),
            _ => match self.below(3) {
                0 => format!("({} - {}) && f", self.pick(&["x", "y"]), self.int_expr(0)),
                _ => self.pick(&["x", "f", "y - 1"]).to_string(),
            },
        }
    }

    /// A string literal of [`TEXTS`].
    fn text(&mut self) -> String {
        format!("'{}'", self.pick(&TEXTS))
    }

    /// A string: a literal, `t`, or (`texts`) a SetBlackboard's text (`k0`, `k1`: not in
    /// statements, which must not throw, and a SetBlackboard copy leaves them empty in
    /// BT.CPP 4.8.2, where reading them throws).
    fn str_atom(&mut self, texts: bool) -> String {
        match self.below(if texts { 5 } else { 3 }) {
            0 | 1 => self.text(),
            2 => "t".into(),
            _ => self.pick(&["k0", "k1"]).into(),
        }
    }

    /// A join ([`Options::joins`]) of `t`, literals and number literals: a statement's
    /// value, never throwing, with texts bounded (`u` is never joined).
    fn join_expr(&mut self) -> String {
        match self.below(8) {
            0 => format!("t .. {}", self.text()),
            1 => format!("{} .. t", self.text()),
            2 => format!(
                "t .. {}",
                self.pick(&["3", "0", "true", "false", "1.5", "(-2)"])
            ),
            3 => format!("{} .. t", self.pick(&["7", "2.25", "1e3"])),
            4 => format!("t + {}", self.text()),
            5 => format!(
                "({} ? {} : {}) .. t",
                self.bool_expr(0, false),
                self.text(),
                self.text()
            ),
            6 => "t .. t".into(),
            _ => format!("{} .. t .. {}", self.text(), self.below(3)),
        }
    }

    /// A condition over joins ([`Options::joins`]): `u` or a join compared with a
    /// string; `risky`: joining `k0`/`k1`, which BT.CPP 4.8.2 throws on where they hold
    /// no value.
    fn join_cond(&mut self, risky: bool) -> String {
        // Parenthesized: `..` and `+` do not mix with other operator groups.
        let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
        match self.below(if risky { 5 } else { 4 }) {
            0 => format!("(u {op} {})", self.text()),
            1 => format!("({} {op} u)", self.join_expr()),
            2 => format!("(({}) {op} {})", self.join_expr(), self.text()),
            3 => format!("(u {op} t + {})", self.text()),
            _ => format!("({} .. {} {op} u)", self.pick(&["k0", "k1"]), self.text()),
        }
    }

    /// A comparison of strings ([`Options::strings`]); `risky`: with the texts
    /// SetBlackboard wrote, and with one that compares a string with a number (a text
    /// that is not one throws) or reads it as the condition of `?:`.
    fn str_cond(&mut self, risky: bool) -> String {
        if self.opts.joins && self.below(3) == 0 {
            return self.join_cond(risky);
        }
        let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
        match self.below(if risky { 6 } else { 3 }) {
            0 => format!("t {op} {}", self.text()),
            1 => format!("{} {op} {}", self.str_atom(risky), self.str_atom(risky)),
            2 => format!("({} {op} {}) == f", self.str_atom(risky), self.text()),
            3 => format!("{} {op} {}", self.str_atom(true), self.below(3)),
            4 => format!("{} {op} {}", self.below(3), self.pick(&["t", "k0", "k1"])),
            _ => format!("({} ? 1 : 0) == 1", self.pick(&["t", "k0", "k1"])),
        }
    }

    /// A condition over `v`, the double the leaves' ports write, or `w`, the one scripts
    /// write for the leaves' input ports ([`Options::port_doubles`]): it throws before
    /// the first write.
    fn v_cond(&mut self) -> String {
        let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
        let v = self.pick(&[
            "v", "v", "(v * 2)", "(v - r)", "-v", "v / 2", "w", "(w - v)",
        ]);
        format!(
            "{v} {op} {}",
            self.pick(&["1.5", "0.5", "0", "r", "x", "-2", "3.25"])
        )
    }

    /// One to three statements.
    fn script(&mut self) -> String {
        let n = 1 + self.below(3);
        let stmts: Vec<String> = (0..n)
            .map(|_| match self.below(if self.opts.bits { 10 } else { 7 }) {
                // A join into `u`: never throws.
                _ if self.opts.joins && self.below(6) == 0 => match self.below(4) {
                    0 => format!("u := t; u += {}", self.text()),
                    1 => format!("u = {}", self.join_expr()),
                    _ => format!("u := {}", self.join_expr()),
                },
                // A string into `t`: never throws.
                _ if self.opts.strings && self.below(4) == 0 => match self.below(3) {
                    0 => format!("t := {}", self.str_atom(false)),
                    1 => format!(
                        "t = ({} ? {} : {})",
                        self.bool_expr(0, false),
                        self.text(),
                        self.text()
                    ),
                    _ => format!("t := {}", self.text()),
                },
                // A double into `w`, the entry the leaves' input ports name: every value
                // a double, so no write throws (an integer first would make it one);
                // `=` only once a leaf of the main tree created `w` with its port.
                _ if self.port_doubles_on() && self.below(5) == 0 => match self.below(3) {
                    0 => format!("w := {} / 2", self.int_expr(1)),
                    _ if !self.has_in => {
                        format!("w := {}", self.pick(&["2.5", "-0.5", "r * 0.5", "r / 2"]))
                    }
                    1 => format!("w = {} * 0.5", self.pick(&["x", "y", "-1", "3"])),
                    _ => format!("w = r {} 1", self.pick(&["+", "-", "*"])),
                },
                7..=9 => self.bits_statement(),
                // Depth 2: chains such as `x - 1 + y - 2`, which BT.CPP groups to the right.
                0 => format!("x := {}", self.int_expr(2)),
                1 => format!("y = {}", self.int_expr(1)),
                2 => format!("x += {}", self.below(3)),
                3 => format!("y -= {}", self.below(3)),
                4 => format!("f := {}", self.bool_expr(1, false)),
                5 => "f = !f".into(),
                _ => format!("x {} y", self.pick(&["+", "-"])),
            })
            .collect();
        stmts.join("; ")
    }

    /// A statement of [`Options::bits`] that never throws: bit operators over the
    /// integer entries, numbers that are not whole stored in the double entry `r`.
    fn bits_statement(&mut self) -> String {
        match self.below(8) {
            0 => format!("y := {}", self.bits_int()),
            1 => format!("r := {}", self.real_value()),
            2 => format!("r /= {}", self.divisor()),
            3 => format!(
                "r {} {}",
                self.pick(&["+=", "-=", "*="]),
                self.pick(&["0.25", "x", "-1", "1.5", "r"])
            ),
            4 => "r := -r".into(),
            5 => format!("r := {} / {}", self.int_expr(0), self.divisor()),
            6 => format!("f := {}", self.bits_cond(false)),
            _ => format!("y := ~{}", self.pick(&["y", "x", "0", "f"])),
        }
    }

    /// An integer value of the bit operators over `x`, `y`, `f` and small literals (no
    /// arithmetic operator: BT.CPP does not mix the two groups).
    fn bits_int(&mut self) -> String {
        let leaf = |g: &mut Self| {
            g.pick(&[
                "x", "y", "f", "1", "2", "3", "6", "~y", "(0 - 2)", "(y - 1)",
            ])
            .to_string()
        };
        match self.below(4) {
            0 => format!("{} & {}", leaf(self), leaf(self)),
            1 => format!("{} | {} ^ {}", leaf(self), leaf(self), leaf(self)),
            2 => format!("{} ^ {} & {}", leaf(self), leaf(self), leaf(self)),
            _ => format!("~{}", leaf(self)),
        }
    }

    /// A divisor: a literal, or an entry or expression that is zero now and then, of
    /// either sign (`-x` with `x` 0 is -0.0 in BT.CPP).
    fn divisor(&mut self) -> String {
        self.pick(&[
            "2", "-4", "0.5", "x", "-x", "y", "(y - 1)", "(x * -1)", "r", "-r", "(0 - x)", "0",
            "(x - x)",
        ])
        .to_string()
    }

    /// A value stored in `r`: not whole, infinite, NaN, or a negative zero now and then.
    fn real_value(&mut self) -> String {
        match self.below(6) {
            0 => format!(
                "{} / {}",
                self.pick(&["x", "y", "1", "-1", "r", "0"]),
                self.divisor()
            ),
            1 => format!("r * {}", self.pick(&["1.5", "-1", "0", "0.5"])),
            2 => self.pick(&["2.5", "0.0", "-0.5", "1e308 * 10"]).to_string(),
            // The condition in parentheses: `!` and `-` do not mix in one expression.
            3 => format!("({}) ? (r / 2) : (-r)", self.bool_expr(0, false)),
            4 => format!("(r {} {}) / 2", self.pick(&["+", "-"]), self.int_expr(0)),
            _ => self.int_expr(1),
        }
    }

    /// A condition of [`Options::bits`]; `risky`: with ones that throw (a bit operator
    /// over a double that is not whole, NaN or infinite; `r` cast to bool when negative;
    /// with [`Options::loop_doubles`], `ld` compared, which throws before its first write).
    fn bits_cond(&mut self, risky: bool) -> String {
        let op = self.pick(&["==", "!=", "<", "<=", ">", ">="]);
        if risky && self.loop_doubles_on() && self.below(4) == 0 {
            return format!("ld {op} {}", self.pick(&["1.5", "0", "r", "x", "2"]));
        }
        match self.below(if risky { 10 } else { 7 }) {
            0 => format!(
                "{} {op} {}",
                self.bits_int(),
                self.pick(&["0", "1", "2", "y", "(0 - 1)"])
            ),
            1 => format!("1 / {} {op} 0", self.divisor()),
            2 => format!(
                "{} / {} {op} {}",
                self.int_expr(0),
                self.divisor(),
                self.pick(&["0", "1", "r", "0.5"])
            ),
            3 => format!("r {op} {}", self.pick(&["0", "2.5", "x", "-0.5", "1"])),
            4 => format!(
                "(r {} {}) {op} 1",
                self.pick(&["+", "*"]),
                self.pick(&["1", "x", "0.5"])
            ),
            5 => format!("!y & 1 {op} 0"),
            6 => format!("(y & 1 ? r : x) {op} 0"),
            7 => format!(
                "({} & 1) {op} 0",
                self.pick(&["r", "x", "(r * 2)", "(1 / x)"])
            ),
            8 => format!("~r {op} {}", self.pick(&["0", "y"])),
            _ => self.pick(&["r", "y & 1", "~y & 1", "r / 2"]).to_string(),
        }
    }

    /// A script leaf, or a Precondition over a node.
    fn script_node(&mut self, depth: u32) -> String {
        if self.opts.bits && self.below(6) == 0 {
            // A Script storing a double into an integer entry: BT.CPP throws unless it
            // is whole ("Invalid floating point to integer conversion").
            let s = match self.below(4) {
                0 => format!("y /= {}", self.pick(&["2", "x", "-1", "0.5"])),
                1 => "y := r".to_string(),
                2 => format!("x := {} / {}", self.pick(&["y", "4", "x"]), self.divisor()),
                _ => format!("y *= {}", self.pick(&["0.5", "r", "2"])),
            };
            return format!("<Script code=\"{}\"/>", esc(&s));
        }
        match self.below(3) {
            0 => format!("<Script code=\"{}\"/>", esc(&self.script())),
            1 => format!(
                "<ScriptCondition code=\"{}\"/>",
                esc(&self.bool_expr(1, true))
            ),
            _ => {
                let e = if self.opts.skipped {
                    self.pick(&["SUCCESS", "FAILURE", "RUNNING", "SKIPPED"])
                } else {
                    self.pick(&["SUCCESS", "FAILURE", "RUNNING"])
                };
                let cond = esc(&self.bool_expr(1, true));
                let child = self.node(depth + 1);
                format!("<Precondition if=\"{cond}\" else=\"{e}\">{child}</Precondition>")
            }
        }
    }

    /// `node` with now and then a pre/post-condition attribute (on a SubTree only with
    /// [`Options::subtree_conds`]);
    /// `skip` allows `_skipIf` and `_while`.
    fn with_conds(&mut self, node: String, skip: bool) -> String {
        let subtree = node.starts_with("<SubTree");
        if !self.scripts_on()
            || self.conds == Conditions::Off
            || (subtree && !self.opts.subtree_conds)
        {
            return node;
        }
        // One node in four gets a condition; a SubTree ([`Options::subtree_conds`]) three
        // in four.
        let draw = self.below(4);
        if (subtree && draw == 0) || (!subtree && draw != 0) {
            return node;
        }
        let names: &[&str] = if skip && self.conds == Conditions::All {
            &[
                "_skipIf",
                "_while",
                "_skipIf",
                "_while",
                "_failureIf",
                "_successIf",
                "_onSuccess",
                "_onFailure",
                "_post",
                "_onHalted",
            ]
        } else {
            &[
                "_failureIf",
                "_successIf",
                "_onSuccess",
                "_onFailure",
                "_post",
                "_onHalted",
            ]
        };
        // On a SubTree, `_onHalted` and the pre-conditions more often: what a body's
        // SKIPPED, which leaves the SubTree node RUNNING, shows through.
        let names: &[&str] = if subtree && skip && self.conds == Conditions::All {
            &[
                "_onHalted",
                "_onHalted",
                "_onHalted",
                "_skipIf",
                "_while",
                "_failureIf",
                "_successIf",
                "_onSuccess",
                "_onFailure",
                "_post",
            ]
        } else {
            names
        };
        let mut name = self.pick(names);
        // With UnsetBlackboard, an `_onHalted` script could read an erased entry and
        // throw inside a halt, which BT.CPP may meet in a destructor (and the oracle
        // does not model): `_post` instead.
        if name == "_onHalted" && (self.opts.bb_nodes || self.opts.unset) {
            name = "_post";
        }
        let code = if name.starts_with("_on") || name == "_post" {
            self.script()
        } else {
            self.bool_expr(1, true)
        };
        let at = node[1..]
            .find([' ', '/', '>'])
            .map_or(node.len(), |i| i + 1);
        let head = &node[..node.find('>').unwrap_or(node.len())];
        if head.contains(&format!(" {name}=")) {
            return node;
        }
        format!("{} {name}=\"{}\"{}", &node[..at], esc(&code), &node[at..])
    }

    /// A SubTree's body root `seq` (a `<Sequence>`) that, with [`Options::subtree_conds`]
    /// and SKIPPED on, may answer SKIPPED one time in two (`_skipIf` or `_while`), so
    /// that a body's SKIPPED leaves the SubTree node RUNNING. Off, nothing is drawn.
    fn body_skip(&mut self, seq: String) -> String {
        if !self.opts.subtree_conds
            || !self.scripts_on()
            || self.conds != Conditions::All
            || self.below(2) != 0
        {
            return seq;
        }
        let name = self.pick(&["_skipIf", "_while"]);
        let code = esc(&self.bool_expr(1, false));
        format!("<Sequence {name}=\"{code}\"{}", &seq["<Sequence".len()..])
    }

    /// Children of a sequence, fallback or parallel: with scripts, those after the first
    /// have a second chance of a condition.
    fn children_skip(&mut self, depth: u32, lo: u64, hi: u64) -> String {
        let n = lo + self.below(hi - lo + 1);
        (0..n)
            .map(|i| {
                let c = self.node(depth + 1);
                self.with_conds(c, i > 0)
            })
            .collect()
    }

    fn children(&mut self, depth: u32, lo: u64, hi: u64) -> String {
        let n = lo + self.below(hi - lo + 1);
        (0..n).map(|_| self.node(depth + 1)).collect()
    }

    /// One of BT.CPP 4's nodes AS2FM has no model of.
    fn btcpp4_node(&mut self, depth: u32) -> String {
        match self.below(7) {
            0 => format!(
                "<AsyncSequence>{}</AsyncSequence>",
                self.children_skip(depth, 1, 4)
            ),
            1 => format!(
                "<AsyncFallback>{}</AsyncFallback>",
                self.children_skip(depth, 1, 4)
            ),
            2 => {
                let n = 1 + self.below(3) as i64;
                let t = 1 + self.below(n as u64) as i64;
                let t = if self.below(3) == 0 { t - n - 1 } else { t };
                let kids = self.kids_skip(depth, n);
                format!("<ParallelAll max_failures=\"{t}\">{kids}</ParallelAll>")
            }
            3 => format!("<WhileDoElse>{}</WhileDoElse>", self.children(depth, 2, 3)),
            4 => format!(
                "<KeepRunningUntilFailure>{}</KeepRunningUntilFailure>",
                self.node(depth + 1)
            ),
            5 if self.opts.skipped && self.below(2) == 0 => {
                let attr = self.pick(&["", " then_skip=\"true\""]);
                format!("<RunOnce{attr}>{}</RunOnce>", self.node(depth + 1))
            }
            5 => format!(
                "<RunOnce then_skip=\"false\">{}</RunOnce>",
                self.node(depth + 1)
            ),
            _ => {
                let n = 2 + self.below(5) as usize;
                let cases: String = (1..=n)
                    .map(|i| format!(" case_{i}=\"{}\"", self.pick(&["a", "b", "c"])))
                    .collect();
                let kids: String = (0..=n).map(|_| self.node(depth + 1)).collect();
                format!("<Switch{n} variable=\"{{s0}}\"{cases}>{kids}</Switch{n}>")
            }
        }
    }

    /// A timed node ([`Options::time_nodes`]) or a TryCatch ([`Options::try_catch`]).
    fn time_node(&mut self, depth: u32) -> String {
        let kinds: &[u64] = match (self.opts.time_nodes, self.opts.try_catch) {
            (true, true) => &[0, 1, 2, 3],
            (true, false) => &[0, 1, 2],
            _ => &[3],
        };
        let ms = ["0", "50", "100", "150", "250", "350"];
        match kinds[self.below(kinds.len() as u64) as usize] {
            0 => {
                let d = self.pick(&ms);
                format!("<Timeout msec=\"{d}\">{}</Timeout>", self.node(depth + 1))
            }
            1 => {
                let d = self.pick(&ms);
                format!("<Delay delay_msec=\"{d}\">{}</Delay>", self.node(depth + 1))
            }
            2 => format!("<Sleep msec=\"{}\"/>", self.pick(&ms)),
            _ => {
                let on_halt = if self.below(2) == 0 {
                    " catch_on_halt=\"true\""
                } else {
                    ""
                };
                format!(
                    "<TryCatch{on_halt}>{}</TryCatch>",
                    self.children(depth, 2, 4)
                )
            }
        }
    }

    /// One of BT.CPP 4's blackboard nodes ([`Options::bb_nodes`]).
    fn bb_node(&mut self, depth: u32) -> String {
        let skip = self.conds == Conditions::All;
        let e = self.pick(&["x", "y", "f", "{x}", "{y}", "{f}"]);
        match self.below(10) {
            0 if !self.in_subtree => {
                format!("<UnsetBlackboard key=\"{}\"/>", self.pick(&["x", "y", "f"]))
            }
            0 | 1 => format!("<WasEntryUpdated entry=\"{e}\"/>"),
            2 => {
                let child = self.node(depth + 1);
                format!("<WaitValueUpdate entry=\"{e}\">{child}</WaitValueUpdate>")
            }
            3 if skip => {
                let child = self.node(depth + 1);
                format!("<SkipUnlessUpdated entry=\"{e}\">{child}</SkipUnlessUpdated>")
            }
            _ => {
                let k = if self.loop_strings_on() && self.below(2) == 0 {
                    2
                } else if self.loop_doubles_on() && self.below(2) == 0 {
                    1
                } else {
                    self.below(6)
                };
                let (tag, items, values): (_, &[&str], &[&str]) = match k {
                    // One item type per entry: BT.CPP refuses a tree whose Loop nodes write one
                    // entry with two types ("was initially created with type").
                    0 => ("LoopBool", &["true", "false", "1", "0"], &["{f}"]),
                    1 if self.loop_doubles_on() => (
                        "LoopDouble",
                        &["1.5", "2.0", "-0.5"],
                        &["{r}", "{r}", "{ld}"],
                    ),
                    1 => ("LoopDouble", &["1.5", "2.0", "-0.5"], &["{ld}"]),
                    2 if self.loop_strings_on() => {
                        ("LoopString", &LOOP_TEXTS, &["{t}", "{t}", "{ls}"])
                    }
                    2 => ("LoopString", &["a", "b"], &["{ls}"]),
                    _ => ("LoopInt", &["0", "1", "2", "-3"], &["{x}", "{y}"]),
                };
                let n = self.below(4);
                let mut q: Vec<&str> = (0..n).map(|_| self.pick(items)).collect();
                if n > 0 && self.below(8) == 0 {
                    q.push("");
                }
                let value = if self.below(4) == 0 {
                    String::new()
                } else {
                    format!(" value=\"{}\"", self.pick(values))
                };
                let empty = match self.below(8) {
                    0 => " if_empty=\"FAILURE\"",
                    1 => " if_empty=\"RUNNING\"",
                    2 if skip => " if_empty=\"SKIPPED\"",
                    3 => " if_empty=\"SUCCESS\"",
                    _ => "",
                };
                let child = self.node(depth + 1);
                format!(
                    "<{tag} queue=\"{}\"{value}{empty}>{child}</{tag}>",
                    q.join(";")
                )
            }
        }
    }

    /// `n` children of a parallel (as [`Self::children_skip`]).
    fn kids_skip(&mut self, depth: u32, n: i64) -> String {
        (0..n)
            .map(|i| {
                let c = self.node(depth + 1);
                self.with_conds(c, i > 0)
            })
            .collect()
    }

    /// A node, with now and then a condition (see [`Options::scripts`]).
    fn node(&mut self, depth: u32) -> String {
        let n = self.node_bare(depth);
        self.with_conds(n, true)
    }

    fn node_bare(&mut self, depth: u32) -> String {
        self.budget -= 1;
        if (self.opts.time_nodes || self.opts.try_catch)
            && !self.v3
            && depth < 5
            && self.budget > 0
            && self.below(5) == 0
        {
            return self.time_node(depth);
        }
        if self.opts.btcpp4_nodes && !self.v3 && depth < 5 && self.budget > 0 && self.below(6) == 0
        {
            return self.btcpp4_node(depth);
        }
        if self.opts.bb_nodes
            && self.scripts_on()
            && depth < 5
            && self.budget > 0
            && self.below(6) == 0
        {
            return self.bb_node(depth);
        }
        if self.opts.unset
            && self.scripts_on()
            && !self.in_subtree
            && depth < 5
            && self.below(10) == 0
        {
            return format!("<UnsetBlackboard key=\"{}\"/>", self.pick(&["x", "y", "f"]));
        }
        if self.scripts_on() && depth < 5 && self.below(6) == 0 {
            return self.script_node(depth);
        }
        if depth >= 5 || self.budget <= 0 || self.below(10) < 3 {
            return match self.below(12) {
                0 => "<AlwaysSuccess/>".into(),
                1 => "<AlwaysFailure/>".into(),
                2 => self.set(),
                3 if !self.subtrees.is_empty() => self.subtree_ref(),
                _ => self.leaf(),
            };
        }
        match self.below(18) {
            0 | 1 => format!("<Sequence>{}</Sequence>", self.children_skip(depth, 1, 4)),
            2 | 3 => format!("<Fallback>{}</Fallback>", self.children_skip(depth, 1, 4)),
            4 => format!(
                "<ReactiveSequence>{}</ReactiveSequence>",
                self.children_skip(depth, 1, 3)
            ),
            5 => format!(
                "<ReactiveFallback>{}</ReactiveFallback>",
                self.children_skip(depth, 1, 3)
            ),
            6 | 7 => {
                // BT.CPP 4 knows `SequenceStar` only under USE_BTCPP3_OLD_NAMES.
                let tag = if self.v3 {
                    "SequenceStar"
                } else {
                    "SequenceWithMemory"
                };
                format!("<{tag}>{}</{tag}>", self.children_skip(depth, 1, 4))
            }
            8 => {
                let n = 1 + self.below(3) as i64;
                let th = |g: &mut Self| {
                    let t = 1 + g.below(n as u64) as i64;
                    if g.below(3) == 0 {
                        t - n - 1
                    } else {
                        t
                    }
                };
                let (s, f) = (th(self), th(self));
                let kids = self.kids_skip(depth, n);
                let (sn, fna) = if self.v3 {
                    ("success_threshold", "failure_threshold")
                } else {
                    ("success_count", "failure_count")
                };
                format!("<Parallel {sn}=\"{s}\" {fna}=\"{f}\">{kids}</Parallel>")
            }
            9 => format!("<IfThenElse>{}</IfThenElse>", self.children(depth, 2, 3)),
            10 => format!("<Inverter>{}</Inverter>", self.node(depth + 1)),
            11 => format!("<ForceSuccess>{}</ForceSuccess>", self.node(depth + 1)),
            12 => format!("<ForceFailure>{}</ForceFailure>", self.node(depth + 1)),
            13..=15 => {
                let (tag, port, stop) = if self.below(3) == 0 {
                    ("Repeat", "num_cycles", Status::Failure)
                } else {
                    let t = if self.v3 && self.below(2) == 0 {
                        "RetryUntilSuccesful"
                    } else {
                        "RetryUntilSuccessful"
                    };
                    (t, "num_attempts", Status::Success)
                };
                // -1: without end, over a leaf whose script stops it.
                let (count, child) = if self.below(5) == 0 {
                    (-1, self.leaf_with(Some(stop)))
                } else {
                    (self.below(4) as i64, self.node(depth + 1))
                };
                format!("<{tag} {port}=\"{count}\">{child}</{tag}>")
            }
            16 => {
                let child = self.node(depth + 1);
                self.check(child)
            }
            _ if !self.subtrees.is_empty() => self.subtree_ref(),
            _ => self.leaf(),
        }
    }

    /// A SubTree instance: the whole blackboard shared, every entry but `p0` remapped
    /// (as itself, or `k0` and `k1` swapped). Format 3 spells it `__shared_blackboard`
    /// and maps by name, or uses `SubTreePlus` (`__autoremap`, `{entry}` values).
    fn subtree_ref(&mut self) -> String {
        let i = self.below(self.subtrees.len() as u64);
        let plus = self.v3 && self.below(3) == 0;
        let (tag, flag, braced) = match (self.v3, plus) {
            (true, false) => ("SubTree", "__shared_blackboard", false),
            (true, true) => ("SubTreePlus", "__autoremap", true),
            _ => ("SubTree", "_autoremap", true),
        };
        let v = |e: &str| {
            if braced {
                format!("{{{e}}}")
            } else {
                e.to_string()
            }
        };
        let more = match (self.scripts_on(), self.opts.bits, self.opts.strings) {
            (true, true, true) => " x=\"{x}\" y=\"{y}\" f=\"{f}\" r=\"{r}\" t=\"{t}\"",
            (true, true, false) => " x=\"{x}\" y=\"{y}\" f=\"{f}\" r=\"{r}\"",
            (true, false, true) => " x=\"{x}\" y=\"{y}\" f=\"{f}\" t=\"{t}\"",
            (true, false, false) => " x=\"{x}\" y=\"{y}\" f=\"{f}\"",
            _ => "",
        };
        let remap = match self.below(3) {
            0 => format!("{flag}=\"true\""),
            1 => format!(
                "k0=\"{}\" k1=\"{}\" d0=\"{}\" s0=\"{}\" b0=\"{}\"",
                v("k0"),
                v("k1"),
                v("d0"),
                v("s0"),
                v("b0")
            ),
            _ => format!(
                "k0=\"{}\" k1=\"{}\" d0=\"{}\" s0=\"{}\" b0=\"{}\"",
                v("k1"),
                v("k0"),
                v("d0"),
                v("s0"),
                v("b0")
            ),
        };
        let more = if self.opts.joins && self.opts.strings && self.scripts_on() {
            format!("{more} u=\"{{u}}\"")
        } else {
            more.to_string()
        };
        format!("<{tag} ID=\"S{i}\" {remap}{more}/>")
    }
}

/// A random case of about `size` nodes.
pub fn case<R: Rng>(rng: &mut R, size: i64) -> Case {
    case_with(rng, size, Options::default())
}

/// A random case of about `size` nodes, with what `opts` adds.
pub fn case_with<R: Rng>(rng: &mut R, size: i64, opts: Options) -> Case {
    case_with_conds(rng, size, opts, Conditions::All)
}

/// As [`case_with`], with [`Options::scripts`] writing the pre/post-condition attributes
/// `conds` says.
pub fn case_with_conds<R: Rng>(rng: &mut R, size: i64, opts: Options, conds: Conditions) -> Case {
    let mut g = G {
        rng,
        scripts: Scripts::new(),
        budget: 0,
        subtrees: Vec::new(),
        v3: false,
        opts,
        conds,
        in_subtree: true,
        has_in: false,
    };
    g.v3 = g.below(3) == 0;
    let n_sub = g.below(3);
    let mut defs = String::new();
    for i in 0..n_sub {
        g.budget = size / 3;
        let p0 = g.below(3);
        let body = g.node(1);
        // The instance's own `p0` written before anything reads it.
        let seq = g.body_skip(format!(
            "<Sequence><SetBlackboard output_key=\"p0\" value=\"{p0}\"/>{body}</Sequence>"
        ));
        defs += &format!("<BehaviorTree ID=\"S{i}\">{seq}</BehaviorTree>");
        g.subtrees.push(format!("S{i}"));
    }
    g.budget = size;
    g.in_subtree = false;
    let body = g.node(0);
    let format = if g.v3 { 3 } else { 4 };
    let init = if g.scripts_on() && g.opts.reals {
        let init = g.pick(&[
            SCRIPT_INIT,
            "x:=0+0; y:=1; f:=true",
            "x:=0; y:=1; f:=1>0",
            "x:=0*1; y:=1; f:=!false",
        ]);
        format!("<Script code=\"{init}\"/>")
    } else if g.scripts_on() && g.opts.bits {
        let r = g.pick(&["0.5", "0+0", "2.5"]);
        format!("<Script code=\"{SCRIPT_INIT}; r:={r}\"/>")
    } else if g.scripts_on() {
        format!("<Script code=\"{SCRIPT_INIT}\"/>")
    } else {
        String::new()
    };
    // `t`, created from a string (BT.CPP keeps the type an entry was created with).
    let init = if g.scripts_on() && g.opts.strings && g.opts.joins {
        format!("{init}<Script code=\"t:='a'; u:=''\"/>")
    } else if g.scripts_on() && g.opts.strings {
        format!("{init}<Script code=\"t:='a'\"/>")
    } else {
        init
    };
    // Every entry written first, so each has a value and a type.
    let xml = format!(
        "<root BTCPP_format=\"{format}\" main_tree_to_execute=\"Main\"><BehaviorTree ID=\"Main\"><Sequence>\
<SetBlackboard output_key=\"k0\" value=\"0\"/><SetBlackboard output_key=\"k1\" value=\"1\"/>\
<SetBlackboard output_key=\"p0\" value=\"2\"/><SetBlackboard output_key=\"d0\" value=\"1.5\"/>\
<SetBlackboard output_key=\"s0\" value=\"a\"/><SetBlackboard output_key=\"b0\" value=\"true\"/>\
{init}{body}</Sequence></BehaviorTree>{defs}</root>"
    );
    let ticks = 4 + g.below(7) as usize;
    let xml = if g.opts.root_skip && g.opts.skipped && !g.v3 && g.below(3) == 0 {
        xml.replacen(
            "<BehaviorTree ID=\"Main\"><Sequence>",
            "<BehaviorTree ID=\"Main\"><RunOnce><Sequence>",
            1,
        )
        .replacen(
            "</Sequence></BehaviorTree>",
            "</Sequence></RunOnce></BehaviorTree>",
            1,
        )
    } else {
        xml
    };
    Case {
        xml,
        scripts: g.scripts,
        ticks,
    }
}

/// A script as an attribute value.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
