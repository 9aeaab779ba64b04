//! Hand-written models the runtime's unit tests share (the generated
//! models are in `moreau-models`; doc examples keep their own small
//! model so that each reads alone).

use nalgebra::{Matrix1, Matrix2, RealField, SMatrix, SVector, Vector1, Vector2};

use crate::model::{Linearization, Model, ModelInfo};

/// A ball of unit mass above the floor `y ≥ 0`, gravity `g`, restitution
/// `e`, in any scalar type.
pub(crate) struct Ball<T> {
    pub g: T,
    pub e: T,
}

impl<T: RealField + Copy> Model<1, 1> for Ball<T> {
    type Scalar = T;
    type Input = SVector<T, 0>;
    const INFO: ModelInfo<1, 1> = ModelInfo {
        name: "Ball",
        coordinates: ["y"],
        velocities: ["vy"],
        constraints: ["floor"],
        parameters: &[],
        inputs: &[],
        source: "",
        op_count: 0,
    };
    fn mass(&self, _: &Vector1<T>) -> Matrix1<T> {
        Matrix1::new(T::one())
    }
    fn coriolis(&self, _: &Vector1<T>, _: &Vector1<T>) -> Matrix1<T> {
        Matrix1::zeros()
    }
    fn gravity(&self, _: &Vector1<T>) -> Vector1<T> {
        Vector1::new(self.g)
    }
    fn forces(&self, _: T, q: &Vector1<T>, _: &Vector1<T>, _: &SVector<T, 0>) -> Vector1<T> {
        self.gravity(q)
    }
    fn gaps(&self, q: &Vector1<T>) -> Vector1<T> {
        *q
    }
    fn gap_jacobian(&self, _: &Vector1<T>) -> Matrix1<T> {
        Matrix1::new(T::one())
    }
    fn restitution(&self) -> Vector1<T> {
        Vector1::new(self.e)
    }
    fn parameter(&self, _: usize) -> Option<T> {
        None
    }
    fn parameter_mut(&mut self, _: usize) -> Option<&mut T> {
        None
    }
}

/// A puck of unit mass on the floor `y ≥ 0`, pressed by gravity and
/// pushed along by a constant force `f`.
pub(crate) struct Puck {
    pub f: f64,
}

