//! A time-stepping plant's impacts on its own step grid.
//!
//! A Moreau–Jean plant of step `τ` ([`KalmanParams::plant`](super::KalmanParams::plant))
//! applies an impact in the step whose γ-prediction sees the gap close:
//! the step from `t_a` with `t* − t_a ∈ (γτ − τ, γτ]`, `t*` the exact
//! impact's instant. Inside that window the plant's outcome does not
//! move with `t*`: the impulse acts in the same step whatever the instant
//! within it. So, relative to an exact impact, the plant's impact comes
//! late by a delay that falls by one unit per unit of `t*` inside a
//! window and jumps by `τ` across a window's edge: the plant's impact
//! time `t_eff` is a staircase of `t*`.
//!
//! Where the samples are the plant's states at its own steps (the
//! interval is a whole number of steps), the grid is known: it passes
//! through the interval's start. The filter then knows in which window
//! its predicted `t̂*` falls, and what is uncertain is only its own error
//! `δ = t* − t̂*`, Gaussian of deviation `σ` (the estimate's gap along
//! the guard's normal over the approach speed; with a machine's spread
//! `σ_t` in quadrature). The plant's post-impact state is the exact
//! impact's at `t̂*` moved by `d · Q(δ)` (`d` the shift per unit of delay,
//! [`Saltation::timing`](super::Saltation::timing)), `Q` the staircase
//! `Q(δ) = Q_0 + jτ` on window `j`. The filter takes its Gaussian
//! moments (statistical linearisation, exact for the staircase):
//!
//! - the mean, `Q_0 + τ E[j]`;
//! - the slope `κ = Cov(δ, Q)/σ² = E[Q′] = τ Σ_j φ_σ(b_j)`, the density
//!   of `δ` at each window's edge `b_j` times the jump (Stein's lemma), so
//!   the covariance maps through `DΔ + κ (Ξ − DΔ)`: the reset's Jacobian
//!   where `σ ≪ τ` (the instant's error does not move the plant's
//!   outcome), the timed saltation `Ξ` where `σ ≫ τ` (`κ → 1`), more near
//!   an edge (the samples after it tell which window);
//! - the residual variance `τ² Var[j] − κ² σ_s²` along `d`, `σ_s` the
//!   state's part of `σ`: what the state's error does not explain.
//!
//! Where `σ ≫ τ` this is the uniform phase of an unknown grid (`κ = 1`,
//! residual `τ²/12`), which is what the filter takes when the grid is not
//! known.

use nalgebra::RealField;

/// The Gaussian moments of a plant's step grid at one impact
/// ([`staircase`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Staircase<T> {
    /// `τ E[j]`: the mean shift of the plant's impact time beyond the
    /// window the predicted instant falls in.
    pub mean: T,
    /// `κ = E[Q′]`: how much of the exact impact's timing the plant's
    /// outcome keeps.
    pub slope: T,
    /// `Var[Q] − κ² σ_s²`: the delay's variance the state does not
    /// explain.
    pub residual: T,
}

