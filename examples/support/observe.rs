//! Runs an observer over a sampled trajectory and measures its error.

use moreau::{Model, Observer, ObserverError};
use nalgebra::SVector;

use super::plot::Result;
use super::reference::Reference;

/// An observer's estimates at every sample.
pub struct Estimates<const N: usize> {
    /// Velocity estimates `v̂(t_k)` (the first is the initial estimate).
    pub v: Vec<SVector<f64, N>>,
    /// `|v − v̂|` at every sample.
    pub error: Vec<f64>,
}

/// Feeds the measured positions of `reference` (from the second sample on)
/// to `observer`, which was started at the first sample; a sample it
/// refuses as an outlier keeps the estimate it had.
pub fn run<O, M, const N: usize, const K: usize, const NU: usize>(
    model: &M,
    observer: &mut O,
    reference: &Reference<N>,
) -> Result<Estimates<N>>
where
    O: Observer<M, N, K>,
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let u = SVector::<f64, NU>::zeros();
    let mut v = vec![observer.estimate().v];
    for (t, q) in reference.t.iter().zip(&reference.measured).skip(1) {
        match observer.update(model, *t, q, &u) {
            Ok(e) => v.push(e.v),
            // a sample refused as an outlier: the estimate is kept, as
            // the estimator kept it
            Err(ObserverError::Outlier { .. }) => v.push(observer.estimate().v),
            Err(e) => return Err(e.into()),
        }
    }
    let error = v
        .iter()
        .zip(&reference.v)
        .map(|(a, b)| (a - b).norm())
        .collect();
    Ok(Estimates { v, error })
}

/// The `p`-quantile (0 ≤ p ≤ 1) of `values`, by the nearest rank.
pub fn quantile(values: &[f64], p: f64) -> f64 {
    let mut sorted: Vec<f64> = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

/// The error at the sample nearest to `t`.
pub fn at(reference_t: &[f64], error: &[f64], t: f64) -> f64 {
    let k = reference_t
        .iter()
        .position(|&s| s >= t - 1e-12)
        .unwrap_or(reference_t.len() - 1);
    error[k]
}

/// Errors over `t ∈ [a, b]`.
pub fn window(reference_t: &[f64], error: &[f64], a: f64, b: f64) -> Vec<f64> {
    reference_t
        .iter()
        .zip(error)
        .filter(|(t, _)| **t >= a && **t <= b)
        .map(|(_, e)| *e)
        .collect()
}
