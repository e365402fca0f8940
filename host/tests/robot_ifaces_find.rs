//! Where a robot model's ROS interfaces are found: a checkout of AS2FM's repository run from
//! another folder, `--interfaces`, a sourced ROS workspace (`AMENT_PREFIX_PATH`), which place
//! wins on a clash, an error naming every place searched, and the built-in packages
//! (every message on a topic of a generated model, `sensor_msgs/BatteryState`).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use hindsight::verify::model::source::SourceMap;
use hindsight::verify::robot::interfaces::{Interfaces, Search};
use hindsight::verify::robot::types::InterfaceLookup;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hindsight-find-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// `hindsight ARGS` run in `cwd` without a sourced ROS workspace (unless `ament` is given).
fn hindsight(cwd: &Path, args: &[&str], ament: Option<&str>) -> (i32, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hindsight"));
    c.args(args)
        .current_dir(cwd)
        .env_remove("AMENT_PREFIX_PATH");
    if let Some(a) = ament {
        c.env("AMENT_PREFIX_PATH", a);
    }
    let out = c.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A checkout of AS2FM's repository: `.git` at its root, `ros_support_interfaces/` at the
/// top, the museum guide five folders down (`test/jani_generator/_test_data/<case>/Main`).
fn as2fm_checkout(root: &Path, with_interfaces: bool) -> PathBuf {
    let repo = root.join("AS2FM");
    std::fs::create_dir_all(repo.join(".git")).unwrap();
    if with_interfaces {
        copy_dir(
            &common::corpus("as2fm/ros_support_interfaces"),
            &repo.join("ros_support_interfaces"),
        );
    }
    let case = repo.join("test/jani_generator/_test_data/uc3_museum_guide");
    copy_dir(&common::corpus("as2fm/test_data/uc3_museum_guide"), &case);
    // Above the repository: never read, as the search stops at the repository's root.
    write(
        &root.join("interfaces/bt_interfaces_dummy/srv/TickAction.srv"),
        "int32[ broken\n---\n",
    );
    std::fs::create_dir_all(root.join("elsewhere")).unwrap();
    case.join("Main/main.xml")
}

#[test]
fn a_checkout_of_as2fm_finds_its_interfaces_from_anywhere() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let root = temp_dir("checkout");
    let main = as2fm_checkout(&root, true);
    let elsewhere = root.join("elsewhere");
    let (code, err) = hindsight(&elsewhere, &["validate", main.to_str().unwrap()], None);
    assert_eq!(code, 0, "{err}");
    // A relative path from another folder too.
    let rel = "../AS2FM/test/jani_generator/_test_data/uc3_museum_guide/Main/main.xml";
    let (code, err) = hindsight(&elsewhere, &["validate", rel], None);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&root);
}

/// Deeper than any fixed number of folders: eight folders down.
#[test]
fn interface_folders_are_found_however_deep() {
    let root = temp_dir("deep");
    std::fs::create_dir_all(root.join("repo/.git")).unwrap();
    write(
        &root.join("repo/interfaces/deep_msgs/msg/Level.msg"),
        "int32 level\n",
    );
    let main = root.join("repo/a/b/c/d/e/f/g/h/main.xml");
    write(&main, "<roaml/>");
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(&mut sm, &main, &[]).unwrap();
    assert_eq!(ifs.message("deep_msgs/Level").unwrap().len(), 1);
    let _ = std::fs::remove_dir_all(&root);
}

