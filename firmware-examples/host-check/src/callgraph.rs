//! Panic paths in a linked image: the direct-call graph from `llvm-objdump -d`, the `core` panic entry points reachable from a root function, and the source locations of the panics it can raise.
//!
//! Only direct calls and branches are followed (`bl`, `b.w`, conditional
//! branches to another symbol); the firmware's step makes no indirect calls,
//! and every `core::panicking` entry is called directly. A panic's source
//! location is the `core::panic::Location` record whose address the caller
//! materialises (`movw`/`movt` pair or literal-pool `ldr`) before calling into
//! `core`: reading the record from the image gives file, line and column.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::process::Command;

use object::{Object, ObjectSection};

/// One function of the disassembly.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Function {
    /// Demangled name, without the `::h<hash>` suffix.
    pub name: String,
    /// Start address.
    pub addr: u64,
    /// Direct calls and branches to other functions: (call site, callee name).
    pub calls: Vec<(u64, String)>,
    /// 32-bit constants the function builds (`movw`/`movt`) or loads from its literal pool.
    pub constants: Vec<u64>,
}

/// A `core::panic::Location` found in the image.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Location {
    /// Source file as compiled.
    pub file: String,
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1.
    pub col: u32,
}

/// What can panic below a root function.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PanicReport {
    /// Functions reachable from the root without entering `core`'s panic machinery (the root first).
    pub reachable: Vec<String>,
    /// Calls into panic entry points: (caller, panic entry, number of call sites).
    pub panic_calls: Vec<(String, String, usize)>,
    /// Panic locations materialised by the reachable functions, sorted.
    pub locations: Vec<Location>,
}

/// Whether `name` is one of `core`'s panic entry points (`core::panicking::*`,
/// the slice and `unwrap`/`expect` failure helpers, the panic handler).
pub fn is_panic_entry(name: &str) -> bool {
    name.starts_with("core::panicking::")
        || (name.starts_with("core::")
            && (name.contains("_fail") || name.contains("failed") || name.contains("panic")))
        || name.ends_with("rust_begin_unwind")
}

/// `name` without a trailing `::h` + 16 hex digits.
fn strip_hash(name: &str) -> &str {
    match name.rsplit_once("::h") {
        Some((head, hash)) if hash.len() == 16 && hash.bytes().all(|b| b.is_ascii_hexdigit()) => {
            head
        }
        _ => name,
    }
}

fn hex(s: &str) -> Option<u64> {
    u64::from_str_radix(s.trim_start_matches("0x"), 16).ok()
}

/// Parses `llvm-objdump -d --no-show-raw-insn -C` output; `read_u32` reads a
/// word of the image (for literal-pool loads).
pub fn parse(disassembly: &str, read_u32: impl Fn(u64) -> Option<u32>) -> Vec<Function> {
    let mut functions: Vec<Function> = Vec::new();
    let mut movw: BTreeMap<String, u64> = BTreeMap::new();
    for line in disassembly.lines() {
        // "00000470 <name>:" (instruction lines are indented)
        if !line.starts_with(char::is_whitespace) {
            if let Some((addr, name)) = line
                .split_once(" <")
                .and_then(|(a, rest)| Some((hex(a)?, rest.strip_suffix(">:")?)))
            {
                functions.push(Function {
                    name: strip_hash(name).to_string(),
                    addr,
                    ..Function::default()
                });
                movw.clear();
            }
            continue;
        }
        // "     668:      \tbl\t0xe5c <core::panicking::panic_bounds_check> @ imm = #0x7f0"
        let Some(f) = functions.last_mut() else {
            continue;
        };
        let Some((addr, insn)) = line.trim_start().split_once(':') else {
            continue;
        };
        let Some(site) = hex(addr) else {
            continue;
        };
        let mut parts = insn.trim().splitn(2, '\t');
        let mnemonic = parts.next().unwrap_or_default().trim();
        let operands = parts.next().unwrap_or_default().trim();
        if mnemonic.starts_with('b') {
            if let Some(target) = operands
                .split_once('<')
                .and_then(|(_, t)| t.split_once('>'))
                .map(|(t, _)| t)
            {
                // A branch into the middle of another function is no call: compiled code
                // enters a function at its start. Such a "branch" is data (a jump table's
                // bytes, padding) that the disassembler decoded as an instruction; seen on
                // Cortex-M0, where `monitor_core::expr::cmp`'s table decoded as `bmi` into
                // `firmware::finish` and made the step seem to reach defmt.
                let (name, into_middle) = match target.split_once('+') {
                    Some((name, _)) => (name, true),
                    None => (target, false),
                };
                let target = strip_hash(name);
                if target != f.name && !into_middle {
                    f.calls.push((site, target.to_string()));
                }
            }
        } else if mnemonic.starts_with("movw") || mnemonic.starts_with("movt") {
            // "movw\tr2, #0x44e8"
            let Some((reg, imm)) = operands.split_once(", #") else {
                continue;
            };
            let Some(imm) = hex(imm.split_whitespace().next().unwrap_or_default()) else {
                continue;
            };
            if mnemonic.starts_with("movw") {
                movw.insert(reg.to_string(), imm);
            } else if let Some(lo) = movw.remove(reg) {
                f.constants.push(imm << 16 | lo);
            }
        } else if mnemonic.starts_with("ldr") && operands.contains("[pc") {
            // "ldr\tr0, [pc, #0x14]  @ 0xe7c <...>"
            if let Some(word) = operands
                .split_once("@ ")
                .and_then(|(_, a)| hex(a.split_whitespace().next().unwrap_or_default()))
                .and_then(&read_u32)
            {
                f.constants.push(u64::from(word));
            }
        }
    }
    functions
}

