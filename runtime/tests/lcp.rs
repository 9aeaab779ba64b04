//! The LCP solver against two independent oracles, on random problems with
//! up to 8 active rows: positive definite ones (`W = AAᵀ + εI`) and
//! degenerate ones (`W = AAᵀ` with dependent rows, zero rows, equal rows, tied
//! and zero entries of `b`), and the post-impact velocity of dependent
//! constraints against a brute-force projection.
//!
//! Oracles: (1) every complementary set solved with a dense pseudo-inverse
//! (nalgebra's SVD), written here without the solver's code; (2) the QP
//! `min ½ zᵀWz + bᵀz, z ≥ 0`, whose KKT system the LCP is, by clarabel.
#![allow(non_snake_case)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
use moreau_runtime::{IndexSet, Lcp, LcpError, LcpSolution, lcp_residual, solve_lcp};
use nalgebra::{DMatrix, DVector, Matrix2, SMatrix, SVector, Vector2};
use proptest::prelude::*;
use proptest::test_runner::{FileFailurePersistence, TestCaseError};

/// Storage size of the random problems; the active set picks `m ≤ 8` rows.
const K: usize = 8;
type Mat = SMatrix<f64, K, K>;
type Vect = SVector<f64, K>;

/// One random LCP. Inactive entries of `W` and `b` are NaN: the solver must
/// not read them.
#[derive(Clone)]
struct Case {
    W: Mat,
    b: Vect,
    active: IndexSet<K>,
    /// `W = AAᵀ + εI` with `ε ≥ 0.05`: `λ` is unique and well conditioned.
    definite: bool,
}

impl std::fmt::Debug for Case {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (W, b) = self.block();
        write!(
            f,
            "active {:?} (definite: {}), W = {:?}, b = {:?}",
            self.active,
            self.definite,
            W.as_slice(),
            b.as_slice()
        )
    }
}

impl Case {
    fn rows(&self) -> Vec<usize> {
        self.active.iter().collect()
    }

    /// The active block, dense.
    fn block(&self) -> (DMatrix<f64>, DVector<f64>) {
        let r = self.rows();
        let W = DMatrix::from_fn(r.len(), r.len(), |i, j| self.W[(r[i], r[j])]);
        let b = DVector::from_fn(r.len(), |i, _| self.b[r[i]]);
        (W, b)
    }
}

/// `β`, `ω` of the active block.
fn scales(W: &DMatrix<f64>, b: &DVector<f64>) -> (f64, f64) {
    (b.amax(), W.amax())
}

fn hide_inactive(W: &mut Mat, b: &mut Vect, active: IndexSet<K>) {
    for i in 0..K {
        if !active.contains(i) {
            b[i] = f64::NAN;
            for j in 0..K {
                W[(i, j)] = f64::NAN;
                W[(j, i)] = f64::NAN;
            }
        }
    }
}

/// `b` in one of three ways: uniform; `−Wc + d` with sparse `c, d ≥ 0`
/// (feasible, with `λ = c` and degenerate zeros); or from `{−1, −½, 0, ½, 1}`
/// (ties and exact zeros).
fn make_b(W: &Mat, mode: u8, u: &[f64; K], c: &[f64; K], d: &[f64; K]) -> Vect {
    match mode {
        0 => Vect::from_fn(|i, _| u[i]),
        1 => {
            let c = Vect::from_fn(|i, _| if c[i] > 0.0 { c[i] } else { 0.0 });
            let d = Vect::from_fn(|i, _| if d[i] > 0.0 { d[i] } else { 0.0 });
            -(W * c) + d
        }
        _ => Vect::from_fn(|i, _| (u[i] * 2.0).round() / 2.0),
    }
}

