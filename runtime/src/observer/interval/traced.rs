//! The predicted motion of one interval, told piece by piece to a
//! [`Tracer`]: what an estimator that carries more than an estimate (the
//! saltation Kalman filter's covariance) needs from the interval.
//!
//! [`Interval::predict_traced`] is the one loop of the predicted motion:
//! [`Interval::predict`] runs it with a tracer that does nothing, so the
//! observers and the filter make the same decisions (classification, root
//! search, Newton's law, sliding) in the same order, with the same bits.

use nalgebra::{RealField, SMatrix, SVector};

use crate::lcp::IndexSet;
use crate::model::Model;

use super::{
    Contact, Crossing, Free, Interval, Law, Path, Point, Result, Segment, UpdateReport,
    check_contact, speed_roundoff,
};

/// One piece of predicted flight: from `(p0, w0)` at local time `s0`, of
/// length `h`, with the persistent contacts `sliding` held at acceleration
/// level (`impulse` their `∫ λ ds`), ending at `(p1, w1)`.
pub(crate) struct Flight<'a, T: RealField + Copy, const N: usize, const K: usize> {
    pub s0: T,
    pub h: T,
    pub p0: &'a SVector<T, N>,
    pub w0: &'a SVector<T, N>,
    pub p1: &'a SVector<T, N>,
    pub w1: &'a SVector<T, N>,
    pub sliding: IndexSet<K>,
    /// Those of `sliding` that rest on their constraint, whether or not a
    /// force holds them there (the contact rule's `resting`).
    pub resting: IndexSet<K>,
    pub impulse: &'a SVector<T, K>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Flight<'_, T, N, K> {
    /// The constraints held along the piece: those of `sliding` that
    /// pushed (a positive impulse) or rest on their constraint with no
    /// force (glued bodies in free flight). The contacts the piece's end
    /// lies on, for the filter's projection and for reading a sample
    /// ([`Interval::read_on_contacts`]).
    pub(crate) fn held(&self) -> IndexSet<K> {
        pressed(self.sliding, self.impulse).union(self.sliding.intersection(self.resting))
    }
}

/// Those of `sliding` that their contact force pressed on along a piece:
/// a positive impulse `∫ λ ds`.
fn pressed<T: RealField + Copy, const K: usize>(
    sliding: IndexSet<K>,
    impulse: &SVector<T, K>,
) -> IndexSet<K> {
    let mut pressed = IndexSet::EMPTY;
    for i in sliding {
        if impulse[i] > T::zero() {
            pressed.insert(i);
        }
    }
    pressed
}

/// One application of Newton's law at local time `s`, configuration `p`:
/// the law took `w⁻` with the impulses `lambda` on the constraints of `set`
/// (`ê` on `elastic`, `0` on the rest); `guard` holds the constraints whose
/// root along the motion was located here (empty when the law met a
/// closed constraint at the start of a piece).
pub(crate) struct Jump<'a, T: RealField + Copy, const N: usize, const K: usize> {
    pub s: T,
    pub p: &'a SVector<T, N>,
    pub w_minus: &'a SVector<T, N>,
    /// The velocity after the law.
    pub w_plus: &'a SVector<T, N>,
    /// The law that gave the post-impact velocity: Newton's with the LCP,
    /// or, where that would put energy in or the constraints oppose,
    /// Moreau's or one constraint at a time (the contact rule in
    /// `runtime/src/observer/mod.rs`).
    pub law: Law<T>,
    pub lambda: &'a SVector<T, K>,
    pub set: IndexSet<K>,
    pub elastic: IndexSet<K>,
    pub guard: IndexSet<K>,
    pub restitution: &'a SVector<T, K>,
    /// `J(p)`, as the law used it.
    pub jac: &'a SMatrix<T, K, N>,
    /// `M(p)` factored and the free acceleration at `(s, p, w⁻)`.
    pub free: &'a Free<T, N>,
    /// Where the law held some of the set as contacts (closed, met with
    /// no restitution) that their force pressed on along the piece before,
    /// beside a fast impact: those contacts, and how much the velocity
    /// after the law would differ, `w⁺_free − w⁺`, had they been a hair
    /// open, so that each bounces on its own when the impact drives it in
    /// ([`Interval::unheld`]). `None` where there is no such contact, where
    /// the two agree within the estimate's velocity noise, or where the
    /// tracer does not ask ([`Tracer::ALTERNATIVE`]).
    pub alternative: Option<(IndexSet<K>, SVector<T, N>)>,
}

