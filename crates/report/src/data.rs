//! What a report shows, as the files hindsight already writes: a study as `verify --json`
//! prints it, sweeps as `sweep --json` prints them, failing runs as `--save-failing` CSV.
//!
//! Every type reads the JSON those commands print (extra fields ignored, new ones
//! optional), so `hindsight report` and `verify --report` build the same [`ReportData`].

use codegen::diag::Diagnostic;
use serde::{Deserialize, Serialize};

pub use hindsight_verify::result::{PropertyRow, Study};
/// A sweep's curves and points are the types `sweep` computes them as.
pub use hindsight_verify::sweep::{SweepCurve, SweepPoint};

/// Everything one page shows.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ReportData {
    /// The page title.
    pub title: String,
    /// The study (probabilities per property), if any.
    pub study: Option<Study>,
    /// Sweeps of time bounds.
    pub sweeps: Vec<Sweep>,
    /// Failing runs, each drawn as a timeline.
    pub runs: Vec<Run>,
}

/// A sweep: what `sweep --json` prints.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Sweep {
    /// Where it came from (a file name, or the model).
    #[serde(default)]
    pub title: String,
    /// Runs per bound (simulated sweeps).
    #[serde(default)]
    pub runs: Option<u64>,
    /// The seed (simulated sweeps).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Confidence of the intervals.
    #[serde(default)]
    pub confidence: f64,
    /// The recorded logs judged (on-line sweeps).
    #[serde(default)]
    pub logs: Vec<String>,
    /// One curve per property.
    pub properties: Vec<SweepCurve>,
}

/// The bound on a chart's x axis: model units, or seconds for a duration.
pub(crate) fn bound_axis(bound: &str) -> Option<(f64, bool)> {
    use codegen::duration::StepsOrDuration;
    match codegen::duration::parse_steps_or_duration(bound).ok()? {
        StepsOrDuration::Steps(v) => Some((v as f64, false)),
        StepsOrDuration::Nanos(v) => Some((v as f64 / 1e9, true)),
    }
}

/// A failing run, column by column (as `--save-failing` writes it, see `verify::record`).
///
/// Invariant: `time`, `step`, `event`, `origin`, `target`, `params`, every `values[i]` and
/// every `verdicts[i]` have one entry per point; times never decrease.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Run {
    /// Where it came from (`alarm_response-run3.csv`).
    pub name: String,
    /// The property it was kept for, if known.
    pub property: Option<String>,
    /// Its index in the study (run k is stream k of the seed), if known.
    pub run: Option<u64>,
    /// Seconds of model time in one step, when known.
    pub step_seconds: Option<f64>,
    /// The property variables' names.
    pub vars: Vec<String>,
    /// The properties' names (one verdict each).
    pub verdict_names: Vec<String>,
    /// Model time of each point.
    pub time: Vec<u64>,
    /// The texts `step`, `event`, `origin` and `target` index (each once: a long run
    /// repeats a few names many times).
    pub names: Vec<String>,
    /// The kind of each point (`init`, `send`, `receive`, `time`), in `names`.
    pub step: Vec<u32>,
    /// The message's event (empty for init and time points), in `names`.
    pub event: Vec<u32>,
    /// The sending machine, in `names`.
    pub origin: Vec<u32>,
    /// The receiving machine, in `names`.
    pub target: Vec<u32>,
    /// The parameters, `name=value` separated by `;`.
    pub params: Vec<String>,
    /// Each variable's value after each point (JSON bool, number or string).
    pub values: Vec<Vec<serde_json::Value>>,
    /// Each property's verdict at each point, as a string of `1` (true) and `0` (false).
    pub verdicts: Vec<String>,
    /// Per property that turned false, when the run was replayed in memory: the
    /// property, the subformula whose value at the first false point explains it
    /// (bounds in ticks), and that value.
    #[serde(default)]
    pub culprits: Vec<hindsight_verify::record::Culprit>,
}

/// A property's first false point in a run.
#[derive(Clone, Debug, PartialEq)]
pub struct FirstFalse {
    /// The property's name.
    pub property: String,
    /// The point's index.
    pub point: usize,
    /// Its model time.
    pub time: u64,
}

