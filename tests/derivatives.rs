//! The generated derivatives against independent references.
//!
//! 1. CasADi: `tests/casadi_reference.py` builds every shipped model in
//!    CasADi SX, differentiates it with CasADi's own AD and evaluates M, C,
//!    G, F, h, J, ∂F/∂q and ∂F/∂v at 32 seeded points per model (the first
//!    four at the default parameters, the others with every parameter scaled
//!    by a random factor in [0.5, 1.5]). Every generated method must agree to
//!    1e-12, relative as `common::relative_error` defines it (for C, ∂F/∂v
//!    and ∂(M v)/∂q, sums of (∂M/∂q) v, to a scale of at least
//!    max|M| max|v|; `common::casadi::against_casadi`). The robots of
//!    `tests/robots/` go through the same comparison in `tests/robots/casadi.rs`.
//! 2. What needs no CasADi: M symmetric positive definite, the skew
//!    symmetry of Ṁ − 2C (property (P1)), J and the force Jacobians against
//!    central finite differences.

mod common;

use common::casadi::{against_casadi, defaults_match, points};
use common::{central, min_eigenvalue, relative_error};
use moreau::Model;
use moreau_models::{Arm3, Billiard, DoublePendulum, Parabola, ThreeBalls};
use nalgebra::{SMatrix, SVector};

#[test]
fn parabola_matches_casadi() {
    against_casadi::<Parabola, 2, 2, 0>("parabola");
}

#[test]
fn three_balls_match_casadi() {
    against_casadi::<ThreeBalls, 3, 4, 0>("three_balls");
}

#[test]
fn billiard_matches_casadi() {
    against_casadi::<Billiard, 2, 4, 0>("billiard");
}

#[test]
fn double_pendulum_matches_casadi() {
    against_casadi::<DoublePendulum, 2, 2, 0>("double_pendulum");
}

#[test]
fn arm3_matches_casadi() {
    against_casadi::<Arm3, 3, 1, 3>("arm3");
}

/// The restitution coefficients and the parameter defaults are the file's.
#[test]
fn defaults_match_the_model_files() {
    defaults_match::<Parabola, 2, 2, 0>("parabola");
    defaults_match::<ThreeBalls, 3, 4, 0>("three_balls");
    defaults_match::<Billiard, 2, 4, 0>("billiard");
    defaults_match::<DoublePendulum, 2, 2, 0>("double_pendulum");
    defaults_match::<Arm3, 3, 1, 3>("arm3");
}

/// What needs no CasADi, at the fixture's points: M symmetric positive
/// definite; vᵀ(Ṁ − 2C)v = 0 with Ṁ = Σ_k ∂M/∂q_k v_k by central
/// differences; J = ∂h/∂q and the force Jacobians against central
/// differences. The finite-difference tolerance, 1e-6 relative, is well
/// above the O(step²) ≈ 1e-12 truncation and the O(ε/step) ≈ 1e-10 rounding
/// error of a central difference with step 1e-6, so it fails only on a wrong
/// derivative.
fn without_casadi<M, const N: usize, const K: usize, const NU: usize>(stem: &str)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    const FD_TOLERANCE: f64 = 1e-6;
    for (i, p) in points::<M, N, K, NU>(stem).iter().enumerate() {
        let (m, t, q, v, u) = (&p.model, p.t, &p.q, &p.v, &p.u);
        let mass = m.mass(q);
        assert_eq!(mass, mass.transpose(), "{stem} point {i}: M symmetric");
        assert!(
            min_eigenvalue(&mass) > 0.0,
            "{stem} point {i}: M not positive definite"
        );

        let mut mdot = SMatrix::<f64, N, N>::zeros();
        for k in 0..N {
            let step = 1e-6 * q[k].abs().max(1.0);
            let (mut plus, mut minus) = (*q, *q);
            plus[k] += step;
            minus[k] -= step;
            mdot += (m.mass(&plus) - m.mass(&minus)) / (2.0 * step) * v[k];
        }
        let skew = mdot - 2.0 * m.coriolis(q, v);
        let quadratic = (v.transpose() * skew * v)[0];
        let scale = mdot.amax().max(m.coriolis(q, v).amax()) * v.norm_squared();
        assert!(
            quadratic.abs() <= FD_TOLERANCE * scale.max(1e-300),
            "{stem} point {i}: vᵀ(Ṁ − 2C)v = {quadratic:e}"
        );

        let jac = m.gap_jacobian(q);
        let lin = m.linearization(t, q, v, u);
        for j in 0..N {
            let dh = central(|x| m.gaps(x), q, j);
            let dfq = central(|x| m.forces(t, x, v, u), q, j);
            let dfv = central(|x| m.forces(t, q, x, u), v, j);
            for (what, fd, exact, scale) in [
                (
                    "J",
                    dh.as_slice(),
                    jac.column(j).iter().copied().collect::<Vec<_>>(),
                    jac.amax(),
                ),
                (
                    "∂F/∂q",
                    dfq.as_slice(),
                    lin.forces_dq.column(j).iter().copied().collect(),
                    lin.forces_dq.amax(),
                ),
                (
                    "∂F/∂v",
                    dfv.as_slice(),
                    lin.forces_dv.column(j).iter().copied().collect(),
                    lin.forces_dv.amax(),
                ),
            ] {
                for (r, (a, b)) in fd.iter().zip(&exact).enumerate() {
                    assert!(
                        (a - b).abs() <= FD_TOLERANCE * scale.max(1.0),
                        "{stem} point {i}: {what}[{r},{j}] = {b}, finite difference {a}"
                    );
                }
            }
        }
    }
}

