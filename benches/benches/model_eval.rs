//! Generated model evaluation against CasADi's generated C, interleaved in
//! one process: the fused evaluation of M, C, G, F, h and J of each
//! shipped model and each N-link chain (N = 2..12).
//!
//! How each side is called:
//!
//! * **moreau**: `model.eval(t, &q, &v, &u)` on the model value, as a Rust
//!   user calls it (the model behind `black_box`, so nothing that depends
//!   only on the parameters is hoisted out of the loop), its result
//!   `black_box`ed.
//! * **CasADi, direct**: the generated C function called as a C user calls
//!   it: one `const double* arg[5]` per input point and the `double*
//!   res[6]` set up once outside the timed loop, one call per evaluation,
//!   its status `black_box`ed (what a C user's `if (f(...))` costs).
//! * **CasADi, Rust wrapper**: the same function through
//!   [`moreau_bench::CasadiModel::eval`], which builds the pointer arrays
//!   and asserts the status on every call (how a Rust user might wrap it).
//!
//! Inputs vary over the 32 sample points of the model's CasADi fixture
//! (`t`, `q`, `v`, `u`; the model's default parameters on both sides), and
//! both results are checked to agree at every point before timing. Both
//! sides are compiled for the same target CPU (`build.rs`: the C at `-O3`,
//! no `-march`; no `-C target-cpu` for the Rust, `opt-level = 3`).
//!
//! One sample is 16 passes over the 32 points (512 calls) of one side; the
//! three sides are sampled in turn, in a rotating order, `REPS` times
//! (`MOREAU_BENCH_REPS`, default 301). The table gives the minimum and the
//! median time per call of each side's samples, and the ratio CasADi /
//! moreau of the medians.
//!
//! `cargo bench -p moreau-bench --bench model_eval`

use std::hint::black_box;
use std::time::Instant;

use moreau::Model;
use moreau_bench::CasadiModel;
use nalgebra::SVector;

const PASSES: usize = 16;

struct Points<const N: usize, const NU: usize> {
    t: Vec<f64>,
    q: Vec<SVector<f64, N>>,
    v: Vec<SVector<f64, N>>,
    u: Vec<SVector<f64, NU>>,
    casadi_ops: u64,
}

fn load<const N: usize, const NU: usize>(path: &str) -> Points<N, NU> {
    let path = format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("fixture JSON");
    let vector = |x: &serde_json::Value| -> Vec<f64> {
        x.as_array()
            .expect("an array")
            .iter()
            .map(|y| y.as_f64().expect("a number"))
            .collect()
    };
    let mut points = Points {
        t: Vec::new(),
        q: Vec::new(),
        v: Vec::new(),
        u: Vec::new(),
        casadi_ops: json["casadi_op_count"].as_u64().expect("casadi_op_count"),
    };
    for point in json["points"].as_array().expect("points") {
        points.t.push(point["t"].as_f64().expect("t"));
        points.q.push(SVector::from_vec(vector(&point["q"])));
        points.v.push(SVector::from_vec(vector(&point["v"])));
        points.u.push(SVector::from_vec(vector(&point["u"])));
    }
    points
}

/// Minimum and median of the samples.
fn stats(samples: &mut [f64]) -> (f64, f64) {
    samples.sort_by(f64::total_cmp);
    (samples[0], samples[samples.len() / 2])
}

