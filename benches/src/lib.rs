//! CasADi's generated C for the shipped models, callable from the
//! benchmarks: the anchor that moreau's generated Rust is measured against.
//!
//! Each `<model>_eval(t, q, v, u, p) -> (M, C, G, F, h, J)` was written by
//! `tests/casadi_reference.py` (CasADi SX with `cse = True`) and is compiled
//! by `build.rs` at `-O3`. Outputs are dense and column-major, as nalgebra
//! stores matrices, so they are written straight into `SMatrix` buffers.

use std::os::raw::c_int;

use nalgebra::{SMatrix, SVector};

/// The signature of a CasADi-generated function.
type Eval = unsafe extern "C" fn(
    arg: *const *const f64,
    res: *const *mut f64,
    iw: *mut i64,
    w: *mut f64,
    mem: c_int,
) -> c_int;

unsafe extern "C" {
    fn parabola_eval(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn three_balls_eval(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn billiard_eval(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn double_pendulum_eval(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn arm3_eval(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
}

/// A CasADi-generated evaluation of one model, with its output buffers.
pub struct CasadiModel<const N: usize, const K: usize> {
    eval: Eval,
    /// `M(q)`.
    pub mass: SMatrix<f64, N, N>,
    /// `C(q, v)`.
    pub coriolis: SMatrix<f64, N, N>,
    /// `G(q)`.
    pub gravity: SVector<f64, N>,
    /// `F(t, q, v, u)`.
    pub forces: SVector<f64, N>,
    /// `h(q)`.
    pub gaps: SVector<f64, K>,
    /// `J(q)`.
    pub jacobian: SMatrix<f64, K, N>,
}

impl<const N: usize, const K: usize> CasadiModel<N, K> {
    fn new(eval: Eval) -> Self {
        Self {
            eval,
            mass: SMatrix::zeros(),
            coriolis: SMatrix::zeros(),
            gravity: SVector::zeros(),
            forces: SVector::zeros(),
            gaps: SVector::zeros(),
            jacobian: SMatrix::zeros(),
        }
    }

    /// Evaluates every output at `(t, q, v, u)` with parameters `p` (in the
    /// model file's order) into the buffers.
    ///
    /// # Panics
    ///
    /// If CasADi reports an error (it never does for these functions).
    pub fn eval(&mut self, t: f64, q: &SVector<f64, N>, v: &SVector<f64, N>, u: &[f64], p: &[f64]) {
        let args = [
            &t as *const f64,
            q.as_ptr(),
            v.as_ptr(),
            u.as_ptr(),
            p.as_ptr(),
        ];
        let res = [
            self.mass.as_mut_ptr(),
            self.coriolis.as_mut_ptr(),
            self.gravity.as_mut_ptr(),
            self.forces.as_mut_ptr(),
            self.gaps.as_mut_ptr(),
            self.jacobian.as_mut_ptr(),
        ];
        // SAFETY: the functions read N, N, NU and NP values from the
        // argument pointers and write dense outputs of the sizes above (their
        // work sizes are 0), which is what the model's CasADi function was
        // built with in tests/casadi_reference.py.
        let status = unsafe {
            (self.eval)(
                args.as_ptr(),
                res.as_ptr(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                0,
            )
        };
        assert_eq!(status, 0, "CasADi evaluation failed");
    }
}

/// Example 1.
pub fn parabola() -> CasadiModel<2, 2> {
    CasadiModel::new(parabola_eval)
}

/// Three balls between two walls.
pub fn three_balls() -> CasadiModel<3, 4> {
    CasadiModel::new(three_balls_eval)
}

/// The nonconvex billiard.
pub fn billiard() -> CasadiModel<2, 4> {
    CasadiModel::new(billiard_eval)
}

/// The double pendulum.
pub fn double_pendulum() -> CasadiModel<2, 2> {
    CasadiModel::new(double_pendulum_eval)
}

/// The three-link arm.
pub fn arm3() -> CasadiModel<3, 1> {
    CasadiModel::new(arm3_eval)
}
