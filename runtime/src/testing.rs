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
