//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod casadi;
pub mod exact;
pub mod phase;
pub mod posterior;
pub mod runs;

use std::path::PathBuf;

use moreau::ModelInfo;
use nalgebra::{DMatrix, SMatrix, SVector};
use serde_json::Value;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A CasADi fixture written by `tests/casadi_reference.py`.
pub fn casadi_fixture(stem: &str) -> Value {
    let path = root().join(format!("tests/fixtures/casadi/{stem}.json"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).expect("fixture is JSON")
}

/// A JSON list of numbers as a vector.
pub fn vector<const L: usize>(v: &Value) -> SVector<f64, L> {
    let items = v.as_array().expect("a list");
    assert_eq!(items.len(), L, "length of {v}");
    SVector::from_iterator(items.iter().map(|x| x.as_f64().expect("a number")))
}

/// A JSON list of rows as a matrix.
pub fn matrix<const R: usize, const C: usize>(v: &Value) -> SMatrix<f64, R, C> {
    let rows = v.as_array().expect("a list of rows");
    assert_eq!(rows.len(), R, "rows of {v}");
    let mut m = SMatrix::<f64, R, C>::zeros();
    for (i, row) in rows.iter().enumerate() {
        let row = row.as_array().expect("a row");
        assert_eq!(row.len(), C, "columns of {v}");
        for (j, x) in row.iter().enumerate() {
            m[(i, j)] = x.as_f64().expect("a number");
        }
    }
    m
}

/// Largest entry-wise difference of `a` from `b`, relative to the larger of
/// the entry and the largest entry of `b`: a normwise-componentwise measure.
/// An entry that is a small difference of large terms (a Coriolis sum, say)
/// carries a rounding error proportional to the terms, not to itself, so it
/// is judged against the size of its matrix.
pub fn relative_error<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
) -> f64 {
    relative_error_above(a, b, 0.0)
}

/// [`relative_error`] with the scale at least `floor`: the size of the
/// terms whose sum `b` is, when `b` is a small difference of them.
pub fn relative_error_above<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
    floor: f64,
) -> f64 {
    let scale = b.amax().max(floor);
    a.iter()
        .zip(b.iter())
        .map(|(x, y)| {
            let d = (x - y).abs();
            if d == 0.0 {
                0.0
            } else {
                d / y.abs().max(scale)
            }
        })
        .fold(0.0, f64::max)
}

/// Smallest eigenvalue of a symmetric matrix.
pub fn min_eigenvalue<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
    let d = DMatrix::from_iterator(N, N, m.iter().copied());
    d.symmetric_eigenvalues().min()
}

/// Central difference of `f` at `x` along coordinate `j`, with the step
/// `1e-6 max(|x_j|, 1)`.
pub fn central<const N: usize, const R: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, R>,
    x: &SVector<f64, N>,
    j: usize,
) -> SVector<f64, R> {
    let step = 1e-6 * x[j].abs().max(1.0);
    let (mut plus, mut minus) = (*x, *x);
    plus[j] += step;
    minus[j] -= step;
    (f(&plus) - f(&minus)) / (2.0 * step)
}

/// Two models' names, inputs and operation counts agree (everything in
/// `ModelInfo` but the model text, which differs with the front end).
pub fn same_info<const N: usize, const K: usize>(a: &ModelInfo<N, K>, b: &ModelInfo<N, K>) {
    let key = |i: &ModelInfo<N, K>| {
        (
            i.name,
            i.coordinates,
            i.velocities,
            i.constraints,
            i.parameters,
            i.inputs,
            i.op_count,
        )
    };
    assert_eq!(key(a), key(b));
}
