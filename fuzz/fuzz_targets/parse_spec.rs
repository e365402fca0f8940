//! Fuzz target: any text through every stage of the `.hspec` front end, then the table loader.
//!
//! Crashes found here go into `codegen/tests/no_panic.rs` (`REGRESSIONS`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use monitor_core::table::Table;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    match codegen::compile_spec(src, "fuzz.hspec") {
        Ok(c) => {
            let _ = c.ir();
            let bytes = c.to_table_bytes();
            // Every compiled program must load back; a failure is a compiler bug.
            if c.program().nodes.len() <= 1024 {
                assert!(Table::<1024>::from_bytes(&bytes).is_ok());
            }
        }
        Err(d) => {
            let _ = d.to_string();
        }
    }
});
