//! The paper's velocity observers: the estimator class (13)–(15)
//! ([`Observer`]), the reduced-order observer (38) ([`ReducedOrder`]), the
//! full-order observer (36) ([`FullOrder`]) and the gain selection of
//! Corollaries 2 and 3 ([`ModelBounds`]).
//!
//! They are driven by measured positions `q(t_k)` only (plus known inputs
//! and time), sampled at their own, possibly irregular, rate and possibly
//! noisy; never by the velocity. Everything is fixed-size, on the stack;
//! an update allocates nothing and never panics on data.
//!
//! # The estimator class (13)–(15)
//!
//! $$\dot z_1 = F_1(t, q, z),\qquad M(q)\,dz_2 + F_2(t, q, z)\,dt \in -N_{V(q)}(\hat v_e),\qquad \hat q = f_1(z_1, q),\quad \hat v = z_2 + f_2(z_1, q),$$
//!
//! `v̂_e = (v̂⁺ + ê v̂⁻)/(1 + ê)`, `V(q)` the tangent cone (6) at the
//! *measured* `q`. Both observers keep their state in the estimate's
//! coordinates `(q_k, q̂_k, v̂_k)` (the map `z ↦ (q̂, v̂)` is a
//! diffeomorphism for each `q`; their `z()` methods give `z` back):
//!
//! | | `z` | `f₁` | `f₂` | `F₁` | `F₂` |
//! |---|---|---|---|---|---|
//! | (38) reduced | `z₂ = z` | `q` | `l_d q` | — | `F̄(t, q, v̂) + l_d M v̂` |
//! | (36) full | `(z₁, z₂)` | `z₁` | `l_d (q − z₁)` | `z₂ + L_d (q − z₁)` | `F̄(t, q, v̂) − (L_ρ1 + M L_ρ2)(q − z₁)` |
//!
//! # The reduced-order observer (38), with the sign its proof needs
//!
//! As printed, `v̂ = z − l_d q` and `M dz + F̄ dt − l_d M v̂ dt ∈ −N`. Since
//! `dq = v dt`, `M dv̂ = M dz − l_d M v dt = −F̄ dt + l_d M v̂ dt − l_d M v dt − η̂`,
//! so with `ṽ = v − v̂` and the plant's `M dv = −F dt − η`:
//!
//! $$M\,d\tilde v = -(F - \bar F)\,dt + l_d M \tilde v\,dt - (\eta - \hat\eta):$$
//!
//! the error grows like `e^{l_d t}` (`tests/observer.rs` shows it:
//! `×9.3e12` in 3 s for `l_d = 10`). The proof of Corollary 3 needs
//! `−l_d M ṽ`; the form that gives it, and that [`ReducedOrder`]
//! implements, is
//!
//! $$\hat v = z + l_d q,\qquad M(q)\,dz + \bar F(t, q, \hat v)\,dt + l_d M(q)\,\hat v\,dt \in -N_{V(q)}(\hat v_e).$$
//!
//! Then `M dv̂ = M dz + l_d M v dt = −F̄ dt + l_d M (v − v̂) dt − η̂` and
//!
//! $$M\,d\tilde v = -(F - \bar F)\,dt - l_d M \tilde v\,dt - (\eta - \hat\eta).$$
//!
//! Between impacts, with `W = ṽᵀ M ṽ`, `ṽᵀṀṽ = 2ṽᵀC(q, v)ṽ` (P1),
//! `|F(t,q,v) − F̄(t,q,v̂)| ≤ C_F |ṽ|` (`|v| ≤ C_v`, Assumption 1) and
//! `‖C(q, v)‖ ≤ C_M C_v` (P2),
//! `dW/dt ≤ −2 l_d W + 2 (C_F + C_M C_v)|ṽ|²` and `ṽᵀ(η − η̂) ≥ 0` (the
//! normal cone is monotone); at an impact `W` does not grow (32). Hence
//! `|ṽ|_M ≤ e^{−r t}|ṽ(0)|_M` with `r = l_d − (C_F + C_M C_v)/λ_min`
//! (see [`ModelBounds::decay_rate`]), which condition (39) makes positive.
//!
//! # The full-order observer (36)
//!
//! With `q̃ = q − q̂`, `q̂ = z₁`, `v̂ = z₂ + l_d q̃`, `L_d = l_d I + Λ`,
//! `L_ρ2 = l_d Λ`:
//! `dq̂/dt = z₂ + L_d q̃ = v̂ − l_d q̃ + (l_d I + Λ) q̃ = v̂ + Λ q̃`, so
//! `q̃' = ṽ − Λ q̃`; and
//! `M dv̂ = M dz₂ + l_d M (ṽ − Λ q̃) dt = −F̄ dt + L_ρ1 q̃ dt + l_d M ṽ dt − η̂`:
//!
//! $$\dot{\hat q} = \hat v + \Lambda \tilde q,\qquad M\,d\hat v + \bar F\,dt - L_{\rho 1}\tilde q\,dt - l_d M\,\tilde v\,dt \in -N_{V(q)}(\hat v_e),$$
//!
//! $$\dot{\tilde q} = \tilde v - \Lambda \tilde q,\qquad M\,d\tilde v = -(F - \bar F)\,dt - L_{\rho 1}\tilde q\,dt - l_d M\tilde v\,dt - (\eta - \hat\eta).$$
//!
//! With `W = q̃ᵀ L_ρ1 q̃ + ṽᵀ M ṽ` the cross terms `±2 q̃ᵀ L_ρ1 ṽ` cancel
//! and `dW/dt ≤ −2 q̃ᵀ L_ρ1 Λ q̃ − 2 l_d ṽᵀ M ṽ + 2 (C_F + C_M C_v)|ṽ|²`
//! (Theorem 2, Corollary 2). (36a)–(36d) as printed are consistent. The
//! paper's "one can equally write" line, and `F̂₁` in the proof of
//! Corollary 2, read `q̃' = v̂ − Λ(q − q̂)`, a sign slip: taken as the
//! estimator, `q̂' = v̂ − Λ q̃` gives `q̃' = ṽ + Λ q̃`, and the error system
//! has a positive eigenvalue (`tests/observer.rs` shows `|q̃|` growing like
//! `e^{3.09 t}` for `Λ = 5`, `L_ρ1 = 25`, `l_d = 10`).
//!
//! # The Lipschitz extension `F̄`
//!
//! `F̄(t, q, v) = F(t, q, sat(v))`, `sat(v) = v min(1, C_v/|v|)`: the
//! radial projection onto the ball `|v| ≤ C_v`, 1-Lipschitz, so `F̄` equals
//! `F` on the ball and is globally Lipschitz in `v` with the constant of `F`
//! on the ball ([`ObserverParams::velocity_bound`]).
//!
//! # Impacts of the estimate
//!
//! `V(q(t))` is driven by the measurement: `v̂` jumps when the *measured*
//! `q(t)` reaches the boundary, by Newton's law with the observer's `ê`
//! (Section VI-D; [`ReducedOrder::with_restitution`]) at that
//! configuration `q*`:
//!
//! $$0 \le \lambda \perp J(q^*)\,(\hat v^+ + \hat e\,\hat v^-) \ge 0,\qquad \hat v^+ = \hat v^- + M(q^*)^{-1} J(q^*)^{\mathsf T}\lambda,$$
//!
//! the complementarity form of (9f) and of (41), whose normalisation of the
//! columns by `|M^{−1/2}∇h_α|` only rescales `λ`.
//!
//! # Discretization
//!
//! Over a sampling interval `[t_k, t_{k+1}]`, `τ = t_{k+1} − t_k`, the
//! estimate obeys `dv̂ = −M⁻¹F̄ dt + l_d (v − v̂) dt − M⁻¹ dη̂`: the
//! injection does not involve `M`, and it integrates to
//!
//! $$\int l_d (v - \hat v)\,dt = l_d\Big(q_{k+1} - q_k - \int \hat v\,dt\Big):$$
//!
//! the samples give `∫ v dt` exactly; what an observer needs is the
//! motion that `v̂` predicts between them, impacts included.
//!
//! ## [`ImpactAware`](Discretization::ImpactAware) (the default)
//!
//! 1. **Predict** `(p(s), w(s))`, `s ∈ [0, τ]`, from the measured `q_k` and
//!    `v̂_k` under the model: classical Runge–Kutta of order 4 on
//!    `p' = w`, `M(p) w' = −F̄(t_k + s, p, w)` (a second-order scheme would
//!    leave a position error `τ³ |d³q/dt³|/6` per interval, which the
//!    injection turns into a lag of `τ² |d³q/dt³|/6`: 8e-5 m/s where
//!    Example 1 slides through the bottom of its parabola), one step per
//!    piece between events, and steps of at most
//!    [`ObserverParams::max_step`] (2 ms) in intervals longer than one
//!    and a half times it, unless the acceleration is constant and one
//!    step is exact. Along each
//!    step, the cubic Hermite interpolant of `(p, w)` at its ends locates
//!    the first constraint to close (Brent's method on `h_i(p(s))`, from
//!    the root of the cubic Hermite interpolant of `h_i` itself, to
//!    `max(1024 ε, ε^⅔) τ`); the piece is integrated again up to that root `s*`,
//!    Newton's law is applied at `q* = p(s*)`, and the prediction goes on
//!    from `(q*, v̂⁺)`: several impacts per interval, and accumulations,
//!    follow (up to [`ObserverParams::max_impacts`]). Persistent contacts
//!    are held by their acceleration-level law inside each Runge–Kutta
//!    stage, `0 ≤ λ ⊥ J a + J̇ w ≥ 0`, `a = M⁻¹(−F̄ + Jᵀλ)` (`J̇ w` by a
//!    central difference of `J` along `w`): the contact force cancels the
//!    normal part of the forces and of the curvature, so `w` stays tangent.
//!    (A velocity-level Moreau–Jean step over the interval would project
//!    `w` onto the tangent at the end, losing `½ |v| (κ|v|τ)²` per
//!    interval on a contact of curvature `κ`: a lag of `κ²|v|³τ/(2 l_d)`,
//!    0.35 m/s at Example 1's 12 m/s through curvature 2. Measured with
//!    that step in place of this one, Example 1's figures below become a
//!    median of 1.9e-5, a 90th percentile of 6.6e-3 and a maximum of 0.13.)
//! 2. **Inject** the innovation `d = q_{k+1} − p(τ)`, the measured minus
//!    the predicted displacement. When the forces do not depend on the
//!    error (Example 1 between impacts), the prediction carries `ṽ_k`
//!    unchanged, `d = τ ṽ_k`, and the continuous error decays by `e^{−l_d τ}`
//!    over the interval; so
//!    `v̂_{k+1} = w(τ) + d (1 − e^{−l_d τ})/τ`, exact there, and
//!    `→ w(τ) + l_d d` for small `τ`. For (36) the samples reveal `q̃_k` and
//!    `ṽ_k = d/τ`, and the update applies the flow `exp(τA)` of the linear
//!    error system `q̃' = ṽ − Λq̃`, `ṽ' = −M⁻¹L_ρ1 q̃ − l_d ṽ` (`M` at
//!    `q_{k+1}`) to them: `q̂_{k+1} = q_{k+1} − q̃_{k+1}`,
//!    `v̂_{k+1} = w(τ) + ṽ_k − ṽ_{k+1}`, again exact for constant forces
//!    and mass, so the Lyapunov function of Theorem 2 decays at least at
//!    its continuous rate in every interval.
//! 3. **Close**: Newton's law at the measured `q_{k+1}` for the closed
//!    constraints the injected estimate approaches, so that every update
//!    leaves `v̂_e ∈ V(q_{k+1})`, as (20) asks.
//!
//! Cost, with no constraint near: four evaluations of `(M, F̄)` and
//! `L D Lᵀ` solves, three of `(h, J)` (per step of `max_step`, in longer
//! intervals). An impact adds two Runge–Kutta legs
//! and a root search on `h`; a persistent contact, one small LCP per stage.
//! Where the model's [`Structure`](crate::Structure) allows it, less: a
//! constant `M` is factored once (a memo across updates), and with `F`
//! also free of `t`, `q`, `v`, `u` one evaluation of `F` and one solve
//! serve the four stages.
//!
//! ## [`SectionVii`](Discretization::SectionVii) (the baseline)
//!
//! The scheme as Section VII prints it: `z_{k+1} = z_k − τ M(q_{k+1})⁻¹
//! F₂(t_{k+1}, q_{k+1}, z_k)` (and `z₁` by explicit Euler), `v̂` from `z` at
//! `q_{k+1}`, then the LCP (41) at `q_{k+1}` on the constraints whose gap is
//! closed at `q_k` or `q_{k+1}`, Newton's law with the approach measured as
//! the plant stepper's default does. Two things limit it. It misses every
//! impact between two samples whose gaps are open (with Moreau–Jean plant
//! data, nearly all). And the semi-explicit step evaluates `v̂' = z_k +
//! l_d q_{k+1}`, mixing the old `z` with the new `q`: with `Δq = τ v_k +
//! τ² a/2`, `b = v̂ − v` obeys `b_{k+1} = (1 − l_d τ) b_k − l_d² τ² v_k +
//! O(τ²)`, a lag `b ≈ −l_d τ v + τ a/2` (1 % of the speed for `l_d = 10`,
//! `τ = 1` ms).
//!
//! # The contact rule
//!
//! At each point where the prediction starts or meets a constraint, with
//! `g_i = |∇h_i|` and [`ObserverParams::contact_band`] `b = d + n_σ σ`:
//!
//! - constraint `i` is **closed** when `h_i ≤ g_i b`, or it was just
//!   reached by a root, or it was held as a persistent contact along the
//!   piece that led here (whatever its gap: a held contact keeps the small
//!   normal speed this rule took for rest where no force holds it, and
//!   drifts by it, 8e-9 m in
//!   0.8 ms on exact samples of the billiard, and with `b = 0` the ball
//!   sliding along one wall into another was read as off the first at the
//!   impact, which was then resolved as a sequence of bounces instead of
//!   one law on both: (38) was 0.38 to 0.45 m/s off for 300 samples);
//!   **open** otherwise;
//! - its resting speed is `v_rest = ρ τ A_i + √(4 A_i g_i b) + g_i ν +
//!   64 ε g_i |w|`, with `A_i = |J_i a + J̇_i w|` the normal acceleration of
//!   the free motion relative to the constraint and `ν = n_σ √2 σ (1 −
//!   e^{−l_d τ})/τ` the velocity noise of the estimate: the normal speed
//!   the forces build in `ρτ`, what a fall through twice the band builds
//!   (so a sample that noise puts outside the band and that falls back in
//!   is no impact), the estimate's noise, round-off;
//! - a closed constraint met **approaching** (`J_i w < 0`) gets Newton's
//!   law now, with `ê_i` if faster than `v_rest`, plastically (`e = 0`)
//!   otherwise, together with every other closed constraint; one
//!   approaching faster than `v_rest` while its gap is still positive is
//!   treated as open instead, so that its root along the prediction times
//!   the impact (the band only says it is near);
//! - a closed constraint with `|J_i w| ≤ v_rest` is a **persistent
//!   contact** (sliding, resting), held at acceleration level, and each
//!   piece of it starts with the separating normal speed of the held
//!   constraints that push taken out in the metric of `M`
//!   (`Interval::settled` in `runtime/src/observer/interval.rs`): a
//!   force on a body that leaves the constraint would do work, on the
//!   estimate's energy and on the error's, which the passivity argument
//!   of (36) and (38) does not allow; it is
//!   **resting** unless grazed (below) or accelerated off its constraint
//!   within the interval faster than the estimate's noise (`α_i τ ≤ g_i
//!   ν`, `α_i` its free normal acceleration, positive away): the filter
//!   keeps a resting contact on its manifold even where no force holds
//!   it there (glued bodies in free flight), as it keeps one that a force
//!   holds (module docs of `runtime/src/observer/kalman/mod.rs`);
//! - a closed constraint separating faster than `v_rest` is **departing**:
//!   free, but watched for a return within the interval; if it has just
//!   bounced (in this interval or the last), it is left out of an impact
//!   on the other constraints (if their impulse turns it back, its root
//!   times its own impact, as the plant meets it). For the observers
//!   (36) and (38) the separating speed is compared with
//!   `v_rest` without its band term `√(4 A_i g_i b)` (that term bounds a
//!   sample falling back into the band, not a separation, and a slow
//!   separation held as a persistent contact would lose all of its
//!   normal speed to the settle where the plant still bounces): under
//!   noise a rebound of a few hundredths to tenths of a m/s in an
//!   accumulation flies and decelerates instead (one
//!   departing slower than `v_rest` with the band term plus the
//!   estimate's uncertainty, or held along the piece before, still takes
//!   part in an impact on the others). With
//!   `σ = 0` and `d = 0` the rule is the same;
//! - a closed constraint still open (`h_i > 0`) and approached, that its
//!   normal acceleration `α_i = J_i a + J̇_i w > 0` turns back before the
//!   gap is more than the band deep (`h_i − (J_i w)²/(2α_i) ≥ −g_i b`), under
//!   the free motion and, beside other closed constraints, with them held
//!   and itself taking no force, is **grazed**: neither hit nor closed, held
//!   at acceleration level (where it gets no force).
//!
//! Newton's law on several constraints at once is checked twice. With
//! unequal restitutions it can put energy in; when it does, Moreau's law
//! with the least restitution of the set replaces it (the plastic
//! projection `w_p`, then `w⁺ = w_p + e (w_p − w⁻)`, which never gains
//! energy). And where the gradients are nearly opposite, the closure of
//! the thin wedge between them takes far more energy than the normal
//! speeds carry (more than four times what each constraint would take
//! alone); the constraints are then met one at a time, the fastest
//! approach first, as alternating bounces meet them (and so too where the
//! impact problem has no solution in floating point). Both come from the
//! double pendulum, whose tip reaches the corner of wall and floor only at
//! the arm's full reach (`tests/kalman.rs`,
//! `the_double_pendulum_passes_the_corner_at_its_full_reach`), where the
//! tip grazes one constraint while it slides along the other.
//!
//! Two sets take one law however opposed their gradients, because a
//! time-stepping plant meets them in one step. A fast (elastic) impact
//! on a set that holds a contact held along the piece before it and not
//! separating from it: the plant's index set holds that contact (one
//! already leaving, however slowly, it does not; joined, the double
//! pendulum's floor, left at 5.7e-4 m/s, took the arm's swing back through
//! Newton's law on the corner's nearly opposite gradients, `tests/kalman.rs`,
//! `a_low_bounce_double_pendulum_passes_the_corner_at_its_full_reach`). And a constraint met earlier at
//! the same point (a bounce, so left out of the next impact there) that
//! the next impact's impulse drives in again: it is shut, its bounce
//! cannot come later at the same point, and it joins that impact. Both
//! come from a gripper whose two fingertips, on one finger coordinate,
//! strike a table (the Panda's fingers free of their limits,
//! `tests/robots/kalman.rs`, `fingertips_striking_a_table_together_take_one_law`):
//! one at a time, a fingertip was left approaching and was held as
//! a persistent contact, flown 2 mm into the table, and the filter was
//! up to 45 rad/s off.
//!
//! Along each piece of prediction: an open gap that ends closed has a root
//! in between; an open gap that starts closing and ends opening is
//! searched for a dip below zero (bisection on its rate, then the root); a
//! departing constraint that ends closing is searched for its top and the
//! root after it, or, if the top stays within the band (it never opened),
//! becomes a persistent contact from its top on, where its normal speed
//! is zero (as Moreau–Jean's index set keeps a closed constraint active).
//!
//! With noise, this keeps a sliding contact closed and impact-free (no
//! impact located while Example 1 slides, for `σ` up to 1e-3), and a noisy
//! resting contact at rest. What it cannot avoid: a sample that noise puts
//! inside the band just before a real impact gets Newton's law up to
//! `n_σ σ / v_n` early, and that one sample carries the whole jump.
//!
//! # Noise
//!
//! The injection passes the difference of two noisy samples with gain
//! `φ = (1 − e^{−l_d τ})/τ` and the interval's decay `1 − φτ` filters it:
//! `e_{k+1} = (1 − φτ) e_k + φ (n_{k+1} − n_k)`, stationary standard
//! deviation `φσ √(2/(2 − φτ)) ≈ l_d σ` per coordinate, whatever `τ`.
//!
//! # Bad samples, bad states, long gaps
//!
//! An estimator in a control loop must keep producing estimates on valid
//! data, whatever came before. The policy, shared by both observers:
//!
//! - **The estimate is held to `C_v`.** Every update ends with
//!   `v̂ ← sat(v̂)`, the projection onto the ball `|v̂| ≤ C_v` that the
//!   Lipschitz extension `F̄` already uses, and starts its prediction from
//!   `sat(v̂_k)` (so a huge `v̂(0)` is held too). The plant obeys `|v| ≤ C_v`
//!   (Assumption 1), so the projection, onto a convex set that holds `v`,
//!   never moves `v̂` away from `v`; it changes nothing while `|v̂| ≤ C_v`.
//!   (Before, one bad sample could drive `v̂` to 1e4–1e300, where the
//!   prediction crossed the constraints so fast that the impact problems
//!   failed, and since a refused update keeps the state, the observer was
//!   wedged for good.)
//! - **Outliers are refused.** A system slower than `C_v` moves at most
//!   `C_v τ` in `τ`; noise adds at most `2 √N n_σ σ` to the distance of two
//!   samples. A measurement farther than `κ (C_v τ + 2 √N n_σ σ)` from the
//!   last accepted one ([`ObserverParams::outlier_bound`], `κ` =
//!   [`ObserverParams::outlier_factor`], default 2) is refused with
//!   [`ObserverError::Outlier`]: the estimate and report stay as they were,
//!   the next accepted update counts it in [`UpdateReport::outliers`]. A
//!   finite glitch of any size beyond the bound (1e2…1e6 m in the tests)
//!   costs nothing: the run goes on bit-identical to one that never saw it
//!   (recovery in 0 samples). A glitch within the bound is a bounded kick,
//!   `|Δv̂| ≤ l_d κ (C_v τ + …)`, that decays like any error.
//! - **Samples that agree with each other win.** After
//!   [`ObserverParams::max_outliers`] (default 3) refused samples in a row
//!   that agree with each other (each within the outlier bound of the one
//!   before: a system that is really there, say after a wrong first
//!   measurement), the next such sample restarts the estimate from the
//!   measurement, `v̂` kept ([`Restart::Outliers`]). Bad samples that do not
//!   agree with each other never restart it.
//! - **A long gap is an extrapolation.** An interval longer than
//!   [`ObserverParams::max_interval`] (default `3/l_d`: after it the
//!   injection has replaced all but `e^{−3}` of what the estimate knew)
//!   is not integrated: the estimate restarts from the measurement with the
//!   mean velocity over the gap, held to `C_v`, and the report says
//!   [`Restart::LongInterval`] (a gap of 1 s used to give an error of 573 m/s
//!   and `Ok`; 1e6 s gave `v̂ = −1.4e24`).
//! - **An infeasible own state restarts.** If integrating the interval from
//!   the observer's own state fails (the model, or an impact problem, fails
//!   along the predicted motion), the estimate restarts from the measurement
//!   with the mean velocity over the interval ([`Restart::Infeasible`]).
//!   Only a failure of the restart itself (Newton's law at the measured
//!   `q`, where the model must be defined) is an error.
//!
//! After any restart the error is at most `C_v + |v|` and decays like any
//! initial error, `e^{−l_d t}` for (38) (`tests/observer.rs`: below 1e-2 m/s
//! within 1000 samples at 1 kHz on Example 1, after a wrong first
//! measurement, a huge `v̂(0)`, or a gap of 1 s or 1e6 s).
//!
//! # Measured (`tests/observer.rs`)
//!
//! Example 1, `l_d = 10`, `v̂(0) = 0`, 1 kHz samples of a plant at
//! `τ = 1e-5` (the default midpoint step), `|v − v̂|` over `t ∈ [2, 10]` s:
//!
//! | discretization | median | 90th percentile | max |
//! |---|---|---|---|
//! | `ImpactAware` | 4.8e-9 | 4.3e-5 | 3.1e-2 |
//! | `SectionVii` | 8.4e-2 | 8.3e-1 | 13.0 |
//!
//! After the initial transient no plant impact leaves the impact-aware
//! error above 1e-2 for more than 4 samples. The same scheme with its
//! search inside the interval off (`max_impacts = 0`, impacts met only
//! where a sampled gap is closed) gets 1.3e-6, 8.1e-1 and 13: locating
//! impacts between samples is what the figures owe most to. Irregular
//! sampling (intervals uniform in [0.5, 1.5] ms) gives 4.2e-9, 4.1e-5,
//! 2.9e-2; 100 Hz gives 4.0e-7, 5.4e-5, 0.15. (Before each piece of a
//! held contact started settled, the first row read 1.8e-8, 7.9e-5,
//! 3.1e-2: the contact rule holds the floor against a separating
//! normal speed below its resting speed, and the force kept it.) (With the θ-method's law
//! `Slower` in the plant the figures were 1.7e-6, 3.2e-4 and 2.1e-2: on
//! the sliding stretch, where the observer holds the contact by its
//! acceleration-level law, it agrees with the midpoint plant a hundred
//! times better.) Run
//! `cargo test --release --test observer -- --nocapture` for every figure
//! (restitution mismatch and noise curves, decay rates against gain
//! selection, all five models).

