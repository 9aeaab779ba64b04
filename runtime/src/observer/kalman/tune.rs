//! Picking settings from a recorded run by the innovation likelihood: the
//! process noise ([`tune_process_noise`], a continuous search), and one of
//! several given settings ([`pick_by_likelihood`]: which plant, if any,
//! made the samples).

use nalgebra::{RealField, SVector};

use crate::error::DataError;
use crate::model::Sensitivities;

use super::super::{Observer, ObserverError};
use super::{KalmanParams, KalmanReport, SaltationKalman};

/// Factors applied to the process-noise knobs of [`KalmanParams`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseFactors<T> {
    /// On [`KalmanParams::accel_noise`].
    pub accel: T,
    /// On [`KalmanParams::impact_noise`].
    pub impact: T,
    /// On [`KalmanParams::impact_time_sigma`].
    pub impact_time: T,
    /// On [`KalmanParams::contact_noise`].
    pub contact: T,
    /// Added to [`KalmanParams::impact_delay`], in seconds: the one knob
    /// that is shifted rather than scaled, since a mean delay has either
    /// sign and its natural start is zero.
    pub delay: T,
}

impl<T: RealField + Copy> NoiseFactors<T> {
    /// No change: every factor one, no delay added.
    ///
    /// ```
    /// use moreau_runtime::{KalmanParams, NoiseFactors};
    ///
    /// let p = KalmanParams::<f64, 2>::new(20.0, 1e-4);
    /// assert_eq!(p.scaled_by(&NoiseFactors::unit()), p);
    /// ```
    #[must_use]
    pub fn unit() -> Self {
        Self {
            accel: T::one(),
            impact: T::one(),
            impact_time: T::one(),
            contact: T::one(),
            delay: T::zero(),
        }
    }

    /// `ten^x` for each of the four scaled knobs, in the order of the
    /// fields; the delay `x[4] σ_t` (`σ_t` the given impact-time spread).
    fn from_coordinates(x: &[T; KNOBS], ten: T, sigma_t: T) -> Self {
        Self {
            accel: ten.powf(x[0]),
            impact: ten.powf(x[1]),
            impact_time: ten.powf(x[2]),
            contact: ten.powf(x[3]),
            delay: x[DELAY] * sigma_t,
        }
    }
}

/// The outcome of [`tune_process_noise`] (`#[non_exhaustive]`: read, not
/// built, so a field added later breaks no caller).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Tuning<T: RealField + Copy, const N: usize> {
    /// The settings with the chosen process noise.
    pub params: KalmanParams<T, N>,
    /// The factors applied to the given knobs.
    pub factors: NoiseFactors<T>,
    /// The innovation log-likelihood of the run at that factor,
    /// `Σ_k −½ (y_kᵀS_k⁻¹y_k + ln det S_k + N ln 2π)`.
    pub log_likelihood: T,
    /// Runs of the filter over the record.
    pub evaluations: u32,
}