/// The moments of the staircase `Q(δ) = jτ` on the windows
/// `(lower + jτ, lower + (j + 1)τ]`, `δ ~ N(0, σ_s² + σ_m²)`, `lower`
/// (in `[−τ, 0]`) the lower edge of the window `δ = 0` falls in; `σ_s` the
/// state's part of the deviation, `σ_m` a machine's.
///
/// Two sums of the same moments, each where it is short:
///
/// - from `σ = 0.3 τ` on, the Fourier series: `Q(δ) = u − τ/2 − f(u)`,
///   `u = δ − lower`, `f` the sawtooth `−(τ/π) Σ_k sin(2πku/τ)/k`, whose
///   terms the Gaussian damps by `e_k = exp(−2π²k²σ²/τ²)` (`e_4` is
///   5e-13 at `0.3 τ`, so four terms; all vanish from `σ ≈ τ` on, the
///   uniform phase);
/// - below it, the windows that meet six deviations either side (at most
///   five; the Gaussian's tail beyond is 2e-9).
pub(super) fn staircase<T: RealField + Copy>(
    tau: T,
    lower: T,
    sigma_state: T,
    sigma_machine: T,
) -> Staircase<T> {
    let sigma = (sigma_state * sigma_state + sigma_machine * sigma_machine).sqrt();
    if sigma.partial_cmp(&(tau * nalgebra::convert(1e-9))) != Some(core::cmp::Ordering::Greater) {
        // the instant is known: the window it falls in
        return Staircase {
            mean: T::zero(),
            slope: T::zero(),
            residual: T::zero(),
        };
    }
    if sigma >= tau * nalgebra::convert(0.3) {
        return fourier(tau, lower, sigma, sigma_machine);
    }
    let mut mean = T::zero();
    let mut square = T::zero();
    // the density at every edge, the lowest one's first
    let mut density: Option<T> = None;
    for w in windows(tau, lower, sigma) {
        let j = w.steps;
        mean += j * w.probability;
        square += j * j * w.probability;
        density = Some(density.unwrap_or(w.density_lower) + w.density_upper);
    }
    let slope = tau * density.unwrap_or(T::zero()) / sigma;
    let variance = tau * tau * (square - mean * mean).max(T::zero());
    Staircase {
        mean: tau * mean,
        slope,
        residual: (variance - slope * slope * sigma_state * sigma_state).max(T::zero()),
    }
}

/// One window `(lower + jτ, lower + (j + 1)τ]` of the instant's error
/// `δ ~ N(0, σ²)` ([`windows`]): its edges in deviations, its probability
/// and the density at each edge.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Edges<T> {
    steps: T,
    lower: T,
    upper: T,
    probability: T,
    density_lower: T,
    density_upper: T,
}

/// The windows of [`staircase`] that meet `[−6σ, 6σ]`, lowest first; each
/// edge's distribution and density is evaluated once, the upper edge's
/// serving as the next window's lower.
fn windows<T: RealField + Copy>(tau: T, lower: T, sigma: T) -> impl Iterator<Item = Edges<T>> {
    let six = nalgebra::convert::<f64, T>(6.0) * sigma;
    let first = ((-six - lower) / tau).ceil() - T::one();
    let last = ((six - lower) / tau).ceil() - T::one();
    let edge = move |j: T| {
        let x = (lower + j * tau) / sigma;
        (x, normal_cdf(x), normal_density(x))
    };
    let mut j = first;
    let mut below = edge(first);
    core::iter::from_fn(move || {
        if j > last {
            return None;
        }
        let above = edge(j + T::one());
        let w = Edges {
            steps: j,
            lower: below.0,
            upper: above.0,
            probability: above.1 - below.1,
            density_lower: below.2,
            density_upper: above.2,
        };
        (j, below) = (j + T::one(), above);
        Some(w)
    })
}

/// One step the plant may have taken an impact into: the window `j`
/// steps from the predicted instant's ([`staircase`]'s windows), its
/// probability, and the mean and variance of the instant's error `δ`
/// within it (a truncated Gaussian's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Window<T> {
    pub steps: T,
    pub probability: T,
    pub mean: T,
    pub variance: T,
}

/// The most steps a split keeps (the filter's state and its
/// alternatives, module `mixture`): below [`SPLIT_BELOW`] three windows
/// span at least six deviations, all but 0.3 % of the instant's
/// probability.
pub(super) const SPLIT: usize = 3;

/// The instant's deviation, in steps, from which an impact is not split
/// but takes [`staircase`]'s moments: from half a step on the sawtooth's
/// first Fourier term is damped to 0.7 % (`exp(−2π² σ²/τ²)`), so the
/// choice of step is as undecided as the instant itself, which one
/// Gaussian (the uniform phase) describes.
const SPLIT_BELOW: f64 = 0.5;

