//! What each receiver of each event does with it in each of its states, worked out once
//! per model: the transitions on the event there and whether the receiver may drop it
//! ([`EventSemantics::As2fm`]'s delivery checks read this instead of searching the
//! state's event list and re-deriving the drop rule at every check).

use super::*;

/// Receiver `k` of event `e` in one of its states: its transitions on `e` (a range of the
/// machine's `dispatch`) and whether it drops `e` when none of them is enabled.
#[derive(Clone, Copy, Debug)]
pub(super) struct RxCase {
    pub start: u32,
    pub end: u32,
    pub discard: bool,
}

/// Per receiver slot (the receivers of every event in turn, as the pool's copies are
/// laid out), the index of its first state's [`RxCase`] in the returned table; then the
/// table, one case per state of the receiving machine.
pub(super) fn receiver_table(model: &CompiledModel) -> (Vec<u32>, Vec<RxCase>) {
    let mut first = Vec::new();
    let mut cases = Vec::new();
    for (e, d) in model.events.iter().enumerate() {
        let flags = event_flags(&d.name);
        for &r in &d.receivers {
            first.push(cases.len() as u32);
            let Some(def) = model.machines.get(r as usize) else {
                continue;
            };
            let never = never_discards(&def.name);
            for st in &def.states {
                let (start, end) = match st.on_event.iter().find(|&&(x, _, _)| x == e as u32) {
                    Some(&(_, s, t)) if (t as usize) <= def.dispatch.len() && s <= t => (s, t),
                    _ => (0, 0),
                };
                cases.push(RxCase {
                    start,
                    end,
                    discard: may_discard(never, end > start, flags),
                });
            }
        }
    }
    (first, cases)
}