fn definite_case() -> impl Strategy<Value = Case> {
    (
        any::<u8>(),
        1usize..=K,
        prop::array::uniform8(prop::array::uniform8(-1.0..1.0f64)),
        0.05..1.0f64,
        0u8..3,
        prop::array::uniform8(-1.0..1.0f64),
        prop::array::uniform8(-1.0..1.0f64),
        prop::array::uniform8(-1.0..1.0f64),
    )
        .prop_map(|(mask, n, a, eps, mode, u, c, d)| {
            let A = Mat::from_fn(|i, j| if j < n { a[i][j] } else { 0.0 });
            let W = A * A.transpose() + Mat::identity() * eps;
            let active = IndexSet::from_bits(u64::from(mask)).unwrap();
            let mut b = make_b(&W, mode, &u, &c, &d);
            let mut W = W;
            hide_inactive(&mut W, &mut b, active);
            Case {
                W,
                b,
                active,
                definite: true,
            }
        })
}

fn degenerate_case() -> impl Strategy<Value = Case> {
    (
        any::<u8>(),
        0usize..=4,
        prop::array::uniform8(prop::array::uniform4(-2i8..=2)),
        prop::array::uniform4(prop::array::uniform4(-1.0..1.0f64)),
        prop::array::uniform8(0usize..16),
        0u8..3,
        prop::array::uniform8(-1.0..1.0f64),
        prop::array::uniform8(-1.0..1.0f64),
        prop::array::uniform8(-1.0..1.0f64),
    )
        .prop_map(|(mask, rank, coef, base, copy, mode, u, c, d)| {
            // A = C B: rank ≤ `rank` < 8, integer combinations of `rank` base
            // rows near the unit vectors. Dependent subsets are exactly
            // dependent; independent ones stay well conditioned (an integer
            // Gram determinant is at least 1).
            let mut A = SMatrix::<f64, K, 4>::zeros();
            for i in 0..K {
                for r in 0..rank {
                    for j in 0..4 {
                        let unit = if r == j { 1.0 } else { 0.0 };
                        A[(i, j)] += f64::from(coef[i][r]) * (unit + 0.3 * base[r][j]);
                    }
                }
                // about half the rows copy an earlier one exactly
                if copy[i] < i {
                    let row = A.row(copy[i]).into_owned();
                    A.set_row(i, &row);
                }
            }
            let W = A * A.transpose();
            let mut b = make_b(&W, mode, &u, &c, &d);
            for i in 0..K {
                // ties in b between copied rows
                if copy[i] < i && mode != 1 && copy[i] % 2 == 0 {
                    b[i] = b[copy[i]];
                }
            }
            let mut W = W;
            hide_inactive(
                &mut W,
                &mut b,
                IndexSet::from_bits(u64::from(mask)).unwrap(),
            );
            Case {
                W,
                b,
                active: IndexSet::from_bits(u64::from(mask)).unwrap(),
                definite: false,
            }
        })
}

/// Oracle 1: every complementary set `F`, `λ_F = −W_FF⁺ b_F` by SVD, kept
/// when `W_FF λ_F = −b_F`, `λ_F ≥ 0` and `w ≥ 0` within `1e-9` relative.
/// Returns every solution found (dense, over the active block).
fn brute_force(W: &DMatrix<f64>, b: &DVector<f64>) -> Vec<DVector<f64>> {
    let m = b.len();
    let (beta, omega) = scales(W, b);
    let mut found = Vec::new();
    for set in 0u32..1 << m {
        let f: Vec<usize> = (0..m).filter(|&i| set >> i & 1 == 1).collect();
        let Wff = DMatrix::from_fn(f.len(), f.len(), |i, j| W[(f[i], f[j])]);
        let bf = DVector::from_fn(f.len(), |i, _| b[f[i]]);
        let lf = if f.is_empty() {
            DVector::zeros(0)
        } else {
            let Ok(pinv) = Wff.clone().pseudo_inverse(1e-10 * omega) else {
                continue;
            };
            -(pinv * &bf)
        };
        let mut lambda = DVector::zeros(m);
        for (k, &i) in f.iter().enumerate() {
            lambda[i] = lf[k];
        }
        let w = W * &lambda + b;
        let big = beta.max(omega * lambda.amax());
        let tol = 1e-9 * big;
        let consistent = f.iter().all(|&i| w[i].abs() <= tol);
        let signs =
            lambda.iter().all(|&l| l >= -1e-9 * lambda.amax()) && w.iter().all(|&x| x >= -tol);
        if consistent && signs {
            found.push(lambda);
        }
    }
    found
}

