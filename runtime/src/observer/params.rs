//! The knobs of an observer.

use nalgebra::RealField;

/// How one sampling interval `[t_k, t_{k+1}]` is discretised (see the
/// module docs of `runtime/src/observer/mod.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Discretization {
    /// Section VII of the paper as printed: one semi-explicit Euler step of
    /// the observer state `z` with `M` and `F̄` at the new measurement
    /// `q_{k+1}`, then the LCP (41) at `q_{k+1}` on the constraints whose
    /// sampled gap `h_i(q_k)` or `h_i(q_{k+1})` is closed. Kept as the
    /// baseline: it misses every impact that falls between two samples
    /// whose gaps are both open.
    SectionVii,
    /// Impacts located inside the sampling interval: the free motion from
    /// the measured `q_k` with `v̂_k` (fourth-order Runge–Kutta on the
    /// model), the first root of each gap along it, Newton's law at the
    /// predicted impact configuration, and on to the end of the interval;
    /// persistent contacts by their acceleration-level complementarity
    /// problem; then the output injection `l_d (q_{k+1} − predicted end
    /// position)`.
    #[default]
    ImpactAware,
}

/// Settings of the observers ([`ReducedOrder`](super::ReducedOrder),
/// [`FullOrder`](super::FullOrder)).
///
/// One `Copy` struct of knobs, each with its default and what moving it
/// does. [`ObserverParams::new`] takes the two the paper's design needs,
/// the gain `l_d` and the velocity bound `C_v`; [`ModelBounds`](super::ModelBounds)
/// computes an `l_d` from `C_v` and a decay rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverParams<T> {
    /// The output-injection gain `l_d > 0` of (36) and (38) (no default;
    /// [`ObserverParams::new`] takes it). The velocity error decays like
    /// `e^{−l_d t}` when the model is exact and `F` does not depend on `v`;
    /// a larger `l_d` converges faster and passes more measurement noise
    /// (the error settles near `l_d σ`).
    pub l_d: T,
    /// The velocity bound `C_v > 0` of Assumption 1 (no default;
    /// [`ObserverParams::new`] takes it): the observer evaluates the forces
    /// at the saturated estimate, `F̄(t, q, v̂) = F(t, q, sat(v̂))`,
    /// `sat(v) = v min(1, C_v/|v|)`. Take it at least the largest speed the
    /// system reaches, or the model is wrong where the estimate is right.
    pub velocity_bound: T,
    /// Standard deviation `σ ≥ 0` of the measurement noise on each
    /// coordinate of `q` (default `0`). It widens the contact band and the
    /// resting-speed threshold so that noise neither opens a closed
    /// contact nor triggers an impact (see the
    /// contact rule in the module docs of `runtime/src/observer/mod.rs`).
    pub noise: T,
    /// How many standard deviations of noise the contact band and the
    /// resting-speed threshold allow (default `3`: a resting contact is
    /// read as open by noise in 0.13 % of samples per constraint).
    pub noise_sigmas: T,
    /// Distance in `q` (default `0`) within which a gap counts as closed on
    /// top of the noise band: constraint `i` is in contact at `q` when
    /// `h_i(q) ≤ |∇h_i(q)| (contact_distance + noise_sigmas · noise)`.
    pub contact_distance: T,
    /// Resting-speed factor `ρ ≥ 0` (default `0.1`). A closed constraint
    /// approached slower than its resting speed, `ρ τ A_i` plus the noise
    /// terms of the contact rule (`A_i` the normal acceleration of the
    /// free motion relative to the constraint, curvature included: the
    /// normal speed it builds in a tenth of the sampling interval `τ`), is
    /// met with a plastic impact, `ê = 0`, and is then a persistent
    /// contact. Bounces whose flight would be shorter than about `2ρê τ`
    /// end an accumulation of impacts instead of being followed one by
    /// one; a larger `ρ` ends it earlier.
    pub rest_factor: T,
    /// Largest number of impacts located in one sampling interval (default
    /// `16`); past it, the interval ends without looking for further
    /// crossings, closed constraints met approaching get plastic impacts,
    /// and one still approaching at the end meets Newton's law there. `0`
    /// turns the search inside the interval off (impacts are then met only
    /// where a sampled gap is closed: a diagnostic, not a scheme).
    pub max_impacts: u32,
    /// The longest piece of the predicted motion that one Runge–Kutta step
    /// covers, in the time unit of the samples (default `2e-3`: 2 ms;
    /// `+∞` takes each piece between two events in one step). A piece
    /// longer than one and a half times it is integrated in equal steps
    /// of at most it, and the impacts are searched for along each step;
    /// where the acceleration is constant (free flight with constant
    /// `M` and `F`) one step is exact and no piece is split. So samples
    /// at 1 kHz and faster take one step per piece, and samples at 100 Hz
    /// take five: on the three-link arm at 100 Hz with `σ = 1e-6` one step
    /// over the 10 ms interval left the filter a prediction error that
    /// its innovation gate refused on 34 of 600 samples, and five leave
    /// none (`the_filter_takes_samples_at_any_rate_on_every_shipped_model`
    /// in `tests/kalman.rs`). Each step costs one more evaluation of the
    /// dynamics per Runge–Kutta stage, so an update's cost grows with the
    /// interval over it: a gap of `max_interval` is that many steps.
    pub max_step: T,
    /// The discretization (default [`Discretization::ImpactAware`]).
    pub scheme: Discretization,
    /// Outlier factor `κ ≥ 1` (default `2`; `+∞` accepts every sample): a
    /// measurement farther from the last accepted one than
    /// [`outlier_bound`](Self::outlier_bound)`(τ) = κ (C_v τ + 2 √N n_σ σ)`,
    /// more than a system slower than `C_v` moves in `τ` plus twice the
    /// noise band, is not a position of the system: the update is refused
    /// with [`ObserverError::Outlier`](super::ObserverError::Outlier) and
    /// the estimate kept (see "Bad samples, bad states, long gaps" in the
    /// module docs of `runtime/src/observer/mod.rs`).
    pub outlier_factor: T,
    /// Consecutive outliers refused before the next one restarts the
    /// estimate from the measurement instead (default `3`): samples that
    /// keep disagreeing with the estimate say that the estimate, not the
    /// samples, is wrong.
    pub max_outliers: u32,
    /// Longest sampling interval integrated (default `3 / l_d`, three time
    /// constants of the injection; `+∞` integrates every interval): over a
    /// longer gap the prediction is an extrapolation, and the update
    /// restarts instead from the measurement with the mean velocity over
    /// the gap, held to `C_v`, and says so in its report
    /// ([`UpdateReport::restart`](super::UpdateReport::restart)).
    pub max_interval: T,
}

