//! Certification of the gain constants (issue 13): `CertifiedBounds::certify`
//! over the working regions of `tests/certified.rs`, with the default
//! budget (the arm's run takes seconds: it spends the whole budget on
//! three of its four constants).
//!
//! `cargo bench -p moreau-bench --bench certify`

use criterion::{Criterion, criterion_group, criterion_main};
use moreau::{Budget, CertifiedBounds, GainRegion, Interval};
use moreau_models::{Arm3, DoublePendulum};
use nalgebra::{Vector2, Vector3};
use std::hint::black_box;
use std::time::Duration;

fn certify(c: &mut Criterion) {
    let mut group = c.benchmark_group("certify");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(5));

    let pendulum = DoublePendulum::<f64>::new();
    let region = GainRegion::new(Vector2::repeat(-1.5), Vector2::repeat(1.5), 5.0);
    group.bench_function("double_pendulum/default_budget", |b| {
        b.iter(|| {
            CertifiedBounds::certify(black_box(&pendulum), &region, &[], &Budget::default())
                .unwrap()
        })
    });

    let arm = Arm3::<f64>::new();
    let q0 = Vector3::new(0.9, -0.6, -0.4);
    let region = GainRegion::new(q0 - Vector3::repeat(0.5), q0 + Vector3::repeat(0.5), 3.0);
    let u = [Interval::new(-5.0, 5.0).unwrap(); 3];
    group.bench_function("arm3/default_budget", |b| {
        b.iter(|| {
            CertifiedBounds::certify(black_box(&arm), &region, &u, &Budget::default()).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, certify);
criterion_main!(benches);