/// Oracle 2: the QP `min ½ zᵀWz + bᵀz, z ≥ 0` by clarabel: its status and
/// `z`.
fn qp(W: &DMatrix<f64>, b: &DVector<f64>) -> (SolverStatus, DVector<f64>) {
    let m = b.len();
    if m == 0 {
        return (SolverStatus::Solved, DVector::zeros(0)); // clarabel needs a variable
    }
    let rows: Vec<Vec<f64>> = (0..m)
        .map(|i| {
            (0..m)
                .map(|j| if j >= i { W[(i, j)] } else { 0.0 })
                .collect()
        })
        .collect();
    let P = CscMatrix::from(rows.iter().map(|r| r.iter()));
    let minus_identity: Vec<Vec<f64>> = (0..m)
        .map(|i| (0..m).map(|j| if i == j { -1.0 } else { 0.0 }).collect())
        .collect();
    let A = CscMatrix::from(minus_identity.iter().map(|r| r.iter()));
    let q: Vec<f64> = b.iter().copied().collect();
    let zeros = vec![0.0; m];
    let settings = DefaultSettings {
        verbose: false,
        tol_gap_abs: 1e-11,
        tol_gap_rel: 1e-11,
        tol_feas: 1e-11,
        ..DefaultSettings::default()
    };
    let cones = [NonnegativeConeT(m)];
    let mut solver = DefaultSolver::new(&P, &q, &A, &zeros, &cones, settings).expect("QP data");
    solver.solve();
    (
        solver.solution.status,
        DVector::from_vec(solver.solution.x.clone()),
    )
}

fn objective(W: &DMatrix<f64>, b: &DVector<f64>, z: &DVector<f64>) -> f64 {
    0.5 * z.dot(&(W * z)) + b.dot(z)
}

fn same_bits(a: &LcpSolution<f64, K>, b: &LcpSolution<f64, K>) -> bool {
    let bits = |s: &LcpSolution<f64, K>| {
        let mut v: Vec<u64> = s
            .lambda
            .iter()
            .chain(s.w.iter())
            .map(|x| x.to_bits())
            .collect();
        v.push(s.residual.to_bits());
        v
    };
    bits(a) == bits(b) && a.support == b.support && a.trials == b.trials
}

