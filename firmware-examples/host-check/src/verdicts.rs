//! The host interpreter's verdicts over a trace, and the point-for-point comparison with a firmware's verdict changes.

use monitor_core::analysis::{settle, settled};
use monitor_core::table::Table;
use monitor_core::{Monitor, Program, Value};
use museum_spec::trace::Reader;

use crate::log::Log;

/// The first properties of `museum.hspec` are the model's requirements (the rest are observers).
pub const REQUIREMENTS: usize = 5;

/// Verdicts of every property at every point of a trace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Expected {
    /// Timestamp of each point.
    pub times: Vec<u64>,
    /// `verdicts[i][p]`: property `p` at point `i`.
    pub verdicts: Vec<Vec<bool>>,
    /// Number of properties.
    pub props: usize,
    /// Monitor state size in bytes.
    pub state_bytes: usize,
    /// The first point after which every verdict is final
    /// (`monitor_core::analysis::settle`), where a table image stops stepping;
    /// `None` when some verdict can still change at the end, or for an image
    /// that does not stop (the generated monitor).
    pub final_point: Option<usize>,
}

/// Runs `monitor_core::Monitor` on this machine over `points`.
pub fn host_run<'v>(
    program: Program<'_>,
    points: impl IntoIterator<Item = (u64, &'v [Value])>,
) -> Result<Expected, String> {
    let monitor = Monitor::try_new(program).map_err(|e| format!("program rejected: {e}"))?;
    let mut state = vec![0u64; monitor.state_words()];
    monitor.reset(&mut state).map_err(|e| e.to_string())?;
    let mut expected = Expected {
        times: Vec::new(),
        verdicts: Vec::new(),
        props: monitor.properties(),
        state_bytes: monitor.state_bytes(),
        final_point: None,
    };
    let program = monitor.program();
    let mut finals = vec![None; program.nodes.len()];
    for (time, values) in points {
        let mut verdicts = vec![false; monitor.properties()];
        monitor
            .try_step(&mut state, time, values, &mut verdicts)
            .map_err(|e| format!("point {}: {e}", expected.times.len()))?;
        expected.times.push(time);
        expected.verdicts.push(verdicts);
        if expected.final_point.is_none() {
            settle(
                program,
                |n| monitor.node_value(&state, n).unwrap_or(false),
                &mut finals,
            );
            if (0..monitor.properties()).all(|p| settled(program, &finals, p).is_some()) {
                expected.final_point = Some(expected.times.len() - 1);
            }
        }
    }
    Ok(expected)
}

/// What `monitor-static` must log: the host interpreter running museum-spec's
/// [`TABLE`](museum_spec::TABLE) (the program codegen compiled from the spec
/// the firmware's generated code comes from) over its `TRACE`. The state size
/// is the generated monitor's (`museum::STATE_BYTES`), which the firmware logs.
pub fn static_expected() -> Result<Expected, String> {
    let points = museum_spec::TRACE
        .iter()
        .map(|p| (p.time, p.values.to_vec()));
    let mut expected = with_table(museum_spec::TABLE, points.collect())?;
    expected.state_bytes = museum_spec::museum::STATE_BYTES;
    // The generated monitor replays every point.
    expected.final_point = None;
    Ok(expected)
}

/// The largest table [`table_expected`] decodes (entries per vector).
pub const HOST_CAPACITY: usize = 4096;

/// What `monitor-table` must log: the table decoded from `table` over the trace
/// decoded from `trace`, read exactly as the firmware reads them.
pub fn table_expected(table: &[u8], trace: &[u8]) -> Result<Expected, String> {
    let vars = on_big_stack(|| {
        let table = Table::<HOST_CAPACITY>::from_bytes(table).map_err(|e| format!("table: {e}"))?;
        Ok(table
            .program()
            .vars
            .iter()
            .map(|v| v.init)
            .collect::<Vec<Value>>())
    })?;
    let mut values = vars;
    let mut reader = Reader::new(trace, values.len()).map_err(|e| format!("trace: {e}"))?;
    let mut points = Vec::new();
    while let Some(time) = reader
        .next_point(&mut values)
        .map_err(|e| format!("trace: {e}"))?
    {
        points.push((time, values.clone()));
    }
    with_table(table, points)
}

/// Runs the program of postcard `table` over `points` on this machine.
fn with_table(table: &[u8], points: Vec<(u64, Vec<Value>)>) -> Result<Expected, String> {
    on_big_stack(|| {
        let table = Table::<HOST_CAPACITY>::from_bytes(table).map_err(|e| format!("table: {e}"))?;
        host_run(table.program(), points.iter().map(|(t, v)| (*t, &v[..])))
    })
}

