//! `hindsight report` (a page from the files `verify --json`, `sweep --json` and
//! `--save-failing` write) and the `--report FILE` of `verify` and `sweep`.

use std::path::{Path, PathBuf};

use super::CliError;
use crate::codegen;
use crate::report::{self, ReportData, Run, Study, Sweep};
use crate::verify::load::Loaded;
use crate::verify::options::Scheduler;
use crate::verify::replay::{scheduler_runs, Failing};

/// Arguments of `hindsight report`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Reads what the other commands write and makes one self-contained HTML page (styles,
script, charts and data inline; nothing is fetched when it is opened):
  --study FILE   the JSON of `verify --json` or `merge --json`: settings, how runs ended,
                 each property's probability, interval and runs; formulas are read from
                 the property file it names when that file is an XML file found here
                 (of `verify --bt both --json`, the study --bt as2fm or btcpp names)
  --sweep FILE   the JSON of `sweep --json` (repeatable): success rate against the bound,
                 with intervals and thresholds
  RUNS           CSV files of `verify --save-failing` or `trace`, or folders of them: each
                 is drawn as a timeline (a file named PROPERTY-runK.csv is linked to PROPERTY)

`verify --report FILE` and `sweep --report FILE` write the same page straight from the
study in memory, with each formula as written and as compiled.

--scheduler ID (with --study) replays the study's model under a scheduler, typically a
witness `verify --schedulers N` printed: per property the study saw fail (in a run, or
under its minimising witness), the first failing run under it beside the first under
the uniform scheduler (among each one's first 500 runs of the study's seed). The model
is loaded again from the study's \"replay\" settings (paths as the study named them:
run `report` where `verify` or its shards ran).

Examples:
  hindsight verify examples/museum-guide --json --save-failing 2 --out runs > study.json
  hindsight report --study study.json runs -o report.html
  hindsight verify MODEL --schedulers 100 --json > study.json
  hindsight report --study study.json --scheduler memoryless:29656f316841437b -o order.html")]
pub struct ReportArgs {
    /// Failing runs: CSV files written by `verify --save-failing` or `trace`, or folders of them.
    pub runs: Vec<PathBuf>,
    /// A study as `verify --json` (or `merge --json`) prints it.
    #[arg(long, value_name = "FILE")]
    pub study: Option<PathBuf>,
    /// A sweep as `sweep --json` prints it (repeat for several).
    #[arg(long = "sweep", value_name = "FILE")]
    pub sweeps: Vec<PathBuf>,
    /// The HTML file to write.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// The page's title (default: the study's model).
    #[arg(long)]
    pub title: Option<String>,
    /// The length of one model step (`100ms`), to show the runs' times in seconds when
    /// no study gives it.
    #[arg(long, value_name = "DURATION")]
    pub time_unit: Option<String>,
    /// With a study that `verify --bt both --json` printed (two studies): which one to
    /// show, `as2fm` or `btcpp`.
    #[arg(long = "bt", value_enum, value_name = "SEMANTICS", requires = "study")]
    pub bt: Option<BtPick>,
    /// Replay the study's model under this scheduler (`memoryless:ID`, `history:ID`,
    /// `uniform`) and show each property's first failing run under it beside one under
    /// the uniform scheduler; needs --study.
    #[arg(long, value_name = "ID", value_parser = super::verify::parse_scheduler, requires = "study")]
    pub scheduler: Option<Scheduler>,
}

/// Which study of `verify --bt both --json` a page shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BtPick {
    /// The study under AS2FM's node models (`"as2fm"`).
    As2fm,
    /// The study under BehaviorTree.CPP 4 (`"btcpp"`).
    Btcpp,
}

/// The study in `path`: the JSON of `verify --json` or `merge --json`, or one of the two
/// of `verify --bt both --json`, picked by `bt` (refused without it, naming the choice).
fn read_study(path: &Path, bt: Option<BtPick>) -> Result<Study, CliError> {
    let doc: serde_json::Value = read_json(path, "`verify --json`")?;
    let both = doc.get("bt").and_then(|b| b.as_str()) == Some("both");
    match (both, bt) {
        (true, Some(pick)) => {
            let key = match pick {
                BtPick::As2fm => "as2fm",
                BtPick::Btcpp => "btcpp",
            };
            let Some(one) = doc.get(key) else {
                return Err(CliError::Input(format!(
                    "{}: `verify --bt both` output without its `{key}` study",
                    path.display()
                )));
            };
            serde_json::from_value(one.clone()).map_err(|e| {
                CliError::Input(format!(
                    "{}: its `{key}` study is not the JSON of `verify --json`: {e}",
                    path.display()
                ))
            })
        }
        (true, None) => Err(CliError::Input(format!(
            "{}: this is `verify --bt both` output, two studies: give --bt as2fm or --bt \
             btcpp to show one",
            path.display()
        ))),
        (false, Some(_)) => Err(CliError::Input(format!(
            "{}: --bt picks one study of `verify --bt both` output; this file is a single \
             study",
            path.display()
        ))),
        // Read again as a study, for an error with its line and column.
        (false, None) => read_json(path, "`verify --json`"),
    }
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path, what: &str) -> Result<T, CliError> {
    let text = super::read_file(path)?;
    serde_json::from_str(&text).map_err(|e| {
        CliError::Input(format!(
            "{}:{}:{}: not the JSON of {what}: {e}",
            path.display(),
            e.line().max(1),
            e.column().max(1)
        ))
    })
}

