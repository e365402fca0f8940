//! The project's one CSV grammar: RFC 4180 quoting, written by `hindsight trace` and `verify --save-failing` and read by `hindsight report` and `hindsight replay`.
//!
//! A field holding `,`, `"` or a line break is quoted, a `"` inside doubled
//! ([`field`]); [`records`] reads such text back, so every value round-trips, and
//! [`rows`] is what every reader of a file calls: the same records, with a UTF-8 byte
//! order mark dropped and comment lines (`#` first) and blank rows skipped, an error as a
//! located [`Diagnostic`]. It lives in the foundation crate so that every reader and
//! writer of the host (recorder, report, trace replay) names this one module.

use crate::diag::Diagnostic;

/// Appends `text` as one CSV field: as it is, or quoted with `"` doubled when it holds a
/// `,`, a `"` or a line break.
pub fn field(out: &mut String, text: &str) {
    if text.contains([',', '"', '\n', '\r']) {
        out.push('"');
        out.push_str(&text.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(text);
    }
}

/// One CSV record: the line it starts on (from 1) and its fields, each with the column
/// (in characters, from 1) where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// The line of the record's first character.
    pub line: usize,
    /// The fields, unquoted, with their starting columns.
    pub fields: Vec<(String, usize)>,
}

/// Reads CSV text (RFC 4180: quoted fields may hold `,`, `""` and line breaks); empty
/// lines are skipped. An unterminated quote is an error at the quote's line and column.
pub fn records(text: &str) -> Result<Vec<Record>, Unterminated> {
    let mut out = Vec::new();
    let (mut line, mut col) = (1usize, 1usize);
    let mut chars = text.chars().peekable();
    while chars.peek().is_some() {
        // An empty line is no record.
        if matches!(chars.peek(), Some('\n')) {
            chars.next();
            line += 1;
            col = 1;
            continue;
        }
        let mut rec = Record {
            line,
            fields: Vec::new(),
        };
        loop {
            let start = col;
            let mut value = String::new();
            if chars.peek() == Some(&'"') {
                let (open_line, open_col) = (line, col);
                chars.next();
                col += 1;
                loop {
                    match chars.next() {
                        None => {
                            return Err(Unterminated {
                                line: open_line,
                                column: open_col,
                            })
                        }
                        Some('"') => {
                            col += 1;
                            if chars.peek() == Some(&'"') {
                                chars.next();
                                col += 1;
                                value.push('"');
                            } else {
                                break;
                            }
                        }
                        Some('\n') => {
                            value.push('\n');
                            line += 1;
                            col = 1;
                        }
                        Some(c) => {
                            value.push(c);
                            col += 1;
                        }
                    }
                }
            }
            // Unquoted (or after a closing quote): up to the next `,` or line end.
            while let Some(&c) = chars.peek() {
                if c == ',' || c == '\n' {
                    break;
                }
                chars.next();
                col += 1;
                if c != '\r' {
                    value.push(c);
                }
            }
            rec.fields.push((value, start));
            match chars.next() {
                Some(',') => col += 1,
                Some(_) => {
                    line += 1;
                    col = 1;
                    break;
                }
                None => break,
            }
        }
        out.push(rec);
    }
    Ok(out)
}

/// A quoted field that the text ends inside: where its opening quote is (1-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unterminated {
    /// The quote's line.
    pub line: usize,
    /// The quote's column, in characters.
    pub column: usize,
}

impl std::fmt::Display for Unterminated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("unterminated quoted field")
    }
}

impl std::error::Error for Unterminated {}

/// The rows of the CSV file `file` (its name, for errors) with text `text`: its
/// [`records`], after a UTF-8 byte order mark, without comment lines (a first field
/// starting with `#`) and rows whose every field is blank. The one reader of CSV files:
/// what `hindsight trace` and `verify --save-failing` write, `replay` and `report` read.
/// An unterminated quote is an error at its `file:line:col`.
pub fn rows(file: &str, text: &str) -> Result<Vec<Record>, Diagnostic> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let all = records(text)
        .map_err(|u| Diagnostic::error(file, (u.line as u32, u.column as u32), u.to_string()))?;
    Ok(all
        .into_iter()
        .filter(|r| {
            let first = r.fields.first().map_or("", |(f, _)| f.trim_start());
            !(first.starts_with('#') || r.fields.iter().all(|(f, _)| f.trim().is_empty()))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip_through_quotes() {
        let values = ["plain", "a,b", "say \"hi\"", "two\nlines", ""];
        let mut text = String::new();
        for (i, v) in values.iter().enumerate() {
            if i > 0 {
                text.push(',');
            }
            field(&mut text, v);
        }
        text.push_str("\nx,y\n");
        let r = records(&text).unwrap();
        assert_eq!(r.len(), 2);
        let got: Vec<&str> = r[0].fields.iter().map(|(v, _)| v.as_str()).collect();
        assert_eq!(got, values);
        assert_eq!(r[1].line, 3);
        assert_eq!(
            r[1].fields,
            vec![("x".to_string(), 1), ("y".to_string(), 3)]
        );
        assert_eq!(
            records("a,\"open\n"),
            Err(Unterminated { line: 1, column: 3 })
        );
    }

    #[test]
    fn rows_skip_the_mark_comments_and_blank_rows() {
        let r = rows("t.csv", "\u{feff}time,x\n# a comment\n , \n\n1,\"#not\"\n").unwrap();
        let got: Vec<(usize, Vec<&str>)> = r
            .iter()
            .map(|r| (r.line, r.fields.iter().map(|(f, _)| f.as_str()).collect()))
            .collect();
        assert_eq!(got, [(1, vec!["time", "x"]), (5, vec!["1", "#not"])]);
        assert_eq!(
            rows("t.csv", "a\n\"open").unwrap_err().to_string(),
            "t.csv:2:1: unterminated quoted field"
        );
    }
}