/// Everything a case must satisfy; `Err` describes the first failure.
fn check(case: &Case) -> Result<(), TestCaseError> {
    let (W, b) = case.block();
    let rows = case.rows();
    let m = rows.len();
    let (beta, omega) = scales(&W, &b);
    let result = solve_lcp(&case.W, &case.b, case.active);
    let again = solve_lcp(&case.W, &case.b, case.active);
    let oracle = brute_force(&W, &b);
    let (status, z) = qp(&W, &b);

    let s = match result {
        Ok(s) => s,
        Err(LcpError::Infeasible { .. }) => {
            prop_assert_eq!(result, again);
            prop_assert!(
                !case.definite,
                "a positive definite LCP always has a solution"
            );
            prop_assert!(
                oracle.is_empty(),
                "infeasible, yet brute force found {:?}",
                oracle
            );
            // The QP is unbounded below (DualInfeasible); an interior point
            // may also stall or, drifting along the unbounded ray, stop on a
            // point it calls solved: then that point must not solve the LCP
            // (some w_i < 0 by more than round-off of the velocities b).
            if matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
                let w_qp = &W * &z + &b;
                prop_assert!(
                    w_qp.min() < -1e-6 * beta,
                    "infeasible, yet the QP is {:?} with w = {}",
                    status,
                    w_qp
                );
            }
            return Ok(());
        }
        Err(e) => return Err(TestCaseError::fail(format!("{e:?}"))),
    };
    prop_assert!(same_bits(&s, &again.unwrap()), "second call differs");

    // λ ≥ 0 exactly, inactive entries zero
    for i in 0..K {
        prop_assert!(s.lambda[i] >= 0.0);
        if !case.active.contains(i) {
            prop_assert_eq!((s.lambda[i], s.w[i]), (0.0, 0.0));
        }
    }
    let lambda = DVector::from_fn(m, |i, _| s.lambda[rows[i]]);
    let w = DVector::from_fn(m, |i, _| s.w[rows[i]]);
    // the backward-error scale: the largest term of w = Wλ + b
    let big = beta.max(omega * lambda.amax());
    // w = Wλ + b, w ≥ 0 and λᵀw = 0, within 1e-12 of that scale
    prop_assert!((&w - (&W * &lambda + &b)).amax() <= 1e-13 * big);
    prop_assert!(w.iter().all(|&x| x >= -1e-12 * big), "w = {}", w);
    prop_assert!(
        lambda.dot(&w).abs() <= 1e-12 * lambda.amax() * big,
        "λᵀw = {}",
        lambda.dot(&w)
    );
    // and the solver's own, stricter residual (w against β) within tolerance
    let tolerance = Lcp::<f64>::default_tolerance();
    prop_assert!(s.residual <= tolerance, "residual {}", s.residual);
    let r = lcp_residual(&case.W, &case.b, case.active, &s.lambda);
    prop_assert_eq!(r, s.residual);

    // oracle 1: w is unique, so it matches every brute-force solution
    prop_assert!(!oracle.is_empty(), "solved, but brute force found nothing");
    let f = objective(&W, &b, &lambda);
    for other in &oracle {
        let w_other = &W * other + &b;
        let big = big.max(omega * other.amax());
        prop_assert!(
            (&w - &w_other).amax() <= 1e-8 * big,
            "w = {}, brute force {}",
            w,
            w_other
        );
        prop_assert!(
            (f - objective(&W, &b, other)).abs()
                <= 1e-8 * big * lambda.amax().max(other.amax()).max(1e-300)
        );
        if case.definite {
            prop_assert!((&lambda - other).amax() <= 1e-8 * lambda.amax().max(beta / omega));
        }
    }

    // oracle 2: the QP. An interior point may stall on a singular W (no
    // strictly complementary solution, unbounded multiplier sets), so there
    // only a verdict of infeasibility would contradict; on a definite W it
    // must converge.
    let converged = matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved);
    if !converged {
        prop_assert!(!case.definite, "definite, yet the QP is {:?}", status);
        prop_assert!(
            !matches!(
                status,
                SolverStatus::PrimalInfeasible
                    | SolverStatus::DualInfeasible
                    | SolverStatus::AlmostPrimalInfeasible
                    | SolverStatus::AlmostDualInfeasible
            ),
            "solved, yet the QP is {:?}",
            status
        );
        return Ok(());
    }
    // The QP solver's tolerances are absolute for data of size 1, as ours are;
    // an interior point converges like √gap where complementarity is not
    // strict (λ_i = w_i = 0), hence 1e-4 on w and λ.
    let w_qp = &W * &z + &b;
    let big = big.max(omega * z.amax()).max(1.0);
    let size = lambda.amax().max(z.amax()).max(1.0);
    prop_assert!((&w - &w_qp).amax() <= 1e-4 * big, "w = {}, QP {}", w, w_qp);
    let f_qp = objective(&W, &b, &z);
    prop_assert!(
        (f - f_qp).abs() <= 1e-7 * big * size,
        "objective {} vs QP {}",
        f,
        f_qp
    );
    if case.definite {
        prop_assert!(
            (&lambda - &z).amax() <= 1e-4 * size,
            "λ = {}, QP {}",
            lambda,
            z
        );
    }
    Ok(())
}

