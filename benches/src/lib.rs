//! CasADi's generated C for the shipped models and the N-link chains,
//! callable from the benchmarks: the anchor that moreau's generated Rust is
//! measured against.
//!
//! Each `<model>_eval(t, q, v, u, p) -> (M, C, G, F, h, J)` was written by
//! `tests/casadi_reference.py` (CasADi SX with `cse = True`) and is compiled
//! by `build.rs` at `-O3` for the same target CPU as the Rust. Outputs are
//! dense and column-major, as nalgebra stores matrices.
//!
//! Two ways to call one: [`CasadiFn`] directly, as a C user does (argument
//! and result pointer arrays set up once, one call per evaluation), and
//! [`CasadiModel::eval`], a safe wrapper that builds the pointer arrays and
//! checks the status on every call (the way a Rust user might wrap it; it
//! costs a few nanoseconds a C user does not pay).

use std::os::raw::c_int;

use nalgebra::{SMatrix, SVector};

/// The signature of a CasADi-generated function:
/// `int f(const double** arg, double** res, casadi_int* iw, double* w, int mem)`.
pub type CasadiFn = unsafe extern "C" fn(
    arg: *const *const f64,
    res: *const *mut f64,
    iw: *mut i64,
    w: *mut f64,
    mem: c_int,
) -> c_int;

macro_rules! casadi_functions {
    ($($name:ident),* $(,)?) => {
        unsafe extern "C" {
            $(fn $name(
                a: *const *const f64,
                r: *const *mut f64,
                iw: *mut i64,
                w: *mut f64,
                m: c_int,
            ) -> c_int;)*
        }
    };
}

casadi_functions!(
    parabola_eval,
    three_balls_eval,
    billiard_eval,
    double_pendulum_eval,
    arm3_eval,
    chain02_eval,
    chain03_eval,
    chain04_eval,
    chain05_eval,
    chain06_eval,
    chain07_eval,
    chain08_eval,
    chain09_eval,
    chain10_eval,
    chain11_eval,
    chain12_eval,
);

/// A CasADi-generated evaluation of one model, with its output buffers.
pub struct CasadiModel<const N: usize, const K: usize> {
    /// The generated C function, to be called directly.
    pub function: CasadiFn,
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
    fn new(function: CasadiFn) -> Self {
        Self {
            function,
            mass: SMatrix::zeros(),
            coriolis: SMatrix::zeros(),
            gravity: SVector::zeros(),
            forces: SVector::zeros(),
            gaps: SVector::zeros(),
            jacobian: SMatrix::zeros(),
        }
    }

    /// The six result pointers into the output buffers, in CasADi's order,
    /// for calling [`function`](Self::function) directly. They stay valid
    /// while `self` is neither moved nor dropped.
    pub fn results(&mut self) -> [*mut f64; 6] {
        [
            self.mass.as_mut_ptr(),
            self.coriolis.as_mut_ptr(),
            self.gravity.as_mut_ptr(),
            self.forces.as_mut_ptr(),
            self.gaps.as_mut_ptr(),
            self.jacobian.as_mut_ptr(),
        ]
    }

