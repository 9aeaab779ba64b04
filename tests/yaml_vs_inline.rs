//! The two front ends make the same model, and a model written inline goes
//! through the CasADi check like a shipped one. (The robots from a URDF,
//! written both ways, are checked in `tests/robots/yaml_vs_inline.rs`.)

mod common;

use common::{same_info, vector};
use moreau::{Model, Sensitivities};
use nalgebra::{SVector, Vector2};

mod from_yaml {
    moreau::model!(file = "models/parabola.yaml");
}

mod inline {
    moreau::model! {
        /// The paper's Example 1, written inline.
        pub struct Parabola;
        coordinates { x: vx, y: vy }
        parameters { m: 1.0, g: 9.81, c: 8.0 }
        kinetic = 0.5 * m * (vx^2 + vy^2);
        potential = m * g * y;
        constraints {
            floor: y - x^2 >= 0,
            ceiling: c - y >= 0,
        }
        restitution = 0.9;
        initial { x: 1.5, y: 4.0, vx: 3.0, vy: 9.0 }
    }
}

/// A cart on a rail carrying a pendulum, pushed by a force `u`, between two
/// walls the bob can hit: a user model with definitions, an input, extra
/// forces and per-constraint restitution.
mod cart_pole {
    moreau::model! {
        /// A cart-pole whose bob can hit two walls.
        pub struct CartPole;
        coordinates { s: ds, th: dth }
        parameters { mc: 1.0, mp: 0.3, l: 0.6, g: 9.81, b: 0.2, w: 0.9 }
        inputs { u }
        let bob_x = s + l * sin(th);
        let bob_vx = ds + l * cos(th) * dth;
        let bob_vy = l * sin(th) * dth;
        kinetic = 0.5 * mc * ds^2 + 0.5 * mp * (bob_vx^2 + bob_vy^2);
        potential = -mp * g * l * cos(th);
        applied { s: u - b * ds }
        constraints {
            #[restitution = 0.5]
            left: bob_x >= -w,
            right: bob_x <= w,
        }
        restitution = 0.8;
    }
}

/// Every function of the model language, the time `t`, `pi`, an input, a
/// configuration-dependent mass matrix and no constraint at all (K = 0),
/// so that CasADi checks each derivative rule. The arguments keep `sqrt`
/// and `ln` in their domains over the CasADi sample box (|q| ≤ 1.5).
mod function_zoo {
    moreau::model! {
        /// A bead on a wire with every smooth function in it.
        pub struct FunctionZoo;
        coordinates { a: da, b: db }
        parameters { m: 1.2, k: 0.7, w: 2.0 }
        inputs { u }
        let r2 = 4 + a^2 + b^2;
        kinetic = 0.5 * m * (1 + 0.1 * tanh(a)^2) * da^2 + 0.5 * m * cosh(0.3 * b) * db^2
            + 0.05 * m * sinh(0.2 * a) * da * db;
        potential = k * (sqrt(r2) + ln(r2) + exp(-0.1 * a^2) + tan(0.3 * b) + atan2(b, 3 + a))
            + a^4 / 4 + r2^0.75;
        applied { a: u * cos(w * t + pi / 4) - 0.1 * da * db^2, b: -0.2 * db^3 }
    }
}

/// Sample points in the box the CasADi script uses.
fn samples() -> impl Iterator<Item = (f64, Vector2<f64>, Vector2<f64>)> {
    // a fixed, dependency-free sequence (a Weyl sequence on the box)
    (1..=50).map(|k| {
        let f = |a: f64| ((k as f64) * a).fract() * 2.0 - 1.0;
        (
            10.0 * (f(0.618_033_988_7) + 1.0) / 2.0,
            Vector2::new(1.5 * f(0.754_877_666), 1.5 * f(0.569_840_291)),
            Vector2::new(2.0 * f(0.438_579_6), 2.0 * f(0.324_718_0)),
        )
    })
}

/// Written in YAML or inline, Example 1 compiles to the same code: every
/// output agrees to the last bit.
#[test]
fn yaml_and_inline_parabola_agree_bit_for_bit() {
    let yaml = from_yaml::Parabola::<f64>::default();
    let inline = inline::Parabola::<f64>::default();
    let u = SVector::<f64, 0>::zeros();
    for (t, q, v) in samples() {
        assert_eq!(yaml.eval(t, &q, &v, &u), inline.eval(t, &q, &v, &u));
        assert_eq!(
            yaml.linearization(t, &q, &v, &u),
            inline.linearization(t, &q, &v, &u)
        );
    }
    assert_eq!(yaml.restitution(), inline.restitution());
    assert_eq!(
        from_yaml::Parabola::<f64>::initial_state(),
        inline::Parabola::<f64>::initial_state()
    );
    same_info(
        &from_yaml::Parabola::<f64>::INFO,
        &inline::Parabola::<f64>::INFO,
    );
}