#[test]
fn parabola_without_casadi() {
    without_casadi::<Parabola, 2, 2, 0>("parabola");
}

#[test]
fn three_balls_without_casadi() {
    without_casadi::<ThreeBalls, 3, 4, 0>("three_balls");
}

#[test]
fn billiard_without_casadi() {
    without_casadi::<Billiard, 2, 4, 0>("billiard");
}

#[test]
fn double_pendulum_without_casadi() {
    without_casadi::<DoublePendulum, 2, 2, 0>("double_pendulum");
}

#[test]
fn arm3_without_casadi() {
    without_casadi::<Arm3, 3, 1, 3>("arm3");
}

/// The generated code is generic over the scalar: in `f32` it agrees with
/// `f64` to single precision.
#[test]
fn f32_agrees_with_f64() {
    let m64 = DoublePendulum::<f64>::default();
    let m32 = DoublePendulum::<f32>::default();
    for p in points::<DoublePendulum, 2, 2, 0>("double_pendulum")
        .iter()
        .take(4)
    {
        let t64 = m64.eval(p.t, &p.q, &p.v, &SVector::zeros());
        let t32 = m32.eval(p.t as f32, &p.q.cast(), &p.v.cast(), &SVector::zeros());
        for (a, b) in [
            (t64.mass, t32.mass.cast::<f64>()),
            (t64.coriolis, t32.coriolis.cast()),
        ] {
            assert!(relative_error(&b, &a) < 1e-5, "{a} vs {b}");
        }
        assert!(relative_error(&t32.forces.cast(), &t64.forces) < 1e-5);
        assert!(relative_error(&t32.jacobian.cast(), &t64.jacobian) < 1e-5);
    }
}

/// A degenerate enclosure: one `f64` point, each operation `f64`'s own
/// (`sin` and `cos` those the generated `f64` code calls, the runtime's).
/// Evaluated through `Enclosure`, it gives the `f64` methods' values (see
/// `enclosures_at_points_are_the_f64_values` for how closely).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pt(f64);

impl std::ops::Add for Pt {
    type Output = Pt;
    fn add(self, o: Pt) -> Pt {
        Pt(self.0 + o.0)
    }
}
impl std::ops::Sub for Pt {
    type Output = Pt;
    fn sub(self, o: Pt) -> Pt {
        Pt(self.0 - o.0)
    }
}
impl std::ops::Mul for Pt {
    type Output = Pt;
    fn mul(self, o: Pt) -> Pt {
        Pt(self.0 * o.0)
    }
}
impl std::ops::Div for Pt {
    type Output = Pt;
    fn div(self, o: Pt) -> Pt {
        Pt(self.0 / o.0)
    }
}
impl std::ops::Neg for Pt {
    type Output = Pt;
    fn neg(self) -> Pt {
        Pt(-self.0)
    }
}
impl moreau::Enclose for Pt {
    fn point(x: f64) -> Self {
        Pt(x)
    }
    fn entire() -> Self {
        Pt(f64::NAN)
    }
    fn powi(self, n: i32) -> Self {
        Pt(self.0.powi(n))
    }
    fn powf(self, e: Self) -> Self {
        Pt(self.0.powf(e.0))
    }
    fn sqrt(self) -> Self {
        Pt(self.0.sqrt())
    }
    fn exp(self) -> Self {
        Pt(self.0.exp())
    }
    fn ln(self) -> Self {
        Pt(self.0.ln())
    }
    fn sin(self) -> Self {
        Pt(moreau::__private::sin(self.0))
    }
    fn cos(self) -> Self {
        Pt(moreau::__private::cos(self.0))
    }
    fn tan(self) -> Self {
        Pt(self.0.tan())
    }
    fn sinh(self) -> Self {
        Pt(self.0.sinh())
    }
    fn cosh(self) -> Self {
        Pt(self.0.cosh())
    }
    fn tanh(self) -> Self {
        Pt(self.0.tanh())
    }
    fn atan2(self, x: Self) -> Self {
        Pt(self.0.atan2(x.0))
    }
}