/// The likely windows of an impact whose instant's error `δ ~ N(0, σ²)`
/// (windows as in [`staircase`]), most probable first, their
/// probabilities renormalised over those kept; `None` where one window
/// holds all but `1e-3` of the probability (nothing to split) or where
/// `σ ≥ τ/2` (many steps: [`staircase`]'s moments instead).
pub(super) fn likely_windows<T: RealField + Copy>(
    tau: T,
    lower: T,
    sigma: T,
) -> Option<([Window<T>; SPLIT], usize)> {
    if !(sigma > tau * nalgebra::convert(1e-9) && sigma < tau * nalgebra::convert(SPLIT_BELOW)) {
        return None;
    }
    let empty = Window {
        steps: T::zero(),
        probability: T::zero(),
        mean: T::zero(),
        variance: T::zero(),
    };
    let mut kept = [empty; SPLIT];
    for edges in windows(tau, lower, sigma) {
        let z = edges.probability;
        if z > T::zero() {
            let (a, b) = (edges.lower, edges.upper);
            let (fa, fb) = (edges.density_lower, edges.density_upper);
            let mean = (fa - fb) / z;
            let second = T::one() + (a * fa - b * fb) / z;
            let window = Window {
                steps: edges.steps,
                probability: z,
                mean: mean * sigma,
                variance: (second - mean * mean).max(T::zero()) * sigma * sigma,
            };
            // insert by probability
            let mut at = SPLIT;
            for (i, k) in kept.iter().enumerate() {
                if window.probability > k.probability {
                    at = i;
                    break;
                }
            }
            if at < SPLIT {
                for i in (at + 1..SPLIT).rev() {
                    kept[i] = kept[i - 1];
                }
                kept[at] = window;
            }
        }
    }
    let total = kept.iter().fold(T::zero(), |acc, w| acc + w.probability);
    let len = kept
        .iter()
        .filter(|w| w.probability > total * nalgebra::convert(1e-3))
        .count();
    if len < 2 {
        return None;
    }
    let total = kept[..len]
        .iter()
        .fold(T::zero(), |acc, w| acc + w.probability);
    for w in &mut kept[..len] {
        w.probability /= total;
    }
    Some((kept, len))
}

/// [`staircase`] by the Fourier series of its sawtooth, for `σ ≥ 0.3 τ`:
/// with `θ = 2π u₀/τ`, `u₀ = −lower`,
///
/// - `E[Q] = u₀ − τ/2 + (τ/π) Σ sin(kθ) e_k / k`,
/// - `κ = E[Q′] = 1 + 2 Σ cos(kθ) e_k` (the comb of edges, by Poisson's
///   sum),
/// - `Var[f] = τ² (1/12 + Σ cos(kθ) e_k / (π²k²)) − E[f]²`, and the
///   residual `Var[Q] − κ²σ_s² = Var[f] − σ² (1 − κ)² + κ² σ_m²`
///   (`Cov(u, f) = σ² (1 − κ)` by Stein's lemma), written so that nothing
///   cancels where `κ → 1`.
fn fourier<T: RealField + Copy>(tau: T, lower: T, sigma: T, sigma_machine: T) -> Staircase<T> {
    let pi = T::pi();
    let ratio = sigma / tau;
    let damping = (-(pi * pi) * ratio * ratio * nalgebra::convert(2.0)).exp();
    let (sin1, cos1) = (T::two_pi() * -lower / tau).sin_cos();
    let (mut sin_k, mut cos_k) = (sin1, cos1);
    let (mut mean_f, mut square_f, mut comb) = (T::zero(), T::zero(), T::zero());
    for k in 1..=4 {
        let kf: T = nalgebra::convert(f64::from(k));
        let e_k = damping.powi(k * k);
        mean_f -= sin_k * e_k / kf;
        square_f += cos_k * e_k / (kf * kf);
        comb += cos_k * e_k;
        (sin_k, cos_k) = (sin_k * cos1 + cos_k * sin1, cos_k * cos1 - sin_k * sin1);
    }
    let mean_f = mean_f * tau / pi;
    let square_f = tau * tau * (T::one() / nalgebra::convert(12.0) + square_f / (pi * pi));
    let slope = T::one() + comb * nalgebra::convert(2.0);
    let half: T = nalgebra::convert(0.5);
    let one_less = T::one() - slope;
    Staircase {
        mean: -lower - tau * half - mean_f,
        slope,
        residual: (square_f - mean_f * mean_f - sigma * sigma * one_less * one_less
            + slope * slope * sigma_machine * sigma_machine)
            .max(T::zero()),
    }
}