/// Runs `f` on a thread with a large stack: a decoded `Table<HOST_CAPACITY>`
/// is about 600 KiB and moves by value.
pub fn on_big_stack<T: Send>(f: impl FnOnce() -> Result<T, String> + Send) -> Result<T, String> {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, f)
            .map_err(|e| format!("spawning the decoder thread: {e}"))?
            .join()
            .map_err(|_| "the decoder thread panicked".to_string())?
    })
}

/// Rebuilds every point's verdicts from a log of changes, for `props` properties over `points` points.
pub fn replay_changes(log: &Log, props: usize, points: usize) -> Result<Vec<Vec<bool>>, String> {
    let mut current: Vec<Option<bool>> = vec![None; props];
    let mut rows = Vec::with_capacity(points);
    let mut changes = log.changes.iter().peekable();
    for point in 0..points {
        while let Some(c) = changes.next_if(|c| c.point as usize == point) {
            let slot = current
                .get_mut(c.prop)
                .ok_or_else(|| format!("verdict for property {} of {props}", c.prop))?;
            *slot = Some(c.value);
        }
        if let Some(c) = changes.peek() {
            if (c.point as usize) < point {
                return Err(format!("verdict changes out of order at {c:?}"));
            }
        }
        let row = current
            .iter()
            .enumerate()
            .map(|(p, v)| v.ok_or_else(|| format!("no verdict for property {p} at point {point}")))
            .collect::<Result<Vec<bool>, String>>()?;
        rows.push(row);
    }
    if let Some(c) = changes.next() {
        return Err(format!(
            "verdict change past the last point {}: {c:?}",
            points - 1
        ));
    }
    Ok(rows)
}