impl Model<2, 1> for Puck {
    type Scalar = f64;
    type Input = SVector<f64, 0>;
    const INFO: ModelInfo<2, 1> = ModelInfo {
        name: "Puck",
        coordinates: ["x", "y"],
        velocities: ["vx", "vy"],
        constraints: ["floor"],
        parameters: &[],
        inputs: &[],
        source: "",
        op_count: 0,
    };
    fn mass(&self, _: &Vector2<f64>) -> Matrix2<f64> {
        Matrix2::identity()
    }
    fn coriolis(&self, _: &Vector2<f64>, _: &Vector2<f64>) -> Matrix2<f64> {
        Matrix2::zeros()
    }
    fn gravity(&self, _: &Vector2<f64>) -> Vector2<f64> {
        Vector2::new(0.0, 9.81)
    }
    fn forces(
        &self,
        _: f64,
        q: &Vector2<f64>,
        _: &Vector2<f64>,
        _: &SVector<f64, 0>,
    ) -> Vector2<f64> {
        self.gravity(q) - Vector2::new(self.f, 0.0)
    }
    fn gaps(&self, q: &Vector2<f64>) -> Vector1<f64> {
        Vector1::new(q[1])
    }
    fn gap_jacobian(&self, _: &Vector2<f64>) -> SMatrix<f64, 1, 2> {
        SMatrix::<f64, 1, 2>::new(0.0, 1.0)
    }
    fn restitution(&self) -> Vector1<f64> {
        Vector1::new(0.9)
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> {
        None
    }
}

/// A particle of mass `m` in polar coordinates `(r, θ)`, no potential:
/// `M = diag(m, m r²)`, `C = m r [[0, −θ̇], [θ̇, ṙ]]`, `F = C v` and
/// `∂F/∂v = 2C`.
pub(crate) struct Polar {
    pub m: f64,
}

impl Model<2, 0> for Polar {
    type Scalar = f64;
    type Input = SVector<f64, 0>;
    const INFO: ModelInfo<2, 0> = ModelInfo {
        name: "Polar",
        coordinates: ["r", "theta"],
        velocities: ["dr", "dtheta"],
        constraints: [],
        parameters: &[],
        inputs: &[],
        source: "",
        op_count: 0,
    };
    fn mass(&self, q: &Vector2<f64>) -> Matrix2<f64> {
        Matrix2::new(self.m, 0.0, 0.0, self.m * q[0] * q[0])
    }
    fn coriolis(&self, q: &Vector2<f64>, v: &Vector2<f64>) -> Matrix2<f64> {
        Matrix2::new(0.0, -v[1], v[1], v[0]) * (self.m * q[0])
    }
    fn gravity(&self, _: &Vector2<f64>) -> Vector2<f64> {
        Vector2::zeros()
    }
    fn forces(
        &self,
        _: f64,
        q: &Vector2<f64>,
        v: &Vector2<f64>,
        _: &SVector<f64, 0>,
    ) -> Vector2<f64> {
        self.coriolis(q, v) * v
    }
    fn gaps(&self, _: &Vector2<f64>) -> SVector<f64, 0> {
        SVector::zeros()
    }
    fn gap_jacobian(&self, _: &Vector2<f64>) -> SMatrix<f64, 0, 2> {
        SMatrix::zeros()
    }
    fn restitution(&self) -> SVector<f64, 0> {
        SVector::zeros()
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> {
        None
    }
    fn linearization(
        &self,
        t: f64,
        q: &Vector2<f64>,
        v: &Vector2<f64>,
        u: &SVector<f64, 0>,
    ) -> Linearization<f64, 2> {
        Linearization {
            mass: self.mass(q),
            forces: self.forces(t, q, v, u),
            forces_dq: Matrix2::zeros(),
            forces_dv: self.coriolis(q, v) * 2.0,
        }
    }
}

/// A ball of unit mass on a vertical line with [`Floors::K`] = 40 floors:
/// `h_i(y) = y − floor_i`, every floor far below the last, `h_39 = y`, which
/// alone is ever reached. With an index set of 32 constraints the ball fell
/// through it.
pub(crate) struct Floors {
    pub g: f64,
    pub e: f64,
}

impl Floors {
    pub const K: usize = 40;

    /// The height of floor `i`: `−(39 − i)` metres (`0` for the last).
    fn floor(i: usize) -> f64 {
        -((Self::K - 1 - i) as f64)
    }
}

impl Model<1, 40> for Floors {
    type Scalar = f64;
    type Input = SVector<f64, 0>;
    const INFO: ModelInfo<1, 40> = ModelInfo {
        name: "Floors",
        coordinates: ["y"],
        velocities: ["vy"],
        constraints: ["floor"; 40],
        parameters: &[],
        inputs: &[],
        source: "",
        op_count: 0,
    };
    fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> {
        Matrix1::new(1.0)
    }
    fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> {
        Matrix1::zeros()
    }
    fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> {
        Vector1::new(self.g)
    }
    fn forces(
        &self,
        _: f64,
        q: &Vector1<f64>,
        _: &Vector1<f64>,
        _: &SVector<f64, 0>,
    ) -> Vector1<f64> {
        self.gravity(q)
    }
    fn gaps(&self, q: &Vector1<f64>) -> SVector<f64, 40> {
        SVector::from_fn(|i, _| q[0] - Self::floor(i))
    }
    fn gap_jacobian(&self, _: &Vector1<f64>) -> SMatrix<f64, 40, 1> {
        SMatrix::repeat(1.0)
    }
    fn restitution(&self) -> SVector<f64, 40> {
        SVector::repeat(self.e)
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> {
        None
    }
}

/// The exact bouncing ball dropped from rest at `y0` (gravity `g`,
/// restitution `e`): `(y, v)` at `t` (right limits), and the impact times
/// so far.
pub(crate) fn exact_ball(g: f64, e: f64, y0: f64, t: f64) -> (f64, f64, Vec<f64>) {
    let mut impacts = Vec::new();
    let mut t_impact = (2.0 * y0 / g).sqrt();
    if t < t_impact {
        return (y0 - 0.5 * g * t * t, -g * t, impacts);
    }
    let mut up = e * g * t_impact;
    loop {
        impacts.push(t_impact);
        let flight = 2.0 * up / g;
        if t < t_impact + flight {
            let s = t - t_impact;
            return (up * s - 0.5 * g * s * s, up - g * s, impacts);
        }
        t_impact += flight;
        up *= e;
    }
}

/// Issue 9, defect 4: a model with more than 32 constraints, the 40th of
/// which is the only one ever reached, is stepped and observed in full.
#[cfg(test)]
mod many_constraints {
    use super::{Floors, exact_ball};
    use crate::lcp::IndexSet;
    use crate::{
        FullOrder, FullOrderGains, MoreauJean, Observer, ObserverParams, ReducedOrder, State,
        StepParams, predict_index_set,
    };
    use nalgebra::{SVector, Vector1};

