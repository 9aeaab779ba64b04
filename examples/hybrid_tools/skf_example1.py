"""The public Python saltation Kalman filter `hybrid-tools` (PyPI) on Example 1.

Runs hybrid-tools' SKF on the exact noisy samples our SaltationKalman is
scored on (written by `cargo run --release --example vs_hybrid_tools` to
out/vs_hybrid_tools/), and prints both filters' figures side by side and
hybrid-tools' wall time per update.

Example 1 (models/parabola.yaml): a unit point mass, q = (x, y), gravity
g = 9.81 along -y, floor h1 = y - x^2 >= 0, ceiling h2 = c - y >= 0 with
c = 8, Newton restitution e = 0.9. Impacts accumulate, then the mass slides
on the parabola.

The system is built the way hybrid-tools' documentation builds one
(docs/HybridDynamicalSystem.md, basic_hybrid_systems/bouncing_ball_2d.py):
SymPy expressions for each mode's dynamics, resets and guards, their
Jacobians by SymPy, Euler-discretised A and B, lambdified. The library
assembles the saltation matrix itself
(hybrid_helper_functions.compute_saltation_matrix:
Xi = R + (f_post - R f_pre) G / (G f_pre)); what it needs from the user is
the reset Jacobian R and the guard Jacobian G (SymPy here), and
`check_saltation` checks the floor impact's Xi against central finite
differences of flight-impact-flight.

State s = (x, y, vx, vy); input u = (ux, uy), a white acceleration (the
process noise enters through B = d(s + f dt)/du, as in the library's
examples); parameters p = (e, g, c, slide, omega).

Modes:
  flight    flight, floor and ceiling guards armed;
  flight_c  the same dynamics and guards, reached by a ceiling bounce (the
            library keys guards and resets by (from, to) mode pairs, so the
            floor bounce flight -> flight and the ceiling bounce need two);
  slide     on the parabola: the constrained dynamics with the contact force
            lambda n, n = grad h1 = (-2x, 1), held by Baumgarte
            stabilisation (d2h1/dt2 = -2 omega dh1/dt - omega^2 h1,
            omega = 50 1/s: measurement updates push the state off the
            curve, the dynamics bring it back); lift-off guard lambda
            (identity reset -> flight), which never fires on this floor
            (lambda = (g + 2 vx^2 + ...)/(1 + 4 x^2) > 0).
Resets: Newton's law v+ = v - (1 + e)(n.v)/(n.n) n on the floor and on the
ceiling (n = (0, -1)); a plastic projection v+ = v - (n.v)/(n.n) n into
slide. Positions are unchanged.

Guards. The library fires a guard where it crosses zero during the
prediction (scipy events, either direction) and, after the measurement
update, where it is negative; among several it takes the first listed.
Every guard here is gated by the direction of motion: the floor guards are
h1 where the approach speed w = 2 x vx - vy >= 0, else 1; the ceiling's is
h2 where vy > 0, else 1. So a state just reset (moving out of the wall)
never re-fires, and an update never reflects a state already moving out.
The library's own bouncing ball instead splits flight at the apex (guard
dh1/dt); that design is not usable with 0.1.0 (see "mode fix" below): an
update that carries dh1/dt past zero applies the apex's identity reset but
leaves the mode "up", whose floor guard is disarmed, and the estimate then
falls through the floor for good (start 0 at 4.395 s, before this design).

Rule for entering the sliding mode (--rule): a floor impact that the rule
calls slow is plastic and starts sliding, a faster one bounces:
  speed (default, chosen beforehand): outgoing normal speed e w < slide
        [m/s];
  hop   (a sensitivity check, tried after seeing start 3): the bounce would
        rise less than `slide` [m] in h1, (e w)^2 / (2 (g + 2 vx^2)).
The two floor guards are h1 where w >= 0 and the rule says slow (resp.
fast), else 1, the slide guard listed first.

Variants: "as shipped" is hybrid_tools.SKF unchanged. "mode fix" is
ModeFixSKF: the library's update with the one line a user adds, switching
the mode when the update applies a reset (0.1.0 applies the reset and the
saltation matrix but keeps the old mode). It matters here for entering
slide from an update.

Process noise: W = q^2 / dt I per mode (B = [0; dt I] in flight, so the
velocity gains q^2 dt per step: q is an acceleration noise density, as
our q_a), q_f in the flight modes, q_s in slide (where B projects it on
the tangent). Measurement noise V = sigma^2 I, sigma = 1e-4. Start:
q0 = first sample, v0 = 0, P0 = diag(sigma^2, sigma^2, 20^2, 20^2) (ours:
initial velocity sigma = the velocity bound 20), mode flight.

Tuning, per variant, on the model file's start only
(out/vs_hybrid_tools/tuning.csv: its 10 s record with noise seed 1000, the
record our filter is tuned on): maximise the innovation log-likelihood
sum_k log N(z_k; C s_k|k-1, C P_k|k-1 C' + V) over (log10 q_f, log10 q_s,
slide) by coordinate-wise grids (one shared q over 1e-6..1e2, then each q
by decades, half and quarter decades, and the threshold over a grid), then
a joint grid around the best point (q_f +-0.5 decade by quarters, q_s +-1
by halves, every threshold): about 190 runs, as many as our tuner's 196; a
run that raises or loses a positive definite S scores -inf. Our
tune_process_noise maximises the same likelihood (plus a weak prior) over
its five knobs. Then every variant runs unchanged on all four starts.

Cost: wall time per update (predict + update), time.perf_counter around
whole runs of the plain loop, median of --repeats runs per start.

Run, after `cargo run --release --example vs_hybrid_tools`:
    python3 -m venv .venv-hybrid
    .venv-hybrid/bin/pip install -r examples/hybrid_tools/requirements.txt
    .venv-hybrid/bin/python examples/hybrid_tools/skf_example1.py [--rule hop]
It writes out/vs_hybrid_tools/hybrid_tools_<rule>_<variant>_start<k>.csv
(t, x, y, vx, vy, mode: 0 flight, 1 flight_c, 2 slide, -1 after a failure).
"""