fn enclosure_at_points<M, const N: usize, const K: usize, const NU: usize>(stem: &str, ulps: f64)
where
    M: moreau::Enclosure<N, K> + Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    let mut worst = 0.0f64;
    for (i, p) in points::<M, N, K, NU>(stem).iter().enumerate() {
        let (m, t, q, v, u) = (&p.model, p.t, &p.q, &p.v, &p.u);
        let qp: [Pt; N] = std::array::from_fn(|k| Pt(q[k]));
        let vp: [Pt; N] = std::array::from_fn(|k| Pt(v[k]));
        let up: Vec<Pt> = u.iter().map(|&x| Pt(x)).collect();
        let (mass, coriolis) = (m.mass(q), m.coriolis(q, v));
        let dfdv = m.linearization(t, q, v, u).forces_dv;
        let (em, ec) = (m.mass_enclosure(&qp), m.coriolis_enclosure(&qp, &vp));
        let ef = m.forces_dv_enclosure(Pt(t), &qp, &vp, &up);
        // the scales of the CasADi comparison: C and ∂F/∂v are sums of
        // (∂M/∂q) v, terms of size up to max|M| max|v|
        let terms = mass.amax() * v.amax();
        for (what, e, x, floor) in [
            ("M", em, mass, 0.0),
            ("C", ec, coriolis, terms),
            ("∂F/∂v", ef, dfdv, terms),
        ] {
            // in units of the last place of that scale
            let unit = x.amax().max(floor).max(f64::MIN_POSITIVE) * f64::EPSILON;
            for r in 0..N {
                for c in 0..N {
                    let d = (e[r][c].0 - x[(r, c)]).abs() / unit;
                    worst = worst.max(d);
                    assert!(
                        d <= ulps,
                        "{stem} {i} {what}[{r},{c}]: {} against {} ({d} units)",
                        e[r][c].0,
                        x[(r, c)]
                    );
                }
            }
        }
    }
    eprintln!("{stem}: largest difference {worst} units of the last place");
}

/// Where no wave of the model is shared the two instruction lists are one
/// and the values agree bit for bit; the double pendulum and the arm build
/// their `f64` waves of angle sums and differences from the angles' own by
/// the addition formulas (`moreau_sym::graph::share_waves`), each formula a
/// few roundings of numbers at most 1, while the enclosure code keeps one
/// call per combination (a tighter interval): there they agree to a few
/// units in the last place of the scale the CasADi comparison uses (the
/// largest entry; for `C` and `∂F/∂v` at least max|M| max|v|).
#[test]
fn enclosures_at_points_are_the_f64_values() {
    enclosure_at_points::<Parabola, 2, 2, 0>("parabola", 0.0);
    enclosure_at_points::<ThreeBalls, 3, 4, 0>("three_balls", 0.0);
    enclosure_at_points::<Billiard, 2, 4, 0>("billiard", 0.0);
    enclosure_at_points::<DoublePendulum, 2, 2, 0>("double_pendulum", 4.0);
    enclosure_at_points::<Arm3, 3, 1, 3>("arm3", 4.0);
}

/// What the compiler proves of the shipped models' structure, against what
/// their model text shows: Example 1 is a point mass under gravity (M = m I,
/// F = G constant); the double pendulum's M depends on th1 − th2 and it has
/// joint damping.
#[test]
fn structure_flags_match_the_models() {
    let p = Parabola::<f64>::STRUCTURE;
    assert!(p.mass_constant && p.mass_diagonal && p.forces_velocity_free);
    assert!(p.forces_configuration_free && p.forces_time_free && p.forces_input_free);
    assert!(!p.jacobian_constant); // the floor y − x² curves
    let d = DoublePendulum::<f64>::STRUCTURE;
    assert!(!d.mass_constant && !d.mass_diagonal && !d.forces_velocity_free);
    let b = ThreeBalls::<f64>::STRUCTURE;
    assert!(b.mass_constant && b.mass_diagonal && b.jacobian_constant);
}
