//! moreau's generated `M` and `C v + G` beside Pinocchio's C++ (CRBA and
//! nonlinear effects), interleaved in one process, for the UR5, the Panda
//! (fingers locked), Unitree Go1's legs (fixed trunk) and the generated
//! 12-joint chain.
//!
//! How each side is called:
//!
//! * **moreau**: `model.dynamics(0, &q, &v, &u)`, the fused `(M, F)` with
//!   `F = C v + G` (no applied force), on the model value behind
//!   `black_box`, its result `black_box`ed.
//! * **Pinocchio**: `pinocchio::crba` then `pinocchio::nonLinearEffects` on
//!   a model and data made once (`pinocchio/shim.cpp`, compiled at `-O3`
//!   against the `pin` 4.1.0 wheel's headers by `build.rs`), then the lower
//!   triangle of `M` mirrored and both copied out (moreau's `M` is full
//!   too).
//!
//! Inputs vary over 32 seeded points (`q` in [−π, π], `v` in [−2, 2]), and
//! both sides are checked to agree at every point (1e-10 relative to the
//! largest entry) before timing. Pinocchio gets the same points in its
//! order of the joints (a link's children sorted by joint name, where
//! moreau keeps the URDF's order: Go1's legs), permuted before timing. One sample is 16 passes over the points
//! (512 calls) of one side; the sides are sampled in turn, in alternating
//! order, `REPS` times (`MOREAU_BENCH_REPS`, default 301). The table gives
//! the minimum and median time per call of each side and the ratio
//! Pinocchio / moreau of the medians.
//!
//! The benchmark is built only when `MOREAU_PINOCCHIO_VENV` names a venv
//! with the wheel (`.venv-pinocchio` at the repository's root, as `.ci/run`
//! makes it, will do) and Eigen's headers are installed:
//!
//! `MOREAU_PINOCCHIO_VENV=/path/to/venv cargo bench -p moreau-bench --bench vs_pinocchio`

#[cfg(pinocchio)]
mod run {
    use std::hint::black_box;
    use std::time::Instant;

    use moreau::Model;
    use moreau_bench::pinocchio::Robot;
    use nalgebra::SVector;

    moreau::model!(file = "robots/ur5.yaml");
    moreau::model!(file = "robots/panda.yaml");
    moreau::model!(file = "robots/serial_12.yaml");
    moreau::model!(file = "robots/go1.yaml");

    const PASSES: usize = 16;
    const POINTS: usize = 32;

