//! Generated model evaluation against CasADi's generated C at -O3, side by
//! side in one run: the fused evaluation of M, C, G, F, h and J of each
//! shipped model at the same point (a CasADi fixture point, non-default
//! parameters). Both results are checked to agree before timing.
//!
//! `cargo bench -p moreau-bench --bench model_eval`

use criterion::{Criterion, criterion_group, criterion_main};
use moreau::Model;
use moreau_bench::CasadiModel;
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::SVector;
use std::hint::black_box;

fn compare<M, const N: usize, const K: usize, const NU: usize>(
    c: &mut Criterion,
    name: &str,
    model: M,
    mut casadi: CasadiModel<N, K>,
) where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    // a point away from symmetric values, parameters scaled off defaults
    let q = SVector::<f64, N>::from_fn(|i, _| 0.3 + 0.17 * i as f64);
    let v = SVector::<f64, N>::from_fn(|i, _| -0.4 + 0.23 * i as f64);
    let u = SVector::<f64, NU>::from_fn(|i, _| 0.1 * (i + 1) as f64);
    let mut model = model;
    let mut p = Vec::new();
    let mut i = 0;
    while let Some(x) = model.parameter(i) {
        *model.parameter_mut(i).unwrap() = x * (1.0 + 0.01 * i as f64);
        p.push(x * (1.0 + 0.01 * i as f64));
        i += 1;
    }
    let t = 1.25;
    let ours = model.eval(t, &q, &v, &u);
    casadi.eval(t, &q, &v, u.as_slice(), &p);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
    assert!(
        ours.mass
            .iter()
            .zip(casadi.mass.iter())
            .all(|(a, b)| close(*a, *b))
    );
    assert!(
        ours.forces
            .iter()
            .zip(casadi.forces.iter())
            .all(|(a, b)| close(*a, *b))
    );
    assert!(
        ours.jacobian
            .iter()
            .zip(casadi.jacobian.iter())
            .all(|(a, b)| close(*a, *b))
    );

    let mut group = c.benchmark_group(format!("eval/{name}"));
    group.bench_function("moreau", |b| {
        b.iter(|| black_box(&model).eval(black_box(t), black_box(&q), black_box(&v), black_box(&u)))
    });
    group.bench_function("casadi-c-O3", |b| {
        b.iter(|| {
            casadi.eval(
                black_box(t),
                black_box(&q),
                black_box(&v),
                black_box(u.as_slice()),
                black_box(&p),
            );
            black_box(&casadi.forces);
        })
    });
    group.finish();
}

fn models(c: &mut Criterion) {
    compare::<_, 2, 2, 0>(
        c,
        "parabola",
        Parabola::<f64>::default(),
        moreau_bench::parabola(),
    );
    compare::<_, 3, 4, 0>(
        c,
        "three_balls",
        ThreeBalls::<f64>::default(),
        moreau_bench::three_balls(),
    );
    compare::<_, 2, 4, 0>(
        c,
        "billiard",
        Billiard::<f64>::default(),
        moreau_bench::billiard(),
    );
    compare::<_, 2, 2, 0>(
        c,
        "double_pendulum",
        DoublePendulum::<f64>::default(),
        moreau_bench::double_pendulum(),
    );
    compare::<_, 3, 1, 3>(c, "arm3", Arm3::<f64>::default(), moreau_bench::arm3());
}

criterion_group!(benches, models);
criterion_main!(benches);
