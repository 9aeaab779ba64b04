use super::*;
use crate::node::{Func, Parity};

fn names(v: VarId) -> String {
    ["x", "y", "z", "w"][v.index()].to_string()
}

/// A graph with variables x, y, z.
fn xyz() -> (Graph, Id, Id, Id) {
    let mut g = Graph::new();
    let x = g.var(VarId(0));
    let y = g.var(VarId(1));
    let z = g.var(VarId(2));
    (g, x, y, z)
}

fn show(g: &Graph, id: Id) -> String {
    g.to_infix(id, &names)
}

#[test]
fn hash_consing_shares_equal_nodes() {
    let (mut g, x, y, _) = xyz();
    let a = g.add(x, y);
    let b = g.add(y, x);
    assert_eq!(a, b);
    let n = g.len();
    let s1 = g.sin(a);
    let s2 = g.sin(b);
    assert_eq!(s1, s2);
    assert_eq!(g.len(), n + 1);
    assert_eq!(g.mul(x, y), g.mul(y, x));
    assert_eq!(g.var(VarId(0)), x);
    let c1 = g.constant(1.5);
    assert_eq!(g.constant(1.5), c1);
}

#[test]
fn constants_canonical_zero_and_nan() {
    let mut g = Graph::new();
    let z = g.constant(0.0);
    assert_eq!(g.constant(-0.0), z);
    let n = g.constant(f64::NAN);
    assert_eq!(g.constant(-f64::NAN), n);
}

#[test]
fn constant_folding_uses_f64_ops() {
    let mut g = Graph::new();
    let a = g.constant(0.1);
    let b = g.constant(0.2);
    let checks = [
        (g.add(a, b), 0.1 + 0.2),
        (g.sub(a, b), 0.1 - 0.2),
        (g.mul(a, b), 0.1 * 0.2),
        (g.div(a, b), 0.1 / 0.2),
        (g.neg(a), -0.1),
        (g.powi(a, 3), 0.1f64.powi(3)),
        (g.pow(a, b), 0.1f64.powf(0.2)),
        (g.sin(a), 0.1f64.sin()),
        (g.atan2(a, b), 0.1f64.atan2(0.2)),
    ];
    for (id, want) in checks {
        assert_eq!(g.as_const(id).map(f64::to_bits), Some(want.to_bits()));
    }
}

#[test]
fn add_zero_either_side() {
    let (mut g, x, _, _) = xyz();
    let zero = g.constant(0.0);
    assert_eq!(g.add(x, zero), x);
    assert_eq!(g.add(zero, x), x);
}

#[test]
fn add_negation_becomes_sub() {
    let (mut g, x, y, _) = xyz();
    let ny = g.neg(y);
    let s = g.add(x, ny);
    assert_eq!(g.node(s), Node::Sub([x, y]));
    let nx = g.neg(x);
    let s = g.add(nx, y);
    assert_eq!(g.node(s), Node::Sub([y, x]));
}

#[test]
fn add_like_terms() {
    let (mut g, x, y, _) = xyz();
    let xx = g.add(x, x);
    assert_eq!(show(&g, xx), "2 * x");
    let three = g.constant(3.0);
    let four = g.constant(4.0);
    let a = g.mul(three, x);
    let b = g.mul(x, four);
    let s = g.add(a, b);
    assert_eq!(show(&g, s), "7 * x");
    let s = g.add(a, x);
    assert_eq!(show(&g, s), "4 * x");
    let p = g.mul(x, y);
    let a = g.mul(three, p);
    let b = g.mul(three, y);
    let s = g.add(a, b);
    assert_eq!(show(&g, s), "3 * (x * y + y)");
    let m3 = g.constant(-3.0);
    let b = g.mul(m3, y);
    let s = g.add(a, b);
    assert_eq!(show(&g, s), "3 * (x * y - y)");
}

#[test]
fn add_constants_left_and_commutes() {
    let (mut g, x, y, _) = xyz();
    let one = g.constant(1.0);
    let s = g.add(x, one);
    assert_eq!(g.node(s), Node::Add([one, x]));
    let a = g.add(y, x);
    assert_eq!(g.node(a), Node::Add([x, y]));
}

#[test]
fn sub_zero_and_self() {
    let (mut g, x, _, _) = xyz();
    let zero = g.constant(0.0);
    assert_eq!(g.sub(x, zero), x);
    let m = g.sub(zero, x);
    assert_eq!(g.node(m), Node::Neg(x));
    assert_eq!(g.sub(x, x), zero);
}