/// `φ(x)`, the standard normal density.
fn normal_density<T: RealField + Copy>(x: T) -> T {
    let half: T = nalgebra::convert(0.5);
    (-(x * x) * half).exp() / T::two_pi().sqrt()
}

/// `Φ(x)`, the standard normal distribution, `erfc(−x/√2)/2`, to a
/// relative `1.2e-7` (the complementary error function of Numerical
/// Recipes' `erfcc`, Chebyshev-fitted).
fn normal_cdf<T: RealField + Copy>(x: T) -> T {
    let half: T = nalgebra::convert(0.5);
    let z = -x / nalgebra::convert::<f64, T>(core::f64::consts::SQRT_2);
    let a = z.abs();
    let t = T::one() / (T::one() + half * a);
    let c = |v: f64| nalgebra::convert::<f64, T>(v);
    let poly = c(-1.265_512_23)
        + t * (c(1.000_023_68)
            + t * (c(0.374_091_96)
                + t * (c(0.096_784_18)
                    + t * (c(-0.186_288_06)
                        + t * (c(0.278_868_07)
                            + t * (c(-1.135_203_98)
                                + t * (c(1.488_515_87)
                                    + t * (c(-0.822_152_23) + t * c(0.170_872_77)))))))));
    let tail = t * (-(a * a) + poly).exp();
    let erfc = if z >= T::zero() { tail } else { c(2.0) - tail };
    half * erfc
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The moments by brute force: `Q(δ)` averaged over a fine grid of the
    /// Gaussian.
    fn by_quadrature(tau: f64, lower: f64, s: f64, m: f64) -> (f64, f64, f64) {
        let sigma = (s * s + m * m).sqrt();
        let n = 400_000;
        let span = 12.0 * sigma;
        let dx = 2.0 * span / n as f64;
        let (mut w, mut mq, mut mq2, mut mdq) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            let d = -span + (i as f64 + 0.5) * dx;
            let p = (-(d * d) / (2.0 * sigma * sigma)).exp();
            let q = ((d - lower) / tau).ceil() - 1.0;
            w += p;
            mq += p * q * tau;
            mq2 += p * (q * tau).powi(2);
            mdq += p * d * q * tau;
        }
        let (mean, sq, cross) = (mq / w, mq2 / w, mdq / w);
        let slope = cross / (sigma * sigma);
        let residual = sq - mean * mean - slope * slope * s * s;
        (mean, slope, residual)
    }

    #[test]
    fn the_moments_are_the_staircases() {
        let tau: f64 = 1e-5;
        for &(lower, s, m) in &[
            (-0.5e-5, 1e-6, 0.0),
            (-0.1e-5, 1e-6, 0.0),
            (-0.95e-5, 3e-6, 1e-6),
            (-0.3e-5, 1.2e-5, 0.0),
            (-0.7e-5, 4e-6, 0.0),
        ] {
            let got = staircase(tau, lower, s, m);
            let (mean, slope, residual) = by_quadrature(tau, lower, s, m);
            assert!((got.mean - mean).abs() < 1e-3 * tau, "{got:?} {mean}");
            assert!(
                (got.slope - slope).abs() < 1e-3 * slope.abs().max(1e-3),
                "{got:?} {slope}"
            );
            assert!(
                (got.residual - residual).abs() < 1e-3 * tau * tau,
                "{got:?} {residual}"
            );
        }
    }

    #[test]
    fn a_wide_spread_is_the_uniform_phase() {
        let tau: f64 = 1e-5;
        let lower = -0.25e-5;
        let wide = staircase(tau, lower, 20.0 * tau, 0.0);
        // many steps wide: the uniform phase about the window's centre
        assert_eq!(wide.slope, 1.0);
        assert!((wide.residual - tau * tau / 12.0).abs() < 1e-20);
        assert!((wide.mean - (-(lower + tau / 2.0))).abs() < 1e-20);
        // and at 0.9 step already, as the damping of the staircase's
        // periodic part, exp(−2π²σ²/τ²), says (1e-7)
        let near = staircase(tau, lower, 0.9 * tau, 0.0);
        assert!((near.slope - 1.0).abs() < 1e-6, "{near:?}");
        assert!((near.mean - wide.mean).abs() < 1e-6 * tau, "{near:?}");
        assert!(
            (near.residual - tau * tau / 12.0).abs() < 1e-6 * tau * tau,
            "{near:?}"
        );
    }

    #[test]
    fn the_two_sums_agree_where_they_meet() {
        let tau: f64 = 1e-5;
        for &lower in &[-0.05e-5, -0.3e-5, -0.5e-5, -0.77e-5, -1e-5] {
            for &(s, m) in &[(0.3e-5_f64, 0.0_f64), (0.2e-5, 0.2236e-5)] {
                let by_fourier = fourier(tau, lower, (s * s + m * m).sqrt(), m);
                // the windows' sum, run just below its switch
                let by_windows = staircase(tau, lower, 0.999_99 * s, 0.999_99 * m);
                let (a, b) = (by_fourier, by_windows);
                assert!((a.mean - b.mean).abs() < 1e-4 * tau, "{a:?} {b:?}");
                assert!((a.slope - b.slope).abs() < 1e-4, "{a:?} {b:?}");
                assert!(
                    (a.residual - b.residual).abs() < 1e-4 * tau * tau,
                    "{a:?} {b:?}"
                );
            }
        }
    }

    #[test]
    fn the_likely_windows_are_the_truncated_gaussians() {
        let tau: f64 = 1e-5;
        // the instant 0.05 step from an edge, a deviation of 0.1 step:
        // the window and the next one share the probability
        let lower = -0.95e-5;
        let sigma = 1e-6;
        let (w, len) = likely_windows(tau, lower, sigma).unwrap();
        assert_eq!(len, 2);
        assert_eq!((w[0].steps, w[1].steps), (0.0, 1.0));
        // P(δ > 0.5 µs) = 1 − Φ(0.5) = 0.3085 (tables)
        assert!((w[1].probability - 0.308_537_5).abs() < 1e-6, "{w:?}");
        // the mixture of the windows is the Gaussian: mean 0, variance σ²
        let mean = w[0].probability * w[0].mean + w[1].probability * w[1].mean;
        let second: f64 = w[..2]
            .iter()
            .map(|w| w.probability * (w.variance + w.mean * w.mean))
            .sum();
        assert!(
            mean.abs() < 1e-12 && (second - sigma * sigma).abs() < 1e-15,
            "{w:?}"
        );
        // far from an edge there is nothing to split
        assert!(likely_windows(tau, -0.5e-5, sigma).is_none());
    }

    #[test]
    fn a_known_instant_is_its_window() {
        let s = staircase(1e-5_f64, -0.5e-5, 0.0, 0.0);
        assert_eq!((s.mean, s.slope, s.residual), (0.0, 0.0, 0.0));
        // far from an edge, next to nothing moves
        let narrow = staircase(1e-5_f64, -0.5e-5, 1e-7, 0.0);
        assert!(narrow.mean.abs() < 1e-15 && narrow.slope < 1e-10 && narrow.residual < 1e-25);
    }

    #[test]
    fn the_normal_distribution_is_within_its_stated_accuracy() {
        // Φ at a few points (to 10 digits, from the error function's tables)
        for &(x, p) in &[
            (0.0, 0.5),
            (1.0, 0.841_344_746_1),
            (-1.0, 0.158_655_253_9),
            (2.5, 0.993_790_334_7),
            (-3.0, 0.001_349_898_0),
        ] {
            let got: f64 = normal_cdf(x);
            assert!(
                (got - p).abs() <= 1.2e-7 * p.max(1.0 - p),
                "Φ({x}) = {got}, not {p}"
            );
        }
    }
}