/// Checks a firmware log against the host's verdicts: the same number of
/// properties and points, every change at the right timestamp, the same
/// verdict for every property at every point stepped, and a `final` line
/// exactly where the host finds every verdict final (the image then stops).
pub fn compare(expected: &Expected, log: &Log) -> Result<(), String> {
    if !log.errors.is_empty() {
        return Err(format!("the firmware logged errors: {:?}", log.errors));
    }
    let start = log.start.as_ref().ok_or("no `start` line")?;
    let done = log
        .done
        .ok_or("no `done` line: the replay did not finish")?;
    let all = expected.times.len();
    if start.props != expected.props {
        return Err(format!(
            "{} properties, the host has {}",
            start.props, expected.props
        ));
    }
    if start.state_bytes != expected.state_bytes {
        return Err(format!(
            "state of {} bytes, the host has {}",
            start.state_bytes, expected.state_bytes
        ));
    }
    let logged = log.finality.map(|f| (f.point as usize, f.time));
    let host = expected
        .final_point
        .map(|i| (i, expected.times.get(i).copied().unwrap_or(0)));
    if logged != host {
        return Err(format!(
            "every verdict final after (point, time) {logged:?}, the host says {host:?}"
        ));
    }
    // Stepped: up to the final point, else the whole trace.
    let n = expected.final_point.map_or(all, |i| i + 1);
    if start.points as usize != all || done.points as usize != n {
        return Err(format!(
            "announced {} and replayed {} points, the trace has {all} and the host expects {n} stepped",
            start.points, done.points
        ));
    }
    for c in &log.changes {
        let want = expected.times.get(c.point as usize);
        if want != Some(&c.time) {
            return Err(format!("{c:?}: the trace's point has time {want:?}"));
        }
    }
    let got = replay_changes(log, expected.props, n)?;
    for (i, (g, e)) in got.iter().zip(&expected.verdicts).enumerate() {
        if let Some(p) = (0..expected.props).find(|&p| g[p] != e[p]) {
            return Err(format!(
                "point {i} (time {}), property {p}: firmware says {}, host says {}",
                expected.times[i], g[p], e[p]
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::{Change, Done, Final, Start};

    fn log_of(changes: &[(usize, u32, u64, bool)], points: u32) -> Log {
        Log {
            start: Some(Start {
                name: "t".into(),
                props: 2,
                points,
                state_bytes: 8,
            }),
            changes: changes
                .iter()
                .map(|&(prop, point, time, value)| Change {
                    prop,
                    point,
                    time,
                    value,
                })
                .collect(),
            done: Some(Done {
                points,
                stack: 0,
                setup_stack: 0,
                replay_stack: 0,
            }),
            ..Log::default()
        }
    }

    fn expected(verdicts: &[[bool; 2]]) -> Expected {
        Expected {
            times: (0..verdicts.len() as u64).map(|i| i * 10).collect(),
            verdicts: verdicts.iter().map(|v| v.to_vec()).collect(),
            props: 2,
            state_bytes: 8,
            final_point: None,
        }
    }

    #[test]
    fn changes_rebuild_every_point() {
        let log = log_of(
            &[
                (0, 0, 0, true),
                (1, 0, 0, false),
                (1, 2, 20, true),
                (0, 3, 30, false),
            ],
            4,
        );
        let rows = replay_changes(&log, 2, 4).unwrap();
        assert_eq!(
            rows,
            [[true, false], [true, false], [true, true], [false, true]]
        );
        let e = expected(&[[true, false], [true, false], [true, true], [false, true]]);
        assert_eq!(compare(&e, &log), Ok(()));
    }

    #[test]
    fn a_missing_change_is_a_mismatch_at_its_point() {
        let log = log_of(&[(0, 0, 0, true), (1, 0, 0, false)], 3);
        let e = expected(&[[true, false], [true, true], [true, true]]);
        let err = compare(&e, &log).unwrap_err();
        assert!(err.starts_with("point 1 (time 10), property 1"), "{err}");
    }

    #[test]
    fn a_wrong_timestamp_or_count_is_rejected() {
        let log = log_of(&[(0, 0, 0, true), (1, 0, 5, false)], 1);
        assert!(compare(&expected(&[[true, false]]), &log).is_err());
        let log = log_of(&[(0, 0, 0, true), (1, 0, 0, false)], 2);
        assert!(compare(&expected(&[[true, false]]), &log).is_err());
    }

    #[test]
    fn a_replay_stops_exactly_where_the_host_finds_every_verdict_final() {
        let verdicts = [[true, false], [true, true], [true, true]];
        let mut e = expected(&verdicts);
        e.final_point = Some(1);
        // Announced 3 points, stepped 2, `final` after point 1 (time 10).
        let mut log = log_of(&[(0, 0, 0, true), (1, 0, 0, false), (1, 1, 10, true)], 3);
        log.done.as_mut().unwrap().points = 2;
        log.finality = Some(Final { point: 1, time: 10 });
        assert_eq!(compare(&e, &log), Ok(()));
        // A stop one point late or early, at the wrong time, or missing.
        let mut late = log.clone();
        late.finality = Some(Final { point: 2, time: 20 });
        assert!(compare(&e, &late).is_err());
        let mut wrong_time = log.clone();
        wrong_time.finality = Some(Final { point: 1, time: 11 });
        assert!(compare(&e, &wrong_time).is_err());
        let mut missing = log.clone();
        missing.finality = None;
        assert!(compare(&e, &missing).is_err());
        // Stepping past the final point is a mismatch too.
        let mut on = log.clone();
        on.done.as_mut().unwrap().points = 3;
        assert!(compare(&e, &on).is_err());
        // And a `final` line where the host expects none.
        e.final_point = None;
        assert!(compare(&e, &log).is_err());
    }

    #[test]
    fn a_property_without_a_first_verdict_is_rejected() {
        let log = log_of(&[(0, 0, 0, true)], 1);
        assert!(replay_changes(&log, 2, 1).is_err());
    }

    #[test]
    fn generated_code_and_table_expect_the_same_verdicts_on_the_museum_run() {
        let a = static_expected().unwrap();
        let b = table_expected(&museum_spec::table_bytes(), &museum_spec::trace_bytes()).unwrap();
        assert_eq!(
            (&a.times, &a.verdicts, a.props),
            (&b.times, &b.verdicts, b.props)
        );
        assert_eq!(b.state_bytes, museum_spec::STATE_BYTES);
        assert_eq!(a.times.len(), museum_spec::TRACE_LEN);
        assert_eq!(a.props, museum_spec::PROPS);
    }

    #[test]
    fn requirements_hold_and_every_observer_changes_on_the_museum_run() {
        // The five requirements hold on the whole run (as `hindsight trace`
        // recorded); the observers after them are there to change verdicts.
        let e = static_expected().unwrap();
        for p in 0..REQUIREMENTS {
            assert!(e.verdicts.iter().all(|v| v[p]), "requirement {p} fails");
        }
        for p in REQUIREMENTS..e.props {
            let first = e.verdicts[0][p];
            assert!(
                e.verdicts.iter().any(|v| v[p] != first),
                "observer {p} never changes"
            );
        }
    }
}