#[test]
fn sub_negations() {
    let (mut g, x, y, _) = xyz();
    let ny = g.neg(y);
    let s = g.sub(x, ny);
    assert_eq!(g.node(s), Node::Add([x, y]));
    let nx = g.neg(x);
    let s = g.sub(nx, y);
    assert_eq!(show(&g, s), "-(x + y)");
}

#[test]
fn sub_like_terms() {
    let (mut g, x, y, _) = xyz();
    let three = g.constant(3.0);
    let a = g.mul(three, x);
    let s = g.sub(a, x);
    assert_eq!(show(&g, s), "2 * x");
    let s = g.sub(x, a);
    assert_eq!(show(&g, s), "-2 * x");
    let s = g.sub(a, a);
    assert_eq!(g.as_const(s), Some(0.0));
    let b = g.mul(three, y);
    let s = g.sub(a, b);
    assert_eq!(show(&g, s), "3 * (x - y)");
}

#[test]
fn add_and_sub_cancel_a_term() {
    let (mut g, x, y, z) = xyz();
    let d = g.sub(y, x); // y - x
    assert_eq!(g.add(x, d), y);
    assert_eq!(g.add(d, x), y);
    let s = g.add(x, y);
    assert_eq!(g.sub(s, x), y);
    assert_eq!(g.sub(s, y), x);
    assert_eq!(g.sub(y, d), x); // y - (y - x)
    // a rotation about z: cos q + (1 - cos q) * 1 is 1
    let one = g.constant(1.0);
    let c = g.cos(z);
    let k = g.sub(one, c);
    let k1 = g.mul(k, one);
    assert_eq!(g.add(c, k1), one);
    // no cancellation without a shared term
    let e = g.add(z, d);
    assert_eq!(show(&g, e), "y - x + z");
    let e = g.sub(s, z);
    assert_eq!(show(&g, e), "x + y - z");
}

#[test]
fn mul_zero_one_minus_one() {
    let (mut g, x, _, _) = xyz();
    let zero = g.constant(0.0);
    let one = g.constant(1.0);
    let m1 = g.constant(-1.0);
    assert_eq!(g.mul(x, zero), zero);
    assert_eq!(g.mul(zero, x), zero);
    assert_eq!(g.mul(x, one), x);
    assert_eq!(g.mul(one, x), x);
    let n = g.mul(x, m1);
    assert_eq!(g.node(n), Node::Neg(x));
}

#[test]
fn mul_constants_left_and_merge() {
    let (mut g, x, y, _) = xyz();
    let two = g.constant(2.0);
    let three = g.constant(3.0);
    let a = g.mul(x, two);
    assert_eq!(g.node(a), Node::Mul([two, x]));
    let b = g.mul(a, three);
    assert_eq!(show(&g, b), "6 * x");
    let q = g.div(x, two);
    let b = g.mul(three, q);
    assert_eq!(show(&g, b), "1.5 * x");
    let p = g.mul(a, y);
    assert_eq!(show(&g, p), "2 * (x * y)");
    let b3 = g.mul(three, y);
    let p = g.mul(a, b3);
    assert_eq!(show(&g, p), "6 * (x * y)");
}

#[test]
fn mul_negations_move_out() {
    let (mut g, x, y, _) = xyz();
    let nx = g.neg(x);
    let two = g.constant(2.0);
    let p = g.mul(two, nx);
    assert_eq!(show(&g, p), "-2 * x");
    let p = g.mul(nx, y);
    assert_eq!(show(&g, p), "-(x * y)");
    let ny = g.neg(y);
    let p = g.mul(nx, ny);
    assert_eq!(g.node(p), Node::Mul([x, y]));
}

#[test]
fn mul_square_and_powers() {
    let (mut g, x, _, _) = xyz();
    let sq = g.mul(x, x);
    assert_eq!(g.node(sq), Node::Powi(x, 2));
    let cube = g.mul(sq, x);
    assert_eq!(g.node(cube), Node::Powi(x, 3));
    let p = g.mul(sq, cube);
    assert_eq!(g.node(p), Node::Powi(x, 5));
    // negative exponents are left alone (x^-1 * x is not x at 0)
    let inv = g.powi(x, -1);
    let p = g.mul(inv, x);
    assert!(matches!(g.node(p), Node::Mul(_)));
}

