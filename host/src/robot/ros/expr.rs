//! Rewrites the ROS pseudo-variables of a callback (`_msg.x`, `_req.x`, `_goal.x`, ...) into
//! the event parameters AS2FM's translation sends (`_event.data.ros_fields__x`).

use crate::robot::types::FlatField;

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

fn is_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

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

/// Rewrites `text`; an error is `(byte offset in text, message)`.
pub(crate) fn rewrite(text: &str, scope: &Scope) -> Result<String, (usize, String)> {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len() + 16);
    let mut i = 0;
    let mut last = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'\'' || c == b'"' {
            // Skip a string literal.
            i += 1;
            while i < b.len() && b[i] != c {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            continue;
        }
        if !is_ident(c) || (i > 0 && (is_ident(b[i - 1]) || b[i - 1] == b'.')) {
            i += 1;
            continue;
        }
        let start = i;
        while i < b.len() && is_ident(b[i]) {
            i += 1;
        }
        let word = &text[start..i];
        let Some(&prefix) = PREFIXES.iter().find(|p| **p == word) else {
            continue;
        };
        // The chain `.a.b.c` after the prefix.
        let mut parts: Vec<(&str, usize)> = Vec::new();
        let mut j = i;
        while j + 1 < b.len() && b[j] == b'.' && is_ident(b[j + 1]) {
            let s = j + 1;
            j = s;
            while j < b.len() && is_ident(b[j]) {
                j += 1;
            }
            parts.push((&text[s..j], j));
        }
        let names: Vec<&str> = parts.iter().map(|p| p.0).collect();
        let (replacement, used) = resolve(prefix, &names, scope).map_err(|m| (start, m))?;
        out.push_str(&text[last..start]);
        out.push_str(&replacement);
        last = if used == 0 { i } else { parts[used - 1].1 };
        i = last;
    }
    out.push_str(&text[last..]);
    Ok(out)
}

/// The replacement for `prefix.names...` and how many names it consumed.
fn resolve(prefix: &str, names: &[&str], scope: &Scope) -> Result<(String, usize), String> {
    let outside = || format!("`{prefix}` can only be used inside {}", owner(prefix));
    let leaf = |fields: &[FlatField], what: &str, path: &[&str], shown: &str| {
        if path.is_empty() {
            return Err(format!(
                "`{shown}` must name a field of {what} (`{shown}.<field>`)"
            ));
        }
        match match_leaf(fields, path) {
            Some((f, n)) => Ok((format!("_event.data.{}", f.param_name()), n)),
            None => {
                let known: Vec<String> = fields.iter().map(|f| f.dotted()).collect();
                let what_is = if fields.iter().any(|f| {
                    f.path.len() > path.len() && f.path.iter().zip(path).all(|(a, b)| a == b)
                }) {
                    "is a message, not a single field,"
                } else {
                    "is not a field"
                };
                Err(format!(
                    "`{shown}.{}` {what_is} of {what} (fields: {})",
                    path.join("."),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ))
            }
        }
    };
    match prefix {
        "_action" => {
            if !scope.action {
                return Err(outside());
            }
            match names.first() {
                Some(&"goal_id") => Ok(("_event.data.goal_id".into(), 1)),
                _ => Err("`_action` has only the field `goal_id`".into()),
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
                _ => Err("`_wrapped_result` has the fields `code` and `result`".into()),
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
        let (at, m) = rewrite("1 + _msg.nope", &scope).unwrap_err();
        assert_eq!(at, 4);
        assert!(m.contains("not a field") && m.contains("pose.x"), "{m}");
        assert!(rewrite("_msg.pose", &scope)
            .unwrap_err()
            .1
            .contains("is a message"));
        assert!(rewrite("_req.a", &scope)
            .unwrap_err()
            .1
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
