//! Example 1 solved exactly, event by event: the analytic reference the
//! estimators are scored against where the plant's own time-stepping error
//! must not enter.
//!
//! In free flight under gravity `x` is linear and `y` quadratic in time, so
//! both gaps, `y − x²` (the parabola) and `c − y` (the ceiling), are
//! quadratics in time: the next impact is the smallest positive root of
//! one of them, found in closed form, and Newton's law with restitution
//! `e` on the normal `∇h` gives the velocity after it. No step size, no
//! event-location tolerance: the states are exact to rounding.

use super::runs::Reference;
use moreau::State;
use nalgebra::Vector2;

/// Example 1's parameters (`models/parabola.yaml`): gravity, ceiling,
/// restitution.
const G: f64 = 9.81;
const CEILING: f64 = 8.0;
const RESTITUTION: f64 = 0.9;

/// The smallest `s > 0` with `a s² + b s + c = 0` for `c ≥ 0`; `on`: the
/// state is on this constraint (`c = 0` exactly), so the roots are `0` and
/// `−b/a`.
fn first_root(a: f64, b: f64, c: f64, on: bool) -> Option<f64> {
    if on {
        let s = -b / a;
        return (s > 0.0).then_some(s);
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    // the root formula without cancellation
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (r1, r2) = (q / a, c / q);
    [r1.min(r2), r1.max(r2)].into_iter().find(|s| *s > 0.0)
}

/// Free flight over `s` from `(q, v)`.
pub fn flow(q: Vector2<f64>, v: Vector2<f64>, s: f64) -> (Vector2<f64>, Vector2<f64>) {
    (
        Vector2::new(q[0] + v[0] * s, q[1] + v[1] * s - 0.5 * G * s * s),
        Vector2::new(v[0], v[1] - G * s),
    )
}

/// Example 1 from `(q0, v0)` to `t_end`, sampled every `dt` (the samples
/// at `j dt`), with its impacts `(time, constraint, normal approach
/// speed)`. `None` when the impacts start to accumulate (an approach
/// slower than 1 mm/s or two impacts within 1 µs): the sliding that
/// follows has no closed form, and this reference does not cover it.
pub fn parabola(
    (q0, v0): (Vector2<f64>, Vector2<f64>),
    t_end: f64,
    dt: f64,
) -> Option<Reference<2>> {
    let (mut t, mut q, mut v) = (0.0_f64, q0, v0);
    let mut on: Option<usize> = None;
    let mut samples = vec![State::new(0.0, q, v)];
    let mut impacts = Vec::new();
    let mut next = 1_usize;
    loop {
        // y − x² = (y − x²) + (v_y − 2 x v_x) s − (g/2 + v_x²) s²
        let floor = first_root(
            -(0.5 * G + v[0] * v[0]),
            v[1] - 2.0 * q[0] * v[0],
            (q[1] - q[0] * q[0]).max(0.0),
            on == Some(0),
        );
        // c − y = (c − y) − v_y s + (g/2) s²
        let ceiling = first_root(0.5 * G, -v[1], (CEILING - q[1]).max(0.0), on == Some(1));
        let (s, which) = match (floor, ceiling) {
            (Some(a), Some(b)) if b < a => (b, 1),
            (Some(a), _) => (a, 0),
            (None, Some(b)) => (b, 1),
            (None, None) => (f64::INFINITY, 0),
        };
        while next as f64 * dt <= (t + s).min(t_end) + 1e-12 {
            let ts = next as f64 * dt;
            let (qs, vs) = flow(q, v, ts - t);
            samples.push(State::new(ts, qs, vs));
            next += 1;
        }
        if t + s > t_end {
            return Some(Reference { samples, impacts });
        }
        let (q1, v1) = flow(q, v, s);
        t += s;
        // on the constraint exactly, and its normal ∇h
        let (q1, normal) = if which == 0 {
            (
                Vector2::new(q1[0], q1[0] * q1[0]),
                Vector2::new(-2.0 * q1[0], 1.0),
            )
        } else {
            (Vector2::new(q1[0], CEILING), Vector2::new(0.0, -1.0))
        };
        let approach = -normal.dot(&v1) / normal.norm();
        if approach < 1e-3 || s < 1e-6 {
            return None;
        }
        impacts.push((t, which, approach));
        // Newton's law: the normal velocity reversed and scaled by e
        v = v1 + normal * ((1.0 + RESTITUTION) * approach / normal.norm());
        q = q1;
        on = Some(which);
    }
}
