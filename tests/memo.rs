//! The observers' memos (the injection gain, a constant `M`'s factor, the
//! full-order error flow) are exact: an observer on Example 1, whose `M`
//! the compiler proved constant, gives the same bits at every update as one
//! on the same model with nothing proved (no memo of `M` can apply), also
//! after a parameter of `M` changes at run time through `parameter_mut`.

use moreau::{
    FullOrder, FullOrderGains, Model, ModelInfo, MoreauJean, Observer, ObserverParams,
    ReducedOrder, State, StepParams,
};
use moreau_models::Parabola;
use nalgebra::{SMatrix, SVector, Vector2};

/// Example 1 with nothing claimed of its structure.
#[derive(Clone, Copy, Default)]
struct Plain(Parabola<f64>);

impl Model<2, 2> for Plain {
    type Scalar = f64;
    type Input = SVector<f64, 0>;
    const INFO: ModelInfo<2, 2> = Parabola::<f64>::INFO;
    fn mass(&self, q: &Vector2<f64>) -> SMatrix<f64, 2, 2> {
        self.0.mass(q)
    }
    fn coriolis(&self, q: &Vector2<f64>, v: &Vector2<f64>) -> SMatrix<f64, 2, 2> {
        self.0.coriolis(q, v)
    }
    fn gravity(&self, q: &Vector2<f64>) -> Vector2<f64> {
        self.0.gravity(q)
    }
    fn forces(&self, t: f64, q: &Vector2<f64>, v: &Vector2<f64>, u: &Self::Input) -> Vector2<f64> {
        self.0.forces(t, q, v, u)
    }
    fn dynamics(
        &self,
        t: f64,
        q: &Vector2<f64>,
        v: &Vector2<f64>,
        u: &Self::Input,
    ) -> (SMatrix<f64, 2, 2>, Vector2<f64>) {
        self.0.dynamics(t, q, v, u)
    }
    fn gaps(&self, q: &Vector2<f64>) -> Vector2<f64> {
        self.0.gaps(q)
    }
    fn gap_jacobian(&self, q: &Vector2<f64>) -> SMatrix<f64, 2, 2> {
        self.0.gap_jacobian(q)
    }
    fn contact(&self, q: &Vector2<f64>) -> (Vector2<f64>, SMatrix<f64, 2, 2>) {
        self.0.contact(q)
    }
    fn restitution(&self) -> Vector2<f64> {
        self.0.restitution()
    }
    fn parameter(&self, index: usize) -> Option<f64> {
        self.0.parameter(index)
    }
    fn parameter_mut(&mut self, index: usize) -> Option<&mut f64> {
        self.0.parameter_mut(index)
    }
}

#[test]
fn memos_give_the_bits_of_a_recomputation() {
    const { assert!(Parabola::<f64>::STRUCTURE.mass_constant) };
    const { assert!(!Plain::STRUCTURE.mass_constant) };
    let (mut proved, mut plain) = (Parabola::<f64>::default(), Plain::default());
    let m = Parabola::<f64>::parameter_index("m").unwrap();
    let stepper = MoreauJean::new(StepParams::new(1e-3)).unwrap();
    let (q0, v0) = Parabola::<f64>::initial_state();
    let mut state = State::new(0.0, q0, v0);
    let params = ObserverParams::new(10.0, 50.0);
    let gains = FullOrderGains::scalar(10.0, 10.0);
    let mut reduced = [ReducedOrder::<f64, 2, 2>::new(params, 0.0, q0, v0 * 0.9).unwrap(); 2];
    let mut full = [FullOrder::<f64, 2, 2>::new(params, gains, 0.0, q0, v0 * 0.9).unwrap(); 2];
    let u = SVector::zeros();
    let mut impacts = 0;
    for k in 0..3000 {
        if k == 1500 {
            // the observers' model changes at run time (the plant's does not)
            *proved.parameter_mut(m).unwrap() = 1.5;
            *plain.parameter_mut(m).unwrap() = 1.5;
        }
        stepper
            .step(&Parabola::<f64>::default(), &mut state, &u)
            .unwrap();
        let a = reduced[0].update(&proved, state.t, &state.q, &u).unwrap();
        let b = reduced[1].update(&plain, state.t, &state.q, &u).unwrap();
        impacts += reduced[0].report().impacts;
        assert_eq!(
            a.v.map(f64::to_bits),
            b.v.map(f64::to_bits),
            "reduced, step {k}"
        );
        let a = full[0].update(&proved, state.t, &state.q, &u).unwrap();
        let b = full[1].update(&plain, state.t, &state.q, &u).unwrap();
        assert_eq!(
            a.q.map(f64::to_bits),
            b.q.map(f64::to_bits),
            "full, step {k}"
        );
        assert_eq!(
            a.v.map(f64::to_bits),
            b.v.map(f64::to_bits),
            "full, step {k}"
        );
    }
    assert!(impacts > 0);
}
