//! The page: the study and sweeps as static HTML, the failing runs as data for the inline
//! script that draws their timelines (`page.js`), styles from `page.css`; nothing fetched.

use std::fmt::Write;

use super::data::{bound_axis, ReportData, Run, Study, Sweep};
use super::plot;

/// Escapes text for HTML content and attribute values (every attribute the page writes
/// is double-quoted): the one markup escaper, `model::xml::escape`.
pub(crate) use hindsight_verify::model::xml::escape as esc;

/// An id fragment for a name: letters, digits, `-` and `_` kept, anything else `_`.
pub(crate) fn anchor(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A model time as the page writes it: seconds when the step is known, else steps.
pub(crate) fn time_text(t: u64, step_seconds: Option<f64>) -> String {
    match step_seconds {
        Some(s) => format!("{} s", plot::label(t as f64 * s)),
        None => format!("{t} (steps)"),
    }
}

/// The whole page.
pub(crate) fn page(data: &ReportData) -> String {
    let mut o = String::new();
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; \
         style-src 'unsafe-inline'; script-src 'unsafe-inline'; img-src data:\">\n\
         <title>{}</title>\n<style>\n{}</style>\n</head>\n<body data-errors=\"0\">\n",
        esc(&data.title),
        crate::PAGE_CSS
    );
    let _ = writeln!(
        o,
        "<header><h1>{}</h1><p class=\"by\">hindsight {}: a self-contained page (no network).</p></header>",
        esc(&data.title),
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(o, "<nav><ul>");
    if data.study.is_some() {
        o.push_str("<li><a href=\"#study\">Study</a></li>");
    }
    for (i, s) in data.sweeps.iter().enumerate() {
        let _ = write!(
            o,
            "<li><a href=\"#sweep-{i}\">Sweep{}</a></li>",
            if s.title.is_empty() {
                String::new()
            } else {
                format!(": {}", esc(&s.title))
            }
        );
    }
    for (i, r) in data.runs.iter().enumerate() {
        let _ = write!(
            o,
            "<li><a href=\"#run-{i}\">{}</a></li>",
            esc(&run_title(r))
        );
    }
    o.push_str("</ul></nav>\n<main>\n");
    if let Some(s) = &data.study {
        study(&mut o, s, &data.runs);
        bounds(&mut o, s);
    }
    for (i, s) in data.sweeps.iter().enumerate() {
        sweep(&mut o, i, s);
    }
    if !data.runs.is_empty() {
        let _ = writeln!(
            o,
            "<h2>Failing runs</h2>\n<p class=\"help\">One lane per message, property \
             variable and verdict. Wheel or the buttons zoom the time axis, dragging pans, \
             hovering shows a point's state, a click pins it, the arrow keys step from point \
             to point (several points may share a time). A red mark is where a property \
             first turned false; its name links to the formula. For a robot model, the \
             behavior tree below shows each node's status at the selected point.</p>"
        );
    }
    for (i, r) in data.runs.iter().enumerate() {
        run(&mut o, i, r);
    }
    o.push_str("</main>\n");
    // The runs as data for the script: `<` escaped so no string closes the element.
    let runs = serde_json::to_string(&data.runs)
        .unwrap_or_else(|_| "[]".into())
        .replace('<', "\\u003c");
    let _ = write!(
        o,
        "<script type=\"application/json\" id=\"hindsight-runs\">{runs}</script>\n\
         <script>\n{}</script>\n</body>\n</html>\n",
        crate::PAGE_JS
    );
    o
}

/// A run's title: `property: run k`, or its name when that says the scheduler it ran
/// under (`verify --schedulers --report`: `p under the min witness ID, run k`).
fn run_title(r: &Run) -> String {
    match (&r.property, r.run) {
        (Some(p), Some(k)) if !r.name.contains(" under the ") => format!("{p}: run {k}"),
        _ => r.name.clone(),
    }
}

/// `verify --schedulers`: per property the uniform estimate beside the min and max over
/// the sampled schedulers, their witnesses, and where an order-sensitive property's
/// order comes from (nothing without `--schedulers`).
fn bounds(o: &mut String, s: &Study) {
    let rows = s.scheduler_rows();
    let Some((_, first)) = rows.first() else {
        return;
    };
    let _ = writeln!(
        o,
        "<section id=\"schedulers\">\n<h2>Orders the model leaves open</h2>\n<p>Bounds over \
         {} sampled {} schedulers: each interval holds its witness's probability, together \
         at confidence {}; order-sensitive: max - min &gt; 2 x precision. Replay a witness \
         with <code>--scheduler ID</code>.</p>",
        first.sampled,
        esc(&first.memory),
        plot::label(s.confidence)
    );
    o.push_str(
        "<table class=\"props\">\n<thead><tr><th>property</th><th>uniform</th><th>min</th>\
         <th>max</th><th>order</th><th>where the order comes from</th></tr></thead>\n<tbody>\n",
    );
    let num = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.4}"));
    for (p, b) in rows {
        let side = |x: &hindsight_verify::schedulers::Bound| {
            format!(
                "{} [{:.4}, {:.4}]<br><code>{}</code>",
                num(x.probability),
                x.interval[0],
                x.interval[1],
                esc(&x.scheduler)
            )
        };
        let why =
            hindsight_verify::schedulers::explain(&b.sources, s.precision).unwrap_or_default();
        let _ = writeln!(
            o,
            "<tr class=\"{}\"><td><b>{}</b></td><td class=\"prob\">{}</td><td>{}</td><td>{}</td>\
             <td>{}</td><td>{}</td></tr>",
            if b.order_sensitive { "bad" } else { "ok" },
            esc(&p.property),
            num(p.probability),
            side(&b.min),
            side(&b.max),
            if b.order_sensitive {
                "order-sensitive"
            } else {
                "-"
            },
            esc(&why)
        );
    }
    o.push_str("</tbody></table>\n</section>\n");
}