import argparse
import json
import os
import time

import numpy as np
import scipy
import sympy as sp
from sympy.matrices import Matrix

import hybrid_tools
from hybrid_tools import (
    SKF,
    HybridDynamicalSystem,
    ModeDynamics,
    ModeGuard,
    ModeNoise,
    ModeReset,
    create_dynamics,
    create_guards,
    create_resets,
)
from hybrid_tools.hybrid_helper_functions import compute_saltation_matrix, solve_ivp_guard_funcs

SIGMA = 1e-4  # measurement noise [m]
DT = 1e-3  # sampling period [s]
RESTITUTION, GRAVITY, CEILING = 0.9, 9.81, 8.0
OMEGA = 50.0  # Baumgarte rate of the sliding mode [1/s]
# the rules for entering the sliding mode: threshold grid for the tuner
RULES = {
    "speed": [0.01, 0.02, 0.05, 0.1, 0.2, 0.5],  # outgoing normal speed [m/s]
    "hop": [1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3],  # bounce height [m]
}
# where the Rust example writes: out/ at the workspace root, or $MOREAU_OUT
OUT = os.path.join(
    os.environ.get("MOREAU_OUT", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "out")),
    "vs_hybrid_tools",
)


def modes(rule="speed"):
    """The lambdified functions of every mode, reset and guard (SymPy), with
    the sliding mode entered by `rule` (see RULES)."""
    x, y, vx, vy, ux, uy, dt = sp.symbols("x y vx vy ux uy dt")
    e, g, c, slide, omega = sp.symbols("e g c slide omega")
    s = Matrix([x, y, vx, vy])
    u = Matrix([ux, uy])
    p = Matrix([e, g, c, slide, omega])
    n = Matrix([-2 * x, 1])  # grad h1 over q
    h1 = y - x**2
    h2 = c - y
    dh1 = vy - 2 * x * vx  # dh1/dt
    w = -dh1  # approach speed to the floor
    v = Matrix([vx, vy])

    # dynamics: flight, and sliding with the contact force lambda n
    f_flight = Matrix([vx, vy, ux, -g + uy])
    a_free = Matrix([ux, -g + uy])
    lam = (2 * vx**2 - (n.T * a_free)[0] - 2 * omega * dh1 - omega**2 * h1) / (n.T * n)[0]
    f_slide = Matrix([vx, vy]).col_join(a_free + lam * n)

    # resets (positions unchanged)
    newton_floor = Matrix([x, y]).col_join(v - (1 + e) * (n.T * v)[0] / (n.T * n)[0] * n)
    plastic_floor = Matrix([x, y]).col_join(v - (n.T * v)[0] / (n.T * n)[0] * n)
    newton_ceiling = Matrix([x, y, vx, -e * vy])
    identity = Matrix([x, y, vx, vy])

    # guards (fire where they cross zero; the update fires them where < 0)
    if rule == "speed":  # outgoing normal speed e w below `slide`
        slow = sp.And(w >= 0, e * w < slide)
    else:  # the bounce would rise less than `slide` (in h1) above the floor
        slow = sp.And(w >= 0, (e * w) ** 2 < 2 * slide * (g + 2 * vx**2))
    fast = sp.And(w >= 0, sp.Not(slow))
    to_slide = Matrix([sp.Piecewise((h1, slow), (1, True))])
    to_bounce = Matrix([sp.Piecewise((h1, fast), (1, True))])
    to_ceiling = Matrix([sp.Piecewise((h2, vy > 0), (1, True))])
    lift_off = Matrix([lam])

    args = (s, u, dt, p)

    def mode(f):
        f_disc = s + f * dt
        return ModeDynamics(
            f_cont=sp.lambdify(args, f),
            A_disc=sp.lambdify(args, f_disc.jacobian(s)),
            B_disc=sp.lambdify(args, f_disc.jacobian(u)),
            y=sp.lambdify((s, p), Matrix([x, y])),
            C=sp.lambdify((s, p), Matrix([x, y]).jacobian(s)),
        )

    def reset(r):
        return ModeReset(r=sp.lambdify(args, r), R=sp.lambdify(args, r.jacobian(s)))

    def guard(gd):
        return ModeGuard(g=sp.lambdify(args, gd), G=sp.lambdify(args, gd.jacobian(s)))

    flight = mode(f_flight)
    dynamics = create_dynamics(
        [("flight", flight), ("flight_c", flight), ("slide", mode(f_slide))]
    )
    # order matters: the library takes the first listed guard that fired
    transitions = [
        ("flight", "slide", plastic_floor, to_slide),
        ("flight", "flight", newton_floor, to_bounce),
        ("flight", "flight_c", newton_ceiling, to_ceiling),
        ("flight_c", "slide", plastic_floor, to_slide),
        ("flight_c", "flight", newton_floor, to_bounce),
        ("flight_c", "flight_c", newton_ceiling, to_ceiling),
        ("slide", "flight", identity, lift_off),
    ]
    resets = create_resets([(a, b, reset(r)) for a, b, r, _ in transitions])
    guards = create_guards([(a, b, guard(gd)) for a, b, _, gd in transitions])
    return dynamics, resets, guards


