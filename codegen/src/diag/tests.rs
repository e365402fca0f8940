//! Unit tests of the source map, positions, snippets and the rendering of diagnostics.

use super::*;

#[test]
fn lines_and_character_columns() {
    let text = "ab\ncdé\nx";
    let index = LineIndex::new(text);
    assert_eq!(index.line_col(text, 0), (1, 1));
    assert_eq!(index.line_col(text, 4), (2, 2));
    // After the two-byte `é`, and inside it (counts as the character).
    assert_eq!(index.line_col(text, 7), (2, 4));
    assert_eq!(index.line_col(text, 6), (2, 3));
    assert_eq!(index.line_col(text, 8), (3, 1));
    assert_eq!(index.line_col(text, 99), (3, 2));
    assert_eq!(index.line_start(3), Some(8));
    assert_eq!(index.line_start(4), None);
    assert_eq!(index.line_start(0), None);
}

#[test]
fn one_rendering_for_every_payload() {
    let text = "<a>\n  <b x=\"1\"/>\r\n</a>";
    let index = LineIndex::new(text);
    let at = text.find("x=").unwrap();
    let mut sm = SourceMap::new();
    let file = sm.add("m.xml", text.to_string());
    let d = sm.diag(file.at(at as u32).to(file.at(at as u32 + 3)), "bad `x`");
    assert_eq!(
        d.to_string(),
        "m.xml:2:6: bad `x`\n      <b x=\"1\"/>\n         ^"
    );
    let w = d.clone().warning();
    assert!(w.to_string().starts_with("m.xml:2:6: warning: bad `x`\n"));
    // A caret found from a line and column gives the same snippet.
    let by_line = Snippet::at_line_col(text, &index, 2, 6);
    assert_eq!(by_line, Snippet::of(text, at, at));
    assert_eq!(Snippet::at_line_col(text, &index, 9, 1), Snippet::default());
    let whole: Diagnostic = Diagnostic::about_file("m.xml", "cannot read".into());
    assert_eq!(whole.to_string(), "m.xml: cannot read");
    let kind = d.map(|m| m.len());
    assert_eq!(kind.message, 7);
    assert_eq!((kind.line, kind.col), (2, 6));
}

#[test]
fn one_map_for_whole_files_and_placed_pieces() {
    let mut sm = SourceMap::new();
    let file = sm.add("a.scxml", "ab\ncdé\nx".to_string());
    // A formula from an attribute at 4:3 of `m.xml`, continued on the next line.
    let piece = FileId(sm.add_piece("m.xml", "p é\n  q", 4, 3, true));
    let made = FileId(sm.add_piece("m.xml", "event e;", 9, 5, false));
    let runs = [PositionRun {
        offset: 0,
        line: 2,
        col: 7,
        exact: true,
    }];
    let mapped = FileId(sm.add_mapped("m.xml", "a < b", (1, 1), &runs));
    let at = |id: FileId, k: u32| {
        let l = sm.locate(id.at(k));
        (l.file, l.line, l.col)
    };
    assert_eq!(at(file, 7), ("a.scxml".into(), 2, 4));
    assert_eq!(at(file, 99), ("a.scxml".into(), 3, 2));
    assert_eq!(
        sm.diag(file.at(8), "m").to_string(),
        "a.scxml:3:1: m\n    x\n    ^"
    );
    assert_eq!(at(piece, 2), ("m.xml".into(), 4, 5));
    // After the two-byte `é`: columns count characters.
    assert_eq!(at(piece, 4), ("m.xml".into(), 4, 6));
    assert_eq!(at(piece, 7), ("m.xml".into(), 5, 3));
    assert_eq!(at(made, 6), ("m.xml".into(), 9, 5));
    assert_eq!(at(mapped, 4), ("m.xml".into(), 2, 11));
    assert_eq!(sm.sources().len(), 4);
    assert_eq!(sm.source(piece).map(|s| s.line_col(2)), Some((4, 5)));
    // One rendering: carets under the span for the compiler, one caret for `diag`.
    let q = piece.at(7).to(piece.at(8));
    assert_eq!(
        sm.diagnostic(Severity::Warning, q, "unused".into())
            .to_string(),
        "m.xml:5:3: warning: unused\n      q\n      ^"
    );
    let word = file.at(3).to(file.at(7));
    assert_eq!(
        sm.diagnostic(Severity::Error, word, "m".into()).caret_len,
        3
    );
    assert_eq!(sm.diag(word, "m").caret_len, 1);
    // A span of no source in the map is about an unknown file, with no position.
    let lost = sm.diag(FileId(9).at(0), "gone");
    assert_eq!(lost.to_string(), "<unknown>: gone");
    assert_eq!(sm.locate(FileId(9).at(0)).line, 0);
    assert_eq!(sm.slice(word), "cdé");
}