/// Picks the process-noise knobs of `params` (acceleration, impact,
/// impact-time and contact noise, and the impacts' mean delay) for a
/// recorded run by maximising the innovation log-likelihood: each of the
/// four noise knobs scaled by a factor `10^x`, `x ∈ [lo, hi]`, and the
/// delay shifted by `y σ_t`, `y ∈ [−3, 3]` (`σ_t` the given
/// [`KalmanParams::impact_time_sigma`]; with `σ_t = 0` the delay stays
/// where it is). A knob given as zero stays zero (a factor cannot move
/// it), as those [`KalmanParams::with_plant_step`] sets do: a plant's
/// exact jumps, and no timing spread beyond its grid's.
/// Coordinate ascent: a first sweep with a grid of seven
/// points per knob and golden-section search around the best, a second
/// with golden-section search around the first's point.
/// Each evaluation runs a filter over the record from `(t[0], q[0])` with
/// the velocity estimate `v0`; nothing allocates.
///
/// A user with data does not tune by hand: the likelihood is largest where
/// the innovations are as large as the filter expects them, neither
/// smaller (too much process noise: the filter follows the noise) nor
/// larger (too little: it lags the motion).
///
/// Where the record cannot tell (a likelihood flat over decades of a knob,
/// as a short or uneventful record leaves it), the maximum is anywhere in
/// the flat region, and a knob picked there does worse on other runs than
/// the knob it started from. So each exponent carries a weak prior,
/// normal with a standard deviation of one decade around the given knob
/// (`x = 0`), and the delay one with a standard deviation of `σ_t` around
/// the given delay (`y = 0`): the search maximises the log-likelihood
/// minus `x²/2` per knob (maximum a posteriori). A record that asks for a knob a decade
/// away pays half a nat for it, while the likelihood of a record that
/// needs the change moves by tens to thousands of nats: such a record
/// still moves the knob freely; a flat one leaves it where it was.
/// [`Tuning::log_likelihood`] is the likelihood itself, without the prior.
///
/// ```
/// use moreau_runtime::{KalmanParams, Model, ModelInfo, Sensitivities, tune_process_noise};
/// use nalgebra::{Matrix1, SMatrix, SVector, Vector1};
///
/// /// A free unit mass on a line.
/// struct Free;
/// impl Model<1, 0> for Free {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 0> = ModelInfo {
///         name: "Free", coordinates: ["y"], velocities: ["vy"], constraints: [],
///         parameters: &[], inputs: &[], source: "", op_count: 0,
///     };
///     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::zeros() }
///     fn forces(&self, _: f64, _: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
///         Vector1::zeros()
///     }
///     fn gaps(&self, _: &Vector1<f64>) -> SVector<f64, 0> { SVector::zeros() }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> { SMatrix::zeros() }
///     fn restitution(&self) -> SVector<f64, 0> { SVector::zeros() }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
/// impl Sensitivities<1, 0> for Free {
///     fn mass_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> { SMatrix::zeros() }
/// }
///
/// // a mass whose acceleration changes by a deterministic ±1 every 10 ms,
/// // sampled exactly at 1 kHz: much more acceleration than the default
/// let (mut y, mut v) = (0.0, 0.0);
/// let (mut t, mut q) = (vec![0.0], vec![Vector1::new(0.0)]);
/// for k in 1..=2000 {
///     let a = if (k / 10) % 3 == 0 { 1.0 } else { -0.5 };
///     y += v * 1e-3 + 0.5 * a * 1e-6;
///     v += a * 1e-3;
///     t.push(k as f64 * 1e-3);
///     q.push(Vector1::new(y + 1e-5 * ((k * 7919) % 13) as f64 / 13.0));
/// }
/// let params = KalmanParams::<f64, 1>::new(10.0, 3e-6);
/// let tuned = tune_process_noise::<_, _, 1, 0>(&Free, params, &t, &q, &Vector1::zeros(), &SVector::zeros(), (-2.0, 4.0))?;
/// assert!(tuned.factors.accel > 2.0, "{:?}", tuned.factors);
/// // no contact in the record: the contact knobs keep their values
/// assert_eq!((tuned.factors.impact, tuned.factors.contact, tuned.factors.delay), (1.0, 1.0, 0.0));
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
///
/// # Errors
///
/// [`DataError::InvalidParams`](crate::DataError::InvalidParams) (`"record"`) when `t` and `q` differ in
/// length or hold fewer than two samples, or `lo ≥ hi`; any error of the
/// filter's construction or updates on the record other than a sample it
/// refuses as impossible ([`ObserverError::Outlier`]), which is skipped.
#[allow(clippy::too_many_arguments)]
pub fn tune_process_noise<M, T, const N: usize, const K: usize>(
    model: &M,
    params: KalmanParams<T, N>,
    t: &[T],
    q: &[SVector<T, N>],
    v0: &SVector<T, N>,
    u: &M::Input,
    (lo, hi): (T, T),
) -> Result<Tuning<T, N>, ObserverError<T>>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    check_record(t, q)?;
    if !(lo < hi && (hi - lo).is_finite()) {
        return Err(ObserverError::Data(DataError::InvalidParams {
            name: "record",
            value: nalgebra::convert(t.len() as f64),
        }));
    }
    let ten: T = nalgebra::convert(10.0);
    let mut evaluations = 0u32;
    // the prior: normal in each exponent, one decade around the given knob
    let sigma_t = params.impact_time_sigma;
    let prior = |x: &[T; KNOBS]| -> T {
        let half: T = nalgebra::convert(0.5);
        x.iter().fold(T::zero(), |acc, &xk| acc - half * xk * xk)
    };
    let mut posterior = |x: &[T; KNOBS]| -> Result<T, ObserverError<T>> {
        evaluations += 1;
        let p = params.scaled_by(&NoiseFactors::from_coordinates(x, ten, sigma_t));
        Ok(record_log_likelihood::<M, T, N, K>(model, p, (t, q), v0, u)? + prior(x))
    };
    // coordinate ascent in the exponents, from the defaults (0): the
    // first sweep a grid over [lo, hi] and golden-section search around
    // its best point, the second golden-section search around the first
    // sweep's point
    let three: T = nalgebra::convert(3.0);
    let mut x = [T::zero(); KNOBS];
    let mut best = posterior(&x)?;
    for sweep in 0..2 {
        for knob in 0..KNOBS {
            let (lo, hi) = if knob == DELAY {
                if sigma_t == T::zero() {
                    continue;
                }
                (-three, three)
            } else {
                (lo, hi)
            };
            let step = (hi - lo) / nalgebra::convert((GRID - 1) as f64);
            let mut centre = x[knob];
            if sweep == 0 {
                for j in 0..GRID {
                    let mut y = x;
                    y[knob] = lo + step * nalgebra::convert(j as f64);
                    let l = posterior(&y)?;
                    if l > best {
                        (best, centre) = (l, y[knob]);
                    }
                }
            }
            let bracket = ((centre - step).max(lo), (centre + step).min(hi));
            let (xk, l) = golden(bracket, |v| {
                let mut y = x;
                y[knob] = v;
                posterior(&y)
            })?;
            x[knob] = if l > best { xk } else { centre };
            best = best.max(l);
        }
    }
    let factors = NoiseFactors::from_coordinates(&x, ten, sigma_t);
    Ok(Tuning {
        params: params.scaled_by(&factors),
        factors,
        log_likelihood: best - prior(&x),
        evaluations,
    })
}

