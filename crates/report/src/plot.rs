//! An SVG chart of success rate against a time bound, one curve per property: the picture `hindsight sweep --svg` writes and reports show.

use std::fmt::Write;

use hindsight_verify::codegen::duration::StepsOrDuration;
use hindsight_verify::model::xml::escape as esc;
use hindsight_verify::sweep::{axis, bound_text, threshold_index, SweepCurve};

/// One measured point of a curve.
#[derive(Clone, Debug)]
pub struct Point {
    /// The bound, in the unit of the x axis.
    pub x: f64,
    /// The success rate.
    pub rate: f64,
    /// Lower end of its confidence interval.
    pub lower: f64,
    /// Upper end of its confidence interval.
    pub upper: f64,
}

/// One property's curve.
#[derive(Clone, Debug)]
pub struct Curve {
    /// The property's name (legend).
    pub name: String,
    /// Points in increasing `x`.
    pub points: Vec<Point>,
    /// The threshold found (the smallest bound from which every run succeeded), if any.
    pub threshold: Option<f64>,
    /// The threshold as the legend writes it (`6.2s`); the bare number when `None`.
    pub threshold_text: Option<String>,
}

/// The curves of a sweep (`hindsight sweep`'s, each bound of `values` a point; a point
/// with no estimate is left out), each with its threshold.
pub fn sweep_curves(values: &[StepsOrDuration], curves: &[SweepCurve]) -> Vec<Curve> {
    curves
        .iter()
        .map(|c| {
            let points = values
                .iter()
                .zip(&c.points)
                .map(|(v, p)| Point {
                    x: axis(*v),
                    rate: p.probability.unwrap_or(f64::NAN),
                    lower: p.lower,
                    upper: p.upper,
                })
                .filter(|p| p.rate.is_finite())
                .collect();
            let found = threshold_index(&c.points);
            Curve {
                name: c.property.clone(),
                points,
                threshold: found.map(|i| axis(values[i])),
                threshold_text: found.map(|i| bound_text(values[i])),
            }
        })
        .collect()
}

const W: f64 = 820.0;
const H: f64 = 500.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 200.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;
/// Colours that stay distinguishable for the common kinds of colour blindness.
const COLOURS: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
];

/// Rounds a tick step to 1, 2 or 5 times a power of ten.
fn nice_step(span: f64, ticks: f64) -> f64 {
    let raw = (span / ticks).max(f64::MIN_POSITIVE);
    let mag = 10f64.powf(raw.log10().floor());
    let m = raw / mag;
    let nice = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    nice * mag
}