fn study(o: &mut String, s: &Study, runs: &[Run]) {
    let _ = writeln!(o, "<section id=\"study\">\n<h2>Study</h2>");
    let mut settings: Vec<(String, String)> = vec![
        ("model".into(), s.model.clone()),
        ("properties".into(), s.properties_file.clone()),
        ("seed".into(), s.seed.to_string()),
        ("confidence".into(), plot::label(s.confidence)),
        ("precision".into(), plot::label(s.precision)),
    ];
    if let Some(step) = s.step_seconds {
        settings.push(("model time step".into(), format!("{} s", plot::label(step))));
    }
    if let Some(max) = s.max_time_seconds {
        settings.push(("run length".into(), format!("{} s", plot::label(max))));
    }
    settings.extend(s.settings.iter().cloned());
    if s.seconds > 0.0 {
        settings.push((
            "wall-clock".into(),
            format!(
                "{:.2} s ({:.0} runs/s)",
                s.seconds,
                s.runs as f64 / s.seconds
            ),
        ));
    }
    o.push_str("<table class=\"settings\">\n");
    for (k, v) in &settings {
        let _ = writeln!(o, "<tr><th>{}</th><td>{}</td></tr>", esc(k), esc(v));
    }
    o.push_str("</table>\n");
    let _ = writeln!(
        o,
        "<p class=\"ends\" id=\"run-ends\"><b>{}</b> runs: <b>{}</b> stopped early (every verdict \
         final), <b>{}</b> at the time horizon, <b>{}</b> quiescent, <b>{}</b> cut at the step \
         limit, <b>{}</b> discarded by assumptions.</p>",
        s.runs, s.decided, s.time_horizon, s.quiescent, s.step_limit, s.discarded
    );
    o.push_str(
        "<table class=\"props\">\n<thead><tr><th>property</th><th>probability</th>\
         <th>interval</th><th>runs</th><th>successes</th><th>cut short</th><th>decision</th>\
         <th>formula</th></tr></thead>\n<tbody>\n",
    );
    for p in &s.properties {
        let failing: Vec<usize> = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.property.as_deref() == Some(&p.property))
            .map(|(i, _)| i)
            .collect();
        let prob = p.probability.map_or("-".to_string(), |x| format!("{x:.4}"));
        let class = match p.probability {
            Some(x) if x >= 1.0 => "ok",
            Some(_) => "bad",
            None => "none",
        };
        let _ = write!(
            o,
            "<tr id=\"prop-{}\" data-property=\"{}\" class=\"{class}\"><td><b>{}</b></td>\
             <td class=\"prob\">{prob}</td><td>[{:.4}, {:.4}]</td><td>{}</td><td>{}</td>\
             <td>{}</td><td>{}</td><td>",
            anchor(&p.property),
            esc(&p.property),
            esc(&p.property),
            p.lower,
            p.upper,
            p.runs,
            p.successes,
            p.cut_short,
            esc(p.decision.as_deref().unwrap_or(""))
        );
        match &p.formula {
            Some(f) => {
                let _ = write!(o, "<div class=\"formula\"><code>{}</code></div>", esc(f));
            }
            None => o.push_str("<div class=\"formula none\">(not recorded)</div>"),
        }
        if let Some(c) = &p.compiled {
            let _ = write!(
                o,
                "<details><summary>as compiled</summary><code>{}</code></details>",
                esc(c)
            );
        }
        if !failing.is_empty() {
            o.push_str("<div class=\"runs\">failing runs:");
            for i in failing {
                let _ = write!(
                    o,
                    " <a href=\"#run-{i}\">{}</a>",
                    esc(&match runs[i].run {
                        Some(k) if !runs[i].name.contains(" under the ") => format!("run {k}"),
                        _ => runs[i].name.clone(),
                    })
                );
            }
            o.push_str("</div>");
        }
        o.push_str("</td></tr>\n");
    }
    o.push_str("</tbody></table>\n</section>\n");
}

