//! Special functions the stopping rules need: log-gamma, the regularized incomplete beta
//! function and its inverse, the standard normal distribution and its quantile.
//!
//! Written for robustness over speed: every function accepts its whole domain, returns
//! `NaN` only for arguments outside it, and the inverses are safeguarded Newton
//! iterations inside a shrinking bracket, so they always converge.

use std::f64::consts::{PI, SQRT_2};

/// Relative precision the series and continued fractions aim for.
const EPS: f64 = 1e-15;
/// Relative step size at which the root finder stops.
const SOLVE_TOLERANCE: f64 = 1e-13;
/// Smallest magnitude the modified Lentz algorithm lets a denominator reach.
const TINY: f64 = 1e-300;

/// Natural logarithm of the gamma function, for `x > 0` (`NaN` otherwise).
///
/// Shifts `x` up to at least 10 with `Γ(x) = Γ(x + 1) / x`, then uses Stirling's series
/// to the `x^-11` term (absolute error below 1e-15 there).
pub fn ln_gamma(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return f64::NAN;
    }
    if x.is_infinite() {
        return f64::INFINITY;
    }
    let mut x = x;
    let mut product = 1.0;
    while x < 10.0 {
        product *= x;
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    // Bernoulli-number coefficients B_2k / (2k (2k - 1)), k = 1..6.
    let series = inv
        * (1.0 / 12.0
            + inv2
                * (-1.0 / 360.0
                    + inv2
                        * (1.0 / 1260.0
                            + inv2
                                * (-1.0 / 1680.0
                                    + inv2 * (1.0 / 1188.0 + inv2 * (-691.0 / 360_360.0))))));
    (x - 0.5) * x.ln() - x + 0.5 * (2.0 * PI).ln() + series - product.ln()
}

/// Natural logarithm of the beta function `B(a, b) = Γ(a) Γ(b) / Γ(a + b)`.
pub(crate) fn ln_beta(a: f64, b: f64) -> f64 {
    ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)
}