mod error;
mod full_order;
mod gains;
mod interval;
mod kalman;
mod params;
mod reduced_order;
mod report;

pub use error::ObserverError;
pub use full_order::{FullOrder, FullOrderGains};
#[cfg(feature = "std")]
pub use gains::{Budget, CertifiedBounds, CertifiedConstant, CertifyError};
pub use gains::{Design, GainRegion, ModelBounds};
pub use kalman::{
    Blocks, KalmanParams, KalmanReport, NoiseFactors, Picked, Saltation, SaltationKalman, Tuning,
    constrained_flow_jacobian, flow_jacobian, pick_by_likelihood, saltation, transition,
    tune_process_noise,
};
pub use params::{Discretization, ObserverParams};
pub use reduced_order::ReducedOrder;
pub use report::{Restart, UpdateReport};

use nalgebra::{RealField, SVector};

use crate::error::DataError;
use crate::model::Model;
use crate::state::Estimate;
use crate::validate;

/// The paper's class of estimators (13)–(15): driven by measured positions
/// `q(t_k)`, known inputs and time, never by the velocity.
///
/// Implemented by [`ReducedOrder`] (38) and [`FullOrder`] (36) for every
/// [`Model`], and by the [`SaltationKalman`] filter for every model with
/// [`Sensitivities`](crate::Sensitivities) (all generated ones): the trait
/// is generic over the model because the filter needs more of it than the
/// observers. A function written against `O: Observer<M, N, K>` runs any
/// of the three. Every update is a pure function of the observer's state and its arguments:
/// the same measurements give the same bits (the well-posedness of
/// Theorem 1, numerically). The derivations (the signs of (36) and (38),
/// the discretization of one sampling interval with impacts inside it,
/// the contact rule under noise) are in the module docs of
/// `runtime/src/observer/mod.rs`.
///
/// A loop over measurements `(t_k, q_k)`:
///
/// ```
/// # use moreau_runtime::{Model, ModelInfo};
/// # use nalgebra::{Matrix1, SVector, Vector1};
/// # struct Ball;
/// # impl Model<1, 1> for Ball {
/// #     type Scalar = f64;
/// #     type Input = SVector<f64, 0>;
/// #     const INFO: ModelInfo<1, 1> = ModelInfo {
/// #         name: "Ball", coordinates: ["y"], velocities: ["vy"], constraints: ["floor"],
/// #         parameters: &[], inputs: &[], source: "", op_count: 0,
/// #     };
/// #     fn mass(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
/// #     fn coriolis(&self, _: &Vector1<f64>, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::zeros() }
/// #     fn gravity(&self, _: &Vector1<f64>) -> Vector1<f64> { Vector1::new(9.81) }
/// #     fn forces(&self, _: f64, q: &Vector1<f64>, _: &Vector1<f64>, _: &SVector<f64, 0>) -> Vector1<f64> {
/// #         self.gravity(q)
/// #     }
/// #     fn gaps(&self, q: &Vector1<f64>) -> Vector1<f64> { *q }
/// #     fn gap_jacobian(&self, _: &Vector1<f64>) -> Matrix1<f64> { Matrix1::new(1.0) }
/// #     fn restitution(&self) -> Vector1<f64> { Vector1::new(0.8) }
/// #     fn parameter(&self, _: usize) -> Option<f64> { None }
/// #     fn parameter_mut(&mut self, _: usize) -> Option<&mut f64> { None }
/// # }
/// use moreau_runtime::{Observer, ObserverParams, ReducedOrder};
///
/// // a ball dropped from 1 m lands at t₁ = 0.4515 s and leaves at 0.8 of
/// // its landing speed; samples every 1 ms, the bounce between two of them
/// let t1 = (2.0 / 9.81_f64).sqrt();
/// let y = |t: f64| if t < t1 { 1.0 - 4.905 * t * t } else { 0.8 * 9.81 * t1 * (t - t1) - 4.905 * (t - t1).powi(2) };
/// let params = ObserverParams::new(10.0, 20.0);
/// let mut observer = ReducedOrder::<f64, 1, 1>::new(params, 0.0, Vector1::new(1.0), Vector1::zeros())?;
/// for k in 1..=500 {
///     let t = k as f64 * 1e-3;
///     let estimate = observer.update(&Ball, t, &Vector1::new(y(t)), &SVector::zeros())?;
///     if k == 452 {
///         // the impact was located inside the last interval, at t₁
///         let report = observer.report();
///         assert_eq!(report.impacts, 1);
///         assert!((report.first_impact.unwrap() - t1).abs() < 1e-12);
///         assert!((estimate.v[0] - (0.8 * 9.81 * t1 - 9.81 * (t - t1))).abs() < 1e-9);
///     }
/// }
/// # Ok::<(), moreau_runtime::ObserverError<f64>>(())
/// ```
pub trait Observer<M, const N: usize, const K: usize>
where
    M: Model<N, K>,
{
    /// Takes the measurement `q` at time `t > t_k` (the known input `u`
    /// applied over `[t_k, t]`) and returns the new estimate.
    ///
    /// # Errors
    ///
    /// An [`ObserverError`] naming the problem (a non-finite measurement,
    /// input or parameter, a time not after the last, a model that
    /// evaluates to NaN, ...); the observer's state is then unchanged.
    fn update(
        &mut self,
        model: &M,
        t: M::Scalar,
        q: &SVector<M::Scalar, N>,
        u: &M::Input,
    ) -> Result<Estimate<M::Scalar, N>, ObserverError<M::Scalar>>;

    /// The current estimate.
    fn estimate(&self) -> Estimate<M::Scalar, N>;

    /// What the last successful update did.
    fn report(&self) -> &UpdateReport<M::Scalar, N, K>;

    /// The settings of the interval (the filter's
    /// [`KalmanParams::observer`]).
    fn params(&self) -> &ObserverParams<M::Scalar>;
}