/// The CSV files among `paths` (a folder stands for its `.csv` files, by name).
fn run_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|e| CliError::Input(format!("{}: cannot read: {e}", p.display())))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|x| x == "csv"))
                .collect();
            files.sort();
            out.extend(files);
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}

/// Runs `hindsight report`.
pub fn run(args: &ReportArgs) -> Result<(), CliError> {
    if args.study.is_none() && args.sweeps.is_empty() && args.runs.is_empty() {
        return Err(CliError::Input(
            "report: nothing to show: give --study, --sweep or failing runs (see --help)".into(),
        ));
    }
    let mut data = ReportData::default();
    let mut replayed = Vec::new();
    if let Some(path) = &args.study {
        let mut study = read_study(path, args.bt)?;
        if let Err(e) = study.read_formulas() {
            eprintln!("warning: formulas not shown: {e}");
        }
        if let Some(scheduler) = args.scheduler {
            let seed = study.seed;
            let mut searching = |property: &str, label: &str| {
                eprintln!(
                    "replaying: the first run of seed {seed} that fails {property} under the \
                     {label} (up to 500 runs)"
                )
            };
            let (loaded, runs) = scheduler_runs(&study, scheduler, &mut searching)
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
            super::print_warnings(&loaded.warnings);
            if runs.is_empty() {
                let under = match scheduler {
                    Scheduler::Uniform => "the uniform scheduler".to_string(),
                    s => format!("{s} or the uniform scheduler"),
                };
                eprintln!(
                    "no run to show: the study saw no property fail (in a run or under its \
                     minimising witness), or none of those fails in the first 500 runs of \
                     seed {} under {under}",
                    study.seed
                );
            }
            replayed = runs;
        }
        data.study = Some(study);
    }
    for path in &args.sweeps {
        let mut sweep: Sweep = read_json(path, "`sweep --json`")?;
        sweep.title = path.display().to_string();
        data.sweeps.push(sweep);
    }
    let step_seconds = match &args.time_unit {
        Some(t) => Some(
            codegen::duration::parse(t)
                .map_err(|m| CliError::Input(format!("--time-unit {t}: {m}")))? as f64
                / 1e9,
        ),
        None => data.study.as_ref().and_then(|s| s.step_seconds),
    };
    for f in &replayed {
        data.runs.push(shown_run(f, step_seconds)?);
    }
    for path in run_files(&args.runs)? {
        let text = super::read_file(&path)?;
        let mut run = Run::from_csv(&path.display().to_string(), &text)?;
        run.step_seconds = step_seconds;
        data.runs.push(run);
    }
    data.title = match (&args.title, &data.study) {
        (Some(t), _) => t.clone(),
        (None, Some(s)) => format!("hindsight report: {}", s.model),
        (None, None) => "hindsight report".into(),
    };
    write(&args.output, &data)
}

fn write(path: &Path, data: &ReportData) -> Result<(), CliError> {
    super::write_whole(path, report::render(data).as_bytes())
        .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", path.display())))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// `verify --report FILE`: the study in memory (`report` is what `--json` prints), each
/// formula as written and as compiled, and the failing runs replayed.
pub fn from_verify(
    path: &Path,
    report: &Study,
    loaded: &Loaded,
    settings: Vec<(String, String)>,
    failing: &[Failing],
) -> Result<(), CliError> {
    let mut study = report.clone();
    study.settings = settings;
    study.add_formulas(loaded);
    let mut data = ReportData {
        title: format!("hindsight verify: {}", study.model),
        ..ReportData::default()
    };
    for f in failing {
        data.runs.push(shown_run(f, study.step_seconds)?);
    }
    data.study = Some(study);
    write(path, &data)
}

/// `sweep --report FILE`: `doc` is what `sweep --json` prints.
pub fn from_sweep(path: &Path, model: &Path, doc: &serde_json::Value) -> Result<(), CliError> {
    let mut sweep: Sweep = serde_json::from_value(doc.clone())
        .map_err(|e| CliError::Failed(format!("report: {e}")))?;
    sweep.title = model.display().to_string();
    let data = ReportData {
        title: format!("hindsight sweep: {}", model.display()),
        sweeps: vec![sweep],
        ..ReportData::default()
    };
    write(path, &data)
}

/// A replayed run as the page draws it: linked to its property, with its culprits.
fn shown_run(f: &Failing, step_seconds: Option<f64>) -> Result<Run, CliError> {
    let mut run = Run::from_csv(&f.file, &f.csv).map_err(|d| CliError::Failed(d.to_string()))?;
    run.property = Some(f.property.clone());
    run.run = Some(f.run);
    run.step_seconds = step_seconds;
    run.culprits = f.culprits.clone();
    Ok(run)
}
