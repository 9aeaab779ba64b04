//! Property test: models whose user names are chosen to collide with the
//! names the emitter makes up (`sin_x`, `x_sq`, `m_0_1`, `k_0_5`, `a0`,
//! `one`, ...), compiled through the whole pipeline, every generated method
//! evaluated by [`interp`](super::interp) from its printed tokens and
//! compared with `moreau-sym`'s evaluator on the derived mechanics.
//!
//! A wrong-code bug of the naming (two bindings printing the same name, a
//! local printing a user's name) shows up as a shadowed value, hence a wrong
//! number; the test also asserts directly that no method binds a name twice.
//! Run longer with `MOREAU_PROPTEST_CASES=5000`.

use moreau_sym::{Quantity, Slot};

use super::interp::{Methods, Value};
use super::{Compiled, Rng, compile_inline};

/// Names a person might choose that look like the emitter's own: role
/// names, their prefixes and suffixes, output and constant names,
/// temporaries, the methods' argument names, and weak keywords that Rust
/// accepts as identifiers.
const POOL: [&str; 60] = [
    "x",
    "y",
    "sin_x",
    "x_sq",
    "sq",
    "cube",
    "x_cube",
    "sin_x_sq",
    "sin",
    "cos",
    "cos_x",
    "tan_x",
    "sqrt_x",
    "exp_x",
    "ln_x",
    "sinh",
    "x_sq_2",
    "sin_x_2",
    "m_0_0",
    "m_0_1",
    "m_1_1",
    "c_0_0",
    "c_0_1",
    "g_0",
    "g_1",
    "f_0",
    "f_1",
    "h_0",
    "j_0_0",
    "j_0_1",
    "dfdq_0_0",
    "dfdv_0_1",
    "dmdq_0_0",
    "djdq_0_0",
    "k_0_5",
    "k_2",
    "k_m1",
    "k0",
    "k1",
    "k2",
    "a0",
    "a1",
    "a2",
    "one",
    "zero",
    "q",
    "v",
    "u",
    "w",
    "T",
    "cst",
    "powi",
    "union",
    "default",
    "auto",
    "raw",
    "safe",
    "macro_rules",
    "m",
    "th1",
];

/// A random model of up to three coordinates, two parameters, one input and
/// two constraints, every name drawn from [`POOL`], as inline model text.
fn model_text(rng: &mut Rng) -> String {
    let mut names: Vec<&str> = Vec::new();
    let fresh = |rng: &mut Rng, names: &mut Vec<&str>| loop {
        let n = rng.pick(&POOL);
        if !names.contains(&n) {
            names.push(n);
            return n;
        }
    };
    let n = 1 + rng.below(3);
    let coords: Vec<(&str, &str)> = (0..n)
        .map(|_| (fresh(rng, &mut names), fresh(rng, &mut names)))
        .collect();
    let params: Vec<&str> = (0..rng.below(3)).map(|_| fresh(rng, &mut names)).collect();
    let input = (rng.below(2) == 0).then(|| fresh(rng, &mut names));
    let qs: Vec<&str> = coords.iter().map(|c| c.0).collect();
    let mut q_and_p = qs.clone();
    q_and_p.extend(&params);
    let mut text = String::from("pub struct Adversarial;\ncoordinates { ");
    text += &coords
        .iter()
        .map(|(q, v)| format!("{q}: {v}"))
        .collect::<Vec<_>>()
        .join(", ");
    text += " }\n";
    if !params.is_empty() {
        text += "parameters { ";
        text += &params
            .iter()
            .map(|p| format!("{p}: {}", 0.5 + rng.below(4) as f64 * 0.25))
            .collect::<Vec<_>>()
            .join(", ");
        text += " }\n";
    }
    if let Some(u) = input {
        text += &format!("inputs {{ {u} }}\n");
    }
    // T = ½ Σ (2 + a_i(q)^2) v_i^2 + a cross term: a quadratic form.
    let mut kinetic: Vec<String> = coords
        .iter()
        .map(|(_, v)| format!("0.5 * (2 + {}^2) * {v}^2", expr(rng, &q_and_p, 2)))
        .collect();
    if n > 1 {
        kinetic.push(format!(
            "0.1 * cos({}) * {} * {}",
            expr(rng, &qs, 1),
            coords[0].1,
            coords[1].1
        ));
    }
    text += &format!("kinetic = {};\n", kinetic.join(" + "));
    text += &format!("potential = {};\n", expr(rng, &q_and_p, 3));
    let mut all = q_and_p.clone();
    all.extend(coords.iter().map(|c| c.1));
    all.extend(input);
    text += &format!("applied {{ {}: {} }}\n", qs[0], expr(rng, &all, 2));
    let k = rng.below(3);
    if k > 0 {
        let hs: Vec<String> = (0..k)
            .map(|i| {
                let q = rng.pick(&qs);
                format!("gap{i}: {q} - {} >= 0", expr(rng, &q_and_p, 2))
            })
            .collect();
        text += &format!("constraints {{ {} }}\nrestitution = 0.5;\n", hs.join(", "));
    }
    text
}