impl Run {
    /// Reads a CSV written by `verify --save-failing` or `trace`; `name` (the file) goes
    /// in errors as `name:line:col`. A file named `PROPERTY-runK.csv` gives the property
    /// and run index.
    pub fn from_csv(name: &str, text: &str) -> Result<Run, Diagnostic> {
        const FIXED: [&str; 6] = ["time", "step", "event", "origin", "target", "params"];
        let err = |line: usize, col: usize, m: String| {
            Diagnostic::error(name, (line as u32, col as u32), m)
        };
        // The project's one CSV reader, as `replay` reads a trace.
        let mut records = codegen::csv::rows(name, text)?.into_iter();
        let header_rec = records
            .next()
            .ok_or_else(|| err(1, 1, "empty file: expected a CSV header".into()))?;
        let header: Vec<&str> = header_rec.fields.iter().map(|(f, _)| f.as_str()).collect();
        for (i, want) in FIXED.iter().enumerate() {
            if header.get(i) != Some(want) {
                return Err(err(
                    header_rec.line,
                    1,
                    format!(
                        "expected the header of `verify --save-failing` or `trace` \
                         (time,step,event,origin,target,params,...), found `{}`",
                        header.join(",")
                    ),
                ));
            }
        }
        let split = header
            .iter()
            .position(|h| h.starts_with("verdict_"))
            .unwrap_or(header.len());
        let mut run = Run {
            name: name.to_string(),
            vars: header[FIXED.len()..split]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            verdict_names: header[split..]
                .iter()
                .map(|s| s.trim_start_matches("verdict_").to_string())
                .collect(),
            ..Run::default()
        };
        let mut ids = std::collections::HashMap::new();
        let mut intern = |names: &mut Vec<String>, s: &str| -> u32 {
            *ids.entry(s.to_string()).or_insert_with(|| {
                names.push(s.to_string());
                names.len() as u32 - 1
            })
        };
        run.values = vec![Vec::new(); run.vars.len()];
        run.verdicts = vec![String::new(); run.verdict_names.len()];
        let stem = name.rsplit(['/', '\\']).next().unwrap_or(name);
        if let Some((prop, k)) = stem.trim_end_matches(".csv").rsplit_once("-run") {
            if let Ok(k) = k.parse() {
                run.property = Some(prop.to_string());
                run.run = Some(k);
            }
        }
        for rec in records {
            // `i + 1` is the record's line in errors.
            let i = rec.line - 1;
            let cells: Vec<&str> = rec.fields.iter().map(|(f, _)| f.as_str()).collect();
            if cells.len() != header.len() {
                return Err(err(
                    i + 1,
                    1,
                    format!("{} fields, the header has {}", cells.len(), header.len()),
                ));
            }
            let col = |c: usize| rec.fields[c].1;
            let time: u64 = cells[0].parse().map_err(|_| {
                err(
                    i + 1,
                    1,
                    format!("time `{}` is not a whole number", cells[0]),
                )
            })?;
            if run.time.last().is_some_and(|&t| t > time) {
                return Err(err(i + 1, 1, format!("time {time} goes backwards")));
            }
            run.time.push(time);
            let names = &mut run.names;
            run.step.push(intern(names, cells[1]));
            run.event.push(intern(names, cells[2]));
            run.origin.push(intern(names, cells[3]));
            run.target.push(intern(names, cells[4]));
            run.params.push(cells[5].to_string());
            for (v, cell) in run.values.iter_mut().zip(&cells[FIXED.len()..split]) {
                v.push(cell_value(cell));
            }
            for (j, (v, cell)) in run.verdicts.iter_mut().zip(&cells[split..]).enumerate() {
                v.push(match *cell {
                    "true" => '1',
                    "false" => '0',
                    other => {
                        return Err(err(
                            i + 1,
                            col(split + j),
                            format!("verdict `{other}`: expected true or false"),
                        ))
                    }
                });
            }
        }
        Ok(run)
    }

    /// Each property's first false point, in the order of the verdict columns.
    pub fn first_false(&self) -> Vec<FirstFalse> {
        self.verdict_names
            .iter()
            .zip(&self.verdicts)
            .filter_map(|(name, v)| {
                let point = v.bytes().position(|b| b == b'0')?;
                Some(FirstFalse {
                    property: name.clone(),
                    point,
                    time: self.time[point],
                })
            })
            .collect()
    }
}