/// Checks one update's data: returns `τ = t − last`.
pub(crate) fn check_update<M, T, const N: usize, const K: usize>(
    model: &M,
    last: T,
    t: T,
    q: &SVector<T, N>,
    u: &M::Input,
) -> Result<T, ObserverError<T>>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    let tau = t - last;
    if !(t.is_finite() && tau > T::zero() && tau.is_finite()) {
        return Err(ObserverError::InvalidTime { t, last });
    }
    validate::finite_vector(q, "q")?;
    validate::model_and_input(model, u)?;
    Ok(tau)
}

/// Checks an observer's initial data: a finite start time `t0`, finite
/// `q0` and `v0`.
pub(crate) fn check_start<T: RealField + Copy, const N: usize>(
    t0: T,
    q0: &SVector<T, N>,
    v0: &SVector<T, N>,
) -> Result<(), ObserverError<T>> {
    if !t0.is_finite() {
        return Err(ObserverError::InvalidTime { t: t0, last: t0 });
    }
    validate::finite_vector(q0, "q0")?;
    validate::finite_vector(v0, "v0")?;
    Ok(())
}

/// What an update does with a measurement that passed the checks.
pub(crate) enum Plan {
    /// Integrate the interval.
    Integrate,
    /// Restart from the measurement.
    Restart(Restart),
}

