//! Firmware C: monitor-table's code with museum-spec's `final.hspec`, whose verdicts all become final during the run: the image must say so and stop stepping there.
#![no_std]
#![no_main]

firmware::table_image!("monitor-final", "final.postcard", "final_info.rs");
