//! The text of a robot model's behavior-tree half for the lowering harness: one plugin
//! per scripted leaf type (answers its script; its ticks and halts are messages the
//! harness observes) and a driver that ticks the root a fixed number of times.

use super::oracle::Scripts;

/// Whether leaf type `name`'s plugin has a `<bt_halt>`: all but `N0`, `N1`, ... The
/// lowering under `Halts::WhenNeeded` sends such a leaf no halt at all (its halt changes
/// nothing), so a comparison drops the halts the oracle gives it.
pub fn has_halt(name: &str) -> bool {
    let b = name.as_bytes();
    !(b.len() > 1 && b[0] == b'N' && b[1].is_ascii_digit())
}

/// What a leaf with an `out` port (a type named `O<digit>...`, [`has_out`]) writes there
/// at its k-th callback: `OUT_VALUES[k % 4]`, a double (the plugin's port is `float64`).
pub const OUT_VALUES: [&str; 4] = ["1.5", "0.5", "-2.0", "3.25"];

/// Whether leaf type `name` has an output port `out` of type `float64` ([`OUT_VALUES`]).
pub fn has_out(name: &str) -> bool {
    let b = name.as_bytes();
    b.len() > 1 && b[0] == b'O' && b[1].is_ascii_digit()
}

/// Whether leaf type `name` has an input port `in` of type `float64` (types `I<digit>...`):
/// it reads nothing the harness observes; the port makes BT.CPP create the entry, empty,
/// when it loads the tree.
pub fn has_in(name: &str) -> bool {
    let b = name.as_bytes();
    b.len() > 1 && b[0] == b'I' && b[1].is_ascii_digit()
}

/// Whether leaf type `name` has an input port `in` of type `string` (types
/// `T<digit>...`): it answers SUCCESS while the text it reads is [`IN_TEXT`], its script
/// otherwise ([`plugin`]).
pub fn has_in_text(name: &str) -> bool {
    let b = name.as_bytes();
    b.len() > 1 && b[0] == b'T' && b[1].is_ascii_digit()
}

/// The text that makes a [`has_in_text`] leaf answer SUCCESS.
pub const IN_TEXT: &str = "a";

/// The plugin of leaf type `name`: on its k-th tick it answers `script[k % len]` (after
/// writing `OUT_VALUES[k % 4]` to its port `out`, [`has_out`]); a halt is answered and
/// does not move it. A type named `N<digit>...` has no `<bt_halt>` ([`has_halt`]), as older
/// AS2FM plugins have none (the lowering answers their halts in every state).
pub fn plugin(name: &str, script: &[super::tree::Status]) -> String {
    let len = script.len();
    let mut branches = String::new();
    for (i, s) in script.iter().enumerate() {
        let head = if i == 0 {
            format!("<if cond=\"k == {i}\">")
        } else if i + 1 == len {
            "<else/>".to_string()
        } else {
            format!("<elseif cond=\"k == {i}\"/>")
        };
        branches += &format!(
            "{head}<assign location=\"k\" expr=\"{}\"/><bt_return_status status=\"{}\"/>",
            (i + 1) % len,
            s.name()
        );
    }
    if len == 1 {
        branches = format!("<bt_return_status status=\"{}\"/>", script[0].name());
    } else {
        branches += "</if>";
    }
    let halt = if !has_halt(name) {
        ""
    } else {
        "<bt_halt target=\"s\"><bt_return_halted/></bt_halt>\n"
    };
    let j = if has_out(name) {
        "<data id=\"j\" type=\"int32\" expr=\"0\"/>"
    } else if has_in_text(name) {
        "<data id=\"m\" type=\"string\" expr=\"''\"/>"
    } else {
        ""
    };
    let (port, write) = if has_out(name) {
        let n = OUT_VALUES.len();
        let mut w = String::new();
        for (i, v) in OUT_VALUES.iter().enumerate() {
            let head = match i {
                0 => format!("<if cond=\"j == {i}\">"),
                _ if i + 1 == n => "<else/>".to_string(),
                _ => format!("<elseif cond=\"j == {i}\"/>"),
            };
            w += &format!("{head}<bt_set_output key=\"out\" expr=\"{v}\"/>");
        }
        w += &format!("</if><assign location=\"j\" expr=\"(j + 1) % {n}\"/>");
        ("<bt_declare_port_out key=\"out\" type=\"float64\"/>\n", w)
    } else if has_in(name) {
        (
            "<bt_declare_port_in key=\"in\" type=\"float64\"/>\n",
            String::new(),
        )
    } else if has_in_text(name) {
        // Read the text; IN_TEXT answers SUCCESS (the script still moves on).
        branches = format!(
            "<assign location=\"m\"><expr><bt_get_input key=\"in\"/></expr></assign>\
             <if cond=\"m == '{IN_TEXT}'\"><assign location=\"k\" expr=\"(k + 1) % {len}\"/>\
             <bt_return_status status=\"SUCCESS\"/><else/>{branches}</if>"
        );
        (
            "<bt_declare_port_in key=\"in\" type=\"string\"/>\n",
            String::new(),
        )
    } else {
        ("", String::new())
    };
    format!(
        r#"<ascxml xmlns="http://www.w3.org/2005/07/scxml" initial="s" version="1.0" name="{name}">
{port}<datamodel><data id="k" type="int32" expr="0"/>{j}</datamodel>
<state id="s">
<bt_tick target="s">{write}{branches}</bt_tick>
{halt}</state>
</ascxml>"#
    )
}

/// Every leaf type's plugin: (type name, text).
pub fn plugins(scripts: &Scripts) -> Vec<(String, String)> {
    scripts
        .iter()
        .map(|(n, s)| (n.clone(), plugin(n, s)))
        .collect()
}

/// The machine that stands in for the tree's root machine `name`: ticks node 1000
/// (machine `root`) `ticks` times, each after the previous answer.
pub fn driver(name: &str, root: &str, ticks: usize) -> String {
    format!(
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" name="{name}" initial="go">
<datamodel><data id="n" type="int32" expr="1"/></datamodel>
<state id="go">
<onentry><send event="bt_1000_tick" target="{root}"/></onentry>
<transition event="bt_1000_response" cond="n &lt; {ticks}" target="go"><assign location="n" expr="n + 1"/></transition>
<transition event="bt_1000_response" target="done"/>
</state>
<state id="done"/>
</scxml>"#
    )
}