/// `cases` cases (or `PROPTEST_CASES`); failures go to
/// `proptest-regressions/lcp.txt` (commit it).
fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(cases);
    ProptestConfig {
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "proptest-regressions/lcp.txt",
        ))),
        ..ProptestConfig::with_cases(cases)
    }
}

proptest! {
    #![proptest_config(config(512))]

    #[test]
    fn definite_problems_match_both_oracles(case in definite_case()) {
        check(&case)?;
    }

    #[test]
    fn degenerate_problems_match_both_oracles(case in degenerate_case()) {
        check(&case)?;
    }

    #[test]
    fn f32_agrees_with_f64(case in definite_case()) {
        let s = solve_lcp(&case.W, &case.b, case.active).unwrap();
        let W32: SMatrix<f32, K, K> = case.W.cast();
        let b32: SVector<f32, K> = case.b.cast();
        let t = Lcp::<f32>::default().solve(&W32, &b32, case.active).unwrap();
        let tolerance = f64::from(Lcp::<f32>::default_tolerance());
        prop_assert!(f64::from(t.residual) <= tolerance);
        // f32 solves to its own tolerance, in units of w (the velocities b);
        // W ≥ 0.05 I turns that into λ
        let beta = case.active.iter().fold(0.0, |m: f64, i| m.max(case.b[i].abs()));
        let bound = 10.0 * K as f64 * tolerance * beta;
        prop_assert!((t.w.cast::<f64>() - s.w).amax() <= bound, "f32 w {} vs f64 {}", t.w, s.w);
        prop_assert!((t.lambda.cast::<f64>() - s.lambda).amax() <= 20.0 * bound, "f32 λ {} vs f64 {}", t.lambda, s.lambda);
    }
}

// --- post-impact velocity with dependent constraints -----------------------

const N: usize = 3;

/// The Moreau impact law's post-impact velocity by brute force: the
/// `M`-metric projection of `v⁻` onto `{v : J_A v + c_A ≥ 0}`, as the nearest
/// of the projections onto the affine sets `{J_S v = −c_S}`, `S ⊆ A`, that
/// are feasible (with `M = LLᵀ`, `y = Lᵀv`: `y = y⁻ − B⁺(B y⁻ + c_S)`, `B =
/// J_S L⁻ᵀ`, by SVD). Uses neither `W` nor any LCP.
fn projection(
    M: &SMatrix<f64, N, N>,
    J: &SMatrix<f64, K, N>,
    c: &Vect,
    v_minus: &SVector<f64, N>,
    active: IndexSet<K>,
) -> Option<SVector<f64, N>> {
    let L = M.cholesky().expect("M is positive definite").l();
    let L_inv_t = L.transpose().try_inverse().expect("L is invertible");
    let y_minus = L.transpose() * v_minus;
    let rows: Vec<usize> = active.iter().collect();
    let scale = v_minus.amax().max(c.amax()).max(1.0);
    let mut best: Option<(f64, SVector<f64, N>)> = None;
    for set in 0u32..1 << rows.len() {
        let s: Vec<usize> = (0..rows.len())
            .filter(|&k| set >> k & 1 == 1)
            .map(|k| rows[k])
            .collect();
        let B = DMatrix::from_fn(s.len(), N, |i, j| (J.row(s[i]) * L_inv_t)[j]);
        let cs = DVector::from_fn(s.len(), |i, _| c[s[i]]);
        let y_dyn = DVector::from_column_slice(y_minus.as_slice());
        let y = if s.is_empty() {
            y_dyn.clone()
        } else {
            let Ok(pinv) = B.clone().pseudo_inverse(1e-12) else {
                continue;
            };
            &y_dyn - pinv * (&B * &y_dyn + &cs)
        };
        let v = L_inv_t * SVector::<f64, N>::from_column_slice(y.as_slice());
        let feasible = rows
            .iter()
            .all(|&i| (J.row(i) * v)[0] + c[i] >= -1e-9 * scale);
        let on_face = s
            .iter()
            .all(|&i| ((J.row(i) * v)[0] + c[i]).abs() <= 1e-9 * scale);
        if feasible && on_face {
            let dist = (y - &y_dyn).norm();
            if best.as_ref().is_none_or(|(d, _)| dist < *d) {
                best = Some((dist, v));
            }
        }
    }
    best.map(|(_, v)| v)
}