/// The outcome of [`pick_by_likelihood`] (`#[non_exhaustive]`, as
/// [`Tuning`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Picked<T: RealField + Copy, const N: usize> {
    /// The index of the likeliest of the candidates.
    pub index: usize,
    /// Its settings.
    pub params: KalmanParams<T, N>,
    /// The innovation log-likelihood of the record under them (as
    /// [`Tuning::log_likelihood`]).
    pub log_likelihood: T,
    /// How much likelier than the next candidate, in nats (the log of the
    /// likelihood ratio; infinite with one candidate). A few nats is a
    /// weak preference; tens, a decided one.
    pub margin: T,
}

/// The likeliest of `candidates` for a recorded run: each runs a filter
/// over the record (from `(t[0], q[0])` with the velocity estimate `v0`)
/// and sums the innovation log-likelihood, as [`tune_process_noise`]
/// does, with no prior. Where [`tune_process_noise`] turns the process
/// noise continuously, this chooses among discrete settings, those no
/// factor can reach: whether the samples come from a simulated plant, and
/// which ([`KalmanParams::with_plant_step`], [`KalmanParams::with_plant`]
/// with another law), and whether they lie on its grid
/// ([`KalmanParams::with_plant_grid`]), or from a machine the rigid model
/// describes (the defaults).
///
/// On Example 1's plant (Moreau–Jean at τ = 10 µs, 1 kHz, σ = 1e-4,
/// 10 s), the plant's own step on its grid is the likeliest of no plant,
/// steps of 5, 10 and 20 µs, 10 µs off the grid and Siconos's law at
/// 10 µs on each of twelve random starts, by 2.4 to 16 nats over the
/// runner-up and 18 to 59 over no plant; on samples taken halfway
/// between its steps, the same step off the grid, by 26 to 44 nats; on
/// samples of Siconos's law, that law, by 103 to 1129 nats; on exact
/// event-driven samples, no plant
/// (five runs of six; on the sixth a 5 µs step, by 0.7 nats: a tie)
/// (`tests/kalman.rs`, `the_likelihood_picks_the_plant_that_made_the_samples`).
///
/// A sample the filter refuses as impossible ([`ObserverError::Outlier`])
/// is skipped, as an observer loop skips it; it adds nothing.
///
/// ```
/// use moreau_runtime::{KalmanParams, Model, ModelInfo, Sensitivities, pick_by_likelihood};
/// use nalgebra::{Matrix1, SMatrix, SVector, Vector1};
///
/// /// A free unit mass on a line.
/// struct Free;
/// impl Model<1, 0> for Free {
///     type Scalar = f64;
///     type Input = SVector<f64, 0>;
///     const INFO: ModelInfo<1, 0> = ModelInfo {
///         name: "Free", coordinates: ["y"], velocities: ["vy"], constraints: [],
///         parameters: &[], inputs: &[], source: "", op_count: 0,
///     };
///     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
///     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::zeros() }
///     fn forces(&self, _: f64, _: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
///         Vector1::zeros()
///     }
///     fn gaps(&self, _: &Vector1<f64>) -> SVector<f64, 0> { SVector::zeros() }
///     fn gap_jacobian(&self, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> { SMatrix::zeros() }
///     fn restitution(&self) -> SVector<f64, 0> { SVector::zeros() }
///     fn parameter(&self, _: usize) -> Option<f64> { None }
///     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// }
/// impl Sensitivities<1, 0> for Free {
///     fn mass_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
///     fn jacobian_dq(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> { SMatrix::zeros() }
/// }
///
/// // a mass at 1 m/s, sampled at 1 kHz with noise of 1e-5 m (a fixed
/// // pseudo-random sequence): which measurement noise is likelier?
/// let (t, q): (Vec<f64>, Vec<Vector1<f64>>) = (0..=1000)
///     .map(|k| {
///         let noise = 1e-5 * (((k * 7919) % 13) as f64 / 13.0 - 0.5) * 3.4;
///         (k as f64 * 1e-3, Vector1::new(k as f64 * 1e-3 + noise))
///     })
///     .unzip();
/// let candidates = [1e-7, 1e-5, 1e-3].map(|sigma| KalmanParams::<f64, 1>::new(10.0, sigma));
/// let picked = pick_by_likelihood::<_, _, 1, 0>(
///     &Free, &candidates, &t, &q, &Vector1::new(1.0), &SVector::zeros(),
/// )?;
/// assert_eq!(picked.index, 1);
/// assert!(picked.margin > 10.0, "{picked:?}");
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
///
/// # Errors
///
/// [`DataError::InvalidParams`](crate::DataError::InvalidParams)
/// (`"record"`) when `t` and `q` differ in length or hold fewer than two
/// samples, (`"candidates"`) when there is none; any error of a filter's
/// construction or updates on the record other than a refused sample.
pub fn pick_by_likelihood<M, T, const N: usize, const K: usize>(
    model: &M,
    candidates: &[KalmanParams<T, N>],
    t: &[T],
    q: &[SVector<T, N>],
    v0: &SVector<T, N>,
    u: &M::Input,
) -> Result<Picked<T, N>, ObserverError<T>>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    check_record(t, q)?;
    let Some(&first) = candidates.first() else {
        return Err(ObserverError::Data(DataError::InvalidParams {
            name: "candidates",
            value: T::zero(),
        }));
    };
    let mut picked = Picked {
        index: 0,
        params: first,
        log_likelihood: record_log_likelihood::<M, T, N, K>(model, first, (t, q), v0, u)?,
        margin: T::one() / T::zero(),
    };
    let mut runner_up = -picked.margin;
    for (index, &params) in candidates.iter().enumerate().skip(1) {
        let l = record_log_likelihood::<M, T, N, K>(model, params, (t, q), v0, u)?;
        if l > picked.log_likelihood {
            runner_up = picked.log_likelihood;
            (picked.index, picked.params, picked.log_likelihood) = (index, params, l);
        } else {
            runner_up = runner_up.max(l);
        }
    }
    picked.margin = picked.log_likelihood - runner_up;
    Ok(picked)
}

