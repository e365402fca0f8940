//! The SCXML subset as read from files: one [`Machine`] per `<scxml>`, every item with its span.
//!
//! Expressions stay as source text ([`SrcExpr`]) here; `expr` parses them and
//! `sim` type-checks and compiles them against the whole model.

use super::source::Span;
use super::types::TypeAnn;

/// A name written in the model (state id, event, target, ...) and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ident {
    /// The name.
    pub name: String,
    /// Span of the name's first byte.
    pub span: Span,
}

/// An expression's source text (unescaped) and the span of its raw attribute value.
///
/// Offset `k` in `text` maps back to the file with
/// [`super::source::unescaped_offset`].
#[derive(Clone, Debug)]
pub struct SrcExpr {
    /// Unescaped ECMAScript text.
    pub text: String,
    /// Span of the attribute value's first byte.
    pub span: Span,
}

/// One `<scxml>` state machine.
#[derive(Clone, Debug)]
pub struct Machine {
    /// The machine's name (`name` attribute, else the file stem).
    pub name: Ident,
    /// The `initial` attribute; the first state when absent.
    pub initial: Option<Ident>,
    /// `<data>` items in document order.
    pub datamodel: Vec<Data>,
    /// States (`<state>` and `<final>`) in document order.
    pub states: Vec<State>,
    /// Span of the `<scxml>` tag.
    pub span: Span,
}

/// A `<data id expr>` item.
#[derive(Clone, Debug)]
pub struct Data {
    /// Variable name.
    pub id: Ident,
    /// Declared type (`<!-- TYPE id:t -->` or `type` attribute).
    pub ty: Option<TypeAnn>,
    /// Initial value; the type's default when absent.
    pub expr: Option<SrcExpr>,
    /// Span of the `<data>` tag.
    pub span: Span,
}

/// A flat state.
#[derive(Clone, Debug)]
pub struct State {
    /// State id.
    pub id: Ident,
    /// `<onentry>` content (several blocks are concatenated).
    pub onentry: Vec<Exec>,
    /// `<onexit>` content (several blocks are concatenated).
    pub onexit: Vec<Exec>,
    /// Transitions in document order.
    pub transitions: Vec<Transition>,
    /// True for `<final>`.
    pub is_final: bool,
    /// Span of the tag.
    pub span: Span,
}

/// A `<transition>`.
#[derive(Clone, Debug)]
pub struct Transition {
    /// Triggering events (space separated in the `event` attribute); empty: eventless.
    pub events: Vec<Ident>,
    /// Guard.
    pub cond: Option<SrcExpr>,
    /// Target state; absent: a targetless transition (runs its content, stays, no exit/entry).
    pub target: Option<Ident>,
    /// Executable content.
    pub body: Vec<Exec>,
    /// Span of the tag.
    pub span: Span,
}

/// Executable content.
#[derive(Clone, Debug)]
pub enum Exec {
    /// `<assign location expr>`.
    Assign {
        /// Left-hand side (`x`, `a[i]`, `s.f`).
        location: SrcExpr,
        /// Value.
        expr: SrcExpr,
        /// Span of the tag.
        span: Span,
    },
    /// `<send>`.
    Send(Send),
    /// `<raise event>`.
    Raise {
        /// The internal event.
        event: Ident,
        /// Span of the tag.
        span: Span,
    },
    /// `<if cond>` ... `<elseif cond/>` ... `<else/>` ... `</if>`.
    If {
        /// `(condition, content)` for the `if` and each `elseif`.
        branches: Vec<(SrcExpr, Vec<Exec>)>,
        /// Content after `<else/>`.
        otherwise: Vec<Exec>,
        /// Span of the tag.
        span: Span,
    },
    /// `<log label expr>`.
    Log {
        /// Label text.
        label: Option<String>,
        /// Logged value.
        expr: Option<SrcExpr>,
        /// Span of the tag.
        span: Span,
    },
}

/// Where a `<send>` goes.
#[derive(Clone, Debug)]
pub enum SendTarget {
    /// `target="name"`.
    Id(Ident),
    /// `targetexpr="..."`: a string expression naming a machine.
    Expr(SrcExpr),
}

/// A `<send>` delay: in model time units, or a duration that the model's time unit
/// converts ([`crate::model::ModelSource::time_unit_ns`]).
#[derive(Clone, Debug)]
pub enum Delay {
    /// `delay="n"`.
    Const(u64, Span),
    /// `delay="1.5s"`: a duration in nanoseconds (the attribute value's span).
    Duration(u64, Span),
    /// `delayexpr="..."`: an integer expression.
    Expr(SrcExpr),
    /// `delayexpr="e + 'ms'"`, SCXML's way of writing a duration an expression computes:
    /// the number `e` (an integer or a float) counts units of the given nanoseconds.
    ExprIn(SrcExpr, u64),
}

/// A `<send>`.
#[derive(Clone, Debug)]
pub struct Send {
    /// Event name.
    pub event: Ident,
    /// Destination; `None`: every machine with a transition on the event.
    pub target: Option<SendTarget>,
    /// Delay before the message is sent.
    pub delay: Option<Delay>,
    /// `<param>`s in document order.
    pub params: Vec<Param>,
    /// Span of the tag.
    pub span: Span,
}

/// A `<param name expr|location>`.
#[derive(Clone, Debug)]
pub struct Param {
    /// Parameter name (read as `_event.data.<name>`).
    pub name: Ident,
    /// Value (`expr`, or `location` read as an expression).
    pub expr: SrcExpr,
    /// Declared type (`<!-- TYPE name:t -->` before it, or `type` attribute).
    pub ty: Option<TypeAnn>,
    /// Span of the tag.
    pub span: Span,
}
