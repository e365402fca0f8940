//! Random texts for the readers' "no input panics" tests: tokens drawn by xorshift64.

/// `count` texts, each of fewer than `max_tokens` tokens from `tokens`, drawn by xorshift64
/// (shifts 13, 7, 17) from `seed`: the same texts on every run.
pub(crate) fn texts(tokens: &[&str], seed: u64, max_tokens: u64, count: usize) -> Vec<String> {
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
