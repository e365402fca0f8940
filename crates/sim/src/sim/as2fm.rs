//! The naming conventions AS2FM's JANI translation gives meaning to, and the rule for
//! which events a machine may drop: the static half of [`super::EventSemantics::As2fm`].

use super::compiled::CompiledModel;
use super::ids::{EventId, MachineId, StateId};

/// A ROS timer event (`ros_time_rate.*`): a rendezvous with the global timer.
pub(crate) const EV_TIMER: u8 = 1;
/// A synchronised event: a machine without a transition on it in its state cannot drop it.
pub(crate) const EV_SYNCHED: u8 = 2;
/// The blackboard request, which waits for pending blackboard writes.
pub(crate) const EV_BB_REQ: u8 = 4;
/// A blackboard write (`bt_blackboard_set_*`).
pub(crate) const EV_BB_SET: u8 = 8;

/// AS2FM's flags for an event name.
///
/// Synchronised: BT `bt_N_tick`, `_halt`, `_response`, `_halt_response`; services
/// `srv_*_request`, `_response`, `_req_client*`; actions `action_*_goal_*`,
/// `action_*_result*`, `action_*_thread_start`, `action_*_thread_free` (feedback is not:
/// a client may drop some).
pub(crate) fn event_flags(name: &str) -> u8 {
    let mut f = 0;
    if name.starts_with("ros_time_rate.") {
        f |= EV_TIMER;
    }
    if name == "bt_blackboard_req" {
        f |= EV_BB_REQ;
    }
    if name.starts_with("bt_blackboard_set_") {
        f |= EV_BB_SET;
    }
    let bt = name.strip_prefix("bt_").and_then(|rest| {
        let digits = rest.find(|c: char| !c.is_ascii_digit())?;
        (digits > 0).then(|| &rest[digits..])
    });
    let synched = matches!(bt, Some("_tick" | "_halt" | "_response" | "_halt_response"))
        || name.strip_prefix("srv_").is_some_and(|rest| {
            ["_response", "_request", "_req_client"]
                .iter()
                .any(|k| rest.find(k).is_some_and(|i| i > 0))
        })
        || name.strip_prefix("action_").is_some_and(|rest| {
            rest.find("_goal_")
                .is_some_and(|i| i > 0 && rest.len() > i + "_goal_".len())
                || rest.find("_result").is_some_and(|i| i > 0)
                || ((rest.ends_with("_thread_start") && rest.len() > "_thread_start".len())
                    || (rest.ends_with("_thread_free") && rest.len() > "_thread_free".len()))
        });
    if synched {
        f |= EV_SYNCHED;
    }
    f
}

/// Machines that never drop an event: BT roots and ROS interface handlers.
pub(crate) fn never_discards(machine_name: &str) -> bool {
    ["bt_root_fsm", "srv_handler_", "action_handler_"]
        .iter()
        .any(|p| machine_name.starts_with(p))
}

/// Whether a machine with a transition-set on an event of `flags` in its state
/// (`has_transitions`) may drop it when none is enabled.
pub(crate) fn may_discard(never: bool, has_transitions: bool, flags: u8) -> bool {
    !never && (has_transitions || flags & EV_SYNCHED == 0)
}

/// Whether machine `m`, idle in state `s`, can take a pending event `e` under
/// [`super::EventSemantics::As2fm`] (fire a transition on it, or drop it). `false` for
/// events it has no transition on anywhere (it is not a receiver) and in states with an
/// unconditional eventless transition (which it leaves at once).
pub fn receptive(model: &CompiledModel, m: MachineId, s: StateId, e: EventId) -> bool {
    let (Some(def), Some(ev)) = (
        model.machines.get(m.0 as usize),
        model.events.get(e.0 as usize),
    ) else {
        return false;
    };
    let Some(st) = def.states.get(s.0 as usize) else {
        return false;
    };
    if !ev.receivers.contains(&m.0) {
        return false;
    }
    let leaves_at_once = st
        .eventless
        .iter()
        .any(|&t| def.trans.get(t as usize).is_some_and(|t| t.cond.is_none()));
    if leaves_at_once {
        return false;
    }
    let has = !st.transitions(e.0, &def.dispatch).is_empty();
    has || may_discard(never_discards(&def.name), has, event_flags(&ev.name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synchronised_event_names() {
        for n in [
            "bt_1000_tick",
            "bt_7_halt_response",
            "srv_X__tick_request",
            "srv_A_response_client_B",
            "srv_A_req_client_B",
            "action_nav_goal_handle",
            "action_nav_goal_accept_client_c",
            "action_nav_result_handle_client_c",
            "action_nav_thread_start",
        ] {
            assert_ne!(event_flags(n) & EV_SYNCHED, 0, "{n}");
        }
        for n in [
            "bt_tick",
            "bt_x_tick",
            "topic_level_msg",
            "action_nav_feedback",
            "ros_time_rate.t",
            "bt_blackboard_get",
        ] {
            assert_eq!(event_flags(n) & EV_SYNCHED, 0, "{n}");
        }
        assert_eq!(event_flags("ros_time_rate.t"), EV_TIMER);
        assert_eq!(event_flags("bt_blackboard_set_x"), EV_BB_SET);
        assert_eq!(event_flags("bt_blackboard_req"), EV_BB_REQ);
    }
}