def system(parts, q_f, q_s):
    """Example 1 with acceleration noise densities q_f (flight), q_s (slide)."""
    dynamics, resets, guards = parts
    noise = {m: (q_s if m == "slide" else q_f) ** 2 / DT * np.eye(2) for m in dynamics}
    noises = {m: ModeNoise(W=noise[m], V=SIGMA**2 * np.eye(2)) for m in dynamics}
    return HybridDynamicalSystem(dynamics=dynamics, resets=resets, guards=guards, noises=noises)


def parameters(slide):
    """The parameter vector p = (e, g, c, slide, omega)."""
    return np.array([RESTITUTION, GRAVITY, CEILING, slide, OMEGA])


class ModeFixSKF(SKF):
    """SKF with the one-line fix a user makes to 0.1.0's measurement update:
    when a guard is negative at the updated state, `SKF.update` applies the
    reset and the saltation matrix but keeps the old mode; here the mode
    switches too. Otherwise the method is the library's, line for line."""

    def update(self, current_time, current_input, measurement):
        """`SKF.update`, switching the mode with the reset it applies."""
        C = self._hybrid_system.dynamics[self._current_mode].C(self._current_state, self._parameters)
        V = self._hybrid_system.noises[self._current_mode].V
        K = self._current_cov @ C.T @ np.linalg.inv(C @ self._current_cov @ C.T + V)
        measurement_est = (
            self._hybrid_system.dynamics[self._current_mode]
            .y(self._current_state, self._parameters)
            .flatten()
        )
        C = self._hybrid_system.dynamics[self._current_mode].C(self._current_state, self._parameters)
        residual = measurement - measurement_est
        self._current_state = self._current_state + K @ residual
        self._current_cov = self._current_cov - K @ C @ self._current_cov
        current_guards, possible_modes = solve_ivp_guard_funcs(
            self._hybrid_system.guards, self._current_mode, current_input, self._dt, self._parameters
        )
        for guard_idx in range(len(current_guards)):
            if current_guards[guard_idx](current_time, self._current_state) < 0:
                new_mode = possible_modes[guard_idx]
                new_state = (
                    self._hybrid_system.resets[self._current_mode][new_mode]
                    .r(self._current_state, current_input, self._dt, self._parameters)
                    .reshape(np.shape(self._current_state))
                )
                salt = compute_saltation_matrix(
                    pre_event_state=self._current_state,
                    inputs=current_input,
                    dt=self._dt,
                    parameters=self._parameters,
                    pre_mode=self._current_mode,
                    post_mode=new_mode,
                    hybrid_system=self._hybrid_system,
                    post_event_state=new_state,
                )
                self._current_state = new_state
                self._current_cov = salt @ self._current_cov @ salt.T
                self._current_mode = new_mode  # the fix
                break
        return self._current_state, self._current_cov