/// `v⁺ = v⁻ + M⁻¹Jᵀλ` from the LCP with `W = J M⁻¹ Jᵀ`, `b = J v⁻ + c`.
fn impact(
    M: &SMatrix<f64, N, N>,
    J: &SMatrix<f64, K, N>,
    c: &Vect,
    v_minus: &SVector<f64, N>,
    active: IndexSet<K>,
) -> Result<SVector<f64, N>, LcpError<f64>> {
    impact_with_residual(M, J, c, v_minus, active).map(|(v, _)| v)
}

/// [`impact`], and the LCP's residual.
fn impact_with_residual(
    M: &SMatrix<f64, N, N>,
    J: &SMatrix<f64, K, N>,
    c: &Vect,
    v_minus: &SVector<f64, N>,
    active: IndexSet<K>,
) -> Result<(SVector<f64, N>, f64), LcpError<f64>> {
    let M_inv = M.try_inverse().expect("M is invertible");
    let W = J * M_inv * J.transpose();
    let b = J * v_minus + c;
    let s = solve_lcp(&W, &b, active)?;
    Ok((v_minus + M_inv * J.transpose() * s.lambda, s.residual))
}

#[test]
fn repeated_floor_contact_stops_the_normal_velocity() {
    // a point mass on the floor y ≥ 0, written three times (one scaled)
    let M = SMatrix::<f64, N, N>::from_diagonal(&SVector::from([2.0, 2.0, 1.0]));
    let mut J = SMatrix::<f64, K, N>::zeros();
    J.set_row(0, &SMatrix::<f64, 1, N>::new(0.0, 1.0, 0.0));
    J.set_row(1, &SMatrix::<f64, 1, N>::new(0.0, 1.0, 0.0));
    J.set_row(2, &SMatrix::<f64, 1, N>::new(0.0, 2.0, 0.0));
    let v = SVector::<f64, N>::new(1.0, -3.0, 0.5);
    let v_plus = impact(&M, &J, &Vect::zeros(), &v, IndexSet::full(3)).unwrap();
    assert_eq!(v_plus, SVector::<f64, N>::new(1.0, 0.0, 0.5));
    // restitution e = ½ on all three: v⁺_y = 1.5
    let c = Vect::from_fn(|i, _| if i < 3 { 0.5 * (J.row(i) * v)[0] } else { 0.0 });
    let v_plus = impact(&M, &J, &c, &v, IndexSet::full(3)).unwrap();
    assert!((v_plus - SVector::<f64, N>::new(1.0, 1.5, 0.5)).amax() < 1e-15);
}

