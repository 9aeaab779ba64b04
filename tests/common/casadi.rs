//! The comparison with CasADi's fixtures (`tests/casadi_reference.py`):
//! every generated method of a model against the values CasADi computed at
//! the fixture's sample points.

use moreau::{Model, Sensitivities};
use nalgebra::{SMatrix, SVector};

use super::{casadi_fixture, matrix, relative_error_above, vector};

/// Agreement with CasADi required of every output.
pub const CASADI_TOLERANCE: f64 = 1e-12;

/// One sample point of a fixture, with the model's parameters set.
pub struct Point<M, const N: usize, const NU: usize> {
    pub model: M,
    pub t: f64,
    pub q: SVector<f64, N>,
    pub v: SVector<f64, N>,
    pub u: SVector<f64, NU>,
    pub json: serde_json::Value,
}

/// The fixture `stem`'s sample points, each with a model whose parameters
/// are the point's. The model's name, coordinates, velocities, constraints
/// and parameters must be the fixture's, in the same order.
pub fn points<M, const N: usize, const K: usize, const NU: usize>(
    stem: &str,
) -> Vec<Point<M, N, NU>>
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    let fixture = casadi_fixture(stem);
    assert_eq!(fixture["model"], M::INFO.name);
    let names: Vec<&str> = fixture["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert_eq!(names, M::INFO.parameters, "parameter order");
    for (key, ours) in [
        ("coordinates", &M::INFO.coordinates[..]),
        ("velocities", &M::INFO.velocities[..]),
        ("constraints", &M::INFO.constraints[..]),
    ] {
        let theirs: Vec<&str> = fixture[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap())
            .collect();
        assert_eq!(theirs, ours, "{stem}: {key}");
    }
    let points = fixture["points"].as_array().unwrap();
    assert!(points.len() >= 20, "{stem}: only {} points", points.len());
    points
        .iter()
        .map(|p| {
            let mut model = M::default();
            for (i, value) in p["p"].as_array().unwrap().iter().enumerate() {
                *model.parameter_mut(i).unwrap() = value.as_f64().unwrap();
            }
            Point {
                model,
                t: p["t"].as_f64().unwrap(),
                q: vector(&p["q"]),
                v: vector(&p["v"]),
                u: vector(&p["u"]),
                json: p.clone(),
            }
        })
        .collect()
}

/// `ours` within [`CASADI_TOLERANCE`] of `casadi`, relative as
/// [`relative_error_above`] measures it with the scale `floor`; the error.
pub fn check_close<const R: usize, const C: usize>(
    what: &str,
    ours: &SMatrix<f64, R, C>,
    casadi: &SMatrix<f64, R, C>,
    floor: f64,
) -> f64 {
    let err = relative_error_above(ours, casadi, floor);
    assert!(
        err <= CASADI_TOLERANCE,
        "{what}: relative error {err:e}\nours   = {ours}\nCasADi = {casadi}"
    );
    err
}

