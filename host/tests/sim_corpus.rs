//! Loads every corpus model (museum, AS2FM plain, UC3) and simulates the museum guide.

use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
}

#[test]
fn as2fm_plain_models_read() {
    let dir = corpus().join("as2fm/plain");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let has_scxml = std::fs::read_dir(&path)
            .unwrap()
            .any(|e| e.unwrap().path().extension().is_some_and(|x| x == "scxml"));
        if !has_scxml {
            // A case AS2FM translated to JANI only: a clear error, not a panic.
            let err = hindsight::model::load(&path).unwrap_err();
            assert!(err.to_string().contains("no .scxml file"), "{err}");
            continue;
        }
        match hindsight::model::load(&path) {
            Ok(m) => assert!(!m.machines.is_empty()),
            Err(e) => panic!("{}: {e}", path.display()),
        }
        n += 1;
    }
    assert!(n > 30);
}

#[test]
fn uc3_reads_through_model_xml() {
    let m = hindsight::model::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    assert_eq!(m.machines.len(), 278);
    assert!(m.properties.is_some());
}

#[test]
fn museum_reads() {
    let m = hindsight::model::load(&corpus().join("museum-simpar2025/model_scxml")).unwrap();
    // 57 machines plus the `NONE` sink machine the generator wrote.
    assert_eq!(m.machines.len(), 58);
}