/// Continued fraction for the incomplete beta function (modified Lentz), valid and fast
/// for `x < (a + 1) / (a + b + 2)`.
fn beta_continued_fraction(a: f64, b: f64, x: f64) -> f64 {
    // It converges in O(sqrt(max(a, b))) iterations.
    let max_iterations = 1000 + 10 * (a.max(b).sqrt() as usize);
    let clamp = |v: f64| if v.abs() < TINY { TINY } else { v };
    let mut c = 1.0;
    let mut d = 1.0 / clamp(1.0 - (a + b) * x / (a + 1.0));
    let mut h = d;
    for m in 1..=max_iterations {
        let m = m as f64;
        // Even step: d_{2m} = m (b - m) x / ((a + 2m - 1)(a + 2m)).
        let even = m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
        d = 1.0 / clamp(1.0 + even * d);
        c = clamp(1.0 + even / c);
        h *= d * c;
        // Odd step: d_{2m+1} = -(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)).
        let odd = -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
        d = 1.0 / clamp(1.0 + odd * d);
        c = clamp(1.0 + odd / c);
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

/// The regularized incomplete beta function `I_x(a, b)`, for `a > 0`, `b > 0`; `x` is
/// clamped to `[0, 1]`. `NaN` for a non-positive or `NaN` shape.
///
/// For integer shapes it is a binomial tail: `I_p(k, n - k + 1) = P[Bin(n, p) >= k]`.
pub fn reg_inc_beta(a: f64, b: f64, x: f64) -> f64 {
    if a.is_nan() || b.is_nan() || x.is_nan() || a <= 0.0 || b <= 0.0 {
        return f64::NAN;
    }
    reg_inc_beta_with(a, b, x, ln_beta(a, b))
}

/// [`reg_inc_beta`] for valid shapes, with `ln B(a, b)` precomputed.
fn reg_inc_beta_with(a: f64, b: f64, x: f64, ln_b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = a * x.ln() + b * (-x).ln_1p() - ln_b;
    if x < (a + 1.0) / (a + b + 2.0) {
        (ln_front.exp() * beta_continued_fraction(a, b, x) / a).clamp(0.0, 1.0)
    } else {
        // Symmetry I_x(a, b) = 1 - I_{1-x}(b, a) keeps the fraction in its fast region.
        (1.0 - ln_front.exp() * beta_continued_fraction(b, a, 1.0 - x) / b).clamp(0.0, 1.0)
    }
}

/// Density of the beta distribution at `x`, the derivative of [`reg_inc_beta`] in `x`.
fn beta_density(a: f64, b: f64, x: f64, ln_b: f64) -> f64 {
    ((a - 1.0) * x.ln() + (b - 1.0) * (-x).ln_1p() - ln_b).exp()
}

/// Solve `f(x) = target` for increasing `f` on `[lo, hi]`: Newton steps with derivative
/// `df`, replaced by bisection whenever a step would leave the current bracket. Always
/// terminates; the answer is within a few ulps of the root or of a bracket end.
fn solve_increasing(
    f: impl Fn(f64) -> f64,
    df: impl Fn(f64) -> f64,
    target: f64,
    mut lo: f64,
    mut hi: f64,
    start: f64,
) -> f64 {
    let mut x = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..400 {
        let value = f(x) - target;
        if value == 0.0 {
            return x;
        }
        if value < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let slope = df(x);
        let newton = x - value / slope;
        let next = if slope.is_finite() && slope > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        // The functions inverted here are accurate to about 1e-14 (relative), so a
        // tighter tolerance would only make Newton dither at rounding noise.
        let scale = next.abs().max(x.abs()).max(f64::MIN_POSITIVE);
        if (next - x).abs() <= SOLVE_TOLERANCE * scale || (hi - lo) <= SOLVE_TOLERANCE * scale {
            return next;
        }
        x = next;
    }
    x
}

/// A rough normal quantile (relative error about 1e-3), good enough for a start point.
fn rough_normal_quantile(p: f64) -> f64 {
    4.91 * (p.powf(0.14) - (1.0 - p).powf(0.14))
}

/// A start point for solving `I_x(a, b) = y`: the normal approximation of the beta
/// distribution, or the small-`x` expansion `I_x ~ x^a / (a B(a, b))` where that falls
/// outside `(0, 1)`.
fn beta_quantile_start(a: f64, b: f64, y: f64, ln_b: f64) -> f64 {
    let sum = a + b;
    let mean = a / sum;
    let sd = (a * b / (sum * sum * (sum + 1.0))).sqrt();
    let normal = mean + rough_normal_quantile(y) * sd;
    if normal > 0.0 && normal < 1.0 {
        return normal;
    }
    if normal <= 0.0 {
        ((y.ln() + a.ln() + ln_b) / a).exp().min(mean)
    } else {
        1.0 - (((1.0 - y).ln() + b.ln() + ln_b) / b).exp().min(1.0 - mean)
    }
}

/// The inverse of [`reg_inc_beta`] in `x`: the `y`-quantile of the `Beta(a, b)`
/// distribution. `y` is clamped to `[0, 1]`; `NaN` for a non-positive or `NaN` shape.
pub fn inv_reg_inc_beta(a: f64, b: f64, y: f64) -> f64 {
    if a.is_nan() || b.is_nan() || y.is_nan() || a <= 0.0 || b <= 0.0 {
        return f64::NAN;
    }
    if y <= 0.0 {
        return 0.0;
    }
    if y >= 1.0 {
        return 1.0;
    }
    let ln_b = ln_beta(a, b);
    let start = beta_quantile_start(a, b, y, ln_b);
    if start > 0.5 {
        // Solve for 1 - x, which is then small and precisely represented:
        // I_x(a, b) = y  <=>  I_{1-x}(b, a) = 1 - y.
        let complement = solve_increasing(
            |x| reg_inc_beta_with(b, a, x, ln_b),
            |x| beta_density(b, a, x, ln_b),
            1.0 - y,
            0.0,
            1.0,
            1.0 - start,
        );
        return 1.0 - complement;
    }
    solve_increasing(
        |x| reg_inc_beta_with(a, b, x, ln_b),
        |x| beta_density(a, b, x, ln_b),
        y,
        0.0,
        1.0,
        start,
    )
}

/// Regularized upper incomplete gamma function `Q(a, x)`, for `a > 0`, `x >= 0`.
fn reg_upper_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_front = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        // Series for the lower function P(a, x).
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut n = a;
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * EPS {
                break;
            }
        }
        1.0 - sum * ln_front.exp()
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let clamp = |v: f64| if v.abs() < TINY { TINY } else { v };
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let i = i as f64;
            let an = -i * (i - a);
            b += 2.0;
            d = 1.0 / clamp(an * d + b);
            c = clamp(b + an / c);
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < EPS {
                break;
            }
        }
        ln_front.exp() * h
    }
}

/// The complementary error function `erfc(x) = 1 - erf(x)`, accurate in both tails.
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x >= 0.0 {
        reg_upper_gamma(0.5, x * x)
    } else {
        2.0 - reg_upper_gamma(0.5, x * x)
    }
}

/// Cumulative distribution function of the standard normal distribution.
pub fn normal_cdf(z: f64) -> f64 {
    0.5 * erfc(-z / SQRT_2)
}

/// Quantile function of the standard normal distribution: the `z` with
/// `normal_cdf(z) = p`. `p` outside `(0, 1)` gives `-inf` / `+inf`; `NaN` for `NaN`.
pub fn normal_quantile(p: f64) -> f64 {
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    // Start from a rough approximation, then refine in the bracket.
    let start = rough_normal_quantile(p);
    let density = |z: f64| (-0.5 * z * z).exp() / (2.0 * PI).sqrt();
    solve_increasing(normal_cdf, density, p, -40.0, 40.0, start)
}
