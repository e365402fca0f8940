//! ROS 2 interface definitions (`.msg`, `.srv`, `.action`): the parsed types, the file
//! format read with positions, and the standard packages built in.
//!
//! `def.rs` the parsed types, `parse.rs` the file format (one field or constant a line,
//! `---` between the parts of a service or an action), `builtin.rs` with
//! `builtin/<package>.txt` the built-in packages. Robot models (`hindsight`'s
//! `robot::interfaces`, which adds where packages are found and the flattening the ROS
//! lowering sends) and recordings ([`crate::schema`]) read definitions through this one
//! reader.

pub mod builtin;
mod def;
mod parse;

pub use def::*;
pub use parse::{parse_interface, valid_generated_type_name, valid_type_name};

/// Random texts for the "no input panics" tests: `count` texts of fewer than `max_tokens`
/// tokens from `tokens`, drawn by xorshift64 (shifts 13, 7, 17) from `seed`.
#[cfg(test)]
pub(crate) fn random_texts(
    tokens: &[&str],
    seed: u64,
    max_tokens: u64,
    count: usize,
) -> Vec<String> {
    let mut state = seed;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    (0..count)
        .map(|_| {
            let mut text = String::new();
            for _ in 0..(next() % max_tokens) {
                text.push_str(tokens[(next() % tokens.len() as u64) as usize]);
            }
            text
        })
        .collect()
}