/// A CSV cell as a JSON value: a bool, an integer, a float, else the text.
fn cell_value(cell: &str) -> serde_json::Value {
    match cell {
        "true" => serde_json::Value::Bool(true),
        "false" => serde_json::Value::Bool(false),
        _ => {
            if let Ok(i) = cell.parse::<i64>() {
                i.into()
            } else if let Some(f) = cell
                .parse::<f64>()
                .ok()
                .and_then(serde_json::Number::from_f64)
            {
                serde_json::Value::Number(f)
            } else {
                cell.into()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "time,step,event,origin,target,params,x,flag,verdict_p,verdict_q\n\
                       0,init,,,,,0,false,true,true\n\
                       3,send,go,a,b,n=1,2.5,true,true,false\n\
                       3,receive,go,a,b,n=1,2.5,true,false,false\n\
                       7,time,,,,,name,false,false,true\n";

    #[test]
    fn a_saved_run_reads_column_by_column() {
        let r = Run::from_csv("dir/p-run12.csv", CSV).unwrap();
        assert_eq!((r.property.as_deref(), r.run), (Some("p"), Some(12)));
        assert_eq!(r.vars, ["x", "flag"]);
        assert_eq!(r.verdict_names, ["p", "q"]);
        assert_eq!(r.time, [0, 3, 3, 7]);
        let name = |i: u32| r.names[i as usize].as_str();
        assert_eq!(
            r.step.iter().map(|&i| name(i)).collect::<Vec<_>>(),
            ["init", "send", "receive", "time"]
        );
        assert_eq!(
            (name(r.event[2]), name(r.origin[2]), name(r.target[2])),
            ("go", "a", "b")
        );
        assert_eq!(r.names.len(), 8);
        assert_eq!(r.values[0][1], serde_json::json!(2.5));
        assert_eq!(r.values[0][3], serde_json::json!("name"));
        assert_eq!(r.values[1][1], serde_json::json!(true));
        assert_eq!(r.verdicts, ["1100", "1001"]);
        let ff = r.first_false();
        assert_eq!(
            ff,
            [
                FirstFalse {
                    property: "p".into(),
                    point: 2,
                    time: 3
                },
                FirstFalse {
                    property: "q".into(),
                    point: 1,
                    time: 3
                }
            ]
        );
    }

    #[test]
    fn quoted_fields_keep_commas_quotes_and_line_breaks() {
        let text = "time,step,event,origin,target,params,s,verdict_p\n\
                    0,init,,,,,\"a,b\",true\n\
                    1,send,go,a,b,\"msg=x, \"\"y\"\"\",\"two\nlines\",false\n";
        let r = Run::from_csv("q.csv", text).unwrap();
        assert_eq!(r.values[0][0], serde_json::json!("a,b"));
        assert_eq!(r.values[0][1], serde_json::json!("two\nlines"));
        assert_eq!(r.params[1], "msg=x, \"y\"");
        assert_eq!(r.verdicts, ["10"]);
        let e = Run::from_csv("q.csv", &text.replace("\"a,b\"", "\"a,b"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("q.csv:"), "{e}");
    }

    #[test]
    fn bad_runs_name_the_line_and_column() {
        let e = |text: &str| Run::from_csv("f.csv", text).unwrap_err().to_string();
        let e1 = e("a,b\n");
        assert!(e1.starts_with("f.csv:1:1: expected the header"), "{e1}");
        // The one CSV reader: a byte order mark and comment lines are no rows.
        let r = Run::from_csv("f.csv", &format!("\u{feff}# saved by hand\n{CSV}")).unwrap();
        assert_eq!(r.time, [0, 3, 3, 7]);
        let bad = CSV.replace(
            "3,receive,go,a,b,n=1,2.5,true,false",
            "3,receive,go,a,b,n=1,2.5,true,maybe",
        );
        assert_eq!(
            e(&bad),
            "f.csv:4:31: verdict `maybe`: expected true or false"
        );
        assert_eq!(
            e(&CSV.replace("7,time", "2,time")),
            "f.csv:5:1: time 2 goes backwards"
        );
        let e = e(&CSV.replace("n=1,2.5,true,true", "n=1,2.5"));
        assert!(
            e.starts_with("f.csv:3:1: 8 fields, the header has 10"),
            "{e}"
        );
        assert!(Run::from_csv("f.csv", "")
            .unwrap_err()
            .to_string()
            .contains("empty file"));
    }

    #[test]
    fn bounds_read_as_units_or_seconds() {
        assert_eq!(bound_axis("62"), Some((62.0, false)));
        assert_eq!(bound_axis("6.2s"), Some((6.2, true)));
        assert_eq!(bound_axis("bad"), None);
    }
}