VARIANTS = {"as shipped": SKF, "mode fix": ModeFixSKF}


def new_filter(hs, params, z0, cls=SKF):
    """The filter at t = 0: q0 the first sample, v0 = 0, mode flight."""
    return cls(
        init_state=np.array([z0[0], z0[1], 0.0, 0.0]),
        init_mode="flight",
        init_cov=np.diag([SIGMA**2, SIGMA**2, 20.0**2, 20.0**2]),
        dt=DT,
        parameters=params,
        hybrid_system=hs,
    )


def run(hs, params, t, z, cls):
    """Runs the filter over the samples: estimates (n x 4), modes, failure."""
    skf = new_filter(hs, params, z[0], cls)
    u = np.zeros(2)
    est = np.full((len(t), 4), np.nan)
    est[0] = skf.current_state
    modes_seen = [skf.current_mode]
    for k in range(1, len(t)):
        try:
            skf.predict(t[k - 1], u)
            skf.update(t[k], u, z[k])
        except Exception as err:  # report where and why, keep the rest NaN
            return est, modes_seen, f"t = {t[k]:.3f} s, mode {skf.current_mode}: {err!r}"
        est[k] = skf.current_state
        modes_seen.append(skf.current_mode)
    return est, modes_seen, None


def log_likelihood(hs, params, t, z, cls):
    """Sum of the innovations' Gaussian log-densities (from the predictions)."""
    skf = new_filter(hs, params, z[0], cls)
    u = np.zeros(2)
    total = 0.0
    for k in range(1, len(t)):
        try:
            state, cov = skf.predict(t[k - 1], u)
            S = cov[:2, :2] + SIGMA**2 * np.eye(2)
            det = np.linalg.det(S)
            if not det > 0:  # the covariance lost positive definiteness
                return -np.inf
            r = z[k] - state[:2]
            total -= 0.5 * (r @ np.linalg.solve(S, r) + np.log(det) + 2 * np.log(2 * np.pi))
            skf.update(t[k], u, z[k])
        except Exception:
            return -np.inf
        if not np.isfinite(total):
            return -np.inf
    return total