#[test]
fn box_landing_flat_on_four_corners() {
    // A box (mass 2, half-sides 0.5 × 0.3, inertia diag(0.1, 0.2, 0.25)) with
    // its four bottom corners on the floor: rows (0, 0, 1, y, −x, 0) of rank
    // three, with q = (x, y, z, θx, θy, θz) and small rotations.
    let M = SMatrix::<f64, 6, 6>::from_diagonal(&SVector::from([2.0, 2.0, 2.0, 0.1, 0.2, 0.25]));
    let mut J = SMatrix::<f64, 4, 6>::zeros();
    for (i, (x, y)) in [(0.5, 0.3), (-0.5, 0.3), (-0.5, -0.3), (0.5, -0.3)]
        .into_iter()
        .enumerate()
    {
        J.set_row(
            i,
            &SMatrix::<f64, 1, 6>::from_row_slice(&[0.0, 0.0, 1.0, y, -x, 0.0]),
        );
    }
    let M_inv = M.try_inverse().unwrap();
    let W = J * M_inv * J.transpose();
    // flat landing: all four corners approach alike; the pivoted
    // factorization keeps three, the fourth then has w = 0: one trial
    let v = SVector::<f64, 6>::from([0.3, 0.0, -2.0, 0.0, 0.0, 1.0]);
    let s = solve_lcp(&W, &(J * v), IndexSet::full(4)).unwrap();
    assert_eq!((s.trials, s.support.len()), (1, 3));
    let v_plus = v + M_inv * J.transpose() * s.lambda;
    assert!((v_plus - SVector::<f64, 6>::from([0.3, 0.0, 0.0, 0.0, 0.0, 1.0])).amax() < 1e-15);
    // tilted landing: one edge first; compare with the projection
    let v = SVector::<f64, 6>::from([0.0, 0.1, -1.0, 0.7, -0.4, 0.2]);
    let s = solve_lcp(&W, &(J * v), IndexSet::full(4)).unwrap();
    let v_plus = v + M_inv * J.transpose() * s.lambda;
    assert!((J * v_plus).min() >= -1e-15);
    // the M-metric projection onto {J v ≥ 0}, by brute force over faces
    let mut best: Option<(f64, SVector<f64, 6>)> = None;
    for set in 0u32..16 {
        let rows: Vec<usize> = (0..4).filter(|&i| set >> i & 1 == 1).collect();
        let Js = DMatrix::from_fn(rows.len(), 6, |i, j| J[(rows[i], j)]);
        let v_dyn = DVector::from_column_slice(v.as_slice());
        let candidate = if rows.is_empty() {
            v_dyn.clone()
        } else {
            // v = v⁻ − M⁻¹Jᵀ(J M⁻¹ Jᵀ)⁺ J v⁻ on the face {J_S v = 0}
            let M_inv_d = DMatrix::from_column_slice(6, 6, M_inv.as_slice());
            let G = &Js * &M_inv_d * Js.transpose();
            let pinv = G.pseudo_inverse(1e-12).unwrap();
            &v_dyn - &M_inv_d * Js.transpose() * pinv * &Js * &v_dyn
        };
        let c = SVector::<f64, 6>::from_column_slice(candidate.as_slice());
        if (J * c).min() >= -1e-12 {
            let d = (c - v).dot(&(M * (c - v)));
            if best.as_ref().is_none_or(|(e, _)| d < *e) {
                best = Some((d, c));
            }
        }
    }
    let expected = best.unwrap().1;
    assert!((v_plus - expected).amax() < 1e-12, "{v_plus} vs {expected}");
}

#[test]
fn corner_with_a_redundant_diagonal_constraint() {
    // x ≥ 0, y ≥ 0 and the redundant x + y ≥ 0, hit in the corner
    let M = SMatrix::<f64, N, N>::identity();
    let mut J = SMatrix::<f64, K, N>::zeros();
    J.set_row(0, &SMatrix::<f64, 1, N>::new(1.0, 0.0, 0.0));
    J.set_row(1, &SMatrix::<f64, 1, N>::new(0.0, 1.0, 0.0));
    J.set_row(2, &SMatrix::<f64, 1, N>::new(1.0, 1.0, 0.0));
    for (v, expected) in [
        ([-1.0, -2.0, 3.0], [0.0, 0.0, 3.0]),
        ([-1.0, 2.0, 3.0], [0.0, 2.0, 3.0]),
        ([1.0, -0.5, 0.0], [1.0, 0.0, 0.0]),
    ] {
        let v_plus = impact(&M, &J, &Vect::zeros(), &SVector::from(v), IndexSet::full(3)).unwrap();
        assert!(
            (v_plus - SVector::from(expected)).amax() < 1e-15,
            "{v:?} → {v_plus}"
        );
    }
}

fn impact_case() -> impl Strategy<
    Value = (
        SMatrix<f64, N, N>,
        SMatrix<f64, K, N>,
        Vect,
        SVector<f64, N>,
        IndexSet<K>,
    ),