impl<T: RealField + Copy> ObserverParams<T> {
    /// Gain `l_d`, velocity bound `C_v`, and the defaults: no noise, the
    /// impact-aware discretization.
    #[must_use]
    pub fn new(l_d: T, velocity_bound: T) -> Self {
        Self {
            l_d,
            velocity_bound,
            noise: T::zero(),
            noise_sigmas: nalgebra::convert(3.0),
            contact_distance: T::zero(),
            rest_factor: nalgebra::convert(0.1),
            max_impacts: 16,
            max_step: nalgebra::convert(2e-3),
            scheme: Discretization::ImpactAware,
            outlier_factor: nalgebra::convert(2.0),
            max_outliers: 3,
            max_interval: nalgebra::convert::<f64, T>(3.0) / l_d,
        }
    }

    /// The same settings with the measurement noise `σ`.
    #[must_use]
    pub fn with_noise(self, noise: T) -> Self {
        Self { noise, ..self }
    }

    /// The same settings with another discretization.
    #[must_use]
    pub fn with_scheme(self, scheme: Discretization) -> Self {
        Self { scheme, ..self }
    }

    /// The same settings with the injection gain `l_d` (see
    /// [`l_d`](Self::l_d); `max_interval` is left as it was).
    #[must_use]
    pub fn with_l_d(self, l_d: T) -> Self {
        Self { l_d, ..self }
    }