fn compare<M, const N: usize, const K: usize, const NU: usize>(
    name: &str,
    fixture: &str,
    model: M,
    mut casadi: CasadiModel<N, K>,
) where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>>,
{
    let points = load::<N, NU>(fixture);
    let mut p = Vec::new();
    while let Some(x) = model.parameter(p.len()) {
        p.push(x);
    }
    p.push(0.0); // a valid pointer when the model has no parameters
    let count = points.t.len();

    // both sides agree at every point
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
    for k in 0..count {
        let ours = model.eval(points.t[k], &points.q[k], &points.v[k], &points.u[k]);
        casadi.eval(
            points.t[k],
            &points.q[k],
            &points.v[k],
            points.u[k].as_slice(),
            &p,
        );
        let pairs = [
            (ours.mass.as_slice(), casadi.mass.as_slice()),
            (ours.coriolis.as_slice(), casadi.coriolis.as_slice()),
            (ours.forces.as_slice(), casadi.forces.as_slice()),
            (ours.gaps.as_slice(), casadi.gaps.as_slice()),
            (ours.jacobian.as_slice(), casadi.jacobian.as_slice()),
        ];
        for (a, b) in pairs {
            assert!(
                a.iter().zip(b).all(|(x, y)| close(*x, *y)),
                "{name}: moreau and CasADi disagree at point {k}"
            );
        }
    }

    // set up once, as a C user does
    let u_ptrs: Vec<*const f64> = points.u.iter().map(|u| u.as_ptr()).collect();
    let args: Vec<[*const f64; 5]> = (0..count)
        .map(|k| {
            [
                &points.t[k] as *const f64,
                points.q[k].as_ptr(),
                points.v[k].as_ptr(),
                if NU == 0 { p.as_ptr() } else { u_ptrs[k] },
                p.as_ptr(),
            ]
        })
        .collect();
    let function = casadi.function;
    let res = casadi.results();

    let reps: usize = std::env::var("MOREAU_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(301);
    let calls = (PASSES * count) as f64;
    let mut samples = [Vec::new(), Vec::new(), Vec::new()];
    for rep in 0..reps {
        for turn in 0..3 {
            let side = (rep + turn) % 3;
            let start = Instant::now();
            match side {
                0 => {
                    for _ in 0..PASSES {
                        for k in 0..count {
                            let r = black_box(&model).eval(
                                points.t[k],
                                &points.q[k],
                                &points.v[k],
                                &points.u[k],
                            );
                            black_box(&r);
                        }
                    }
                }
                1 => {
                    for _ in 0..PASSES {
                        for a in &args {
                            // SAFETY: the pointers point at N, N, NU and NP
                            // values and at the output buffers of the sizes
                            // the function was generated with (work size 0),
                            // all alive for the whole loop.
                            let status = unsafe {
                                function(
                                    a.as_ptr(),
                                    res.as_ptr(),
                                    std::ptr::null_mut(),
                                    std::ptr::null_mut(),
                                    0,
                                )
                            };
                            black_box(status);
                        }
                    }
                }
                _ => {
                    for _ in 0..PASSES {
                        for k in 0..count {
                            casadi.eval(
                                points.t[k],
                                &points.q[k],
                                &points.v[k],
                                points.u[k].as_slice(),
                                &p,
                            );
                            black_box(&casadi.forces);
                        }
                    }
                }
            }
            samples[side].push(start.elapsed().as_nanos() as f64 / calls);
        }
    }
    let [ours, direct, wrapped] = &mut samples;
    let (ours, direct, wrapped) = (stats(ours), stats(direct), stats(wrapped));
    println!(
        "| {name} | {N} | {K} | {} | {} | {:.1} / {:.1} | {:.1} / {:.1} | {:.2} | {:.1} |",
        M::INFO.op_count,
        points.casadi_ops,
        ours.0,
        ours.1,
        direct.0,
        direct.1,
        direct.1 / ours.1,
        wrapped.1,
    );
}

fn main() {
    // `cargo bench` passes `--bench` (and a filter, if any): a filter
    // selects the models whose name contains it
    let filter = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .unwrap_or_default();
    let run = |name: &str| name.contains(filter.as_str());
    println!(
        "| model | N | K | ops moreau | ops CasADi | moreau ns (min / median) \
         | CasADi direct ns (min / median) | CasADi / moreau (medians) \
         | CasADi via Rust wrapper ns (median) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    macro_rules! shipped {
        ($($name:literal, $ty:ident, $casadi:ident, $n:literal, $k:literal, $nu:literal;)*) => {$(
            if run($name) {
                compare::<_, $n, $k, $nu>(
                    $name,
                    concat!("tests/fixtures/casadi/", $name, ".json"),
                    moreau_models::$ty::<f64>::default(),
                    moreau_bench::$casadi(),
                );
            }
        )*};
    }
    shipped! {
        "parabola", Parabola, parabola, 2, 2, 0;
        "three_balls", ThreeBalls, three_balls, 3, 4, 0;
        "billiard", Billiard, billiard, 2, 4, 0;
        "double_pendulum", DoublePendulum, double_pendulum, 2, 2, 0;
        "arm3", Arm3, arm3, 3, 1, 3;
    }
    macro_rules! chains {
        ($($name:literal, $ty:ident, $casadi:ident, $n:literal;)*) => {$(
            if run($name) {
                compare::<_, $n, $n, 0>(
                    $name,
                    concat!("benches/casadi/chains/", $name, ".json"),
                    moreau_models::$ty::<f64>::default(),
                    moreau_bench::$casadi(),
                );
            }
        )*};
    }
    chains! {
        "chain02", Chain2, chain02, 2;
        "chain03", Chain3, chain03, 3;
        "chain04", Chain4, chain04, 4;
        "chain05", Chain5, chain05, 5;
        "chain06", Chain6, chain06, 6;
        "chain07", Chain7, chain07, 7;
        "chain08", Chain8, chain08, 8;
        "chain09", Chain9, chain09, 9;
        "chain10", Chain10, chain10, 10;
        "chain11", Chain11, chain11, 11;
        "chain12", Chain12, chain12, 12;
    }
}