/// Functions reachable from those named `root` (demangled, without hash), and their calls into panic entry points.
pub fn panic_report(
    functions: &[Function],
    root: &str,
    location_at: impl Fn(u64) -> Option<Location>,
) -> Result<PanicReport, String> {
    let by_name: BTreeMap<&str, &Function> =
        functions.iter().map(|f| (f.name.as_str(), f)).collect();
    let start = by_name
        .get(root)
        .ok_or_else(|| format!("no function `{root}` in the image"))?;
    let mut seen = BTreeSet::from([start.name.as_str()]);
    let mut queue = VecDeque::from([*start]);
    let mut report = PanicReport::default();
    let mut calls: BTreeMap<(String, String), usize> = BTreeMap::new();
    let mut locations = BTreeSet::new();
    while let Some(f) = queue.pop_front() {
        report.reachable.push(f.name.clone());
        locations.extend(f.constants.iter().filter_map(|&c| location_at(c)));
        for (_, callee) in &f.calls {
            if is_panic_entry(callee) {
                *calls.entry((f.name.clone(), callee.clone())).or_default() += 1;
            } else if let Some(g) = by_name.get(callee.as_str()) {
                if seen.insert(g.name.as_str()) {
                    queue.push_back(g);
                }
            }
        }
    }
    report.panic_calls = calls.into_iter().map(|((a, b), n)| (a, b, n)).collect();
    report.locations = locations.into_iter().collect();
    Ok(report)
}

/// Reads a little-endian word of the image at `addr`, from whichever allocated section holds it.
pub fn read_u32(elf: &object::File<'_>, addr: u64) -> Option<u32> {
    let bytes = read_bytes(elf, addr, 4)?;
    Some(u32::from_le_bytes(bytes.try_into().ok()?))
}

fn read_bytes<'d>(elf: &object::File<'d>, addr: u64, len: u64) -> Option<&'d [u8]> {
    elf.sections().find_map(|s| {
        let object::SectionFlags::Elf { sh_flags } = s.flags() else {
            return None;
        };
        let end = s.address().checked_add(s.size())?;
        // Only sections in target memory (SHF_ALLOC); debug sections also start at 0.
        if sh_flags & 0x2 == 0 || addr < s.address() || addr.checked_add(len)? > end {
            return None;
        }
        let data = s.data().ok()?;
        let off = usize::try_from(addr - s.address()).ok()?;
        data.get(off..off + usize::try_from(len).ok()?)
    })
}