#[test]
fn div_one_minus_one_zero() {
    let (mut g, x, _, _) = xyz();
    let one = g.constant(1.0);
    let m1 = g.constant(-1.0);
    let zero = g.constant(0.0);
    assert_eq!(g.div(x, one), x);
    let n = g.div(x, m1);
    assert_eq!(g.node(n), Node::Neg(x));
    assert_eq!(g.div(zero, x), zero);
}

#[test]
fn div_negations_and_coefficients() {
    let (mut g, x, y, _) = xyz();
    let nx = g.neg(x);
    let q = g.div(nx, y);
    assert_eq!(show(&g, q), "-(x / y)");
    let ny = g.neg(y);
    let q = g.div(x, ny);
    assert_eq!(show(&g, q), "-(x / y)");
    let three = g.constant(3.0);
    let two = g.constant(2.0);
    let a = g.mul(three, x);
    let q = g.div(a, two);
    assert_eq!(show(&g, q), "1.5 * x");
    let q = g.div(a, y);
    assert_eq!(show(&g, q), "3 * (x / y)");
    let q = g.div(x, two);
    assert_eq!(show(&g, q), "x / 2");
}

#[test]
fn neg_rules() {
    let (mut g, x, y, _) = xyz();
    let n = g.neg(x);
    assert_eq!(g.neg(n), x);
    let d = g.sub(x, y);
    let n = g.neg(d);
    assert_eq!(g.node(n), Node::Sub([y, x]));
    let two = g.constant(2.0);
    let p = g.mul(two, x);
    let n = g.neg(p);
    assert_eq!(show(&g, n), "-2 * x");
    let c = g.constant(2.5);
    let n = g.neg(c);
    assert_eq!(g.as_const(n), Some(-2.5));
}

#[test]
fn powi_zero_one_nested_negated() {
    let (mut g, x, _, _) = xyz();
    let p = g.powi(x, 0);
    assert_eq!(g.as_const(p), Some(1.0));
    assert_eq!(g.powi(x, 1), x);
    let p2 = g.powi(x, 2);
    let p = g.powi(p2, -3);
    assert_eq!(g.node(p), Node::Powi(x, -6));
    let nx = g.neg(x);
    let p = g.powi(nx, 2);
    assert_eq!(p, p2);
    let p = g.powi(nx, 3);
    assert_eq!(show(&g, p), "-x^3");
    // overflowing exponent products are kept nested
    let big = g.powi(x, 1 << 20);
    let p = g.powi(big, 1 << 20);
    assert_eq!(g.node(p), Node::Powi(big, 1 << 20));
}

#[test]
fn pow_constant_exponents() {
    let (mut g, x, y, _) = xyz();
    let two = g.constant(2.0);
    let p = g.pow(x, two);
    assert_eq!(g.node(p), Node::Powi(x, 2));
    let m = g.constant(-1.0);
    let p = g.pow(x, m);
    assert_eq!(g.node(p), Node::Powi(x, -1));
    let half = g.constant(0.5);
    let p = g.pow(x, half);
    assert_eq!(g.node(p), Node::Func(Func::Sqrt, x));
    let e = g.constant(1.5);
    let p = g.pow(x, e);
    assert_eq!(g.node(p), Node::Pow([x, e]));
    let p = g.pow(x, y);
    assert_eq!(g.node(p), Node::Pow([x, y]));
    let zero = g.constant(0.0);
    let p = g.pow(x, zero);
    assert_eq!(g.as_const(p), Some(1.0));
}

#[test]
fn func_parity() {
    let (mut g, x, _, _) = xyz();
    let nx = g.neg(x);
    for f in Func::ALL {
        let fx = g.func(f, x);
        let fnx = g.func(f, nx);
        match f.parity() {
            Parity::Odd => assert_eq!(g.node(fnx), Node::Neg(fx), "{f}"),
            Parity::Even => assert_eq!(fnx, fx, "{f}"),
            Parity::None => assert_eq!(g.node(fnx), Node::Func(f, nx), "{f}"),
        }
    }
    let c = g.constant(0.0);
    let e = g.exp(c);
    assert_eq!(g.as_const(e), Some(1.0));
}

