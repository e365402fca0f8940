//! Rewrites the ROS pseudo-variables of a callback (`_msg.x`, `_req.x`, `_goal.x`, ...) into
//! the event parameters AS2FM's translation sends (`_event.data.ros_fields__x`).

use crate::expr::ast::{Expr, ExprKind};
use crate::expr::parse_expr;
use crate::types::FlatField;

/// What the pseudo-variables of one callback refer to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Scope<'a> {
    /// `(prefix, fields, what)`: `_msg` with a topic's fields, `_req` with a request's, ...
    /// `what` names the message in errors (`topic /level (std_msgs/Int32)`).
    pub fields: Vec<(&'static str, &'a [FlatField], String)>,
    /// `_action.goal_id` is allowed (goal and thread-start handlers).
    pub action: bool,
    /// `_wrapped_result.result.x` and `_wrapped_result.code` are allowed, with these fields.
    pub result: Option<(&'a [FlatField], String)>,
}

/// The pseudo-variables this module knows; any of them outside its callback is an error.
const PREFIXES: [&str; 7] = [
    "_msg",
    "_req",
    "_res",
    "_goal",
    "_feedback",
    "_action",
    "_wrapped_result",
];

/// Where a pseudo-variable's callback is, for errors.
fn owner(prefix: &str) -> &'static str {
    match prefix {
        "_msg" => "<ros_topic_callback>",
        "_req" => "<ros_service_handle_request>",
        "_res" => "<ros_service_handle_response>",
        "_goal" => "<ros_action_handle_goal> or <ros_action_handle_thread_start>",
        "_feedback" => "<ros_action_handle_feedback>",
        "_action" => "<ros_action_handle_goal> or <ros_action_handle_thread_start>",
        _ => "a <ros_action_handle_*_result>",
    }
}

/// The leaf field that is the longest prefix of `path`, and how many path parts it uses.
fn match_leaf<'f>(fields: &'f [FlatField], path: &[&str]) -> Option<(&'f FlatField, usize)> {
    fields
        .iter()
        .filter(|f| f.path.len() <= path.len() && f.path.iter().zip(path).all(|(a, b)| a == b))
        .max_by_key(|f| f.path.len())
        .map(|f| (f, f.path.len()))
}

/// Rewrites `text`; an error is the byte offset in text and what is wrong there.
///
/// The text is read with the model's own expression parser ([`parse_expr`]); every chain
/// `prefix.a.b` whose root is a pseudo-variable is replaced, in the text, over the byte
/// range its syntax tree gives, so the rest of the text stays as the user wrote it. Text
/// that does not parse is left alone: reading the plain machine reports the syntax error
/// at its position.
pub(crate) fn rewrite(text: &str, scope: &Scope) -> Result<String, (usize, FieldError)> {
    let Ok(tree) = parse_expr(text) else {
        return Ok(text.to_string());
    };
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    collect(&tree, scope, &mut edits)?;
    edits.sort_by_key(|e| e.0);
    let mut out = String::with_capacity(text.len() + 16);
    let mut last = 0;
    for (from, to, with) in edits {
        out.push_str(&text[last..from]);
        out.push_str(&with);
        last = to;
    }
    out.push_str(&text[last..]);
    Ok(out)
}