/// Every generated method of `M` against the CasADi fixture `stem`.
pub fn against_casadi<M, const N: usize, const K: usize, const NU: usize>(stem: &str)
where
    M: Sensitivities<N, K> + Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    // the largest error of each output over the points, printed at the end
    let mut worst: Vec<(&str, f64)> = Vec::new();
    let mut note = |what: &'static str, err: f64| match worst.iter_mut().find(|w| w.0 == what) {
        Some(w) => w.1 = w.1.max(err),
        None => worst.push((what, err)),
    };
    for (i, p) in points::<M, N, K, NU>(stem).iter().enumerate() {
        let at = |what: &str| format!("{stem} point {i}: {what}");
        let (m, t, q, v, u) = (&p.model, p.t, &p.q, &p.v, &p.u);
        let mass: SMatrix<f64, N, N> = matrix(&p.json["M"]);
        let coriolis: SMatrix<f64, N, N> = matrix(&p.json["C"]);
        let gravity: SVector<f64, N> = vector(&p.json["G"]);
        let forces: SVector<f64, N> = vector(&p.json["F"]);
        let gaps: SVector<f64, K> = vector(&p.json["h"]);
        let jacobian: SMatrix<f64, K, N> = matrix(&p.json["J"]);
        let dfdq: SMatrix<f64, N, N> = matrix(&p.json["dFdq"]);
        let dfdv: SMatrix<f64, N, N> = matrix(&p.json["dFdv"]);
        // C, ∂F/∂v and ∂(M v)/∂q are sums of (∂M/∂q) v: where M is
        // stationary (a joint near a configuration of extremal coupling) their
        // terms cancel to a small result whose rounding error, on any route
        // that does not simplify symbolically (moreau's recursions, CasADi's
        // AD of the energies), is that of the terms. They are judged against
        // the terms' size max|M| max|v| when they are smaller than it.
        let velocity_scale = mass.amax() * v.amax();

        // the per-quantity methods
        note("M", check_close(&at("M"), &m.mass(q), &mass, 0.0));
        note(
            "C",
            check_close(&at("C"), &m.coriolis(q, v), &coriolis, velocity_scale),
        );
        note("G", check_close(&at("G"), &m.gravity(q), &gravity, 0.0));
        note(
            "F",
            check_close(&at("F"), &m.forces(t, q, v, u), &forces, 0.0),
        );
        note("h", check_close(&at("h"), &m.gaps(q), &gaps, 0.0));
        note(
            "J",
            check_close(&at("J"), &m.gap_jacobian(q), &jacobian, 0.0),
        );
        // the fused evaluation and its cuts
        let all = m.eval(t, q, v, u);
        note("eval M", check_close(&at("eval M"), &all.mass, &mass, 0.0));
        note(
            "eval C",
            check_close(&at("eval C"), &all.coriolis, &coriolis, velocity_scale),
        );
        note(
            "eval G",
            check_close(&at("eval G"), &all.gravity, &gravity, 0.0),
        );
        note(
            "eval F",
            check_close(&at("eval F"), &all.forces, &forces, 0.0),
        );
        note("eval h", check_close(&at("eval h"), &all.gaps, &gaps, 0.0));
        note(
            "eval J",
            check_close(&at("eval J"), &all.jacobian, &jacobian, 0.0),
        );
        let (dm, df) = m.dynamics(t, q, v, u);
        note(
            "dynamics M",
            check_close(&at("dynamics M"), &dm, &mass, 0.0),
        );
        note(
            "dynamics F",
            check_close(&at("dynamics F"), &df, &forces, 0.0),
        );
        let (ch, cj) = m.contact(q);
        note("contact h", check_close(&at("contact h"), &ch, &gaps, 0.0));
        note(
            "contact J",
            check_close(&at("contact J"), &cj, &jacobian, 0.0),
        );
        let lin = m.linearization(t, q, v, u);
        note(
            "linearization M",
            check_close(&at("linearization M"), &lin.mass, &mass, 0.0),
        );
        note(
            "linearization F",
            check_close(&at("linearization F"), &lin.forces, &forces, 0.0),
        );
        note(
            "∂F/∂q",
            check_close(&at("∂F/∂q"), &lin.forces_dq, &dfdq, 0.0),
        );
        note(
            "∂F/∂v",
            check_close(&at("∂F/∂v"), &lin.forces_dv, &dfdv, velocity_scale),
        );
        // the sensitivities (∂(M v)/∂q, ∂(J v)/∂q at the point's v)
        let dmvdq: SMatrix<f64, N, N> = matrix(&p.json["dMvdq"]);
        let djvdq: SMatrix<f64, K, N> = matrix(&p.json["dJvdq"]);
        note(
            "∂(M v)/∂q",
            check_close(&at("∂(M v)/∂q"), &m.mass_dq(q, v), &dmvdq, velocity_scale),
        );
        note(
            "∂(J v)/∂q",
            check_close(&at("∂(J v)/∂q"), &m.jacobian_dq(q, v), &djvdq, 0.0),
        );
    }
    let shown: Vec<String> = worst.iter().map(|(w, e)| format!("{w} {e:.1e}")).collect();
    eprintln!("{stem}: largest relative error: {}", shown.join(", "));
}

/// The restitution coefficients and the parameter defaults of `M` are the
/// fixture's (its model file's).
pub fn defaults_match<M, const N: usize, const K: usize, const NU: usize>(stem: &str)
where
    M: Model<N, K, Scalar = f64, Input = SVector<f64, NU>> + Default,
{
    let fixture = casadi_fixture(stem);
    let model = M::default();
    let expected: SVector<f64, K> = vector(&fixture["restitution"]);
    assert_eq!(model.restitution(), expected, "{stem}");
    for (i, d) in fixture["parameter_defaults"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        assert_eq!(model.parameter(i), d.as_f64(), "{stem} parameter {i}");
    }
    assert_eq!(model.parameter(M::INFO.parameters.len()), None);
}