/// The `core::panic::Location` at `addr`, if the 16 bytes there look like one:
/// a pointer to a `.rs` path of plausible length, then line and column.
pub fn location_at(elf: &object::File<'_>, addr: u64) -> Option<Location> {
    if addr % 4 != 0 {
        return None;
    }
    let ptr = read_u32(elf, addr)?;
    let len = read_u32(elf, addr + 4)?;
    let line = read_u32(elf, addr + 8)?;
    let col = read_u32(elf, addr + 12)?;
    if !(1..4096).contains(&len) || line == 0 || col == 0 || line > 1_000_000 {
        return None;
    }
    let file = std::str::from_utf8(read_bytes(elf, u64::from(ptr), u64::from(len))?).ok()?;
    let file = file.trim_end_matches('\0');
    file.ends_with(".rs").then(|| Location {
        file: file.to_string(),
        line,
        col,
    })
}

/// Whether `name` is a compiler-builtins routine (or libm's `fmod`) for
/// soft floating point or 64-bit division: what an integer-only spec's step
/// must not reach on a core without an FPU or a 64-bit divider. Other
/// builtins (`memcpy`, 64-bit shifts and multiplies) are not counted.
pub fn is_soft_float_or_division(name: &str) -> bool {
    let n = name.rsplit("::").next().unwrap_or(name);
    // ARM EABI names: __aeabi_d* (f64), __aeabi_f* (f32), __aeabi_[u]ldivmod,
    // __aeabi_[u]idiv*, conversions to and from floats (*2d, *2f, d2*, f2*).
    let aeabi = n.strip_prefix("__aeabi_").is_some_and(|r| {
        r.starts_with('d')
            || r.starts_with('f')
            || r.contains("div")
            || r.ends_with("2d")
            || r.ends_with("2f")
    });
    // Generic compiler-builtins names: __adddf3, __divdi3, __udivmoddi4, ...
    let generic = n.starts_with("__")
        && (n.ends_with("df3")
            || n.ends_with("sf3")
            || n.contains("div")
            || n.contains("mod")
            || n.contains("float"));
    aeabi
        || generic
        || n == "fmod"
        || name.contains("::float::")
        || name.contains("libm_math")
        || name.contains("div_rem")
        || name.contains("::int::udiv")
        || name.contains("::int::sdiv")
}