/// A random expression over `names`, of the shapes the emitter gives role
/// names to (`sin(x)`, `x^2`, `x^3`) and shared products.
fn expr(rng: &mut Rng, names: &[&str], depth: usize) -> String {
    let atom = |rng: &mut Rng| rng.pick(names).to_string();
    if depth == 0 {
        return atom(rng);
    }
    let a = expr(rng, names, depth - 1);
    match rng.below(9) {
        0 => format!("sin({})", atom(rng)),
        1 => format!("cos({})", atom(rng)),
        2 => format!("{}^2", atom(rng)),
        3 => format!("{}^3", atom(rng)),
        4 => format!("{a} * {}", expr(rng, names, depth - 1)),
        5 => format!("{a} + sin({}) * {}^2", atom(rng), atom(rng)),
        6 => format!("exp(0.1 * {}) - {a}", atom(rng)),
        7 => format!("atan2({a}, 2 + {}^2)", atom(rng)),
        _ => format!("0.5 * {a} - 2"),
    }
}

/// Every method of `Model` and `Sensitivities`, with its arguments and the
/// quantities it returns (in the order its value holds them).
const METHODS: [(&str, &[&str], &[Quantity]); 12] = {
    use Quantity::*;
    [
        ("mass", &["q"], &[Mass]),
        ("coriolis", &["q", "v"], &[Coriolis]),
        ("gravity", &["q"], &[Gravity]),
        ("forces", &["t", "q", "v", "u"], &[Force]),
        ("gaps", &["q"], &[Gap]),
        ("gap_jacobian", &["q"], &[Jacobian]),
        ("dynamics", &["t", "q", "v", "u"], &[Mass, Force]),
        ("contact", &["q"], &[Gap, Jacobian]),
        (
            "linearization",
            &["t", "q", "v", "u"],
            &[Mass, Force, ForceDq, ForceDv],
        ),
        ("eval", &["t", "q", "v", "u"], &Quantity::EVAL),
        ("mass_dq", &["q", "v"], &[MassDq]),
        ("jacobian_dq", &["q", "v"], &[JacobianDq]),
    ]
};

/// Checks every method of one compiled model at a few random points.
fn check_model(c: &Compiled, text: &str, rng: &mut Rng) {
    let methods = Methods::parse(c.tokens.clone()).unwrap_or_else(|e| panic!("{e}\n{text}"));
    for (name, _, _) in METHODS {
        let lets = methods.bindings(name);
        let mut sorted = lets.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(
            sorted.len(),
            lets.len(),
            "`{name}` binds a name twice: {lets:?}\n{text}"
        );
    }
    let (n, k, nu) = (c.n, c.k, c.inputs);
    for _ in 0..3 {
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.5, 1.5)).collect();
        let v: Vec<f64> = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let u: Vec<f64> = (0..nu).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let t = rng.uniform(0.0, 5.0);
        let vars = c.variables(&q, &v, t, &u);
        for (name, arg_names, quantities) in METHODS {
            let args: Vec<(&str, Vec<f64>)> = arg_names
                .iter()
                .map(|&a| {
                    let value = match a {
                        "q" => q.clone(),
                        "v" => v.clone(),
                        "u" => u.clone(),
                        _ => vec![t],
                    };
                    (a, value)
                })
                .collect();
            let got = methods
                .call(name, &args, &c.fields)
                .unwrap_or_else(|e| panic!("`{name}`: {e}\n{text}"));
            let mats = got.matrices();
            assert_eq!(mats.len(), quantities.len(), "`{name}`\n{text}");
            for ((rows, cols, data), &quantity) in mats.iter().zip(quantities) {
                let (r, cl) = quantity.shape(n, k);
                assert_eq!((*rows, *cols), (r, cl), "`{name}` {quantity:?}\n{text}");
                for i in 0..r {
                    for j in 0..cl {
                        let slot = Slot {
                            quantity,
                            row: i,
                            col: j,
                        };
                        let want = c.reference(slot, &vars);
                        let ours = data[j * r + i];
                        let tol = 1e-12 * (1.0 + want.abs());
                        assert!(
                            (ours - want).abs() <= tol || (ours.is_nan() && want.is_nan()),
                            "`{name}` {}: generated {ours}, reference {want}\n{text}",
                            slot.describe()
                        );
                    }
                }
            }
            let _: &Value = &got;
        }
    }
}

#[test]
fn adversarial_names_never_change_the_generated_values() {
    let cases: usize = std::env::var("MOREAU_PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let mut rng = Rng(0x05ee_d0fa_11ce);
    for _ in 0..cases {
        let text = model_text(&mut rng);
        let compiled = compile_inline(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        check_model(&compiled, &text, &mut rng);
    }
}

/// The reproducer: coordinates `sin_x` and `x_sq`, whose role names
/// `sin(x_sq)` → `sin_x_sq` and `sin_x^2` → `sin_x_sq` collided.
#[test]
fn sin_x_and_x_sq_keep_their_own_helpers() {
    let text = "pub struct C2; coordinates { sin_x: v1, x_sq: v2 }
        kinetic = 0.5*(v1^2 + v2^2);
        potential = sin(x_sq)*sin_x^2 + sin(x_sq)*x_sq^3 + sin_x^2*exp(x_sq);";
    let c = compile_inline(text).unwrap();
    let methods = Methods::parse(c.tokens.clone()).unwrap();
    let g = methods
        .call("gravity", &[("q", vec![0.3, 0.7])], &c.fields)
        .unwrap();
    let g1 = g.matrices()[0].2[1];
    // ∂V/∂x_sq = cos(x_sq) sin_x² + cos(x_sq) x_sq³ + 3 sin(x_sq) x_sq² + sin_x² exp(x_sq)
    let (a, b) = (0.3_f64, 0.7_f64);
    let exact = b.cos() * a * a + b.cos() * b.powi(3) + 3.0 * b.sin() * b * b + a * a * b.exp();
    assert!((g1 - exact).abs() < 1e-12, "{g1} vs {exact}");
    assert!((exact - 1.4594).abs() < 1e-4);
}