/// What an observer remembers of the outliers it refused since its last
/// accepted measurement (bookkeeping only: a refused sample never touches
/// the estimate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Outliers<T: RealField + Copy, const N: usize> {
    /// Refused since the last accepted measurement.
    skipped: u32,
    /// The last refused one, and how many refused in a row agree with each
    /// other (each within the outlier bound of the one before).
    last: Option<(T, SVector<T, N>)>,
    run: u32,
}

impl<T: RealField + Copy, const N: usize> Outliers<T, N> {
    pub(crate) const NONE: Self = Self {
        skipped: 0,
        last: None,
        run: 0,
    };

    /// Screens the measurement `q` at `t`, `τ` after the last accepted
    /// `q_k`: farther than the outlier bound, it is refused (and recorded),
    /// unless it is the `max_outliers + 1`-th of a run of outliers that
    /// agree with each other (a system that is really there: the estimate
    /// restarts); an interval longer than `max_interval` restarts; the rest
    /// is integrated.
    pub(crate) fn screen(
        &mut self,
        params: &ObserverParams<T>,
        (t, tau): (T, T),
        q_k: &SVector<T, N>,
        q: &SVector<T, N>,
    ) -> Result<Plan, ObserverError<T>> {
        let distance = (q - q_k).norm();
        let bound = params.outlier_bound(tau, N);
        if distance > bound {
            let agrees = self
                .last
                .is_some_and(|(t_o, q_o)| (q - q_o).norm() <= params.outlier_bound(t - t_o, N));
            let run = if agrees {
                self.run.saturating_add(1)
            } else {
                1
            };
            if run > params.max_outliers {
                return Ok(Plan::Restart(Restart::Outliers));
            }
            self.skipped = self.skipped.saturating_add(1);
            (self.last, self.run) = (Some((t, *q)), run);
            return Err(ObserverError::Outlier { distance, bound });
        }
        if tau > params.max_interval {
            return Ok(Plan::Restart(Restart::LongInterval));
        }
        Ok(Plan::Integrate)
    }

    /// A measurement was accepted: returns how many were skipped before it,
    /// and forgets them.
    pub(crate) fn accept(&mut self) -> u32 {
        let skipped = self.skipped;
        *self = Self::NONE;
        skipped
    }
}

/// An invalid setting, as an [`ObserverError`].
pub(crate) fn invalid<T>(name: &'static str, value: T) -> ObserverError<T> {
    ObserverError::Data(DataError::InvalidParams { name, value })
}
