//! The benchmarked formulas and the spec each is compiled from; shared by `build.rs` and the crate.

/// Every benchmarked formula, in table order: the shapes of issue 2, then the
/// point interval `P[b:b]` over five bounds to show that the cost per point does
/// not depend on `b` (its state does: `b + 1` runs).
pub const FORMULAS: [&str; 11] = [
    "H({p} -> H(!{q}))",
    "H(({q} -> P {p}) && !(!{q} S[10:] {p}))",
    "H(P[10:] true -> P[:10] {r})",
    "{p} S[2:4] {q}",
    "P[0:100] {p}",
    "P[50:100] {p}",
    "P[10:10] {p}",
    "P[100:100] {p}",
    "P[1000:1000] {p}",
    "P[10000:10000] {p}",
    "P[100000:100000] {p}",
];

/// The `.hspec` text for one formula: time unit one tick, the three boolean state
/// variables of the trace, and the formula as property `f`.
pub fn spec(formula: &str) -> String {
    format!(
        "unit 1s;\n\
         state p: bool = false;\n\
         state q: bool = false;\n\
         state r: bool = false;\n\
         property f = {formula};\n"
    )
}