> {
    (
        prop::array::uniform3(prop::array::uniform3(-1.0..1.0f64)),
        (
            prop::array::uniform3(prop::array::uniform3(-1.0..1.0f64)),
            prop::array::uniform8(prop::array::uniform3(-2i8..=2)),
        ),
        prop::array::uniform8(0usize..12),
        prop::array::uniform8(-2i8..=2),
        prop::array::uniform8(0.0..1.0f64),
        prop::array::uniform3(-2.0..2.0f64),
        any::<u8>(),
    )
        .prop_map(|(g, (basis, coef), dep, k, e, v, mask)| {
            let G = SMatrix::<f64, N, N>::from_fn(|r, c| g[r][c]);
            let M = G * G.transpose() + SMatrix::<f64, N, N>::identity() * 0.2;
            // rows: integer combinations of a basis near the unit vectors, so
            // that subsets are exactly dependent or well conditioned
            let B = SMatrix::<f64, N, N>::from_fn(|r, c| {
                f64::from(u8::from(r == c)) + 0.3 * basis[r][c]
            });
            let C = SMatrix::<f64, K, N>::from_fn(|r, c| f64::from(coef[r][c]));
            let mut J = C * B;
            for i in 0..K {
                // dependent rows: a copy, a multiple, or a sum of two earlier rows
                match dep[i] {
                    d if d < i && d % 3 == 0 => {
                        let row = J.row(d).into_owned();
                        J.set_row(i, &row);
                    }
                    d if d < i && d % 3 == 1 => {
                        let row = J.row(d) * f64::from(k[i]);
                        J.set_row(i, &row);
                    }
                    d if d < i => {
                        let row = J.row(d) + J.row(i - 1);
                        J.set_row(i, &row);
                    }
                    _ => {}
                }
            }
            let v = SVector::<f64, N>::from(v);
            // restitution: c = e J v⁻, with e equal on copies of a row
            let c = Vect::from_fn(|i, _| {
                if i % 2 == 0 {
                    0.0
                } else {
                    e[i] * (J.row(i) * v)[0]
                }
            });
            (M, J, c, v, IndexSet::from_bits(u64::from(mask)).unwrap())
        })
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn dependent_constraints_give_the_projected_velocity((M, J, c, v, active) in impact_case()) {
        match impact_with_residual(&M, &J, &c, &v, active) {
            Ok((v_plus, residual)) => {
                let Some(expected) = projection(&M, &J, &c, &v, active) else {
                    // infeasible by less than the tolerance (opposed rows with
                    // a tiny gap between them): accepted, and said so
                    prop_assert!(residual > 1e-9 && residual <= Lcp::<f64>::default_tolerance(), "residual {}", residual);
                    return Ok(());
                };
                let scale = v.amax().max(v_plus.amax()).max(1.0);
                prop_assert!((v_plus - expected).amax() <= 1e-9 * scale, "LCP {} vs projection {}", v_plus, expected);
            }
            Err(e) => {
                // only when the target set {J v + c ≥ 0} is empty
                prop_assert!(matches!(e, LcpError::Infeasible { .. }), "{:?}", e);
                prop_assert!(projection(&M, &J, &c, &v, active).is_none());
            }
        }
    }
}

#[test]
fn two_by_two_matches_oracles_exactly() {
    // the same known problem as the unit tests, through the oracles
    let W = Matrix2::new(2.0, 1.0, 1.0, 2.0);
    let b = Vector2::new(-4.0, -1.0);
    let s = solve_lcp(&W, &b, IndexSet::full(2)).unwrap();
    let (Wd, bd) = (
        DMatrix::from_column_slice(2, 2, W.as_slice()),
        DVector::from_column_slice(b.as_slice()),
    );
    let oracle = brute_force(&Wd, &bd);
    assert_eq!(oracle.len(), 1);
    assert!((oracle[0][0] - s.lambda[0]).abs() < 1e-14 && oracle[0][1].abs() < 1e-14);
    let (status, z) = qp(&Wd, &bd);
    assert_eq!(status, SolverStatus::Solved);
    assert!((z[0] - 2.0).abs() < 1e-7 && z[1].abs() < 1e-7);
}
