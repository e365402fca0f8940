//! Fuzz target: any bytes as one file of a model, loaded as `hindsight verify` loads it
//! and, when it loads, verified on two short runs. It must give a result or an error,
//! never panic.
//!
//! The first byte picks the file the rest replaces in one of two small models
//! (`templates/`, copied once per process into a scratch folder): a plain SCXML machine
//! or the plain model's property file; a robot model's behavior tree, node model, BT
//! plugin, main file or property file. The same byte divided by the number of files picks
//! the tree's semantics (`--bt as2fm`, `btcpp` or `btcpp-exactly-once`). The readers, the lowering of the tree and the ROS tags, the
//! expression and property compilers, the simulator and the judge all see the input.
#![no_main]

use hindsight_verify::load::{load, LoadOptions};
use hindsight_verify::options::{BtSemantics, BtTick, VerifyOptions};
use hindsight_verify::pipeline::{verify, Request};
use libfuzzer_sys::fuzz_target;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::OnceLock;

/// The file each selector replaces: (model folder, file in it).
const FILES: [(&str, &str); 7] = [
    ("plain", "a.scxml"),
    ("plain", "properties.xml"),
    ("robot", "tree.xml"),
    ("robot", "Grasp.scxml"),
    ("robot", "Plugins/ROS2Action.scxml"),
    ("robot", "main.xml"),
    ("robot", "properties.xml"),
];

/// Copies `from` into `to`, folders included.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("scratch folder");
    for entry in std::fs::read_dir(from).expect("template folder") {
        let entry = entry.expect("template entry");
        let dst = to.join(entry.file_name());
        if entry.file_type().expect("file type").is_dir() {
            copy_dir(&entry.path(), &dst);
        } else {
            std::fs::copy(entry.path(), dst).expect("template file");
        }
    }
}

/// This process's scratch copy of the templates; the robot model gets the museum
/// guide's BT plugins and tick interfaces from `examples/`.
fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = std::env::temp_dir().join(format!("hindsight-fuzz-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        copy_dir(&root.join("templates"), &dir);
        let guide = root.join("../examples/museum-guide");
        copy_dir(&guide.join("Plugins"), &dir.join("robot/Plugins"));
        copy_dir(
            &guide.join("Interfaces/bt_interfaces_dummy"),
            &dir.join("robot/Interfaces/bt_interfaces_dummy"),
        );
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, text)) = data.split_first() else {
        return;
    };
    let (folder, file) = FILES[pick as usize % FILES.len()];
    let dir = scratch().join(folder);
    // Each input is written over its file and the template put back afterwards, so the
    // other files stay as they are.
    let path = dir.join(file);
    let template = std::fs::read(&path).expect("template file");
    std::fs::write(&path, text).expect("scratch file");
    let bt = match (pick as usize / FILES.len()) % 3 {
        0 => BtSemantics::As2fm,
        1 => BtSemantics::Btcpp { tick: BtTick::Once },
        _ => BtSemantics::Btcpp {
            tick: BtTick::ExactlyOnce,
        },
    };
    let opts = LoadOptions {
        model: dir.clone(),
        bt: if folder == "robot" {
            bt
        } else {
            BtSemantics::As2fm
        },
        ..LoadOptions::default()
    };
    if let Ok(loaded) = load(&opts) {
        let vopts = VerifyOptions {
            seed: 1,
            threads: 1,
            max_runs: Some(2),
            max_steps: 4_000,
            max_instant_steps: 1_000,
            ..VerifyOptions::default()
        };
        let model = dir.clone();
        let request = Request::new(&loaded, &model, &vopts);
        let _ = verify(&request, &mut |_| {}, &AtomicBool::new(false));
    }
    std::fs::write(&path, template).expect("template put back");
});