#[test]
fn long_lines_and_long_lists_are_cut() {
    // A problem in the middle of a 100 000-character line shows 200 characters
    // around it, the caret under the problem.
    let mut text = "é".repeat(50_000);
    let at = text.len();
    text.push_str("BAD");
    text.push_str(&"x".repeat(50_000));
    text.push_str("\nnext");
    let s = Snippet::of(&text, at, at + 3);
    assert!(
        s.line.starts_with("...é") && s.line.ends_with("x..."),
        "{s:?}"
    );
    assert_eq!(s.line.chars().count(), SNIPPET_WIDTH + 6);
    let under: String = s.line.chars().skip(s.caret_col).take(3).collect();
    assert_eq!((under.as_str(), s.caret_len), ("BAD", 3));
    // Short lines are whole, without marks.
    let s = Snippet::of("ab\ncd\r\nef", 4, 4);
    assert_eq!((s.line.as_str(), s.caret_col), ("cd", 1));
    // Columns of a long ASCII line come without reading it.
    let mut sm = SourceMap::new();
    let line = format!("{}BAD", "y".repeat(70_000));
    let file = sm.add("m.xml", line.clone());
    assert_eq!(sm.locate(file.at(70_000)).col, 70_001);
    // A huge message is cut in the middle.
    let d = sm.diag(file.at(70_000), format!("bad `{line}`"));
    let shown = d.to_string();
    assert!(shown.len() < 3 * MESSAGE_WIDTH, "{}", shown.len());
    assert!(shown.contains("characters cut"));
    // A list shows its first MAX_SHOWN items and counts the rest.
    let all: Diagnostics = (0..50)
        .map(|i| sm.diag(file.at(i), format!("problem {i}")))
        .collect::<Vec<_>>()
        .into();
    let shown = all.to_string();
    assert!(shown.contains("problem 19") && !shown.contains("problem 20"));
    assert!(
        shown.ends_with("... and 30 more: 30 errors, 0 warnings"),
        "{shown}"
    );
}

#[test]
fn runs_map_offsets_back_to_the_file() {
    // `a &lt; b` unescaped to `a < b`: the run after the entity starts at column 11.
    let runs = [
        PositionRun {
            offset: 0,
            line: 4,
            col: 3,
            exact: true,
        },
        PositionRun {
            offset: 2,
            line: 4,
            col: 5,
            exact: true,
        },
        PositionRun {
            offset: 3,
            line: 4,
            col: 9,
            exact: true,
        },
        PositionRun {
            offset: 5,
            line: 7,
            col: 1,
            exact: false,
        },
    ];
    let text = "a < b and";
    assert_eq!(locate_in_runs(text, &runs, 0), Some((4, 3)));
    assert_eq!(locate_in_runs(text, &runs, 4), Some((4, 10)));
    assert_eq!(locate_in_runs(text, &runs, 8), Some((7, 1)));
    assert_eq!(locate_in_runs(text, &[], 1), None);
}

#[test]
fn sources_are_regular_utf8_files() {
    let dir = std::env::temp_dir().join(format!("diag-read-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bom = dir.join("bom.txt");
    std::fs::write(&bom, b"\xEF\xBB\xBFa\nb").unwrap();
    assert_eq!(read_source(&bom).unwrap(), "a\nb");
    let bad = dir.join("bad.txt");
    std::fs::write(&bad, b"ok\nab\xC3\xA9c\xFFd").unwrap();
    let d = read_source(&bad).unwrap_err();
    assert_eq!((d.line, d.col), (2, 5));
    assert!(d.message.contains("byte 0xFF"), "{d}");
    let cut = dir.join("cut.txt");
    std::fs::write(&cut, b"x\xC3").unwrap();
    assert!(read_source(&cut)
        .unwrap_err()
        .message
        .contains("ends inside"));
    let d = read_source(&dir).unwrap_err();
    assert_eq!(
        d.to_string(),
        format!("{}: is a directory, not a file", dir.display())
    );
    assert!(read_source(&dir.join("none"))
        .unwrap_err()
        .message
        .contains("not found"));
    #[cfg(unix)]
    assert_eq!(
        not_a_source_file(Path::new("/dev/zero")).as_deref(),
        Some("is a character device, not a regular file")
    );
    let _ = std::fs::remove_dir_all(&dir);
}
