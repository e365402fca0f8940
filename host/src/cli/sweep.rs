//! `hindsight sweep`: one property's success rate as every time bound in it takes each value of a range.

use std::path::PathBuf;
use std::time::Duration;

use super::verify::{load, study};
use super::CliError;
use crate::props::{self, SourceText};
use crate::sim::{CompiledModel, RunConfig};
use crate::smc::stats::RuleConfig;
use crate::smc::StudyConfig;
use crate::verify::observe::PropertySet;

/// Arguments of `hindsight sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// The model: a folder of .scxml machines, a SCAN model.xml, or one .scxml file.
    pub model: PathBuf,
    /// The SCAN property file; default as for `verify`.
    pub props: Option<PathBuf>,
    /// The guarantee to sweep; every integer bound in its formula (`[a:]`, `[:b]`,
    /// `[a:b]`) takes the swept value.
    #[arg(long)]
    pub property: String,
    /// First bound value.
    #[arg(long)]
    pub from: u64,
    /// Last bound value (inclusive).
    #[arg(long)]
    pub to: u64,
    /// Step between values.
    #[arg(long, default_value_t = 1)]
    pub step: u64,
    /// Confidence of the intervals.
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    /// Half-width of the intervals (SCAN's adaptive rule).
    #[arg(long, default_value_t = 0.01)]
    pub precision: f64,
    /// Study seed (the same for every bound).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Runs per bound at most.
    #[arg(long)]
    pub max_runs: Option<u64>,
    /// A run ends when model time reaches this.
    #[arg(long, default_value_t = 10_000)]
    pub max_time: u64,
}

/// Replaces every number inside `[...]` bounds of `formula` with `value` (text inside
/// `{...}` atoms is left alone).
pub fn set_bounds(formula: &str, value: u64) -> (String, usize) {
    let mut out = String::with_capacity(formula.len());
    let mut replaced = 0;
    let mut in_bound = false;
    let mut atom_depth = 0usize;
    let mut chars = formula.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '{' => atom_depth += 1,
            '}' => atom_depth = atom_depth.saturating_sub(1),
            '[' if atom_depth == 0 => in_bound = true,
            ']' if atom_depth == 0 => in_bound = false,
            d if in_bound && d.is_ascii_digit() => {
                while chars.peek().is_some_and(|c| c.is_ascii_digit()) {
                    chars.next();
                }
                out.push_str(&value.to_string());
                replaced += 1;
                continue;
            }
            _ => {}
        }
        out.push(c);
    }
    (out, replaced)
}

/// Runs `hindsight sweep`: prints `bound,probability,lower,upper,runs` as CSV.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    if args.step == 0 || args.from > args.to {
        return Err(CliError::Input(
            "sweep: need --from <= --to and --step > 0".into(),
        ));
    }
    let (model, _, props_path) = load(&args.model, args.props.as_deref())?;
    let file = props::parse_file(&props_path).map_err(|d| CliError::Input(d.to_string()))?;
    let Some(target) = file
        .guarantees
        .iter()
        .find(|g| g.id == args.property)
        .cloned()
    else {
        return Err(CliError::Input(format!(
            "{}: no guarantee `{}`",
            props_path.display(),
            args.property
        )));
    };
    if set_bounds(target.formula.as_str(), 0).1 == 0 {
        return Err(CliError::Input(format!(
            "{}: guarantee `{}` has no time bound to sweep",
            props_path.display(),
            args.property
        )));
    }
    let rule = RuleConfig {
        confidence: args.confidence,
        precision: args.precision,
        ..RuleConfig::default()
    };
    let run_cfg = RunConfig {
        max_time: args.max_time,
        ..RunConfig::default()
    };
    let study_cfg = StudyConfig {
        seed: args.seed,
        threads: args.threads,
        max_runs: args.max_runs,
        keep_failing: 0,
        progress_every: Duration::from_millis(200),
    };
    println!("bound,probability,lower,upper,runs");
    let mut t = args.from;
    while t <= args.to {
        let rate = one_bound(&model, &file, &target, t, &run_cfg, &study_cfg, &rule)?;
        println!("{t},{:.4},{:.4},{:.4},{}", rate.0, rate.1, rate.2, rate.3);
        t = match t.checked_add(args.step) {
            Some(n) => n,
            None => break,
        };
    }
    Ok(())
}

fn one_bound(
    model: &CompiledModel,
    file: &props::PropertyFile,
    target: &props::Property,
    t: u64,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
) -> Result<(f64, f64, f64, u64), CliError> {
    let mut one = file.clone();
    let mut g = target.clone();
    g.formula = SourceText::generated(set_bounds(target.formula.as_str(), t).0, target.at);
    one.guarantees = vec![g];
    let set = PropertySet::new(&one, model).map_err(CliError::Input)?;
    let r = study(model, &set, run_cfg, study_cfg, rule, false)?;
    let p = &r.properties[0];
    Ok((
        p.estimate.estimate.unwrap_or(f64::NAN),
        p.interval.lower,
        p.interval.upper,
        p.counts.judged(),
    ))
}

#[cfg(test)]
mod tests {
    use super::set_bounds;

    #[test]
    fn every_bound_is_replaced_and_nothing_else() {
        let f = "historically((once[10:] true) -> once[:10] {x == 10})";
        assert_eq!(
            set_bounds(f, 7),
            (
                "historically((once[7:] true) -> once[:7] {x == 10})".to_string(),
                2
            )
        );
        assert_eq!(set_bounds("{a} since[2:40] {b}", 5).0, "{a} since[5:5] {b}");
        assert_eq!(set_bounds("once {a}", 5).1, 0);
        assert_eq!(
            set_bounds("once[3:] {a[2] == 1}", 5).0,
            "once[5:] {a[2] == 1}"
        );
    }
}
