use super::lincomb::lincomb;
use super::*;
use crate::node::Node;
use crate::testing::{ARM3, Built, DOUBLE_PENDULUM, PARABOLA, Rng, Spec};

fn derive(b: &mut Built) -> Result<Mechanics, MechanicsError> {
    b.derive()
}

fn eval_matrix(g: &Graph, m: &[Vec<Id>], vars: &[f64]) -> Vec<Vec<f64>> {
    m.iter().map(|row| g.eval(row, vars)).collect()
}

/// A random point: angles and velocities in [-2, 2], parameters in
/// [0.5, 2].
fn point(rng: &mut Rng, b: &Built) -> Vec<f64> {
    (0..b.names.len())
        .map(|k| {
            if k < 2 * b.q.len() {
                rng.uniform(-2.0, 2.0)
            } else {
                rng.uniform(0.5, 2.0)
            }
        })
        .collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn point_mass_under_gravity() {
    let mut b = Spec {
        coords: &[("x", "vx"), ("y", "vy")],
        params: &["m", "g"],
        defs: &[],
        kinetic: "0.5 * m * (vx^2 + vy^2)",
        potential: "m * g * y",
        applied: &[],
        gaps: &[],
    }
    .build();
    let mech = derive(&mut b).unwrap();
    let g = &mut b.g;
    let m = g.var(VarId(4));
    let grav = g.var(VarId(5));
    let zero = g.constant(0.0);
    assert_eq!(mech.mass, vec![vec![m, zero], vec![zero, m]]);
    assert_eq!(mech.coriolis, vec![vec![zero; 2]; 2]);
    assert_eq!(mech.gravity, vec![zero, g.mul(m, grav)]);
    assert_eq!(mech.forces, mech.gravity);
    let vx = g.var(VarId(2));
    assert_eq!(mech.momentum[0], g.mul(m, vx));
    assert!(mech.jacobian.is_empty());
}

#[test]
fn double_pendulum_closed_forms() {
    let mut b = DOUBLE_PENDULUM.build();
    let mech = derive(&mut b).unwrap();
    let mut rng = Rng::new(7);
    for _ in 0..20 {
        let x = point(&mut rng, &b);
        let [th1, th2, w1, w2, m1, m2, l1, l2, grav, damp, wall, floor] = x[..] else {
            unreachable!()
        };
        let (s, c) = ((th1 - th2).sin(), (th1 - th2).cos());
        let mass = [
            [(m1 + m2) * l1 * l1, m2 * l1 * l2 * c],
            [m2 * l1 * l2 * c, m2 * l2 * l2],
        ];
        let cor = [[0.0, m2 * l1 * l2 * s * w2], [-m2 * l1 * l2 * s * w1, 0.0]];
        let grv = [
            (m1 + m2) * grav * l1 * th1.sin(),
            m2 * grav * l2 * th2.sin(),
        ];
        let q = [-damp * w1 + damp * (w2 - w1), -damp * (w2 - w1)];
        let h = [
            wall - l1 * th1.sin() - l2 * th2.sin(),
            floor - l1 * th1.cos() - l2 * th2.cos(),
        ];
        let jac = [
            [-l1 * th1.cos(), -l2 * th2.cos()],
            [l1 * th1.sin(), l2 * th2.sin()],
        ];
        let got_m = eval_matrix(&b.g, &mech.mass, &x);
        let got_c = eval_matrix(&b.g, &mech.coriolis, &x);
        let got_j = eval_matrix(&b.g, &mech.jacobian, &x);
        let got_g = b.g.eval(&mech.gravity, &x);
        let got_f = b.g.eval(&mech.forces, &x);
        let got_h = b.g.eval(&mech.gaps, &x);
        for i in 0..2 {
            for j in 0..2 {
                assert!(close(got_m[i][j], mass[i][j], 1e-14), "M{i}{j}");
                assert!(close(got_c[i][j], cor[i][j], 1e-14), "C{i}{j}");
                assert!(close(got_j[i][j], jac[i][j], 1e-14), "J{i}{j}");
            }
            assert!(close(got_g[i], grv[i], 1e-14), "G{i}");
            let f = cor[i][0] * w1 + cor[i][1] * w2 + grv[i] - q[i];
            assert!(close(got_f[i], f, 1e-14), "F{i}");
            assert!(close(got_h[i], h[i], 1e-14), "h{i}");
        }
    }
    // Zero entries are literal zeros; C_01 is one product of shared nodes.
    assert!(b.g.is_zero(mech.coriolis[0][0]));
    assert!(b.g.is_zero(mech.coriolis[1][1]));
    let names = |v| b.name(v);
    assert_eq!(
        b.g.to_infix(mech.coriolis[0][1], &names),
        "l1 * l2 * m2 * sin(th1 - th2) * w2"
    );
    assert_eq!(b.g.to_infix(mech.mass[0][0], &names), "(m1 + m2) * l1^2");
}

/// Checks, at random points, that `Ṁ − 2C` is skew-symmetric (so
/// `vᵀ (Ṁ − 2C) v = 0`), with `Ṁ = Σ_k ∂M/∂q_k v_k` by central
/// differences of `M` along `v`, and that `F = Ṁ v − ∂T/∂q + G − Q`
/// (the Euler–Lagrange equations), with `∂T/∂q` by central differences.
fn check_skew_and_lagrange(spec: &Spec, seed: u64) {
    let mut b = spec.build();
    let mech = derive(&mut b).unwrap();
    let n = b.q.len();
    let mut rng = Rng::new(seed);
    for _ in 0..10 {
        let x = point(&mut rng, &b);
        let h = 1e-5;
        let shifted = |s: f64| {
            let mut y = x.clone();
            for k in 0..n {
                y[k] += s * x[n + k];
            }
            eval_matrix(&b.g, &mech.mass, &y)
        };
        let (mp, mm) = (shifted(h), shifted(-h));
        let mdot: Vec<Vec<f64>> = (0..n)
            .map(|i| (0..n).map(|j| (mp[i][j] - mm[i][j]) / (2.0 * h)).collect())
            .collect();
        let c = eval_matrix(&b.g, &mech.coriolis, &x);
        let scale = 1.0 + mdot.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        let mut vmv = 0.0;
        for i in 0..n {
            for j in 0..n {
                let a = mdot[i][j] - 2.0 * c[i][j];
                let at = mdot[j][i] - 2.0 * c[j][i];
                assert!(
                    (a + at).abs() <= 1e-7 * scale,
                    "skew at {i},{j}: {a} vs {at}"
                );
                vmv += x[n + i] * a * x[n + j];
            }
        }
        assert!(vmv.abs() <= 1e-7 * scale * 16.0, "vᵀ(Ṁ − 2C)v = {vmv}");
        let f = b.g.eval(&mech.forces, &x);
        let gr = b.g.eval(&mech.gravity, &x);
        let q = b.g.eval(&b.applied, &x);
        for i in 0..n {
            let mut tp = x.clone();
            let mut tm = x.clone();
            tp[i] += h;
            tm[i] -= h;
            let dtdq =
                (b.g.eval(&[b.kinetic], &tp)[0] - b.g.eval(&[b.kinetic], &tm)[0]) / (2.0 * h);
            let mdv: f64 = (0..n).map(|j| mdot[i][j] * x[n + j]).sum();
            let want = mdv - dtdq + gr[i] - q[i];
            assert!(close(f[i], want, 1e-7), "F{i} = {}, E-L gives {want}", f[i]);
        }
    }
}

#[test]
fn double_pendulum_mdot_minus_2c_is_skew() {
    check_skew_and_lagrange(&DOUBLE_PENDULUM, 11);
}

#[test]
fn arm3_mdot_minus_2c_is_skew() {
    check_skew_and_lagrange(&ARM3, 13);
}

#[test]
fn parabola_is_a_point_mass() {
    let mut b = PARABOLA.build();
    let mech = derive(&mut b).unwrap();
    let names = |v| b.name(v);
    let show = |e| b.g.to_infix(e, &names);
    assert_eq!(show(mech.jacobian[0][0]), "-2 * x");
    assert_eq!(show(mech.jacobian[0][1]), "1");
    assert_eq!(show(mech.jacobian[1][1]), "-1");
    assert_eq!(show(mech.forces[1]), "m * g");
}

fn kinetic_error(kinetic: &'static str) -> MechanicsError {
    let mut b = Spec {
        coords: &[("x", "vx"), ("y", "vy")],
        params: &["m"],
        defs: &[],
        kinetic,
        potential: "0",
        applied: &[],
        gaps: &[],
    }
    .build();
    derive(&mut b).unwrap_err()
}

#[test]
fn quartic_kinetic_energy_is_not_quadratic() {
    assert_eq!(
        kinetic_error("vx^4"),
        MechanicsError::NotQuadratic {
            row: 0,
            col: 0,
            velocity: 0
        }
    );
}

#[test]
fn cubic_product_kinetic_energy_is_not_quadratic() {
    assert_eq!(
        kinetic_error("vx * vy * vx"),
        MechanicsError::NotQuadratic {
            row: 0,
            col: 0,
            velocity: 1
        }
    );
}

#[test]
fn mass_matrix_depending_on_velocity_is_rejected() {
    assert_eq!(
        kinetic_error("0.5 * m * vx^2 + cos(vx) * vy^2"),
        MechanicsError::NotQuadratic {
            row: 0,
            col: 0,
            velocity: 0
        }
    );
    assert_eq!(
        kinetic_error("0.5 * m * vx^2 + 0.5 * m * vy^2 * (1 + vx^2)"),
        MechanicsError::NotQuadratic {
            row: 0,
            col: 0,
            velocity: 1
        }
    );
}

#[test]
fn linear_term_in_kinetic_energy_is_rejected() {
    let err = kinetic_error("m * vx^2 + vx");
    assert_eq!(err, MechanicsError::LinearTerm { velocity: 0 });
    assert!(err.describe(&["vx", "vy"]).contains("linear in vx"));
    assert_eq!(
        kinetic_error("m * vx^2 + x * vy"),
        MechanicsError::LinearTerm { velocity: 1 }
    );
}

#[test]
fn velocity_free_term_in_kinetic_energy_is_rejected() {
    assert_eq!(
        kinetic_error("m * vx^2 + y^2"),
        MechanicsError::VelocityFreeTerm
    );
}

#[test]
fn disguised_quadratic_forms_are_accepted() {
    let mut b = Spec {
        coords: &[("x", "vx")],
        params: &["m", "a"],
        defs: &[],
        kinetic: "0.5 * m * (vx + a)^2 - m * a * vx - 0.5 * m * a^2",
        potential: "0",
        applied: &[],
        gaps: &[],
    }
    .build();
    let mech = derive(&mut b).unwrap();
    assert_eq!(b.g.eval(&mech.mass[0], &[0.0, 0.0, 3.0, 5.0]), vec![3.0]);
}

#[test]
fn shape_errors() {
    let mut g = Graph::new();
    let x = g.var(VarId(0));
    let sys = Lagrangian {
        q: &[VarId(0), VarId(1)],
        v: &[VarId(2)],
        kinetic: x,
        potential: x,
        applied: &[],
        gaps: &[],
    };
    assert_eq!(
        Mechanics::derive(&mut g, &sys),
        Err(MechanicsError::Shape {
            what: "v",
            expected: 2,
            found: 1
        })
    );
    let sys = Lagrangian {
        v: &[VarId(2), VarId(3)],
        applied: &[x],
        ..sys
    };
    let err = Mechanics::derive(&mut g, &sys).unwrap_err();
    assert_eq!(err.to_string(), "`applied` has 1 entries, expected 2");
}

#[test]
fn lincomb_merges_and_factors() {
    let mut g = Graph::new();
    let a = g.var(VarId(0));
    let b = g.var(VarId(1));
    let c = g.var(VarId(2));
    let names = |v: VarId| ["a", "b", "c"][v.index()].to_string();
    let e = lincomb(&mut g, &[(0.5, a), (0.5, b), (-0.5, a)]);
    assert_eq!(g.to_infix(e, &names), "0.5 * b");
    let e = lincomb(&mut g, &[(0.5, a), (0.5, a), (-0.5, b)]);
    assert_eq!(g.to_infix(e, &names), "a - 0.5 * b");
    let e = lincomb(&mut g, &[(-0.5, c), (0.5, a), (0.5, b)]);
    assert_eq!(g.to_infix(e, &names), "0.5 * (a + b - c)");
    let e = lincomb(&mut g, &[(0.5, a), (-0.5, a)]);
    assert!(g.is_zero(e));
}

#[test]
fn lincomb_cancels_inside_sums() {
    let mut g = Graph::new();
    let a = g.var(VarId(0));
    let b = g.var(VarId(1));
    let c = g.var(VarId(2));
    let names = |v: VarId| ["a", "b", "c"][v.index()].to_string();
    let half = g.constant(0.5);
    let hb = g.mul(half, b);
    let d1 = g.add(a, hb); // a + b/2
    let d2 = g.add(hb, c); // b/2 + c
    let e = lincomb(&mut g, &[(1.0, d1), (-1.0, d2)]);
    assert_eq!(g.to_infix(e, &names), "a - c");
    // without cancellation the sums are reused whole
    let e = lincomb(&mut g, &[(1.0, d1), (1.0, c)]);
    assert_eq!(g.to_infix(e, &names), "0.5 * b + a + c");
    assert_eq!(g.node(e), Node::Add([d1, c]));
}

#[test]
fn lincomb_gives_up_on_exploding_sum_dags() {
    let mut g = Graph::new();
    let mut s = g.var(VarId(0));
    let y = g.var(VarId(1));
    for _ in 0..40 {
        let d = g.sub(s, y);
        s = g.add(s, d); // a DAG of 2^40 paths
    }
    let z = g.var(VarId(2));
    let e = lincomb(&mut g, &[(1.0, s), (1.0, z)]);
    assert_eq!(g.node(e), Node::Add([s, z]));
}

#[test]
fn output_layout_order() {
    let mut b = DOUBLE_PENDULUM.build();
    let mech = derive(&mut b).unwrap();
    let layout = mech.layout();
    let outputs = mech.outputs();
    // M (3), C (4), G (2), F (2), h (2), J (4), ∂F/∂q (4), ∂F/∂v (4),
    // ∂(Mv)/∂q (4), ∂(Jv)/∂q (4)
    assert_eq!(outputs.len(), layout.total());
    assert_eq!(layout.total(), 3 + 4 + 2 + 2 + 2 + 4 + 4 + 4 + 4 + 4);
    let slots: Vec<Slot> = (0..layout.total()).map(|k| layout.slot(k)).collect();
    let at = |k: usize| (slots[k].quantity, slots[k].row, slots[k].col);
    assert_eq!(at(0), (Quantity::Mass, 0, 0));
    assert_eq!(at(2), (Quantity::Mass, 1, 1));
    assert_eq!(at(3), (Quantity::Coriolis, 0, 0));
    assert_eq!(at(16), (Quantity::Jacobian, 1, 1));
    assert!(slots.windows(2).all(|w| w[0] < w[1]));
    for (k, &slot) in slots.iter().enumerate() {
        assert_eq!(layout.index(slot), k);
        assert_eq!(outputs[k], mech.get(slot));
    }
}

/// `∂(M v)/∂q` and `∂(J v)/∂q` against central differences of `M(q) v` and
/// `J(q) v` evaluated through the graph.
#[test]
fn contracted_derivatives_match_central_differences() {
    for (name, spec) in [
        ("double pendulum", &DOUBLE_PENDULUM),
        ("arm3", &ARM3),
        ("parabola", &PARABOLA),
    ] {
        let mut b = spec.build();
        let mech = derive(&mut b).unwrap();
        let n = mech.mass.len();
        let mut rng = Rng::new(11);
        for _ in 0..5 {
            let x = point(&mut rng, &b);
            let mv = |x: &[f64]| -> Vec<f64> {
                let m = eval_matrix(&b.g, &mech.mass, x);
                (0..n)
                    .map(|i| (0..n).map(|k| m[i][k] * x[b.v[k].index()]).sum())
                    .collect()
            };
            let jv = |x: &[f64]| -> Vec<f64> {
                let j = eval_matrix(&b.g, &mech.jacobian, x);
                j.iter()
                    .map(|row| (0..n).map(|k| row[k] * x[b.v[k].index()]).sum())
                    .collect()
            };
            let dm = eval_matrix(&b.g, &mech.mass_dq, &x);
            let dj = eval_matrix(&b.g, &mech.jacobian_dq, &x);
            for j in 0..n {
                let h = 1e-6;
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[b.q[j].index()] += h;
                xm[b.q[j].index()] -= h;
                let (a, c) = (mv(&xp), mv(&xm));
                for i in 0..n {
                    let fd = (a[i] - c[i]) / (2.0 * h);
                    assert!(
                        close(dm[i][j], fd, 1e-6),
                        "{name}: dMv[{i}][{j}] {} vs {fd}",
                        dm[i][j]
                    );
                }
                let (a, c) = (jv(&xp), jv(&xm));
                for i in 0..dj.len() {
                    let fd = (a[i] - c[i]) / (2.0 * h);
                    assert!(
                        close(dj[i][j], fd, 1e-6),
                        "{name}: dJv[{i}][{j}] {} vs {fd}",
                        dj[i][j]
                    );
                }
            }
        }
    }
}

/// A gap nesting all coordinates, `sin(q1 + sin(q2 + … sin(q8)))`: its
/// forward-mode gradient multiplies cosines anew for each coordinate
/// (~N²/2 products), one reverse sweep shares them (~N), so `J` is built
/// in reverse mode: fewer operations in the fused evaluation than the
/// forward row, and the same values (against central differences of `h`).
#[test]
fn gap_jacobian_takes_the_smaller_mode() {
    let mut b = Spec {
        coords: &[
            ("q1", "v1"),
            ("q2", "v2"),
            ("q3", "v3"),
            ("q4", "v4"),
            ("q5", "v5"),
            ("q6", "v6"),
            ("q7", "v7"),
            ("q8", "v8"),
        ],
        params: &[],
        defs: &[],
        kinetic: "0.5 * (v1^2 + v2^2 + v3^2 + v4^2 + v5^2 + v6^2 + v7^2 + v8^2)",
        potential: "0",
        applied: &[],
        gaps: &[
            "sin(q1 + sin(q2 + sin(q3 + sin(q4 + sin(q5 + sin(q6 + sin(q7 + sin(q8))))))))",
            "q3 + 1",
        ],
    }
    .build();
    let mech = derive(&mut b).unwrap();
    let g = &mut b.g;
    let forward = g.gradient(mech.gaps[0], &b.q);
    let ops = |g: &Graph, row: &[Id]| {
        let mut outputs = mech.gaps.clone();
        outputs.extend_from_slice(row);
        Schedule::new(g, &outputs).op_count()
    };
    let (ours, theirs) = (ops(g, &mech.jacobian[0]), ops(g, &forward));
    assert!(ours < theirs, "J row {ours} operations, forward {theirs}");
    // a gap of one coordinate: forward mode, the constant 1
    assert_eq!(mech.jacobian[1], g.gradient(mech.gaps[1], &b.q));
    let mut rng = Rng::new(0x1ac0);
    for _ in 0..10 {
        let x: Vec<f64> = (0..16).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let j = g.eval(&mech.jacobian[0], &x);
        for k in 0..8 {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[k] += 1e-6;
            xm[k] -= 1e-6;
            let fd = (g.eval(&mech.gaps[..1], &xp)[0] - g.eval(&mech.gaps[..1], &xm)[0]) / 2e-6;
            assert!(close(j[k], fd, 1e-8), "J[0,{k}] {} against {fd}", j[k]);
        }
    }
}