    #[test]
    fn the_40th_constraint_is_predicted() {
        let gaps = SVector::<f64, 40>::from_fn(|i, _| if i == 39 { -1e-9 } else { 1.0 });
        let set = predict_index_set(&gaps, &SVector::zeros(), 0.5e-3);
        assert_eq!(set, IndexSet::from_indices(&[39]).unwrap());
    }

    /// The plant bounces on floor 39 as the exact ball does (apex after
    /// the first bounce at `e² y0`), and never passes below it by more
    /// than `O(τ)`.
    #[test]
    fn the_plant_bounces_on_the_40th_constraint() {
        let model = Floors { g: 9.81, e: 0.5 };
        let stepper = MoreauJean::new(StepParams::new(1e-4)).unwrap();
        let mut state = State::new(0.0, Vector1::new(1.0), Vector1::zeros());
        let (mut bounces, mut lowest, mut apex) = (0, f64::INFINITY, 0.0_f64);
        while state.t < 0.9 {
            let report = stepper.step(&model, &mut state, &SVector::zeros()).unwrap();
            for impact in report.impacts() {
                assert_eq!(impact.constraint, 39);
                bounces += 1;
            }
            lowest = lowest.min(state.q[0]);
            if bounces == 1 {
                apex = apex.max(state.q[0]);
            }
        }
        assert_eq!(bounces, 1);
        assert!(lowest > -1e-3, "{lowest}");
        // e² y0 = 0.25 m, to O(τ) of the discrete impact
        assert!((apex - 0.25).abs() < 2e-3, "{apex}");
    }