def tune(parts, t, z, cls, grid, log):
    """Maximises the innovation log-likelihood over (log10 q_f, log10 q_s,
    the sliding threshold): coordinate-wise grids with refinements, then a
    joint grid around the best point."""
    cache = {}

    def ll(a, b, vs):
        key = (round(a, 3), round(b, 3), vs)
        if key not in cache:
            cache[key] = log_likelihood(system(parts, 10**a, 10**b), parameters(vs), t, z, cls)
            log(f"  log10 q_f {a:+.2f}  log10 q_s {b:+.2f}  slide {vs:.1e}: {cache[key]:.1f}")
        return cache[key]

    a, b, vs = -2.0, -2.0, grid[len(grid) // 2]
    # 1. one shared q over a wide grid
    a = b = max(np.arange(-6.0, 2.01, 1.0), key=lambda x: ll(x, x, vs))
    # 2. each coordinate on its own, then half and quarter decades
    for step in (1.0, 0.5, 0.25):
        a = max(a + step * np.arange(-2, 3), key=lambda x: ll(x, b, vs))
        b = max(b + step * np.arange(-2, 3), key=lambda x: ll(a, x, vs))
        if step == 1.0:
            vs = max(grid, key=lambda x: ll(a, b, x))
    # 3. a joint grid around that point (about as many runs as our tuner's)
    joint = [
        (a + da, b + db, x)
        for da in (-0.5, -0.25, 0.0, 0.25, 0.5)
        for db in (-1.0, -0.5, 0.0, 0.5, 1.0)
        for x in grid
    ]
    a, b, vs = max(joint, key=lambda k: ll(*k))
    return 10**a, 10**b, vs, ll(a, b, vs), len(cache)


def figures(err):
    """Median, 90th percentile and maximum, ranked as tests/common/runs.rs."""
    s = np.sort(err)
    n = len(s)
    return s[n // 2], s[(n * 9) // 10], s[-1]


def score(d, vx, vy):
    """(median, p90, max, max without the bracketing samples) over [2, 10] s."""
    err = np.hypot(d["vx"] - vx, d["vy"] - vy)
    err = np.where(np.isnan(err), np.inf, err)  # a failed run scores infinite
    window = (d["t"] >= 2.0 - 1e-9) & (d["t"] < 10.0 + 1e-3 - 1e-9)
    clean = window & (d["bracket"] == 0)
    return (*figures(err[window]), figures(err[clean])[2])


def check_saltation(parts):
    """The floor impact's saltation matrix, as the library assembles it from
    our R and G, against central finite differences of flight-impact-flight
    over 1 ms (flight in closed form, the impact time by the quadratic)."""
    resets = parts[1]
    p = parameters(1e-9)  # a threshold under which this impact bounces
    u = np.zeros(2)

    def flight(s, h):
        x, y, vx, vy = s
        return np.array([x + vx * h, y + vy * h - GRAVITY * h * h / 2, vx, vy - GRAVITY * h])

    def hit(s):  # first root in (0, T] of h1(flight(s, t))
        x, y, vx, vy = s
        a2, a1, a0 = -(GRAVITY / 2 + vx**2), vy - 2 * x * vx, y - x**2
        return min(r.real for r in np.roots([a2, a1, a0]) if abs(r.imag) < 1e-12 and r.real > 0)

    T = 1e-3
    r = resets["flight"]["flight"].r

    def through(s):
        ti = hit(s)
        return flight(r(flight(s, ti), u, DT, p).ravel(), T - ti)

    # 0.4 ms before a floor impact at x = 0.7 with v = (2, -3)
    pre_hit = np.array([0.7, 0.49, 2.0, -3.0])
    s0 = flight(pre_hit, -4e-4)
    ti = hit(s0)
    s_minus = flight(s0, ti)
    s_plus = r(s_minus, u, DT, p).ravel()
    xi = compute_saltation_matrix(s_minus, u, DT, p, "flight", "flight", hybrid_system(parts), s_plus)

    def phi(h):
        m = np.eye(4)
        m[0, 2] = m[1, 3] = h
        return m

    analytic = phi(T - ti) @ xi @ phi(ti)
    fd = np.zeros((4, 4))
    for j in range(4):
        d = np.zeros(4)
        d[j] = 1e-6
        fd[:, j] = (through(s0 + d) - through(s0 - d)) / 2e-6
    return np.abs(fd - analytic).max() / np.abs(analytic).max(), xi


def hybrid_system(parts):
    """The system with placeholder noise (for the saltation check)."""
    return system(parts, 1.0, 1.0)


def read(path):
    """A CSV of examples/vs_hybrid_tools.rs as a structured array."""
    return np.genfromtxt(path, delimiter=",", names=True)


def timed(hs, params, t, z, cls, repeats):
    """Wall time per update (predict + update) over whole runs, each run
    timed by time.perf_counter around the plain loop: median and minimum."""
    u = np.zeros(2)
    per_update = []
    for _ in range(repeats):
        skf = new_filter(hs, params, z[0], cls)
        start = time.perf_counter()
        for k in range(1, len(t)):
            skf.predict(t[k - 1], u)
            skf.update(t[k], u, z[k])
        per_update.append((time.perf_counter() - start) / (len(t) - 1))
    return float(np.median(per_update)), float(np.min(per_update))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per start")
    ap.add_argument("--knobs", help='skip tuning: JSON {"variant": [q_f, q_s, slide], ...}')
    ap.add_argument("--rule", choices=RULES, default="speed", help="rule for entering the sliding mode")
    args = ap.parse_args()
    print(
        f"hybrid-tools {hybrid_tools.__version__}, numpy {np.__version__}, "
        f"scipy {scipy.__version__}, sympy {sp.__version__}"
    )
    parts = modes(args.rule)
    print(f"sliding entered by the {args.rule} rule")

    rel, xi = check_saltation(parts)
    print(f"floor-impact saltation vs finite differences of flow-impact-flow: max rel. error {rel:.1e}")
    assert rel < 1e-6, xi

    knobs = json.loads(args.knobs) if args.knobs else {}
    tr = read(os.path.join(OUT, "tuning.csv"))
    tz = np.column_stack([tr["x_meas"], tr["y_meas"]])
    starts = [read(os.path.join(OUT, f"start{k}.csv")) for k in range(4)]
    results = {}
    for variant, cls in VARIANTS.items():
        if variant not in knobs:
            print(f"{variant}: tuning on the model file's start, noise seed 1000 (log-likelihood)")
            t0 = time.perf_counter()
            q_f, q_s, slide, best, runs = tune(parts, tr["t"], tz, cls, RULES[args.rule], print)
            knobs[variant] = [q_f, q_s, slide]
            print(
                f"{variant}: q_f {q_f:.3e}, q_s {q_s:.3e}, slide {slide:.1e}, "
                f"log-likelihood {best:.1f}, {runs} runs, {time.perf_counter() - t0:.0f} s"
            )
        q_f, q_s, slide = knobs[variant]
        hs, params = system(parts, q_f, q_s), parameters(slide)
        results[variant] = []
        for k, d in enumerate(starts):
            t, z = d["t"], np.column_stack([d["x_meas"], d["y_meas"]])
            est, seen, failure = run(hs, params, t, z, cls)
            switches = [
                (t[j], seen[j - 1], seen[j]) for j in range(1, len(seen)) if seen[j] != seen[j - 1]
            ]
            slides = [f"{a:.3f}" for a, _, b in switches if b == "slide"]
            lifts = [f"{a:.3f}" for a, b, _ in switches if b == "slide"]
            if failure:
                note = f"failed at {failure}"
            else:
                note = f"slide entered at {slides or 'never'}" + (f", left at {lifts}" if lifts else "")
            per = timed(hs, params, t, z, cls, args.repeats) if failure is None else (np.nan, np.nan)
            results[variant].append((score(d, est[:, 2], est[:, 3]), per, note))
            code = {"flight": 0, "flight_c": 1, "slide": 2}
            mode_col = [code[m] for m in seen] + [-1] * (len(t) - len(seen))
            np.savetxt(
                os.path.join(OUT, f"hybrid_tools_{args.rule}_{variant.replace(' ', '_')}_start{k}.csv"),
                np.column_stack([t, est, mode_col]),
                delimiter=",",
                header="t,x,y,vx,vy,mode",
                comments="",
            )
    print(f"knobs: {json.dumps(knobs)}")

    def fmt(f):
        return " ".join(f"{v:8.2e}" for v in f)

    print()
    print("|v - v^| [m/s] over t in [2, 10] s:  median      p90      max  max w/o brackets")
    for k, d in enumerate(starts):
        print(f"start {k}")
        print(f"  ours, defaults          : {fmt(score(d, d['vx_defaults'], d['vy_defaults']))}")
        print(f"  ours, tuned             : {fmt(score(d, d['vx_tuned'], d['vy_tuned']))}")
        for variant in VARIANTS:
            f, per, note = results[variant][k]
            print(
                f"  hybrid-tools {variant:10s} : {fmt(f)}   {per[0] * 1e6:.0f} us/update "
                f"(median of {args.repeats} runs, min {per[1] * 1e6:.0f}); {note}"
            )


if __name__ == "__main__":
    main()