/// What follows the predicted motion of an interval, piece by piece.
pub(crate) trait Tracer<T: RealField + Copy, const N: usize, const K: usize> {
    /// Whether the tracer takes [`Jump::alternative`], which is computed
    /// only for it.
    const ALTERNATIVE: bool = false;
    /// A piece of flight (or sliding) was integrated.
    fn flight(&mut self, piece: &Flight<'_, T, N, K>) -> Result<(), T>;
    /// An impact law was applied (which one: [`Jump::law`]).
    fn jump(&mut self, jump: &Jump<'_, T, N, K>) -> Result<(), T>;
}

/// The tracer of the observers, which carry nothing beyond the estimate.
pub(crate) struct NoTrace;

impl<T: RealField + Copy, const N: usize, const K: usize> Tracer<T, N, K> for NoTrace {
    #[inline(always)]
    fn flight(&mut self, _: &Flight<'_, T, N, K>) -> Result<(), T> {
        Ok(())
    }
    #[inline(always)]
    fn jump(&mut self, _: &Jump<'_, T, N, K>) -> Result<(), T> {
        Ok(())
    }
}

/// What [`Interval::meet`] applied at an impact: the velocity after it,
/// the law, and the constraints it met, the elastic ones among them.
struct Met<T, const N: usize, const K: usize> {
    w_plus: SVector<T, N>,
    law: Law<T>,
    set: IndexSet<K>,
    elastic: IndexSet<K>,
}

impl<M, T, const N: usize, const K: usize> Interval<'_, M, T, N, K>
where
    T: RealField + Copy,
    M: Model<N, K, Scalar = T>,
{
    /// Newton's law at `at` on `set` (`ê` on `elastic`; `together`: see
    /// [`newton`](Interval::newton)), widened to the constraints already
    /// `resolved` at this point that its impulse turns back.
    ///
    /// A constraint met at this point, and left out of a later impact here
    /// (it had just bounced), is shut: its gap `h` is within its band. Where
    /// that impact's impulse drives it in again faster than the estimate's
    /// velocity noise, it takes part in the impact, and the set meets one
    /// law, since its own bounce cannot come later at the same point: the
    /// rule meets each constraint once per point, so it was held as a
    /// persistent contact while approaching and flown through (two
    /// fingertips on one coordinate: one fingertip 2 mm inside a table, the
    /// filter 18 rad/s off).
    fn meet(
        &self,
        at: &Contact<'_, T, N, K>,
        (mut set, mut elastic): (IndexSet<K>, IndexSet<K>),
        together: bool,
        (h, resolved): (&SVector<T, K>, IndexSet<K>),
        report: &mut UpdateReport<T, N, K>,
    ) -> Result<Met<T, N, K>, T> {
        // a lone impact (nothing met at this point yet): the law alone,
        // without the copy of the report that a widened set restores
        if resolved.difference(set).is_empty() {
            let (w_plus, law) = self.newton(at, (set, elastic), together, report)?;
            return Ok(Met {
                w_plus,
                law,
                set,
                elastic,
            });
        }
        let opened = *report;
        let (mut w_plus, mut law) = self.newton(at, (set, elastic), together, report)?;
        // each round adds a constraint to the set: at most K rounds
        loop {
            let roundoff = speed_roundoff(&w_plus);
            let mut joined = IndexSet::EMPTY;
            for j in resolved.difference(set) {
                let row = at.jac.row(j);
                let g = row.norm();
                let shut = h[j] <= g * self.bands[j];
                if shut && row.dot(&w_plus.transpose()) < -g * (self.noise_speed + roundoff) {
                    joined.insert(j);
                }
            }
            if joined.is_empty() {
                return Ok(Met {
                    w_plus,
                    law,
                    set,
                    elastic,
                });
            }
            *report = opened;
            set = set.union(joined);
            // (one that met this point approaching still bounces, within
            // `max_impacts`)
            if opened.impacts < self.params.max_impacts {
                for j in joined {
                    if at.jac.row(j).dot(&at.w.transpose()) < T::zero() {
                        elastic.insert(j);
                    }
                }
            }
            (w_plus, law) = self.newton(at, (set, elastic), true, report)?;
        }
    }

    /// The velocity change by which the law's outcome `w_plus` at `at` on
    /// `set` (`ê` on `elastic`, none on the rest) would differ had the
    /// contacts `hovering` of the set been a hair open: the set met one
    /// constraint at a time, the fastest approach first, the elastic and
    /// the hovering ones each with its own restitution
    /// ([`one_at_a_time`](Interval::one_at_a_time)).
    ///
    /// The contact rule holds a closed constraint that its samples cannot
    /// tell from one that hovers within the noise, and the two laws part
    /// by the whole impulse the held one takes: a box rocking onto its
    /// second corner while the first micro-bounces 16 µm up (the plant)
    /// rebounds at 0.32 rad/s, and held at 0.79 rad/s the other way. The
    /// filter keeps this outcome in reserve (module docs of
    /// `runtime/src/observer/kalman/propagate.rs`, "A contact that may
    /// hover").
    /// `None` where the two agree within the estimate's velocity noise on
    /// every constraint of the set.
    fn unheld(
        &self,
        at: &Contact<'_, T, N, K>,
        (set, elastic, hovering): (IndexSet<K>, IndexSet<K>, IndexSet<K>),
        w_plus: &SVector<T, N>,
        report: &UpdateReport<T, N, K>,
    ) -> Option<SVector<T, N>> {
        let mut e = SVector::<T, K>::zeros();
        for i in elastic.union(hovering) {
            e[i] = self.restitution[i];
        }
        let minv_jt = at.chol.solve(&at.jac.transpose());
        let mut scratch = *report;
        let dv = self.one_at_a_time(at, &minv_jt, set, &e, &mut scratch);
        let d = at.w + dv - w_plus;
        let differs = set.iter().any(|i| {
            let row = at.jac.row(i);
            row.dot(&d.transpose()).abs() > row.norm() * self.noise_speed
        });
        (differs && d.iter().all(|x| x.is_finite())).then_some(d)
    }

    /// [`predict`](Interval::predict), reporting every piece of flight and
    /// every impact to `tracer` as it happens.
    pub(crate) fn predict_traced<R: Tracer<T, N, K>>(
        &self,
        v0: &SVector<T, N>,
        report: &mut UpdateReport<T, N, K>,
        tracer: &mut R,
    ) -> Result<(SVector<T, N>, SVector<T, N>), T> {
        let max_impacts = self.params.max_impacts;
        let max_rounds = max_impacts.saturating_mul(2).saturating_add(8);
        let (mut s, mut p, mut w) = (T::zero(), self.q0, *v0);
        // constraints that met Newton's law at this point (no second law
        // here), and how the prediction came here (touched, held, bounced)
        let mut resolved = IndexSet::EMPTY;
        let mut path = Path {
            bounced: self.last_impacted,
            ..Path::default()
        };
        // rounds counted by the events that end them (an impact, a
        // crossing); a step that ends at `max_step` continues its round
        let mut round = 1;
        // `path.pressed`, only for a tracer that takes `Jump::alternative`
        let pressed_for = |sliding: IndexSet<K>, impulse: &SVector<T, K>| {
            if R::ALTERNATIVE {
                pressed(sliding, impulse)
            } else {
                IndexSet::EMPTY
            }
        };
        loop {
            let last_round = round >= max_rounds;
            // CLASSIFY at (s, p, w)
            let free = self.free(s, &p, &w, report)?;
            let (h, jac) = self.model.contact(&p);
            check_contact(&h, &jac)?;
            let point = Point {
                s,
                p: &p,
                w: &w,
                free: &free,
            };
            let c = self.classes(&point, (&h, &jac), resolved, path)?;
            // IMPACT now, on the closed constraints met approaching
            if !c.approaching.is_empty() && !last_round {
                let elastic = if report.impacts < max_impacts {
                    c.elastic
                } else {
                    IndexSet::EMPTY
                };
                let before = report.impulses;
                let at = Contact {
                    s,
                    w: &w,
                    jac: &jac,
                    chol: &free.chol,
                };
                // a fast impact beside a contact held along the piece
                // before and not leaving it: one law on the set, as the
                // plant's step holds that contact in its index set (one
                // already separating, however slowly, is not in it: the
                // double pendulum's tip, a bounce off the floor 23 µs
                // before its wall, met with the floor took the arm's swing
                // back through Newton's law on two nearly opposite
                // gradients)
                let roundoff = speed_roundoff(&w);
                let resting = path.held.intersection(c.contact).iter().any(|i| {
                    let row = jac.row(i);
                    row.dot(&w.transpose()) <= roundoff * row.norm()
                });
                let together = resting && !elastic.is_empty();
                let Met {
                    w_plus,
                    law,
                    set,
                    elastic,
                } = self.meet(&at, (c.contact, elastic), together, (&h, resolved), report)?;
                let lambda = report.impulses - before;
                // (a contact pressed by its force along the piece before: it
                // may hover a hair above; one glued with no force does not)
                let hovering = set.difference(elastic).intersection(path.pressed);
                let alternative = if R::ALTERNATIVE && !hovering.is_empty() && !elastic.is_empty() {
                    self.unheld(&at, (set, elastic, hovering), &w_plus, report)
                        .map(|dv| (hovering, dv))
                } else {
                    None
                };
                for i in elastic {
                    if lambda[i] > T::zero() {
                        path.bounced.insert(i);
                    }
                }
                tracer.jump(&Jump {
                    s,
                    p: &p,
                    w_minus: &w,
                    w_plus: &w_plus,
                    law,
                    lambda: &lambda,
                    set,
                    elastic,
                    guard: path.touched.intersection(c.approaching),
                    restitution: &self.restitution,
                    jac: &jac,
                    free: &free,
                    alternative,
                })?;
                w = w_plus;
                let met = c.approaching.union(set.difference(c.contact));
                resolved = resolved.union(met);
                path.touched = path.touched.union(met);
                round += 1;
                continue;
            }
            // FLIGHT (and sliding) to the end of the interval, one
            // Runge–Kutta step of at most `max_step` at a time (one step
            // where it is exact: a constant acceleration, nothing held)
            let left = self.tau - s;
            if left <= T::zero() {
                return Ok((p, w));
            }
            let rest = self.piece(left, c.sliding);
            let short = rest < left;
            // the held contacts' acceleration and force at the start, the
            // first Runge–Kutta stage of every piece from here
            let mut stage = self.constrained(&p, &w, c.sliding, &free, report)?;
            // SETTLE: the held constraints' separating normal speed out
            // where they push, so that their force does no work
            let free = match self.settled(&point, &jac, c.sliding, &stage.1) {
                Some(settled) => {
                    w = settled;
                    let free = self.free(s, &p, &w, report)?;
                    stage = self.constrained(&p, &w, c.sliding, &free, report)?;
                    free
                }
                None => free,
            };
            let point = Point {
                s,
                p: &p,
                w: &w,
                free: &free,
            };
            let arc = self.advance(&point, rest, c.sliding, &stage, report)?;
            report.contacts = report.contacts.union(c.sliding);
            // SEARCH for the first closing constraint along it
            if !last_round && report.impacts < max_impacts {
                let (h1, jac1) = self.model.contact(&arc.p);
                check_contact(&h1, &jac1)?;
                let seg = Segment {
                    p0: p,
                    w0: w,
                    p1: arc.p,
                    w1: arc.w,
                    h: rest,
                };
                let rate0 = jac * w;
                let rate1 = jac1 * arc.w;
                if let Some(Crossing { at, set }) =
                    self.first_crossing(&seg, &c, &jac, (&h, &rate0), (&h1, &rate1))?
                {
                    let part = self.advance(&point, at, c.sliding, &stage, report)?;
                    tracer.flight(&Flight {
                        s0: s,
                        h: at,
                        p0: &p,
                        w0: &w,
                        p1: &part.p,
                        w1: &part.w,
                        sliding: c.sliding,
                        resting: c.resting,
                        impulse: &part.impulse,
                    })?;
                    report.impulses += part.impulse;
                    (s, p, w) = (s + at, part.p, part.w);
                    (resolved, path.touched, path.held) = (IndexSet::EMPTY, set, c.sliding);
                    path.pressed = pressed_for(c.sliding, &part.impulse);
                    round += 1;
                    continue;
                }
            }
            tracer.flight(&Flight {
                s0: s,
                h: rest,
                p0: &p,
                w0: &w,
                p1: &arc.p,
                w1: &arc.w,
                sliding: c.sliding,
                resting: c.resting,
                impulse: &arc.impulse,
            })?;
            report.impulses += arc.impulse;
            if !short {
                return Ok((arc.p, arc.w));
            }
            // a step ended, not an event: the flight goes on from here,
            // classified again, without counting as a round
            (s, p, w) = (s + rest, arc.p, arc.w);
            (resolved, path.touched, path.held) = (IndexSet::EMPTY, IndexSet::EMPTY, c.sliding);
            path.pressed = pressed_for(c.sliding, &arc.impulse);
        }
    }
}
