//! What a property port that does not fit the model is told: an event the model does not
//! send, a parameter or message field its event does not have, each named as the user
//! wrote it (a ROS port's topic and field, not the plain event they become).

use crate::sim::{CompiledModel, EventId};

/// A port's event the model does not send, said as the user wrote it (a ROS port's
/// `topic_a__b_msg` is topic `/a/b`) with the closest name the model does send.
pub(super) fn no_such_event(model: &CompiledModel, event: &str) -> String {
    let shown = |name: &str| match name
        .strip_prefix("topic_")
        .and_then(|n| n.strip_suffix("_msg"))
    {
        Some(t) => format!("topic `/{}`", t.replace("__", "/")),
        None => format!("event `{name}`"),
    };
    let closest = (0..model.event_count())
        .map(|e| model.event_name(EventId(e as u32)))
        .map(|n| (crate::robot::interfaces::edit_distance(event, n), n))
        .min();
    let hint = match closest {
        Some((d, n)) if d <= (event.len() / 4).max(2) => format!(" (did you mean {}?)", shown(n)),
        _ => String::new(),
    };
    let what = shown(event);
    if what.starts_with("topic") {
        format!("no node model publishes {what}{hint}")
    } else {
        format!("the model sends no {what}{hint}")
    }
}

/// Why `param` cannot be read from `event`: a ROS message field (`ros_fields__a__b`, a
/// port over a topic or service) is named as the user wrote it, with the fields there are.
pub(super) fn missing_param(model: &CompiledModel, event: EventId, param: &str) -> String {
    let params = model.event_params(event);
    match param.strip_prefix("ros_fields__") {
        Some(field) => {
            let fields: Vec<String> = params
                .iter()
                .filter_map(|(n, _)| n.strip_prefix("ros_fields__"))
                .map(|f| f.replace("__", "."))
                .collect();
            format!(
                "the message has no field `{}` (fields: {})",
                field.replace("__", "."),
                if fields.is_empty() {
                    "none".to_string()
                } else {
                    fields.join(", ")
                }
            )
        }
        None => {
            let names: Vec<&str> = params.iter().map(|(n, _)| n.as_str()).collect();
            format!(
                "event `{}` has no parameter `{param}` (parameters: {})",
                model.event_name(event),
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        }
    }
}
