//! Prints the firmware size report: flash and RAM with and without the monitor, state bytes per property, stack high-water mark in QEMU, panic paths below the monitor step.
//!
//! Usage: `firmware-report` (images of `$FIRMWARE_TARGET`, default
//! thumbv7em-none-eabihf, from `$FIRMWARE_DIR` or the firmware project's
//! release output for that target). Exits non-zero when an image is missing, fails
//! in QEMU, or a measurement cannot be made.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, ExitCode};
use std::time::Duration;

use host_check::callgraph::{self, Location};
use host_check::log::{decode, Log};
use host_check::verdicts::on_big_stack;
use host_check::{elf, qemu, read_image, state_breakdown, table_inputs, IMAGES, STEPS};
use monitor_core::table::Table;
use museum_spec::museum;

fn main() -> ExitCode {
    match report() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("firmware-report: {e}");
            ExitCode::FAILURE
        }
    }
}

fn report() -> Result<(), String> {
    let board = host_check::board()?;
    println!(
        "==== {} ({}, QEMU machine {})",
        board.target, board.core, board.machine
    );
    let mut sizes = BTreeMap::new();
    let mut stacks = BTreeMap::new();
    let mut tables = Vec::new();
    for (name, _) in IMAGES {
        let (path, bytes) = read_image(name)?;
        sizes.insert(name, elf::sizes(&bytes)?);
        let run = qemu::run(&path, Duration::from_secs(30))?;
        let log = Log::parse(decode(&bytes, &run.stdout)?)?;
        if !run.status.success() || !log.errors.is_empty() {
            return Err(format!(
                "{name} failed in QEMU ({:?}): {:?}",
                run.status, log.errors
            ));
        }
        let done = log.done.ok_or_else(|| format!("{name}: no `done` line"))?;
        stacks.insert(name, (done, run.elapsed));
        tables.extend(log.messages.into_iter().filter(|m| m.starts_with("table ")));
    }

    println!(
        "== Flash and RAM (bytes; RAM = static .data + .bss + .uninit, the stack comes on top)"
    );
    println!(
        "{:<16} {:>7} {:>7} {:>7} {:>7}   {:<15} {:>12} {:>10}",
        "image", "flash", "text", "rodata", "ram", "baseline", "flash - base", "ram - base"
    );
    for (name, baseline) in IMAGES {
        let s = sizes[name];
        let base = sizes[baseline];
        println!(
            "{:<16} {:>7} {:>7} {:>7} {:>7}   {:<15} {:>+12} {:>+10}",
            name,
            s.flash,
            s.text,
            s.rodata,
            s.ram,
            baseline,
            s.flash as i64 - base.flash as i64,
            s.ram as i64 - base.ram as i64
        );
    }
    println!(
        "(each image embeds the {}-point replay trace: as a static array in monitor-static and \
         baseline, as bytes in monitor-table and baseline-bytes; a baseline replays it without a monitor)",
        museum_spec::TRACE_LEN
    );
    largest_additions("monitor-static", "baseline")?;
    largest_additions("monitor-table", "baseline-bytes")?;

    println!();
    println!(
        "== Monitor state (bytes, fixed at compile time; the firmware allocates exactly this)"
    );
    let (museum_table, _) = table_inputs()?;
    let (breakdown, table_state, table_len) = on_big_stack(|| {
        let t = Table::<4096>::from_bytes(museum_spec::TABLE).map_err(|e| e.to_string())?;
        let b = state_breakdown(&t.program()).ok_or("museum program has no layout")?;
        let t2 = Table::<4096>::from_bytes(&museum_table).map_err(|e| e.to_string())?;
        let m = t2.monitor().map_err(|e| e.to_string())?;
        Ok((b, m.state_bytes(), museum_table.len()))
    })?;
    println!(
        "compiled from museum-spec/museum.hspec by hindsight-codegen; the compiler's layout \
         (interpreter state words), per property:"
    );
    println!(
        "shared by all properties (timestamp, atom bits, node value bits): {}",
        breakdown.shared
    );
    for (i, (name, bytes)) in breakdown.props.iter().enumerate() {
        let reported = museum_spec::PROPERTY_STATE_BYTES.get(i).copied();
        if reported != Some(*bytes) {
            return Err(format!(
                "property {name}: layout says {bytes} bytes, the compiler reported {reported:?}"
            ));
        }
        println!(
            "property {i} {name:<20} {bytes:>4}   {}",
            museum_spec::FORMULAS.get(i).copied().unwrap_or("")
        );
    }
    println!(
        "total (Monitor::state_bytes, monitor-table with the default table): {}",
        breakdown.total()
    );
    println!(
        "generated monitor (museum::STATE_BYTES, size_of its Monitor struct, monitor-static): {}",
        museum::STATE_BYTES
    );
    println!(
        "monitor-table: state {} bytes, postcard table {} bytes in flash; firmware log: {}",
        table_state,
        table_len,
        tables.join("; ")
    );

    println!();
    println!(
        "== Stack high-water mark (bytes; QEMU {}, cortex-m-rt paint-stack)",
        board.machine
    );
    println!(
        "{:<16} {:>6} {:>7} {:>7}   (set-up: decode and validate the program; replay: from then on, live frames included)",
        "image", "peak", "set-up", "replay"
    );
    for (name, _) in IMAGES {
        let (done, elapsed) = stacks[name];
        println!(
            "{name:<16} {:>6} {:>7} {:>7}   (QEMU run {elapsed:.2?})",
            done.stack, done.setup_stack, done.replay_stack
        );
    }

    println!();
    println!("== Panic paths below the monitor step (direct calls into core's panic entry points)");
    for (name, step) in STEPS {
        let (path, _) = read_image(name)?;
        let r = callgraph::analyse(&path, step)?;
        let (builtins, own): (Vec<&String>, Vec<&String>) = r.reachable.iter().partition(|f| {
            f.starts_with("__") || f.starts_with("compiler_builtins::") || f.as_str() == "fmod"
        });
        let own: Vec<&str> = own.iter().map(|s| s.as_str()).collect();
        let (float_div, other): (Vec<&String>, Vec<&String>) = builtins
            .iter()
            .partition(|f| callgraph::is_soft_float_or_division(f));
        println!(
            "{name}: the step reaches {} and {} compiler-builtins routines",
            own.join(", "),
            builtins.len()
        );
        let list = |v: &[&String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ")
            }
        };
        println!("  soft-float or 64-bit division: {}", list(&float_div));
        println!("  other builtins: {}", list(&other));
        if r.panic_calls.is_empty() {
            println!("  no panic entry point is reachable");
        }
        for (caller, callee, n) in &r.panic_calls {
            println!("  {caller} -> {callee}  ({n} call sites)");
        }
        print_locations("  panic locations", &r.locations);
    }
    for (name, step) in STEPS {
        let (path, _) = read_image(name)?;
        let step = callgraph::analyse(&path, step)?;
        let all = callgraph::analyse(&path, "main")?;
        let outside: Vec<Location> = all
            .locations
            .into_iter()
            .filter(|l| !step.locations.contains(l))
            .collect();
        print_locations(
            &format!("{name}: further panic locations reachable from `main` (start-up, logging)"),
            &outside,
        );
    }
    Ok(())
}