    /// xorshift, in [−1, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn stats(samples: &mut [f64]) -> (f64, f64) {
        samples.sort_by(f64::total_cmp);
        (samples[0], samples[samples.len() / 2])
    }

    fn agree(ours: &[f64], theirs: &[f64], what: &str) {
        let scale = theirs.iter().fold(1e-300_f64, |m, x| m.max(x.abs()));
        for (a, b) in ours.iter().zip(theirs) {
            assert!(
                (a - b).abs() <= 1e-10 * scale,
                "{what}: moreau {a} vs Pinocchio {b}"
            );
        }
    }

    pub fn compare<M, const N: usize>(name: &str, model: M, mut robot: Robot)
    where
        M: Model<N, 0, Scalar = f64, Input = SVector<f64, 0>>,
    {
        assert_eq!(robot.nv(), N, "{name}: coordinates");
        // Moreau's coordinate i is Pinocchio's order[i].
        let order: [usize; N] = M::INFO.coordinates.map(|c| {
            robot
                .joints()
                .iter()
                .position(|j| j == c)
                .unwrap_or_else(|| panic!("{name}: `{c}` is not one of Pinocchio's joints"))
        });
        let pinocchio_order = |x: &SVector<f64, N>| {
            let mut out = vec![0.0; N];
            for (i, &k) in order.iter().enumerate() {
                out[k] = x[i];
            }
            out
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let q: Vec<SVector<f64, N>> = (0..POINTS)
            .map(|_| SVector::from_fn(|_, _| std::f64::consts::PI * uniform(&mut seed)))
            .collect();
        let v: Vec<SVector<f64, N>> = (0..POINTS)
            .map(|_| SVector::from_fn(|_, _| 2.0 * uniform(&mut seed)))
            .collect();
        let q_pin: Vec<Vec<f64>> = q.iter().map(pinocchio_order).collect();
        let v_pin: Vec<Vec<f64>> = v.iter().map(pinocchio_order).collect();
        let u = SVector::<f64, 0>::zeros();
        let mut mass = vec![0.0; N * N];
        let mut nle = vec![0.0; N];
        for k in 0..POINTS {
            let (m, f) = model.dynamics(0.0, &q[k], &v[k], &u);
            robot.crba_nle(&q_pin[k], &v_pin[k], &mut mass, &mut nle);
            let mass: Vec<f64> = (0..N * N)
                .map(|e| mass[order[e / N] * N + order[e % N]])
                .collect();
            let nle: Vec<f64> = order.iter().map(|&i| nle[i]).collect();
            agree(m.as_slice(), &mass, &format!("{name} point {k}: M"));
            agree(f.as_slice(), &nle, &format!("{name} point {k}: C v + G"));
        }
        let reps: usize = std::env::var("MOREAU_BENCH_REPS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(301);
        let calls = (PASSES * POINTS) as f64;
        let mut samples = [Vec::new(), Vec::new()];
        for rep in 0..reps {
            for turn in 0..2 {
                let side = (rep + turn) % 2;
                let start = Instant::now();
                for _ in 0..PASSES {
                    for k in 0..POINTS {
                        if side == 0 {
                            let r = black_box(&model).dynamics(0.0, &q[k], &v[k], &u);
                            black_box(&r);
                        } else {
                            robot.crba_nle(&q_pin[k], &v_pin[k], &mut mass, &mut nle);
                            black_box(&mass);
                            black_box(&nle);
                        }
                    }
                }
                samples[side].push(start.elapsed().as_nanos() as f64 / calls);
            }
        }
        let (ours_min, ours) = stats(&mut samples[0]);
        let (pin_min, pin) = stats(&mut samples[1]);
        println!(
            "| {name} | {N} | {ours_min:.0} / {ours:.0} ns | {pin_min:.0} / {pin:.0} ns | {:.2} |",
            pin / ours
        );
    }

    pub fn main() {
        for (copy, original) in [
            (
                &include_bytes!("../robots/ur5_robot.urdf")[..],
                &include_bytes!("../../tests/robots/urdf/ur_description/ur5_robot.urdf")[..],
            ),
            (
                include_bytes!("../robots/panda.urdf"),
                include_bytes!("../../tests/robots/urdf/panda_description/panda.urdf"),
            ),
            (
                include_bytes!("../robots/go1.urdf"),
                include_bytes!("../../tests/robots/urdf/go1_description/go1.urdf"),
            ),
            (
                include_bytes!("../robots/serial_12.urdf"),
                include_bytes!("../../tests/robots/urdf/synthetic/serial/serial_12.urdf"),
            ),
        ] {
            assert!(
                copy == original,
                "benches/robots/ differs from tests/robots/"
            );
        }
        println!(
            "| robot | joints | moreau `dynamics` (min / median) | Pinocchio CRBA + NLE (min / median) | Pinocchio / moreau |"
        );
        println!("|---|---:|---:|---:|---:|");
        compare("UR5", Ur5::<f64>::new(), Robot::load("ur5"));
        compare("Panda", Panda::<f64>::new(), Robot::load("panda"));
        compare(
            "Go1 (legs, trunk fixed)",
            Go1::<f64>::new(),
            Robot::load("go1"),
        );
        compare(
            "12-joint chain",
            Serial12::<f64>::new(),
            Robot::load("serial_12"),
        );
    }
}

fn main() {
    #[cfg(pinocchio)]
    run::main();
    #[cfg(not(pinocchio))]
    println!(
        "vs_pinocchio: Pinocchio's wheel was not found when the benchmarks were built; \
         set MOREAU_PINOCCHIO_VENV to a venv with tests/requirements-pinocchio.txt installed \
         (and install Eigen's headers, Debian's libeigen3-dev)"
    );
}
