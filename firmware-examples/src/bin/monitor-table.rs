//! Firmware B: a postcard monitor table and a replay trace, both embedded as bytes by build.rs, decoded and run at start-up: a new spec needs no new code.
#![no_std]
#![no_main]

// The table is `HINDSIGHT_TABLE` when set at build time, else museum.hspec's.
firmware::table_image!("monitor-table", "table.postcard", "table_info.rs");