    /// Evaluates every output at `(t, q, v, u)` with parameters `p` (in the
    /// model file's order) into the buffers, through a safe wrapper that
    /// builds the pointer arrays and checks the status on every call.
    ///
    /// # Panics
    ///
    /// If CasADi reports an error (it never does for these functions), or
    /// if `u` or `p` is shorter than the model's inputs or parameters.
    pub fn eval(&mut self, t: f64, q: &SVector<f64, N>, v: &SVector<f64, N>, u: &[f64], p: &[f64]) {
        let args = [
            &t as *const f64,
            q.as_ptr(),
            v.as_ptr(),
            u.as_ptr(),
            p.as_ptr(),
        ];
        let res = self.results();
        // SAFETY: the functions read N, N, NU and NP values from the
        // argument pointers and write dense outputs of the sizes above (their
        // work sizes are 0), which is what the model's CasADi function was
        // built with in tests/casadi_reference.py.
        let status = unsafe {
            (self.function)(
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

macro_rules! constructors {
    ($($(#[$doc:meta])* $name:ident: $f:ident, $n:literal, $k:literal;)*) => {
        $($(#[$doc])* pub fn $name() -> CasadiModel<$n, $k> {
            CasadiModel::new($f)
        })*
    };
}

constructors! {
    /// Example 1.
    parabola: parabola_eval, 2, 2;
    /// Three balls between two walls.
    three_balls: three_balls_eval, 3, 4;
    /// The nonconvex billiard.
    billiard: billiard_eval, 2, 4;
    /// The double pendulum.
    double_pendulum: double_pendulum_eval, 2, 2;
    /// The three-link arm.
    arm3: arm3_eval, 3, 1;
    /// The 2-link chain.
    chain02: chain02_eval, 2, 2;
    /// The 3-link chain.
    chain03: chain03_eval, 3, 3;
    /// The 4-link chain.
    chain04: chain04_eval, 4, 4;
    /// The 5-link chain.
    chain05: chain05_eval, 5, 5;
    /// The 6-link chain.
    chain06: chain06_eval, 6, 6;
    /// The 7-link chain.
    chain07: chain07_eval, 7, 7;
    /// The 8-link chain.
    chain08: chain08_eval, 8, 8;
    /// The 9-link chain.
    chain09: chain09_eval, 9, 9;
    /// The 10-link chain.
    chain10: chain10_eval, 10, 10;
    /// The 11-link chain.
    chain11: chain11_eval, 11, 11;
    /// The 12-link chain.
    chain12: chain12_eval, 12, 12;
}

/// Pinocchio's C++ (CRBA and nonlinear effects) through `pinocchio/shim.cpp`,
/// built by `build.rs` when the `pin` wheel is found.
#[cfg(pinocchio)]
pub mod pinocchio {
    use std::ffi::{CString, c_char, c_int, c_void};

    unsafe extern "C" {
        fn moreau_pin_load(path: *const c_char) -> *mut c_void;
        fn moreau_pin_nv(robot: *const c_void) -> c_int;
        fn moreau_pin_crba_nle(
            robot: *mut c_void,
            q: *const f64,
            v: *const f64,
            mass: *mut f64,
            nle: *mut f64,
        );
        fn moreau_pin_free(robot: *mut c_void);
    }

    /// A Pinocchio model and its data, loaded from the archive that
    /// `build.rs` saved as `OUT_DIR/<name>.txt`.
    pub struct Robot {
        handle: *mut c_void,
        nv: usize,
        joints: Vec<String>,
    }

    impl Robot {
        /// The robot saved as `name` (`ur5`, `panda`, `serial_12`, `go1`),
        /// with its joints' names (`OUT_DIR/<name>.joints`).
        ///
        /// # Panics
        /// If the archive or the names are missing or cannot be loaded.
        #[must_use]
        pub fn load(name: &str) -> Robot {
            let path = format!("{}/{name}.txt", env!("OUT_DIR"));
            let c = CString::new(path.clone()).expect("no NUL in the path");
            // SAFETY: a NUL-terminated path; the shim returns null on failure.
            let handle = unsafe { moreau_pin_load(c.as_ptr()) };
            assert!(!handle.is_null(), "Pinocchio cannot load {path}");
            // SAFETY: a live handle.
            let nv = usize::try_from(unsafe { moreau_pin_nv(handle) }).expect("nv ≥ 0");
            let names = format!("{}/{name}.joints", env!("OUT_DIR"));
            let joints: Vec<String> = std::fs::read_to_string(&names)
                .unwrap_or_else(|e| panic!("cannot read {names}: {e}"))
                .lines()
                .map(str::to_string)
                .collect();
            assert_eq!(joints.len(), nv, "{names}: one joint per coordinate");
            Robot { handle, nv, joints }
        }

        /// The joints' names, in the order of Pinocchio's coordinates.
        #[must_use]
        pub fn joints(&self) -> &[String] {
            &self.joints
        }

        /// The number of coordinates.
        #[must_use]
        pub fn nv(&self) -> usize {
            self.nv
        }

        /// `M(q)` (column-major, both triangles) into `mass` and
        /// `C(q, v) v + G(q)` into `nle`: `pinocchio::crba` then
        /// `pinocchio::nonLinearEffects`.
        ///
        /// # Panics
        /// If a slice does not have the robot's size.
        pub fn crba_nle(&mut self, q: &[f64], v: &[f64], mass: &mut [f64], nle: &mut [f64]) {
            let n = self.nv;
            assert!(q.len() == n && v.len() == n && mass.len() == n * n && nle.len() == n);
            // SAFETY: a live handle and buffers of the sizes checked above.
            unsafe {
                moreau_pin_crba_nle(
                    self.handle,
                    q.as_ptr(),
                    v.as_ptr(),
                    mass.as_mut_ptr(),
                    nle.as_mut_ptr(),
                );
            }
        }
    }

    impl Drop for Robot {
        fn drop(&mut self) {
            // SAFETY: the handle was made by moreau_pin_load and is freed once.
            unsafe { moreau_pin_free(self.handle) }
        }
    }
}
