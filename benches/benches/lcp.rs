//! The step's LCP `w = Wλ + b, 0 ≤ λ ⊥ w ≥ 0` with `m` active rows: a
//! well-conditioned `W = AAᵀ + I/10` (every active row gets an impulse)
//! and a box landing on four corners (dependent rows: rank 3 of 4).
//!
//! `cargo bench -p moreau-bench --bench lcp`

use criterion::{Criterion, criterion_group, criterion_main};
use moreau::{IndexSet, Lcp};
use nalgebra::{SMatrix, SVector};
use std::hint::black_box;

/// `W = AAᵀ + I/10` with a fixed, well-spread `A`, and `b = −W 1`, so that
/// `λ = 1` on every active row.
fn problem<const K: usize>() -> (SMatrix<f64, K, K>, SVector<f64, K>) {
    let a = SMatrix::<f64, K, K>::from_fn(|i, j| {
        ((i * 7 + j * 3) % 5) as f64 - 2.0 + if i == j { 3.0 } else { 0.0 }
    });
    let w = a * a.transpose() + SMatrix::identity() * 0.1;
    let b = -(w * SVector::<f64, K>::repeat(1.0));
    (w, b)
}

fn lcp(c: &mut Criterion) {
    let solver = Lcp::<f64>::default();
    // what is timed is right: λ = 1 on every row (W positive definite)
    let check =
        |lambda: &[f64]| assert!(lambda.iter().all(|l| (l - 1.0).abs() < 1e-12), "{lambda:?}");
    check(
        solver
            .solve(&problem::<1>().0, &problem::<1>().1, IndexSet::full(1))
            .unwrap()
            .lambda
            .as_slice(),
    );
    check(
        solver
            .solve(&problem::<3>().0, &problem::<3>().1, IndexSet::full(3))
            .unwrap()
            .lambda
            .as_slice(),
    );
    check(
        solver
            .solve(&problem::<8>().0, &problem::<8>().1, IndexSet::full(8))
            .unwrap()
            .lambda
            .as_slice(),
    );
    let mut group = c.benchmark_group("lcp");
    let (w1, b1) = problem::<1>();
    group.bench_function("1 active", |b| {
        b.iter(|| solver.solve(black_box(&w1), black_box(&b1), IndexSet::full(1)))
    });
    let (w3, b3) = problem::<3>();
    group.bench_function("3 active", |b| {
        b.iter(|| solver.solve(black_box(&w3), black_box(&b3), IndexSet::full(3)))
    });
    let (w8, b8) = problem::<8>();
    group.bench_function("8 active", |b| {
        b.iter(|| solver.solve(black_box(&w8), black_box(&b8), IndexSet::full(8)))
    });
    // a unit box (mass 1, inertia 1/6) landing flat on four corners: the
    // four contact normals span only three directions
    let corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)];
    let jac = SMatrix::<f64, 4, 3>::from_fn(|i, j| match j {
        0 => 1.0,           // vertical
        1 => corners[i].1,  // roll
        _ => -corners[i].0, // pitch
    });
    let minv = SMatrix::<f64, 3, 3>::from_diagonal(&nalgebra::Vector3::new(1.0, 6.0, 6.0));
    let w = jac * minv * jac.transpose();
    let approach = SVector::<f64, 4>::repeat(-1.0);
    // the box stops: every corner's normal velocity becomes zero
    let landing = solver.solve(&w, &approach, IndexSet::full(4)).unwrap();
    assert!(landing.w.amax() < 1e-12, "{}", landing.w);
    group.bench_function("4 corners, rank 3", |b| {
        b.iter(|| solver.solve(black_box(&w), black_box(&approach), IndexSet::full(4)))
    });
    group.finish();
}

criterion_group!(benches, lcp);
criterion_main!(benches);