fn sweep(o: &mut String, i: usize, s: &Sweep) {
    let _ = writeln!(
        o,
        "<section id=\"sweep-{i}\" class=\"sweep\">\n<h2>Sweep{}</h2>",
        if s.title.is_empty() {
            String::new()
        } else {
            format!(": {}", esc(&s.title))
        }
    );
    let mut seconds = false;
    let curves: Vec<plot::Curve> = s
        .properties
        .iter()
        .map(|c| {
            let points = c
                .points
                .iter()
                .filter_map(|p| {
                    let (x, secs) = bound_axis(&p.bound)?;
                    seconds |= secs;
                    Some(plot::Point {
                        x,
                        rate: p.probability?,
                        lower: p.lower,
                        upper: p.upper,
                    })
                })
                .collect();
            plot::Curve {
                name: c.property.clone(),
                points,
                threshold: c.threshold.as_deref().and_then(bound_axis).map(|(x, _)| x),
                threshold_text: c.threshold.clone(),
            }
        })
        .collect();
    let what = match (s.logs.len(), s.runs) {
        (0, Some(r)) => format!("{r} runs each"),
        (n, _) => format!("{n} recorded run{}", if n == 1 { "" } else { "s" }),
    };
    let x_label = if seconds {
        "bound (s)"
    } else {
        "bound (model time units)"
    };
    o.push_str(&plot::svg_element(
        &format!("success rate against the bound ({what})"),
        x_label,
        &curves,
    ));
    o.push_str(
        "<table class=\"thresholds\"><thead><tr><th>property</th><th>threshold</th>\
         <th>bounds</th></tr></thead><tbody>\n",
    );
    for c in &s.properties {
        let _ = writeln!(
            o,
            "<tr data-property=\"{}\"><td>{}</td><td class=\"threshold\">{}</td><td>{}</td></tr>",
            esc(&c.property),
            esc(&c.property),
            esc(c.threshold.as_deref().unwrap_or("none in the range")),
            c.points.len()
        );
    }
    o.push_str("</tbody></table>\n");
    // The numbers behind the chart, for copying.
    o.push_str("<details><summary>every bound</summary><table class=\"points\"><thead><tr><th>property</th><th>bound</th><th>successes</th><th>failures</th><th>unknown</th><th>probability</th><th>interval</th></tr></thead><tbody>\n");
    for c in &s.properties {
        for p in &c.points {
            let _ = writeln!(
                o,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>[{:.4}, {:.4}]</td></tr>",
                esc(&c.property),
                esc(&p.bound),
                p.successes,
                p.failures,
                p.unknown,
                p.probability.map_or("-".into(), |x| format!("{x:.4}")),
                p.lower,
                p.upper
            );
        }
    }
    o.push_str("</tbody></table></details>\n</section>\n");
}

fn run(o: &mut String, i: usize, r: &Run) {
    let end = r.time.last().copied().unwrap_or(0);
    let _ = writeln!(
        o,
        "<section id=\"run-{i}\" class=\"run\">\n<h3>{}</h3>\n<p class=\"meta\">{} \
         points over {} (from <code>{}</code>)</p>",
        esc(&run_title(r)),
        r.time.len(),
        time_text(end, r.step_seconds),
        esc(&r.name)
    );
    o.push_str("<ul class=\"first-false\">\n");
    for f in r.first_false() {
        let mine = r.property.as_deref() == Some(f.property.as_str());
        let because =
            r.culprits
                .iter()
                .find(|c| c.property == f.property)
                .map_or(String::new(), |c| {
                    format!(
                        ": <code class=\"culprit\">{}</code> was {} there",
                        esc(&c.formula),
                        c.value
                    )
                });
        let _ = writeln!(
            o,
            "<li class=\"{}\" data-property=\"{}\" data-point=\"{}\" data-time=\"{}\">\
             <a href=\"#prop-{}\">{}</a> is false from t = {} (point {}){because} \
             <a class=\"show\" href=\"#run-{i}-point-{}\">show</a></li>",
            if mine { "kept-for" } else { "other" },
            esc(&f.property),
            f.point,
            f.time,
            anchor(&f.property),
            esc(&f.property),
            time_text(f.time, r.step_seconds),
            f.point,
            f.point
        );
    }
    o.push_str("</ul>\n");
    let _ = writeln!(
        o,
        "<div class=\"tools\"><button data-act=\"fit\">fit</button>\
         <button data-act=\"in\">zoom in</button><button data-act=\"out\">zoom out</button>\
         <button data-act=\"false\">first false</button> <span class=\"view\"></span></div>\n\
         <div class=\"timeline\" id=\"timeline-{i}\" data-run=\"{i}\" tabindex=\"0\">\
         <noscript>The timeline needs JavaScript; the run's points are in {}.</noscript></div>\n\
         <div class=\"state\" id=\"state-{i}\"></div>\n</section>",
        esc(&r.name)
    );
}