/// The museum guide's packages installed in a workspace (`<prefix>/share/<pkg>`), out of
/// the repository: a missing one names every place searched; `AMENT_PREFIX_PATH` and
/// `--interfaces` each find them.
#[test]
fn a_sourced_workspace_and_the_interfaces_option() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let root = temp_dir("ament");
    let main = as2fm_checkout(&root, false);
    let install = root.join("ws/install");
    copy_dir(
        &common::corpus("as2fm/ros_support_interfaces/uc3_interfaces"),
        &install.join("share"),
    );
    let elsewhere = root.join("elsewhere");
    let m = main.to_str().unwrap();

    let (code, err) = hindsight(&elsewhere, &["validate", m], None);
    assert_eq!(code, 2, "{err}");
    // At the use, with file, line and column.
    assert!(err.contains(".ascxml:"), "{err}");
    assert!(err.contains("no package `"), "{err}");
    // Listed once, however many uses are missing.
    assert_eq!(err.matches("searched, in this order:").count(), 1, "{err}");
    assert!(
        err.contains("(the places searched are listed above)"),
        "{err}"
    );
    assert!(
        err.contains("packages in ") && err.contains("Main (the main file's folder)"),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "ros_support_interfaces/, interfaces/, Interfaces/ in {}",
            main.parent().unwrap().display()
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "in {} (the repository's root)",
            root.join("AS2FM").display()
        )),
        "{err}"
    );
    assert!(
        err.contains("AMENT_PREFIX_PATH: no sourced ROS workspace"),
        "{err}"
    );
    assert!(err.contains("built in: builtin_interfaces"), "{err}");
    assert!(!err.contains("broken"), "read above the repository: {err}");

    let ament = format!("{}:{}", root.join("ws/empty").display(), install.display());
    let (code, err) = hindsight(&elsewhere, &["validate", m], Some(&ament));
    assert_eq!(code, 0, "{err}");

    let share = install.join("share");
    let (code, err) = hindsight(
        &elsewhere,
        &["validate", m, "--interfaces", share.to_str().unwrap()],
        None,
    );
    assert_eq!(code, 0, "{err}");

    // A folder that is not there is an error.
    let (code, err) = hindsight(&elsewhere, &["validate", m, "--interfaces", "nope"], None);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("nope: --interfaces"), "{err}");
    let _ = std::fs::remove_dir_all(&root);
}

/// The search order decides a clash: `--interfaces`, then beside the model, then above it,
/// then the workspace, then the built-ins (type by type).
#[test]
fn the_first_place_wins_a_clash() {
    let root = temp_dir("clash");
    std::fs::create_dir_all(root.join("repo/.git")).unwrap();
    let main = root.join("repo/model/main.xml");
    write(&main, "<roaml/>");
    let given = root.join("given");
    write(&given.join("my_msgs/msg/M.msg"), "int32 from_option\n");
    write(&root.join("repo/model/my_msgs/msg/M.msg"), "int32 beside\n");
    write(
        &root.join("repo/ros_support_interfaces/my_msgs/msg/M.msg"),
        "int32 above\n",
    );
    let ws = root.join("ws");
    write(&ws.join("share/my_msgs/msg/M.msg"), "int32 workspace\n");
    // A workspace package that does not read only matters to a model that uses it.
    write(&ws.join("share/odd_msgs/msg/Odd.msg"), "int32[ odd\n");
    write(
        &root.join("repo/model/std_msgs/msg/Int32.msg"),
        "int64 data\n",
    );
    let field = |search: &Search| {
        let mut sm = SourceMap::new();
        let ifs = Interfaces::discover_with(&mut sm, &main, search).unwrap();
        ifs.message("my_msgs/M").unwrap()[0].param_name()
    };
    let all = Search {
        dirs: vec![given.clone()],
        ament_prefixes: vec![ws.clone()],
    };
    assert_eq!(field(&all), "ros_fields__from_option");
    let no_option = Search {
        dirs: vec![],
        ament_prefixes: vec![ws.clone()],
    };
    assert_eq!(field(&no_option), "ros_fields__beside");
    std::fs::remove_dir_all(root.join("repo/model/my_msgs")).unwrap();
    assert_eq!(field(&no_option), "ros_fields__above");
    std::fs::remove_dir_all(root.join("repo/ros_support_interfaces")).unwrap();
    assert_eq!(field(&no_option), "ros_fields__workspace");
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover_with(&mut sm, &main, &no_option).unwrap();
    // A package on disk replaces the built-in one type by type.
    assert_eq!(
        ifs.message("std_msgs/Int32").unwrap()[0].scxml_type,
        "int64"
    );
    assert_eq!(ifs.message("std_msgs/Bool").unwrap()[0].scxml_type, "bool");
    let e = ifs.message("odd_msgs/Odd").unwrap_err().to_string();
    assert!(e.contains("did not read"), "{e}");
    let _ = std::fs::remove_dir_all(&root);
}