    /// Both observers, on exact samples of that ball, locate its bounce on
    /// floor 39 and keep the velocity: before, the 33rd to 40th constraints
    /// were never looked at and the estimate fell through the floor.
    #[test]
    fn both_observers_see_the_40th_constraint() {
        let model = Floors { g: 9.81, e: 0.8 };
        let u = SVector::zeros();
        let params = ObserverParams::new(10.0, 20.0);
        let q0 = Vector1::new(1.0);
        let mut reduced =
            ReducedOrder::<f64, 1, 40>::new(params, 0.0, q0, Vector1::zeros()).unwrap();
        let gains = FullOrderGains::scalar(5.0, 25.0);
        let mut full =
            FullOrder::<f64, 1, 40>::new(params, gains, 0.0, q0, Vector1::zeros()).unwrap();
        let (mut worst, mut impacts) = ([0.0_f64; 2], [0; 2]);
        for k in 1..=1000 {
            let t = f64::from(k) * 1e-3;
            let (y, v, _) = exact_ball(9.81, 0.8, 1.0, t);
            let y = Vector1::new(y);
            let a = reduced.update(&model, t, &y, &u).unwrap();
            let b = full.update(&model, t, &y, &u).unwrap();
            for (j, (estimate, report)) in [(a, *reduced.report()), (b, *full.report())]
                .into_iter()
                .enumerate()
            {
                worst[j] = worst[j].max((estimate.v[0] - v).abs());
                if report.impacts > 0 {
                    assert_eq!(report.impacted, IndexSet::from_indices(&[39]).unwrap());
                    impacts[j] += report.impacts;
                }
            }
        }
        assert_eq!(impacts, [1, 1]);
        assert!(worst[0] < 1e-10 && worst[1] < 1e-10, "{worst:?}");
    }
}

/// A unit mass falling freely, no constraint, whose model is undefined
/// below `y = −1` (its forces are NaN there, as a `sqrt` of a negative
/// number would give).
pub(crate) struct Cliff;

impl Model<1, 0> for Cliff {
    type Scalar = f64;
    type Input = SVector<f64, 0>;
    const INFO: ModelInfo<1, 0> = ModelInfo {
        name: "Cliff",
        coordinates: ["y"],
        velocities: ["vy"],
        constraints: [],
        parameters: &[],
        inputs: &[],
        source: "",
        op_count: 0,
    };
    fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> {
        Matrix1::new(1.0)
    }
    fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> {
        Matrix1::zeros()
    }
    fn gravity(&self, q: &Vector1<f64>) -> Vector1<f64> {
        Vector1::new(if q[0] < -1.0 { f64::NAN } else { 9.81 })
    }
    fn forces(
        &self,
        _: f64,
        q: &Vector1<f64>,
        _: &Vector1<f64>,
        _: &SVector<f64, 0>,
    ) -> Vector1<f64> {
        self.gravity(q)
    }
    fn gaps(&self, _: &Vector1<f64>) -> SVector<f64, 0> {
        SVector::zeros()
    }
    fn gap_jacobian(&self, _: &Vector1<f64>) -> SMatrix<f64, 0, 1> {
        SMatrix::zeros()
    }
    fn restitution(&self) -> SVector<f64, 0> {
        SVector::zeros()
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> {
        None
    }
}

/// Issue 9, defect 1: an observer whose own state leads its prediction
/// where the model is undefined restarts from the measurement instead of
/// refusing every update for good.
#[cfg(test)]
mod infeasible_state {
    use super::Cliff;
    use crate::{FullOrder, FullOrderGains, Observer, ObserverParams, ReducedOrder, Restart};
    use nalgebra::{SVector, Vector1};

    fn check<O: Observer<Cliff, 1, 0>>(mut o: O) {
        let u = SVector::zeros();
        // v̂ = −20 m/s predicts y = −2 m at 0.1 s, where F is NaN; the mass
        // in fact rests at y = 0 (held by something outside the model)
        let e = o.update(&Cliff, 0.1, &Vector1::new(0.0), &u).unwrap();
        assert_eq!(o.report().restart, Some(Restart::Infeasible));
        assert_eq!(e.v[0], 0.0); // the mean velocity over the interval
        // and it goes on: the next interval is integrated
        o.update(&Cliff, 0.101, &Vector1::new(0.0), &u).unwrap();
        assert_eq!(o.report().restart, None);
    }

    #[test]
    fn an_infeasible_prediction_restarts_both_observers() {
        let params = ObserverParams::new(10.0, 20.0);
        let v0 = Vector1::new(-20.0);
        check(ReducedOrder::<f64, 1, 0>::new(params, 0.0, Vector1::new(0.0), v0).unwrap());
        let gains = FullOrderGains::scalar(5.0, 25.0);
        check(FullOrder::<f64, 1, 0>::new(params, gains, 0.0, Vector1::new(0.0), v0).unwrap());
    }
}

/// Seeded Gaussian samples for the unit tests: the integration tests'
/// generator (`tests/common/gauss.rs`), included by path so that both
/// suites draw from one source.
#[path = "../../tests/common/gauss.rs"]
mod gauss;
pub(crate) use gauss::Gauss;