#[test]
fn depends_on_wide_variable_sets() {
    let mut g = Graph::new();
    let x = g.var(VarId(1));
    let s = g.sin(x);
    // a variable past the first word widens every set
    let y = g.var(VarId(130));
    let e = g.mul(s, y);
    assert!(g.depends_on(s, VarId(1)));
    assert!(!g.depends_on(s, VarId(130)));
    assert!(g.depends_on(e, VarId(130)));
    assert!(g.depends_on(e, VarId(1)));
    assert!(!g.depends_on(e, VarId(500)));
    assert_eq!(g.free_vars(e), vec![VarId(1), VarId(130)]);
    let c = g.constant(2.0);
    assert!(g.free_vars(c).is_empty());
}

#[test]
fn depends_on_ten_thousand_nodes() {
    let mut g = Graph::new();
    let mut e = g.var(VarId(0));
    for k in 0..10_000 {
        let v = g.var(VarId(1 + k % 40));
        let s = g.sin(e);
        e = g.add(s, v);
    }
    assert!(g.len() > 20_000);
    for v in 0..41 {
        assert!(g.depends_on(e, VarId(v)));
    }
    assert!(!g.depends_on(e, VarId(41)));
}

#[test]
fn subst_rebuilds_with_simplification() {
    let (mut g, x, y, z) = xyz();
    let s = g.sin(x);
    let p = g.mul(s, y);
    let e = g.add(p, z);
    let zero = g.constant(0.0);
    let e0 = g.subst(e, &[(VarId(1), zero)]);
    assert_eq!(e0, z);
    let e1 = g.subst(e, &[(VarId(2), x)]);
    assert_eq!(show(&g, e1), "sin(x) * y + x");
    assert_eq!(g.subst(e, &[(VarId(3), zero)]), e);
}

#[test]
fn to_infix_parenthesizes_by_precedence() {
    let (mut g, x, y, z) = xyz();
    let s = g.sub(y, z);
    let d = g.sub(x, s);
    assert_eq!(show(&g, d), "x - (y - z)");
    let q = g.div(y, z);
    let q = g.div(x, q);
    assert_eq!(show(&g, q), "x / (y / z)");
    let n = g.neg(x);
    let p = g.pow(n, y);
    assert_eq!(show(&g, p), "(-x)^y");
    let a = g.atan2(x, y);
    let e = g.exp(a);
    assert_eq!(show(&g, e), "exp(atan2(x, y))");
}

mod trig {
    use crate::graph::TrigForm;
    use crate::{Graph, VarId};

