//! The two front ends make the same model, and a model written inline goes
//! through the CasADi check like a shipped one.

mod common;

use common::{matrix, relative_error, vector};
use moreau::Model;
use nalgebra::{SMatrix, SVector, Vector2};

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
        forces { s: u - b * ds }
        constraints {
            #[restitution = 0.5]
            left: bob_x >= -w,
            right: bob_x <= w,
        }
        restitution = 0.8;
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
    let (a, b) = (
        from_yaml::Parabola::<f64>::INFO,
        inline::Parabola::<f64>::INFO,
    );
    assert_eq!(
        (
            a.name,
            a.coordinates,
            a.velocities,
            a.constraints,
            a.parameters,
            a.op_count
        ),
        (
            b.name,
            b.coordinates,
            b.velocities,
            b.constraints,
            b.parameters,
            b.op_count
        )
    );
}

/// A YAML model's text is its file, verbatim.
#[test]
fn yaml_model_text_is_the_file() {
    let file = std::fs::read_to_string(common::root().join("models/parabola.yaml")).unwrap();
    assert_eq!(from_yaml::Parabola::<f64>::INFO.source, file);
}

/// The inline cart-pole's model text is the committed
/// `tests/fixtures/inline/cart_pole.yaml`, which CI puts through
/// `tests/casadi_reference.py` to make `tests/fixtures/inline/cart_pole.json`
/// (see `.ci/run`). If the model changes, refresh both:
/// `cargo test --test yaml_vs_inline` prints the new text.
#[test]
fn inline_model_text_is_the_committed_file() {
    let path = common::root().join("tests/fixtures/inline/cart_pole.yaml");
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    let text = cart_pole::CartPole::<f64>::INFO.source;
    assert!(
        committed == text,
        "{} is stale; its text should be:\n{text}",
        path.display()
    );
}

/// The inline cart-pole against CasADi, to 1e-12 like the shipped models.
#[test]
fn inline_cart_pole_matches_casadi() {
    let path = common::root().join("tests/fixtures/inline/cart_pole.json");
    let fixture: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(fixture["model"], "CartPole");
    for point in fixture["points"].as_array().unwrap() {
        let mut model = cart_pole::CartPole::<f64>::default();
        for (i, p) in point["p"].as_array().unwrap().iter().enumerate() {
            *model.parameter_mut(i).unwrap() = p.as_f64().unwrap();
        }
        let t = point["t"].as_f64().unwrap();
        let q: SVector<f64, 2> = vector(&point["q"]);
        let v: SVector<f64, 2> = vector(&point["v"]);
        let u: SVector<f64, 1> = vector(&point["u"]);
        let all = model.eval(t, &q, &v, &u);
        let lin = model.linearization(t, &q, &v, &u);
        let pairs: [(&str, SMatrix<f64, 2, 2>, SMatrix<f64, 2, 2>); 4] = [
            ("M", all.mass, matrix(&point["M"])),
            ("C", all.coriolis, matrix(&point["C"])),
            ("J", all.jacobian, matrix(&point["J"])),
            ("∂F/∂q", lin.forces_dq, matrix(&point["dFdq"])),
        ];
        for (what, ours, casadi) in pairs {
            assert!(
                relative_error(&ours, &casadi) <= 1e-12,
                "{what}: {ours} vs {casadi}"
            );
        }
        for (what, ours, casadi) in [
            ("G", all.gravity, vector::<2>(&point["G"])),
            ("F", all.forces, vector::<2>(&point["F"])),
            ("h", all.gaps, vector::<2>(&point["h"])),
        ] {
            assert!(
                relative_error(&ours, &casadi) <= 1e-12,
                "{what}: {ours} vs {casadi}"
            );
        }
        let dfdv: SMatrix<f64, 2, 2> = matrix(&point["dFdv"]);
        assert!(relative_error(&lin.forces_dv, &dfdv) <= 1e-12);
    }
}