/// `t` and `q` of equal length, at least two samples.
fn check_record<T: RealField + Copy, const N: usize>(
    t: &[T],
    q: &[SVector<T, N>],
) -> Result<(), ObserverError<T>> {
    if t.len() != q.len() || t.len() < 2 {
        return Err(ObserverError::Data(DataError::InvalidParams {
            name: "record",
            value: nalgebra::convert(t.len() as f64),
        }));
    }
    Ok(())
}

/// The innovation log-likelihood of the record `(t, q)` under `params`:
/// a filter from `(t[0], q[0])` with the velocity estimate `v0`, each
/// sample's `−½ (yᵀS⁻¹y + ln det S + N ln 2π)` summed, with a sample past
/// the gate counted as at the gate (one impact the model places a sample
/// off must not set the noise level of the whole run), and a sample the
/// filter refuses as impossible skipped.
fn record_log_likelihood<M, T, const N: usize, const K: usize>(
    model: &M,
    params: KalmanParams<T, N>,
    (t, q): (&[T], &[SVector<T, N>]),
    v0: &SVector<T, N>,
    u: &M::Input,
) -> Result<T, ObserverError<T>>
where
    T: RealField + Copy,
    M: Sensitivities<N, K, Scalar = T>,
{
    let mut filter = SaltationKalman::<T, N, K>::new(params, t[0], q[0], *v0)?;
    let mut total = T::zero();
    for (&tk, qk) in t.iter().zip(q).skip(1) {
        match filter.update(model, tk, qk, u) {
            Ok(_) => {}
            Err(ObserverError::Outlier { .. }) => continue,
            Err(e) => return Err(e),
        }
        let r = filter.kalman_report();
        let capped = KalmanReport {
            nis: r.nis.min(params.gate),
            ..*r
        };
        total += capped.log_likelihood(N);
    }
    Ok(total)
}

/// Points of the first sweep's grid per knob.
const GRID: usize = 7;
/// The knobs: acceleration, impact, impact-time and contact noise (as
/// exponents), and the mean delay (in units of `σ_t`).
const KNOBS: usize = 5;
/// The coordinate of the mean delay.
const DELAY: usize = 4;

/// The maximum of `f` over `[a, b]` by golden-section search (14 steps),
/// with its value.
fn golden<T, F>((mut a, mut b): (T, T), mut f: F) -> Result<(T, T), ObserverError<T>>
where
    T: RealField + Copy,
    F: FnMut(T) -> Result<T, ObserverError<T>>,
{
    let ratio: T = nalgebra::convert(0.618_033_988_749_895);
    let mut c = b - (b - a) * ratio;
    let mut d = a + (b - a) * ratio;
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    for _ in 0..14 {
        if fc > fd {
            (b, d, fd) = (d, c, fc);
            c = b - (b - a) * ratio;
            fc = f(c)?;
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + (b - a) * ratio;
            fd = f(d)?;
        }
    }
    Ok(if fc > fd { (c, fc) } else { (d, fd) })
}