    /// The same settings with the velocity bound `C_v` (see
    /// [`velocity_bound`](Self::velocity_bound)).
    #[must_use]
    pub fn with_velocity_bound(self, velocity_bound: T) -> Self {
        Self {
            velocity_bound,
            ..self
        }
    }

    /// The same settings with `n_σ` (see [`noise_sigmas`](Self::noise_sigmas)).
    #[must_use]
    pub fn with_noise_sigmas(self, noise_sigmas: T) -> Self {
        Self {
            noise_sigmas,
            ..self
        }
    }

    /// The same settings with this contact distance (see
    /// [`contact_distance`](Self::contact_distance)).
    #[must_use]
    pub fn with_contact_distance(self, contact_distance: T) -> Self {
        Self {
            contact_distance,
            ..self
        }
    }

    /// The same settings with this resting-speed factor (see
    /// [`rest_factor`](Self::rest_factor)).
    #[must_use]
    pub fn with_rest_factor(self, rest_factor: T) -> Self {
        Self {
            rest_factor,
            ..self
        }
    }

    /// The same settings with at most this many impacts per interval (see
    /// [`max_impacts`](Self::max_impacts)).
    #[must_use]
    pub fn with_max_impacts(self, max_impacts: u32) -> Self {
        Self {
            max_impacts,
            ..self
        }
    }

    /// The same settings with this outlier factor (see
    /// [`outlier_factor`](Self::outlier_factor)).
    #[must_use]
    pub fn with_outlier_factor(self, outlier_factor: T) -> Self {
        Self {
            outlier_factor,
            ..self
        }
    }

    /// The same settings with this many outliers in a row before a restart
    /// (see [`max_outliers`](Self::max_outliers)).
    #[must_use]
    pub fn with_max_outliers(self, max_outliers: u32) -> Self {
        Self {
            max_outliers,
            ..self
        }
    }

    /// The same settings with the longest interval integrated (see
    /// [`max_interval`](Self::max_interval)).
    #[must_use]
    pub fn with_max_interval(self, max_interval: T) -> Self {
        Self {
            max_interval,
            ..self
        }
    }

    /// The largest distance `κ (C_v τ + 2 √N n_σ σ)` between two samples
    /// `τ` apart that is not an outlier (see
    /// [`outlier_factor`](Self::outlier_factor)).
    pub fn outlier_bound(&self, tau: T, n: usize) -> T {
        let two: T = nalgebra::convert(2.0);
        let root_n = nalgebra::convert::<f64, T>(n as f64).sqrt();
        self.outlier_factor
            * (self.velocity_bound * tau + two * root_n * self.noise_sigmas * self.noise)
    }

    /// The distance band of the contact rule, `contact_distance +
    /// noise_sigmas · noise`, in units of `q`.
    pub fn contact_band(&self) -> T {
        self.contact_distance + self.noise_sigmas * self.noise
    }

    /// Checks every setting: `l_d > 0`, `C_v > 0`, `σ, n_σ, d, ρ ≥ 0`, all
    /// finite; `κ ≥ 1` and `max_interval > 0` (either may be `+∞`).
    pub(crate) fn check(&self) -> Result<(), super::ObserverError<T>> {
        let zero = T::zero();
        let bad = |name, value| Err(super::invalid(name, value));
        let positive = [("l_d", self.l_d), ("velocity_bound", self.velocity_bound)];
        for (name, value) in positive {
            if !(value > zero && value.is_finite()) {
                return bad(name, value);
            }
        }
        let non_negative = [
            ("noise", self.noise),
            ("noise_sigmas", self.noise_sigmas),
            ("contact_distance", self.contact_distance),
            ("rest_factor", self.rest_factor),
        ];
        for (name, value) in non_negative {
            if !(value >= zero && value.is_finite()) {
                return bad(name, value);
            }
        }
        // +∞ allowed: it turns the test off
        let (k, m) = (self.outlier_factor, self.max_interval);
        #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN fails too
        if !(k >= T::one()) {
            return bad("outlier_factor", k);
        }
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(m > zero) {
            return bad("max_interval", m);
        }
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(self.max_step > zero) {
            return bad("max_step", self.max_step);
        }
        Ok(())
    }
}