/// A YAML model's text is its file, verbatim.
#[test]
fn yaml_model_text_is_the_file() {
    let file = std::fs::read_to_string(common::root().join("models/parabola.yaml")).unwrap();
    assert_eq!(from_yaml::Parabola::<f64>::INFO.source, file);
}

/// The inline models' texts are the committed
/// `tests/fixtures/inline/<stem>.yaml`, which CI puts through
/// `tests/casadi_reference.py` to make `tests/fixtures/inline/<stem>.json`
/// (see `.ci/run`). If a model changes, refresh both:
/// `cargo test --test yaml_vs_inline` prints the new text.
#[test]
fn inline_model_texts_are_the_committed_files() {
    for (stem, text) in [
        ("cart_pole", cart_pole::CartPole::<f64>::INFO.source),
        (
            "function_zoo",
            function_zoo::FunctionZoo::<f64>::INFO.source,
        ),
    ] {
        let path = common::root().join(format!("tests/fixtures/inline/{stem}.yaml"));
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == text,
            "{} is stale; its text should be:\n{text}",
            path.display()
        );
    }
}

/// An inline model against its CasADi fixture, to 1e-12 like the shipped
/// models: every output, the force Jacobians included.
fn inline_matches_casadi<M, const N: usize, const K: usize, const NU: usize>(stem: &str)
where
    M: Sensitivities<N, K> + Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    let path = common::root().join(format!("tests/fixtures/inline/{stem}.json"));
    let fixture: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(fixture["model"], M::INFO.name);
    let check = |what: &str, ours: &[f64], casadi: &[f64], scale: f64| {
        for (a, b) in ours.iter().zip(casadi) {
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(scale).max(f64::MIN_POSITIVE),
                "{stem} {what}: {ours:?} vs {casadi:?}"
            );
        }
    };
    let flat = |v: &serde_json::Value| -> Vec<f64> {
        // rows of a matrix or a vector, flattened column-major like nalgebra
        let rows: Vec<Vec<f64>> = match v.as_array().unwrap().first() {
            Some(serde_json::Value::Array(_)) => v
                .as_array()
                .unwrap()
                .iter()
                .map(|r| {
                    r.as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_f64().unwrap())
                        .collect()
                })
                .collect(),
            _ => v
                .as_array()
                .unwrap()
                .iter()
                .map(|x| vec![x.as_f64().unwrap()])
                .collect(),
        };
        let cols = rows.first().map_or(0, Vec::len);
        (0..cols)
            .flat_map(|j| rows.iter().map(move |r| r[j]))
            .collect()
    };
    let points = fixture["points"].as_array().unwrap();
    assert!(points.len() >= 20);
    for point in points {
        let mut model = M::default();
        for (i, p) in point["p"].as_array().unwrap().iter().enumerate() {
            *model.parameter_mut(i).unwrap() = p.as_f64().unwrap();
        }
        let t = point["t"].as_f64().unwrap();
        let q: SVector<f64, N> = vector(&point["q"]);
        let v: SVector<f64, N> = vector(&point["v"]);
        let u: SVector<f64, NU> = vector(&point["u"]);
        let all = model.eval(t, &q, &v, &u);
        let lin = model.linearization(t, &q, &v, &u);
        let (dmv, djv) = (model.mass_dq(&q, &v), model.jacobian_dq(&q, &v));
        for (what, ours) in [
            ("M", all.mass.as_slice()),
            ("C", all.coriolis.as_slice()),
            ("G", all.gravity.as_slice()),
            ("F", all.forces.as_slice()),
            ("h", all.gaps.as_slice()),
            ("J", all.jacobian.as_slice()),
            ("dFdq", lin.forces_dq.as_slice()),
            ("dFdv", lin.forces_dv.as_slice()),
            ("dMvdq", dmv.as_slice()),
            ("dJvdq", djv.as_slice()),
        ] {
            let casadi = flat(&point[what]);
            let scale = casadi.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            assert_eq!(ours.len(), casadi.len(), "{what}");
            check(what, ours, &casadi, scale);
        }
    }
}

#[test]
fn inline_cart_pole_matches_casadi() {
    inline_matches_casadi::<cart_pole::CartPole, 2, 2, 1>("cart_pole");
}

#[test]
fn inline_function_zoo_matches_casadi() {
    inline_matches_casadi::<function_zoo::FunctionZoo, 2, 0, 1>("function_zoo");
}