/// The replacements for every pseudo-variable chain in `e`: `(start, end, text)`.
fn collect(
    e: &Expr,
    scope: &Scope,
    edits: &mut Vec<(usize, usize, String)>,
) -> Result<(), (usize, FieldError)> {
    // `root.a.b`: the member nodes from the outermost in, and the root.
    let mut members: Vec<(&str, &Expr)> = Vec::new();
    let mut root = e;
    while let ExprKind::Member(object, name, _) = &root.kind {
        members.push((name.as_str(), root));
        root = object;
    }
    if let ExprKind::Ident(id) = &root.kind {
        if let Some(&prefix) = PREFIXES.iter().find(|p| **p == id.as_str()) {
            members.reverse();
            let names: Vec<&str> = members.iter().map(|m| m.0).collect();
            let (with, used) =
                resolve(prefix, &names, scope).map_err(|m| (root.start as usize, m))?;
            // The node of the last name used: its range covers the chain from the root and
            // any parentheses around it, so what is replaced is balanced.
            let node = if used == 0 { root } else { members[used - 1].1 };
            edits.push((node.start as usize, node.end as usize, with));
            return Ok(());
        }
    }
    match &e.kind {
        ExprKind::Int(_)
        | ExprKind::Float(_)
        | ExprKind::Bool(_)
        | ExprKind::Str(_)
        | ExprKind::Ident(_) => Ok(()),
        ExprKind::Array(items) => items.iter().try_for_each(|x| collect(x, scope, edits)),
        ExprKind::Object(fields) => fields
            .iter()
            .try_for_each(|f| collect(&f.value, scope, edits)),
        ExprKind::Member(object, _, _) => collect(object, scope, edits),
        ExprKind::Unary(_, x) => collect(x, scope, edits),
        ExprKind::Index(a, b) | ExprKind::Binary(_, a, b) => {
            collect(a, scope, edits)?;
            collect(b, scope, edits)
        }
        ExprKind::Call(f, args) => {
            collect(f, scope, edits)?;
            args.iter().try_for_each(|x| collect(x, scope, edits))
        }
        ExprKind::Cond(c, a, b) => {
            collect(c, scope, edits)?;
            collect(a, scope, edits)?;
            collect(b, scope, edits)
        }
    }
}

/// The replacement for `prefix.names...` and how many names it consumed.
fn resolve(prefix: &str, names: &[&str], scope: &Scope) -> Result<(String, usize), FieldError> {
    let outside = || FieldError::Outside(prefix.to_string());
    let leaf = |fields: &[FlatField], what: &str, path: &[&str], shown: &str| {
        if path.is_empty() {
            return Err(FieldError::NoField {
                shown: shown.to_string(),
                what: what.to_string(),
            });
        }
        match match_leaf(fields, path) {
            Some((f, n)) => Ok((format!("_event.data.{}", f.param_name()), n)),
            None => Err(FieldError::NotALeaf {
                name: format!("{shown}.{}", path.join(".")),
                message: fields.iter().any(|f| {
                    f.path.len() > path.len() && f.path.iter().zip(path).all(|(a, b)| a == b)
                }),
                what: what.to_string(),
                known: fields.iter().map(|f| f.dotted()).collect(),
            }),
        }
    };
    match prefix {
        "_action" => {
            if !scope.action {
                return Err(outside());
            }
            match names.first() {
                Some(&"goal_id") => Ok(("_event.data.goal_id".into(), 1)),
                _ => Err(FieldError::ActionFields),
            }
        }
        "_wrapped_result" => {
            let Some((fields, what)) = &scope.result else {
                return Err(outside());
            };
            match names.first() {
                Some(&"code") => Ok(("_event.data.code".into(), 1)),
                Some(&"result") => {
                    let (r, n) = leaf(fields, what, &names[1..], "_wrapped_result.result")?;
                    Ok((r, n + 1))
                }
                _ => Err(FieldError::WrappedResultFields),
            }
        }
        _ => {
            let Some((_, fields, what)) = scope.fields.iter().find(|(p, _, _)| *p == prefix) else {
                return Err(outside());
            };
            leaf(fields, what, names, prefix)
        }
    }
}

/// Why a pseudo-variable chain names no event parameter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum FieldError {
    /// The pseudo-variable (`_msg`, ...) outside the callback that has it.
    Outside(String),
    /// The chain `shown` stops before a field of `what`.
    NoField { shown: String, what: String },
    /// `name` is not a leaf field of `what`: a message (`message`) or nothing; `known`,
    /// the leaf fields there are.
    NotALeaf {
        name: String,
        message: bool,
        what: String,
        known: Vec<String>,
    },
    /// `_action.` something other than `goal_id`.
    ActionFields,
    /// `_wrapped_result.` something other than `code` or `result`.
    WrappedResultFields,
}

