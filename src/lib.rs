//! # moreau
//!
//! Compile a declarative mechanical model into fixed-size Rust, then run
//! Moreau–Jean simulators and passivity-based velocity observers on it, for
//! machines that hit things: robots touching walls, balls bouncing in
//! containers, stacks of colliding bodies.
//!
//! The theory is Tanwani, Brogliato and Prieur, *Observer design for
//! unilaterally constrained Lagrangian systems: a passivity-based approach*
//! (IEEE TAC 2016); equation numbers in these docs are the paper's.
//!
//! A model is a Lagrangian with frictionless unilateral constraints, written
//! in YAML (`models/*.yaml`) or inline:
//!
//! ```
//! moreau::model! {
//!     /// The paper's Example 1: a unit mass under gravity in a parabola.
//!     pub struct Parabola;
//!     coordinates { x: vx, y: vy }
//!     parameters { m: 1.0, g: 9.81, c: 8.0 }
//!     kinetic = 0.5 * m * (vx^2 + vy^2);
//!     potential = m * g * y;
//!     constraints {
//!         floor: y - x^2 >= 0,
//!         ceiling: y <= c,
//!     }
//!     restitution = 0.9;
//! }
//!
//! use moreau::Model;
//! use nalgebra::{SVector, Vector2};
//!
//! let model = Parabola::<f64>::default();
//! let q = Vector2::new(1.0, 2.0);
//! let terms = model.eval(0.0, &q, &Vector2::new(0.5, 0.0), &SVector::zeros());
//! assert_eq!(terms.gaps, Vector2::new(2.0 - 1.0, 8.0 - 2.0));
//! assert_eq!(terms.jacobian.row(0)[0], -2.0); // ∂h1/∂x = -2x
//! assert_eq!(terms.forces, Vector2::new(0.0, 9.81));
//! ```
//!
//! A robot is a URDF named beside its contacts and restitution
//! (`urdf = "path/to/robot.urdf";`): see [`model!`].
//!
//! An observer estimates the velocity from measured positions alone, through
//! the impacts (the paper's reduced-order observer (38), with a gain chosen
//! for a guaranteed decay rate by Corollary 3):
//!
//! ```
//! use moreau::{Design, GainRegion, ModelBounds, Observer, ObserverParams, ReducedOrder};
//! use moreau_models::Parabola;
//! use nalgebra::{SVector, Vector2};
//! # use moreau::{MoreauJean, State, StepParams};
//! # let plant = MoreauJean::new(StepParams::new(1e-5))?;
//! # let (q0, v0) = Parabola::<f64>::initial_state();
//! # let mut state = State::new(0.0, q0, v0);
//! # let samples: Vec<(f64, Vector2<f64>)> = (1..=2000).map(|k| {
//! #     for _ in 0..100 { plant.step(&Parabola::<f64>::default(), &mut state, &SVector::zeros()).unwrap(); }
//! #     (k as f64 * 1e-3, state.q)
//! # }).collect();
//!
//! let model = Parabola::<f64>::default();
//! let region = GainRegion::new(Vector2::new(-3.0, 0.0), Vector2::new(3.0, 8.0), 20.0);
//! let bounds = ModelBounds::estimate(&model, &region, &SVector::zeros())?;
//! let beta = 10.0; // Corollary 3's margin β (kg/s), not a rate
//! let l_d = bounds.gain_for_margin(Design::ReducedOrder, beta); // the gain l_d (1/s)
//! let rate = bounds.decay_rate(l_d); // the guaranteed decay rate of |v − v̂| (1/s)
//! // Example 1's force bounds vanish and its mass is 1 kg: both are 10 here
//! assert!((l_d - 10.0).abs() < 1e-9 && (rate - 10.0).abs() < 1e-9);
//! let params = ObserverParams::new(l_d, 20.0); // gain l_d, velocity bound C_v
//! let mut observer = ReducedOrder::new(params, 0.0, q0, Vector2::zeros())?;
//! for (t, q) in &samples {
//!     let estimate = observer.update(&model, *t, q, &SVector::zeros())?;
//!     // estimate.v: the velocity, after every impact of the interval
//! #   let _ = estimate;
//! }
//! # assert!((observer.estimate().v - state.v).norm() < 1e-3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