    /// Values of `e` and of its normal form agree at scattered points.
    fn agrees(g: &mut Graph, e: crate::Id, n: crate::Id, vars: usize) {
        for k in 0..20 {
            let x: Vec<f64> = (0..vars)
                .map(|i| ((k * 7 + i * 13) as f64 * 0.731).sin() * 3.0)
                .collect();
            let (a, b) = (g.eval(&[e], &x)[0], g.eval(&[n], &x)[0]);
            assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }

    #[test]
    fn pythagoras_and_angle_differences_cancel() {
        let mut g = Graph::new();
        let (a, b, m) = (g.var(VarId(0)), g.var(VarId(1)), g.var(VarId(2)));
        // m (l1 cos a + l2 cos(a+b))² + m (l1 sin a + l2 sin(a+b))²
        // = m (l1² + l2² + 2 l1 l2 cos b) with l1 = 2, l2 = 3
        let ab = g.add(a, b);
        let (ca, sa, cab, sab) = (g.cos(a), g.sin(a), g.cos(ab), g.sin(ab));
        let (two, three) = (g.constant(2.0), g.constant(3.0));
        let x = g.mul(two, ca);
        let x2 = g.mul(three, cab);
        let x = g.add(x, x2);
        let y = g.mul(two, sa);
        let y2 = g.mul(three, sab);
        let y = g.add(y, y2);
        let (xx, yy) = (g.powi(x, 2), g.powi(y, 2));
        let s = g.add(xx, yy);
        let e = g.mul(m, s);
        let n = TrigForm::new().normal(&mut g, e);
        assert!(
            !g.depends_on(n, VarId(0)),
            "{}",
            g.to_infix(n, &|v| v.to_string())
        );
        agrees(&mut g, e, n, 3);
        let names = |v: VarId| ["a", "b", "m"][v.index()].to_string();
        assert_eq!(g.to_infix(n, &names), "(13 + 12 * cos(b)) * m");
    }

    #[test]
    fn products_become_waves_of_sums_and_differences() {
        let mut g = Graph::new();
        let (a, b) = (g.var(VarId(0)), g.var(VarId(1)));
        let (sa, cb) = (g.sin(a), g.cos(b));
        let e = g.mul(sa, cb);
        let c = g.sin(a);
        let e = g.mul(e, c); // sin²a cos b
        let n = TrigForm::new().normal(&mut g, e);
        agrees(&mut g, e, n, 2);
        // a constant offset or a non-integer multiple keeps its argument whole
        let one = g.constant(1.0);
        let half = g.constant(0.5);
        for arg in [g.add(a, one), g.mul(half, a)] {
            let s = g.sin(arg);
            let s2 = g.powi(s, 2);
            let cc = g.cos(arg);
            let c2 = g.powi(cc, 2);
            let e = g.add(s2, c2);
            let n = TrigForm::new().normal(&mut g, e);
            assert_eq!(n, e);
        }
    }

    #[test]
    fn a_form_too_large_is_kept_as_it_was() {
        let mut g = Graph::new();
        let mut e = g.constant(1.0);
        for i in 0..40 {
            let x = g.var(VarId(i));
            let c = g.cos(x);
            let s = g.add(c, x);
            e = g.mul(e, s);
        }
        let n = TrigForm::new().normal(&mut g, e);
        assert_eq!(n, e);
    }

    /// The `sin` and `cos` calls among the nodes reachable from `roots`.
    fn calls(g: &Graph, roots: &[crate::Id]) -> usize {
        g.reachable(roots)
            .into_iter()
            .filter(|&id| {
                matches!(
                    g.node(id),
                    crate::Node::Func(crate::Func::Sin | crate::Func::Cos, _)
                )
            })
            .count()
    }

    #[test]
    fn shared_waves_call_each_angle_once_and_keep_their_values() {
        use crate::graph::share_waves;
        let mut g = Graph::new();
        let q: Vec<crate::Id> = (0..3).map(|i| g.var(VarId(i))).collect();
        let two = g.constant(2.0);
        let (q12, q23) = (g.add(q[0], q[1]), g.add(q[1], q[2]));
        let q123 = g.add(q12, q[2]);
        let (q31, twice) = (g.sub(q[2], q[0]), g.mul(two, q[1]));
        // the arm's six combinations, a difference in the order that flips
        // its sign, a double angle; M-like ones in the first phase
        let first = vec![g.cos(q[1]), g.cos(q[2]), g.cos(q23), g.sin(q23)];
        let second = vec![
            g.sin(q[0]),
            g.cos(q12),
            g.sin(q123),
            g.cos(q123),
            g.sin(q31),
            g.cos(twice),
        ];
        let before: Vec<crate::Id> = first.iter().chain(&second).copied().collect();
        let all = share_waves(&mut g, &before, &first);
        // the first phase: q2 + q3 derived from q2 and q3, nothing of q1
        assert_eq!(calls(&g, &first), 4);
        assert_eq!(calls(&g, &all[..first.len()]), 4);
        assert!(
            all[..first.len()]
                .iter()
                .all(|&e| !g.depends_on(e, VarId(0)))
        );
        // all of it from the three angles' own: six calls instead of ten
        assert_eq!((calls(&g, &before), calls(&g, &all)), (10, 6));
        for (before, after) in before.iter().zip(&all) {
            for k in 0..20 {
                let x: Vec<f64> = (0..3)
                    .map(|i| ((k * 7 + i * 13) as f64 * 0.731).sin() * 3.0)
                    .collect();
                let (a, b) = (g.eval(&[*before], &x)[0], g.eval(&[*after], &x)[0]);
                // a few roundings of numbers at most 1, two formulas deep
                assert!((a - b).abs() <= 8.0 * f64::EPSILON, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn a_wave_not_of_a_combination_is_left_alone() {
        use crate::graph::share_waves;
        let mut g = Graph::new();
        let (a, b) = (g.var(VarId(0)), g.var(VarId(1)));
        let one = g.constant(1.0);
        let ab = g.mul(a, b);
        let a1 = g.add(a, one);
        let roots = vec![g.sin(ab), g.cos(a1), g.sin(a)];
        assert_eq!(share_waves(&mut g, &roots, &[]), roots);
    }
}