impl std::fmt::Display for FieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FieldError::Outside(prefix) => {
                write!(f, "`{prefix}` can only be used inside {}", owner(prefix))
            }
            FieldError::NoField { shown, what } => write!(
                f,
                "`{shown}` must name a field of {what} (`{shown}.<field>`)"
            ),
            FieldError::NotALeaf {
                name,
                message,
                what,
                known,
            } => {
                let what_is = if *message {
                    "is a message, not a single field,"
                } else {
                    "is not a field"
                };
                let known = if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                };
                write!(f, "`{name}` {what_is} of {what} (fields: {known})")
            }
            FieldError::ActionFields => f.write_str("`_action` has only the field `goal_id`"),
            FieldError::WrappedResultFields => {
                f.write_str("`_wrapped_result` has the fields `code` and `result`")
            }
        }
    }
}

impl std::error::Error for FieldError {}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(path: &str, ty: &str) -> FlatField {
        FlatField {
            path: path.split('.').map(String::from).collect(),
            scxml_type: ty.into(),
            default: "0".into(),
        }
    }

    #[test]
    fn rewrites_leaves_and_keeps_the_rest() {
        let fields = [
            f("data", "int32[]"),
            f("pose.x", "float64"),
            f("pose.y", "float64"),
        ];
        let scope = Scope {
            fields: vec![("_msg", &fields, "topic t".into())],
            ..Scope::default()
        };
        assert_eq!(
            rewrite("_msg.data.length > 0 && _msg.pose.x < '_msg.no'", &scope).unwrap(),
            "_event.data.ros_fields__data.length > 0 && _event.data.ros_fields__pose__x < '_msg.no'"
        );
        assert_eq!(rewrite("a._msg + x_msg", &scope).unwrap(), "a._msg + x_msg");
        // Parentheses, indices and calls: the syntax tree says where a chain ends.
        assert_eq!(
            rewrite(
                "(_msg.pose.x) == f(( _msg.pose).y, _msg.data[_msg.pose.x])",
                &scope
            )
            .unwrap(),
            "_event.data.ros_fields__pose__x == f(_event.data.ros_fields__pose__y, \
             _event.data.ros_fields__data[_event.data.ros_fields__pose__x])"
        );
        // Text that does not parse is left to the reader of the plain machine.
        assert_eq!(rewrite("_msg.pose.x +", &scope).unwrap(), "_msg.pose.x +");
        let (at, m) = rewrite("1 + _msg.nope", &scope).unwrap_err();
        assert_eq!(at, 4);
        let m = m.to_string();
        assert!(m.contains("not a field") && m.contains("pose.x"), "{m}");
        assert!(rewrite("_msg.pose", &scope)
            .unwrap_err()
            .1
            .to_string()
            .contains("is a message"));
        assert!(rewrite("_req.a", &scope)
            .unwrap_err()
            .1
            .to_string()
            .contains("only be used inside"));
    }

    #[test]
    fn actions_and_results() {
        let fields = [f("sequence", "int32[]")];
        let scope = Scope {
            action: true,
            result: Some((&fields, "result".into())),
            ..Scope::default()
        };
        assert_eq!(
            rewrite(
                "_action.goal_id + _wrapped_result.result.sequence[1] + _wrapped_result.code",
                &scope
            )
            .unwrap(),
            "_event.data.goal_id + _event.data.ros_fields__sequence[1] + _event.data.code"
        );
    }

    #[test]
    fn never_panics_on_odd_text() {
        let fields = [f("data", "int32")];
        let scope = Scope {
            fields: vec![("_msg", &fields, "t".into())],
            ..Scope::default()
        };
        let text = "é_msg.data'\\'\"ü_msg._msg.é.data\\_msg.";
        let chars: Vec<(usize, char)> = text.char_indices().collect();
        for &(i, _) in &chars {
            for &(j, _) in &chars {
                if i <= j {
                    let _ = rewrite(&text[i..j], &scope);
                }
            }
            let _ = rewrite(&text[i..], &scope);
        }
    }
}