/// Compiles a mechanical model into a type implementing [`Model`],
/// [`Sensitivities`] and [`Enclosure`]: from a YAML file
/// (`model!(file = "models/parabola.yaml")`, the path relative to the
/// crate's directory) or written inline (`model! { pub struct Name; ... }`,
/// see the [crate] documentation). The language is described in
/// `models/README.md`.
///
/// A robot is a URDF named beside its contacts, in YAML (`urdf:`, `locked:`,
/// `limits:`) or inline, in a few lines:
///
/// ```
/// moreau::model! {
///     /// A UR5 whose tool may strike a table 20 cm below its base.
///     pub struct Ur5;
///     urdf = "tests/robots/urdf/ur_description/ur5_robot.urdf";
///     constraints { table: position_z(tool0, 0, 0, 0.05) >= -0.2 }
///     restitution = 0.3;
/// }
///
/// use moreau::Model;
/// use nalgebra::SVector;
///
/// // the coordinates are the URDF's moving joints, the velocities `d<joint>`
/// assert_eq!(Ur5::<f64>::INFO.coordinates[0], "shoulder_pan_joint");
/// assert_eq!(Ur5::<f64>::INFO.velocities[5], "dwrist_3_joint");
/// let model = Ur5::<f64>::new();
/// let q = SVector::<f64, 6>::zeros();
/// // At q = 0 the arm lies along x: the flange's height is the shoulder's
/// // 0.089159 m less the wrist's 0.09465 m (the point 5 cm out along the
/// // tool's z is horizontal), and panning about the vertical axis does not
/// // move it up or down.
/// let h = model.gaps(&q)[0];
/// assert!((h - (0.089159 - 0.09465 + 0.2)).abs() < 1e-9);
/// assert!(model.gap_jacobian(&q)[(0, 0)].abs() < 1e-12);
/// ```
///
/// Beside `urdf = "path";` (relative to the crate's directory; editing the
/// URDF rebuilds the model), `locked { joint, ... }` holds joints at zero and
/// `limits { joint, ... }` turns their `<limit>`s into constraints, as the
/// YAML keys do; any other item (parameters, `applied` forces such as joint
/// damping, more constraints, `initial`) is written as in any inline model.
pub use moreau_macro::model;
pub use moreau_runtime::*;

/// Items the code generated by [`model!`] refers to by absolute path. Not a
/// public API: it may change in any release.
#[doc(hidden)]
pub mod __private {
    pub use moreau_runtime::{
        Enclose, Enclosure, Linearization, Model, ModelInfo, Sensitivities, Structure, Terms,
    };
    pub use nalgebra::{ArrayStorage, RealField, SMatrix, SVector};

    /// Converts a literal of the model to the scalar type; exact for `f64`,
    /// rounded once for `f32`.
    #[inline(always)]
    pub fn cst<T: RealField + Copy>(x: f64) -> T {
        nalgebra::convert(x)
    }

    /// `(sin x, cos x)`, what the generated code asks for when it needs
    /// both. For `f64` and `f32` the `libm` crate's `sincos` (musl's), one
    /// argument reduction for both: Rust's `f64::sin_cos` is two calls to
    /// the C library, about 30 % slower on this machine, where a C
    /// compiler fuses `sin` and `cos` of one argument into one call. It
    /// gives the same bits as [`sin`] and [`cos`] (musl's `sincos` shares
    /// their kernels), so a sine is the same whether the generated code
    /// computed it alone or in a pair. Any other scalar uses its own
    /// `sin_cos`; the branch is resolved at compile time.
    #[inline(always)]
    pub fn sin_cos<T: RealField + Copy>(x: T) -> (T, T) {
        let any = &x as &dyn core::any::Any;
        if let Some(&x) = any.downcast_ref::<f64>() {
            let (s, c) = libm::sincos(x);
            return (nalgebra::convert(s), nalgebra::convert(c));
        }
        if let Some(&x) = any.downcast_ref::<f32>() {
            let (s, c) = libm::sincosf(x);
            return (nalgebra::convert(s), nalgebra::convert(c));
        }
        x.sin_cos()
    }

    /// `sin x`: the `libm` crate's for `f64` and `f32` (see [`sin_cos`]),
    /// any other scalar's own.
    #[inline(always)]
    pub fn sin<T: RealField + Copy>(x: T) -> T {
        let any = &x as &dyn core::any::Any;
        if let Some(&x) = any.downcast_ref::<f64>() {
            return nalgebra::convert(libm::sin(x));
        }
        if let Some(&x) = any.downcast_ref::<f32>() {
            return nalgebra::convert(libm::sinf(x));
        }
        x.sin()
    }

    /// `cos x`: the `libm` crate's for `f64` and `f32` (see [`sin_cos`]),
    /// any other scalar's own.
    #[inline(always)]
    pub fn cos<T: RealField + Copy>(x: T) -> T {
        let any = &x as &dyn core::any::Any;
        if let Some(&x) = any.downcast_ref::<f64>() {
            return nalgebra::convert(libm::cos(x));
        }
        if let Some(&x) = any.downcast_ref::<f32>() {
            return nalgebra::convert(libm::cosf(x));
        }
        x.cos()
    }

    /// A parameter's value as an `f64` point of an enclosure (`NaN`, which
    /// encloses nothing, if the scalar has no `f64` value).
    #[inline(always)]
    pub fn point<T: RealField + Copy, I: Enclose>(x: T) -> I {
        I::point(x.to_subset().unwrap_or(f64::NAN))
    }
}