/// The rustup `llvm-tools` binary `name` (`rustup component add llvm-tools`).
pub fn llvm_tool(name: &str) -> Result<PathBuf, String> {
    let out = |args: &[&str]| -> Result<String, String> {
        let o = Command::new("rustc")
            .args(args)
            .output()
            .map_err(|e| format!("rustc: {e}"))?;
        Ok(String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let sysroot = out(&["--print", "sysroot"])?;
    let vv = out(&["-vV"])?;
    let host = vv
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .ok_or("rustc -vV names no host")?;
    let path = Path::new(&sysroot)
        .join("lib/rustlib")
        .join(host)
        .join("bin")
        .join(name);
    if path.exists() {
        Ok(path)
    } else {
        Err(format!(
            "{} not found: rustup component add llvm-tools",
            path.display()
        ))
    }
}

/// Disassembles `image` with llvm-objdump, names demangled.
pub fn disassemble(image: &Path) -> Result<String, String> {
    let objdump = llvm_tool("llvm-objdump")?;
    let out = Command::new(&objdump)
        .args(["-d", "--no-show-raw-insn", "-C"])
        .arg(image)
        .output()
        .map_err(|e| format!("{}: {e}", objdump.display()))?;
    if !out.status.success() {
        return Err(format!(
            "llvm-objdump failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    String::from_utf8(out.stdout).map_err(|e| format!("llvm-objdump output: {e}"))
}

/// The panic report of `image` below `root`: disassembles, parses and resolves locations.
pub fn analyse(image: &Path, root: &str) -> Result<PanicReport, String> {
    let bytes = std::fs::read(image).map_err(|e| format!("{}: {e}", image.display()))?;
    let elf = object::File::parse(&*bytes).map_err(|e| format!("{}: {e}", image.display()))?;
    let functions = parse(&disassemble(image)?, |a| read_u32(&elf, a));
    panic_report(&functions, root, |a| location_at(&elf, a))
}

#[cfg(test)]
mod tests {
    #[test]
    fn soft_float_and_division_routines_are_told_apart_from_other_builtins() {
        for name in [
            "__aeabi_dadd",
            "__aeabi_fmul",
            "__aeabi_uldivmod",
            "__aeabi_l2d",
            "__adddf3",
            "__udivmoddi4",
            "fmod",
            "compiler_builtins::float::div::__divdf3",
            "compiler_builtins::int::specialized_div_rem::u64_div_rem",
            "compiler_builtins::math::libm_math::fmod::fmod",
        ] {
            assert!(super::is_soft_float_or_division(name), "{name}");
        }
        for name in [
            "__aeabi_memcpy",
            "__aeabi_memclr8",
            "__aeabi_llsl",
            "__aeabi_lmul",
            "compiler_builtins::mem::memcpy",
            "__muldi3",
        ] {
            assert!(!super::is_soft_float_or_division(name), "{name}");
        }
    }

    use super::*;

    const DIS: &str = "
00000100 <firmware::step_point::h3ab4713ba77f7c1b>:
     100:      \tpush\t{r4, lr}
     104:      \tbl\t0x200 <monitor_core::helper::h0123456789abcdef> @ imm = #0xfc
     108:      \tmovw\tr2, #0x44e8
     10c:      \tmovt\tr2, #0x0
     110:      \tbl\t0x300 <core::panicking::panic_bounds_check> @ imm = #0x1f0
     114:      \tb\t0x120 <firmware::step_point::h3ab4713ba77f7c1b+0x20> @ imm = #0x8
     118:      \tbl\t0x300 <core::panicking::panic_bounds_check> @ imm = #0x1f0

00000200 <monitor_core::helper::h0123456789abcdef>:
     200:      \tldr\tr0, [pc, #0x8]          @ 0x20c <monitor_core::helper+0xc>
     204:      \tb.w\t0x310 <core::panicking::panic_const::panic_const_rem_by_zero> @ imm = #0x10
     208:      \tbmi\t0x53e <unrelated+0x3e> @ imm = #0x330

00000300 <core::panicking::panic_bounds_check>:
     300:      \tbl\t0x400 <core::panicking::panic_fmt> @ imm = #0x100

00000500 <unrelated>:
     500:      \tbl\t0x400 <core::panicking::panic_fmt> @ imm = #0x100
";

    #[test]
    fn follows_direct_calls_and_stops_at_panic_entries() {
        let fns = parse(DIS, |a| (a == 0x20c).then_some(0x5000));
        assert_eq!(fns.len(), 4);
        assert_eq!(fns[0].name, "firmware::step_point");
        assert_eq!(fns[0].constants, [0x44e8]);
        assert_eq!(fns[1].constants, [0x5000]);
        let report = panic_report(&fns, "firmware::step_point", |a| {
            (a == 0x44e8).then(|| Location {
                file: "monitor.rs".into(),
                line: 3,
                col: 4,
            })
        })
        .unwrap();
        assert_eq!(
            report.reachable,
            ["firmware::step_point", "monitor_core::helper"]
        );
        assert_eq!(
            report.panic_calls,
            [
                (
                    "firmware::step_point".to_string(),
                    "core::panicking::panic_bounds_check".to_string(),
                    2
                ),
                (
                    "monitor_core::helper".to_string(),
                    "core::panicking::panic_const::panic_const_rem_by_zero".to_string(),
                    1
                )
            ]
        );
        assert_eq!(report.locations.len(), 1);
        assert_eq!(report.locations[0].line, 3);
    }

    #[test]
    fn a_missing_root_is_an_error() {
        let fns = parse(DIS, |_| None);
        assert!(panic_report(&fns, "nope", |_| None).is_err());
    }

    #[test]
    fn panic_entries_are_recognised() {
        assert!(is_panic_entry("core::panicking::panic_bounds_check"));
        assert!(is_panic_entry("core::slice::index::slice_index_fail"));
        assert!(is_panic_entry("core::option::unwrap_failed"));
        assert!(is_panic_entry("__rustc::rust_begin_unwind"));
        assert!(!is_panic_entry("monitor_core::layout::node_words"));
        assert!(!is_panic_entry("core::fmt::write"));
    }
}
