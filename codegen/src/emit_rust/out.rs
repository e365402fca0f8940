//! The text of the emitted module: indented lines and doc comments.

#[derive(Default)]
pub(super) struct Out {
    pub(super) buf: String,
    pub(super) depth: usize,
}

impl Out {
    pub(super) fn line(&mut self, s: &str) {
        if !s.is_empty() {
            for _ in 0..self.depth {
                self.buf.push_str("    ");
            }
            self.buf.push_str(s);
        }
        self.buf.push('\n');
    }

    /// Every line of `text`, each indented to the current depth (blank lines stay blank).
    pub(super) fn block(&mut self, text: &str) {
        for l in text.lines() {
            self.line(l);
        }
    }

    pub(super) fn open(&mut self, s: &str) {
        self.line(s);
        self.depth += 1;
    }

    pub(super) fn close(&mut self, s: &str) {
        self.depth = self.depth.saturating_sub(1);
        self.line(s);
    }

    pub(super) fn doc(&mut self, s: &str) {
        if s.is_empty() {
            self.line("///");
        } else {
            self.line(&format!("/// {s}"));
        }
    }
}

/// User text made safe inside a one-line doc comment code span.
pub(super) fn doc_text(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\n' | '\r' => ' ',
            '`' => '\'',
            c => c,
        })
        .collect()
}

pub(super) fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