/// `sensor_msgs/BatteryState` at the field list of ROS 2 Jazzy, flattened.
#[test]
fn battery_state_is_built_in() {
    let ifs = Interfaces::with_builtins();
    let fields: Vec<(String, String)> = ifs
        .message("sensor_msgs/BatteryState")
        .unwrap()
        .iter()
        .map(|f| (f.param_name(), f.scxml_type.clone()))
        .collect();
    let want = [
        ("header__stamp__sec", "int32"),
        ("header__stamp__nanosec", "uint32"),
        ("header__frame_id", "string"),
        ("voltage", "float32"),
        ("temperature", "float32"),
        ("current", "float32"),
        ("charge", "float32"),
        ("capacity", "float32"),
        ("design_capacity", "float32"),
        ("percentage", "float32"),
        ("power_supply_status", "uint8"),
        ("power_supply_health", "uint8"),
        ("power_supply_technology", "uint8"),
        ("present", "bool"),
        ("cell_voltage", "float32[]"),
        ("cell_temperature", "float32[]"),
        ("location", "string"),
        ("serial_number", "string"),
    ];
    let want: Vec<(String, String)> = want
        .iter()
        .map(|(n, t)| (format!("ros_fields__{n}"), t.to_string()))
        .collect();
    assert_eq!(fields, want);
    let consts = ifs.constants("sensor_msgs/BatteryState").unwrap();
    assert!(consts.contains(&("POWER_SUPPLY_STATUS_FULL".to_string(), "4".to_string())));
}

/// A generated robot model publishes one message of every built-in message type on its
/// own topic and a second machine subscribes to each: it loads, lowers and compiles; one
/// that reads `sensor_msgs/BatteryState`'s percentage runs.
#[test]
fn every_builtin_message_lowers_on_a_topic() {
    let root = temp_dir("lower");
    let ifs = Interfaces::with_builtins();
    let msgs: Vec<String> = ifs
        .iter()
        .filter(|d| d.kind == hindsight::verify::robot::interfaces::InterfaceKind::Message)
        .map(|d| format!("{}/{}", d.package, d.name))
        .collect();
    assert!(msgs.len() > 130, "{}", msgs.len());
    let mut decls = String::new();
    let mut sends = String::new();
    let mut subs = String::new();
    let mut callbacks = String::new();
    for (i, ty) in msgs.iter().enumerate() {
        decls.push_str(&format!(
            "  <ros_topic_publisher name=\"p{i}\" topic=\"/t{i}\" type=\"{ty}\"/>\n"
        ));
        sends.push_str(&format!("      <ros_topic_publish name=\"p{i}\"/>\n"));
        subs.push_str(&format!(
            "  <ros_topic_subscriber name=\"s{i}\" topic=\"/t{i}\" type=\"{ty}\"/>\n"
        ));
        callbacks.push_str(&format!(
            "    <ros_topic_callback name=\"s{i}\" target=\"idle\"/>\n"
        ));
    }
    write(
        &root.join("pub.ascxml"),
        &format!(
            "<ascxml initial=\"go\" version=\"1.0\" name=\"Pub\" xmlns=\"http://www.w3.org/2005/07/scxml\">\n{decls}\
             <ros_time_rate name=\"tick\" rate_hz=\"1\"/>\n\
             <state id=\"go\">\n    <ros_rate_callback name=\"tick\" target=\"go\">\n{sends}    </ros_rate_callback>\n  </state>\n</ascxml>\n"
        ),
    );
    write(
        &root.join("sub.ascxml"),
        &format!(
            "<ascxml initial=\"idle\" version=\"1.0\" name=\"Sub\" xmlns=\"http://www.w3.org/2005/07/scxml\">\n{subs}\
             <state id=\"idle\">\n{callbacks}  </state>\n</ascxml>\n"
        ),
    );
    write(
        &root.join("main.xml"),
        "<roaml>\n  <parameters><max_time value=\"3\" unit=\"s\"/></parameters>\n  <node_models>\n    \
         <input type=\"node-ascxml\" src=\"./pub.ascxml\"/>\n    <input type=\"node-ascxml\" src=\"./sub.ascxml\"/>\n  \
         </node_models>\n</roaml>\n",
    );
    let robot = hindsight::verify::robot::load::load(&root.join("main.xml"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(robot.machines.len() >= 3);
    let _ = std::fs::remove_dir_all(&root);
}