/// A number without float noise (at most 6 decimals, trailing zeros dropped): tick
/// labels here, settings and times in the page.
pub(crate) fn label(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// The SVG document: rate (0 to 1) against bound, with interval bars, thresholds as dashed
/// vertical lines, and a legend naming each property and its threshold.
pub fn svg(title: &str, x_label: &str, curves: &[Curve]) -> String {
    chart(
        title,
        x_label,
        curves,
        r#" xmlns="http://www.w3.org/2000/svg""#,
    )
}

/// The same chart as an element to put inside an HTML page (no namespace attribute: the
/// HTML parser gives `<svg>` its namespace, and the page names no URL).
pub(crate) fn svg_element(title: &str, x_label: &str, curves: &[Curve]) -> String {
    chart(title, x_label, curves, "")
}

fn chart(title: &str, x_label: &str, curves: &[Curve], xmlns: &str) -> String {
    let xs = curves.iter().flat_map(|c| c.points.iter().map(|p| p.x));
    let (mut lo, mut hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if !lo.is_finite() || !hi.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if hi <= lo {
        hi = lo + 1.0;
    }
    let pw = W - LEFT - RIGHT;
    let ph = H - TOP - BOTTOM;
    let sx = |x: f64| LEFT + (x - lo) / (hi - lo) * pw;
    let sy = |y: f64| TOP + (1.0 - y.clamp(0.0, 1.0)) * ph;
    let mut o = String::new();
    let _ = writeln!(
        o,
        r#"<svg{xmlns} class="chart" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(o, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        LEFT + pw / 2.0,
        esc(title)
    );
    // Grid and axes.
    for i in 0..=10 {
        let y = i as f64 / 10.0;
        let _ = writeln!(
            o,
            r##"<line x1="{LEFT}" x2="{}" y1="{:.1}" y2="{:.1}" stroke="#e5e5e5"/>"##,
            LEFT + pw,
            sy(y),
            sy(y)
        );
        if i % 2 == 0 {
            let _ = writeln!(
                o,
                r#"<text x="{}" y="{:.1}" text-anchor="end">{}</text>"#,
                LEFT - 6.0,
                sy(y) + 4.0,
                label(y)
            );
        }
    }
    let step = nice_step(hi - lo, 10.0);
    let mut t = (lo / step).ceil() * step;
    while t <= hi + step * 1e-9 {
        let x = sx(t);
        let _ = writeln!(
            o,
            r##"<line x1="{x:.1}" x2="{x:.1}" y1="{TOP}" y2="{}" stroke="#f0f0f0"/>"##,
            TOP + ph
        );
        let _ = writeln!(
            o,
            r#"<text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"#,
            TOP + ph + 18.0,
            label(t)
        );
        t += step;
    }
    let _ = writeln!(
        o,
        r#"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
    );
    let _ = writeln!(
        o,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        LEFT + pw / 2.0,
        H - 15.0,
        esc(x_label)
    );
    let _ = writeln!(
        o,
        r#"<text transform="translate(18 {}) rotate(-90)" text-anchor="middle">success rate</text>"#,
        TOP + ph / 2.0
    );
    // Curves; earlier curves are drawn wider so that coinciding curves stay visible.
    for (i, c) in curves.iter().enumerate() {
        let width = 2.0 + 2.0 * (curves.len() - 1 - i) as f64;
        let col = COLOURS[i % COLOURS.len()];
        if let Some(th) = c.threshold {
            let x = sx(th);
            let _ = writeln!(
                o,
                r#"<line x1="{x:.1}" x2="{x:.1}" y1="{TOP}" y2="{}" stroke="{col}" stroke-dasharray="5 4"/>"#,
                TOP + ph
            );
        }
        for p in &c.points {
            let x = sx(p.x);
            let _ = writeln!(
                o,
                r#"<line x1="{x:.1}" x2="{x:.1}" y1="{:.1}" y2="{:.1}" stroke="{col}" stroke-opacity="0.5"/>"#,
                sy(p.lower),
                sy(p.upper)
            );
        }
        let path: Vec<String> = c
            .points
            .iter()
            .map(|p| format!("{:.1},{:.1}", sx(p.x), sy(p.rate)))
            .collect();
        let _ = writeln!(
            o,
            r#"<polyline points="{}" fill="none" stroke="{col}" stroke-width="{width}" stroke-linejoin="round"/>"#,
            path.join(" ")
        );
        for p in &c.points {
            let _ = writeln!(
                o,
                r#"<circle cx="{:.1}" cy="{:.1}" r="3" fill="{col}"><title>{}: {} -> {:.3} [{:.3}, {:.3}]</title></circle>"#,
                sx(p.x),
                sy(p.rate),
                esc(&c.name),
                label(p.x),
                p.rate,
                p.lower,
                p.upper
            );
        }
        // Legend.
        let ly = TOP + 10.0 + i as f64 * 36.0;
        let lx = LEFT + pw + 16.0;
        let _ = writeln!(
            o,
            r#"<line x1="{lx}" x2="{}" y1="{ly}" y2="{ly}" stroke="{col}" stroke-width="3"/>"#,
            lx + 22.0
        );
        let _ = writeln!(
            o,
            r#"<text x="{}" y="{}">{}</text>"#,
            lx + 28.0,
            ly + 4.0,
            esc(&c.name)
        );
        let th = match (&c.threshold_text, c.threshold) {
            (Some(text), Some(_)) => format!("threshold {text}"),
            (None, Some(t)) => format!("threshold {}", label(t)),
            (_, None) => "no threshold in range".to_string(),
        };
        let _ = writeln!(
            o,
            r##"<text x="{}" y="{}" fill="#555">{}</text>"##,
            lx + 28.0,
            ly + 19.0,
            esc(&th)
        );
    }
    o.push_str("</svg>\n");
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(name: &str, threshold: Option<f64>) -> Curve {
        Curve {
            name: name.into(),
            points: (0..5)
                .map(|i| Point {
                    x: i as f64 * 0.5,
                    rate: if i >= 3 { 1.0 } else { 0.0 },
                    lower: 0.0,
                    upper: 1.0,
                })
                .collect(),
            threshold,
            threshold_text: None,
        }
    }

    #[test]
    fn one_polyline_and_legend_per_curve_and_escaped_names() {
        let s = svg(
            "t",
            "bound (s)",
            &[curve("a<b", Some(1.5)), curve("c", None)],
        );
        assert!(s.starts_with("<svg"));
        assert!(s.trim_end().ends_with("</svg>"));
        assert_eq!(s.matches("<polyline").count(), 2);
        assert_eq!(s.matches("<circle").count(), 10);
        assert!(s.contains("a&lt;b"));
        assert!(!s.contains("a<b"));
        assert!(s.contains("threshold 1.5"));
        assert!(s.contains("no threshold in range"));
        assert!(s.contains("xmlns="));
        let e = svg_element("t", "x", &[curve("c", None)]);
        assert!(e.starts_with("<svg class=") && !e.contains("http"), "{e}");
        assert_eq!(s.matches("stroke-dasharray").count(), 1);
    }

    #[test]
    fn empty_or_single_point_charts_do_not_divide_by_zero() {
        let s = svg("t", "x", &[]);
        assert!(!s.contains("NaN") && !s.contains("inf"));
        let one = Curve {
            name: "p".into(),
            points: vec![Point {
                x: 2.0,
                rate: 1.0,
                lower: 0.9,
                upper: 1.0,
            }],
            threshold: Some(2.0),
            threshold_text: Some("2s".into()),
        };
        let s = svg("t", "x", &[one]);
        assert!(s.contains("threshold 2s"), "{s}");
        assert!(!s.contains("NaN") && !s.contains("inf"));
    }

    #[test]
    fn tick_steps_are_round() {
        assert_eq!(nice_step(10.0, 10.0), 1.0);
        assert_eq!(nice_step(7.0, 10.0), 1.0);
        assert_eq!(nice_step(25.0, 10.0), 5.0);
        assert_eq!(label(0.30000000000000004), "0.3");
    }
}
