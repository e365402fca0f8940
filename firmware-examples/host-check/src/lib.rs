//! Host side of the firmware examples: run an image under QEMU, decode its defmt log, check its verdicts against the host interpreter, measure it.
//!
//! # Pipeline
//!
//! 1. [`qemu::run`] boots an image on `qemu-system-arm` (machine
//!    `mps2-an386` for the Cortex-M4F build, `microbit` for the Cortex-M0
//!    one: [`BOARDS`], chosen by `$FIRMWARE_TARGET`) with semihosting, under
//!    a time limit, and returns the raw defmt stream and the exit status.
//! 2. [`log::decode`] turns the stream into messages with the image's defmt
//!    table (`defmt-decoder`); [`log::Log::parse`] reads the firmware's log
//!    lines (see the firmware crate's docs for the format).
//! 3. [`verdicts`] runs `monitor_core::Monitor` on this machine over the same
//!    program and trace, and [`verdicts::compare`] checks the firmware's
//!    verdict changes against it point for point.
//! 4. [`elf::sizes`] and [`callgraph`] measure the image: flash and RAM, and
//!    the `core::panicking` functions reachable from the monitor step.
//!
//! `tests/qemu.rs` runs steps 1-3 for each image; the `firmware-report`
//! binary prints the size, state, stack and panic-path report.

pub mod callgraph;
pub mod elf;
pub mod log;
pub mod qemu;
pub mod verdicts;

use std::path::{Path, PathBuf};

/// A program's state size split up: the words every property shares, and each property's own.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StateBreakdown {
    /// Bytes shared by all properties: last timestamp, atom bits, node value bits.
    pub shared: usize,
    /// Each property's name and the bytes its nodes own.
    pub props: Vec<(String, usize)>,
}

impl StateBreakdown {
    /// Every byte: what `Monitor::state_bytes` reports.
    pub fn total(&self) -> usize {
        self.shared + self.props.iter().map(|(_, b)| b).sum::<usize>()
    }
}

/// Splits `program`'s state by [`monitor_core::layout`]; `None` when a node has no layout.
pub fn state_breakdown(program: &monitor_core::Program<'_>) -> Option<StateBreakdown> {
    use monitor_core::layout;
    let shared = 8 * layout::first_node_word(program.atoms.len(), program.nodes.len());
    let mut props = Vec::new();
    for p in program.props {
        let nodes = program.nodes.get(p.first as usize..=p.root as usize)?;
        let words = nodes
            .iter()
            .map(|n| layout::node_words(&n.op))
            .sum::<Option<u64>>()?;
        props.push((p.name.to_string(), 8 * usize::try_from(words).ok()?));
    }
    Some(StateBreakdown { shared, props })
}

/// The images that replay the museum trace, as built by `firmware-examples`,
/// each with the baseline that replays the same trace without a monitor.
pub const IMAGES: [(&str, &str); 4] = [
    ("monitor-static", "baseline"),
    ("monitor-table", "baseline-bytes"),
    ("baseline", "baseline"),
    ("baseline-bytes", "baseline-bytes"),
];

/// Each monitored image and the function every monitor step goes through
/// (never inlined): where the panic-path analysis starts.
pub const STEPS: [(&str, &str); 2] = [
    ("monitor-static", "museum_spec::step"),
    ("monitor-table", "firmware::step_point"),
];

/// A target the firmware is built for and the QEMU board that runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Board {
    /// Rust target triple.
    pub target: &'static str,
    /// The core, for the report.
    pub core: &'static str,
    /// QEMU's `-machine`.
    pub machine: &'static str,
    /// QEMU's `-cpu`, when the machine's default is not the one.
    pub cpu: Option<&'static str>,
}

/// Every target the firmware is built for (`scripts/firmware` builds and checks each).
pub const BOARDS: [Board; 2] = [
    Board {
        target: "thumbv7em-none-eabihf",
        core: "Cortex-M4F",
        machine: "mps2-an386",
        cpu: Some("cortex-m4"),
    },
    Board {
        target: "thumbv6m-none-eabi",
        core: "Cortex-M0",
        machine: "microbit",
        cpu: None,
    },
];

/// The board of `$FIRMWARE_TARGET` (a target triple of [`BOARDS`]), else the first.
pub fn board() -> Result<Board, String> {
    match std::env::var("FIRMWARE_TARGET") {
        Ok(t) => BOARDS
            .iter()
            .copied()
            .find(|b| b.target == t)
            .ok_or_else(|| {
                format!(
                    "FIRMWARE_TARGET={t}: not one of {:?}",
                    BOARDS.map(|b| b.target)
                )
            }),
        Err(_) => Ok(BOARDS[0]),
    }
}

/// Where the images are: `$FIRMWARE_DIR`, else the firmware project's release output for [`board`].
pub fn image_dir() -> PathBuf {
    match std::env::var_os("FIRMWARE_DIR") {
        Some(d) => PathBuf::from(d),
        None => {
            let target = board().map(|b| b.target).unwrap_or(BOARDS[0].target);
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../target")
                .join(target)
                .join("release")
        }
    }
}

/// Reads image `name` from [`image_dir`], with a hint when it has not been built.
pub fn read_image(name: &str) -> Result<(PathBuf, Vec<u8>), String> {
    let path = image_dir().join(name);
    match std::fs::read(&path) {
        Ok(bytes) => Ok((path, bytes)),
        Err(e) => Err(format!(
            "{}: {e} (build the firmware first: scripts/firmware, or `cargo build --release` in firmware-examples/)",
            path.display()
        )),
    }
}

/// The table and trace bytes `monitor-table` embeds: the files named by
/// `HINDSIGHT_TABLE` / `HINDSIGHT_TRACE` when set (as for its build script),
/// else museum-spec's.
pub fn table_inputs() -> Result<(Vec<u8>, Vec<u8>), String> {
    let read = |var: &str, default: fn() -> Vec<u8>| match std::env::var_os(var) {
        Some(p) => std::fs::read(&p).map_err(|e| format!("{var}={}: {e}", Path::new(&p).display())),
        None => Ok(default()),
    };
    Ok((
        read("HINDSIGHT_TABLE", museum_spec::table_bytes)?,
        read("HINDSIGHT_TRACE", museum_spec::trace_bytes)?,
    ))
}
