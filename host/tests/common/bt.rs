//! Lowering a small format-4 tree written in a test: the document around a body, one
//! always-successful leaf `Act`, and the lowering's errors as the CLI prints them.

use hindsight::verify::model::source::SourceMap;
use hindsight::verify::model::xml::Element;
use hindsight::verify::model::Diagnostics;
use hindsight::verify::robot::bt::{self, BtInput, BtSemantics, BtTick, Halts};

/// The leaf type `Act`: SUCCESS at every tick.
pub const ACT: &str = r#"<ascxml xmlns="http://www.w3.org/2005/07/scxml" initial="s" version="1.0" name="Act">
<state id="s"><bt_tick target="s"><bt_return_status status="SUCCESS"/></bt_tick></state>
</ascxml>"#;

/// BT.CPP's rules, ticked with `tickOnce`.
pub const BTCPP: BtSemantics = BtSemantics::Btcpp { tick: BtTick::Once };

/// Lowers the document `tree.xml` that holds `body` in its main tree `Main` and `more`
/// after it, with `plugins` (file name, text): the machines, or the errors (each with
/// its file:line:col and the line under it).
pub fn lower_doc(
    body: &str,
    more: &str,
    plugins: &[(&str, &str)],
    semantics: BtSemantics,
) -> Result<Vec<Element>, String> {
    let tree = format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n{more}</root>\n"
    );
    let mut sm = SourceMap::new();
    let t = sm.add("tree.xml", tree);
    let plugins = plugins
        .iter()
        .map(|(name, text)| sm.add(*name, text.to_string()))
        .collect();
    bt::lower(
        &sm,
        &BtInput {
            tree: t,
            plugins,
            tick_rate_hz: 1.0,
            tick_if_not_running: false,
            halts: Halts::As2fm,
            semantics,
        },
    )
    .map_err(|ds| Diagnostics(ds).to_string())
}

/// [`lower_doc`] with the leaf `Act` only.
pub fn lower_act(body: &str, more: &str, semantics: BtSemantics) -> Result<Vec<Element>, String> {
    lower_doc(body, more, &[("act.ascxml", ACT)], semantics)
}