fn print_locations(title: &str, locations: &[Location]) {
    println!("{title}: {}", locations.len());
    for l in locations {
        println!("    {}:{}:{}", short_path(&l.file), l.line, l.col);
    }
}

/// `monitor-core/src/..` for the workspace crate, `crate-x.y.z/src/..` for a registry crate.
fn short_path(file: &str) -> String {
    if let Some((_, rest)) = file.split_once("/monitor-core/") {
        return format!("monitor-core/{rest}");
    }
    if let Some((_, rest)) = file.split_once("/registry/src/") {
        if let Some((_, krate)) = rest.split_once('/') {
            return krate.to_string();
        }
    }
    file.to_string()
}

/// The largest symbols of `image` that `baseline` does not have: where the monitor's flash goes.
fn largest_additions(image: &str, baseline: &str) -> Result<(), String> {
    let nm = callgraph::llvm_tool("llvm-nm")?;
    let symbols = |image: &Path| -> Result<BTreeMap<String, u64>, String> {
        let out = Command::new(&nm)
            .args(["-C", "--print-size", "--size-sort"])
            .arg(image)
            .output()
            .map_err(|e| format!("{}: {e}", nm.display()))?;
        let text = String::from_utf8_lossy(&out.stdout);
        Ok(text
            .lines()
            .filter_map(|l| {
                // "000011cc 00000e52 T firmware::step_point::h3ab4713ba77f7c1b"
                let mut f = l.splitn(4, ' ');
                let (_, size, kind, name) = (f.next()?, f.next()?, f.next()?, f.next()?);
                if !matches!(kind, "T" | "t" | "R" | "r" | "D" | "d") {
                    return None;
                }
                let size = u64::from_str_radix(size, 16).ok()?;
                let name = match name.rsplit_once("::h") {
                    Some((head, hash)) if hash.len() == 16 => head,
                    _ => name,
                };
                Some((name.to_string(), size))
            })
            .collect())
    };
    let (monitor, _) = read_image(image)?;
    let (base, _) = read_image(baseline)?;
    let base = symbols(&base)?;
    // Anonymous constants (`.Lanon.<hash>.<n>`) are named per image: one of
    // the baseline's with the same size (the embedded trace) is the same data.
    let mut base_anon: Vec<u64> = base
        .iter()
        .filter(|(n, _)| n.starts_with(".Lanon."))
        .map(|(_, s)| *s)
        .collect();
    let mut added: Vec<(String, u64)> = symbols(&monitor)?
        .into_iter()
        .filter(|(n, _)| !base.contains_key(n))
        .collect();
    added.retain(|(n, size)| {
        if !n.starts_with(".Lanon.") {
            return true;
        }
        match base_anon.iter().position(|s| s == size) {
            Some(i) => {
                base_anon.swap_remove(i);
                false
            }
            None => true,
        }
    });
    added.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    let total: u64 = added.iter().map(|(_, s)| s).sum();
    println!(
        "largest symbols {image} adds to {baseline} ({total} bytes in {} symbols):",
        added.len()
    );
    for (name, size) in added.iter().take(12) {
        println!("  {size:>6}  {name}");
    }
    Ok(())
}
