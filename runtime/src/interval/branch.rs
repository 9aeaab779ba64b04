//! Best-first branch and bound for the supremum of a function over a box
//! `Q × W` (configurations × directions or velocities), from an upper
//! bound over each cell and a value at a point of it.
//!
//! The cells live in a `std` binary heap (a max-heap on their upper
//! bounds): this is a design-time tool, so it allocates, and it exists
//! only with the `std` feature. The heap holds at most `boxes` cells.
//!
//! Each step pops the cell with the largest upper bound `U`. The supremum
//! is at most `U` (every other cell is at most `U`, and every discarded
//! cell is accounted for below) and at least the best value `w` seen at a
//! point. The search stops when `U − w ≤ tolerance · |w|` (converged) or
//! when the budget of evaluated cells is spent, and returns
//! `max(U, largest upper bound of the pruned cells)`: a cell is pruned
//! when its upper bound is below `w`, so it cannot hold the supremum, but
//! its bound still enters the result (the point values are computed in
//! floating point, not proven, and must not decide the proof). Otherwise
//! it bisects the popped cell along the coordinate that is widest relative
//! to the root box, and bounds both halves.

use std::collections::BinaryHeap;

use super::Interval;

/// A cell `Q × W`: a box of configurations and a box of directions or
/// velocities (all points for a search over `Q` only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cell<const N: usize> {
    pub q: [Interval; N],
    pub w: [Interval; N],
}

impl<const N: usize> Cell<N> {
    /// Bisects along coordinate `hint` (`q_k` for `k < N`, `w_{k−N}`
    /// above), or, without a hint, along the coordinate widest relative to
    /// `root` (`q` first, then `w` if `split_w`).
    fn split(&self, root: &Self, split_w: bool, hint: Option<usize>) -> (Self, Self) {
        if let Some(k) = hint.filter(|&k| k < N || (split_w && k < 2 * N)) {
            return self.split_at(k);
        }
        let mut best = (0.0, 0usize);
        let dims = if split_w { 2 * N } else { N };
        for k in 0..dims {
            let (x, r) = if k < N {
                (self.q[k], root.q[k])
            } else {
                (self.w[k - N], root.w[k - N])
            };
            let rw = r.width();
            if rw > 0.0 {
                let rel = x.width() / rw;
                if rel > best.0 {
                    best = (rel, k);
                }
            }
        }
        self.split_at(best.1)
    }

    fn split_at(&self, k: usize) -> (Self, Self) {
        let (mut a, mut b) = (*self, *self);
        if k < N {
            (a.q[k], b.q[k]) = self.q[k].bisect();
        } else {
            (a.w[k - N], b.w[k - N]) = self.w[k - N].bisect();
        }
        (a, b)
    }
}

/// What the search found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Outcome<const N: usize> {
    /// The proven upper bound of the supremum.
    pub bound: f64,
    /// The largest value seen at a point.
    pub witness: f64,
    /// The cell whose upper bound is the result (the root when every cell
    /// was pruned or empty).
    pub worst: Cell<N>,
    /// Cells bounded.
    pub boxes: usize,
    /// Whether `bound − witness ≤ tolerance · |witness|`.
    pub converged: bool,
}

struct Entry<const N: usize> {
    upper: f64,
    cell: Cell<N>,
    hint: Option<usize>,
}

impl<const N: usize> PartialEq for Entry<N> {
    fn eq(&self, other: &Self) -> bool {
        self.upper.total_cmp(&other.upper).is_eq()
    }
}
impl<const N: usize> Eq for Entry<N> {}
impl<const N: usize> PartialOrd for Entry<N> {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl<const N: usize> Ord for Entry<N> {
    fn cmp(&self, other: &Self) -> core::cmp::Ordering {
        self.upper.total_cmp(&other.upper)
    }
}

/// The supremum over `root` of the function whose cell bound and point
/// value `eval` returns: `(U, Some(w), hint)`, `U = −∞` for a cell outside
/// the domain (it is dropped), `U` NaN read as `+∞`; `hint` the coordinate
/// to bisect the cell along, if the bound knows which one it depends on
/// most (else the widest relative to the root).
pub(crate) fn maximize<const N: usize>(
    root: Cell<N>,
    split_w: bool,
    boxes: usize,
    tolerance: f64,
    mut eval: impl FnMut(&Cell<N>) -> (f64, Option<f64>, Option<usize>),
) -> Outcome<N> {
    let mut count = 0usize;
    let mut witness = f64::NEG_INFINITY;
    let mut pruned = f64::NEG_INFINITY;
    let mut heap = BinaryHeap::new();
    let mut push = |cell: Cell<N>,
                    heap: &mut BinaryHeap<Entry<N>>,
                    witness: &mut f64,
                    pruned: &mut f64,
                    count: &mut usize| {
        let (upper, value, hint) = eval(&cell);
        let upper = if upper.is_nan() { f64::INFINITY } else { upper };
        *count += 1;
        if let Some(v) = value.filter(|v| !v.is_nan()) {
            *witness = witness.max(v);
        }
        if upper == f64::NEG_INFINITY {
            return;
        }
        if upper < *witness {
            *pruned = pruned.max(upper);
        } else {
            heap.push(Entry { upper, cell, hint });
        }
    };
    push(root, &mut heap, &mut witness, &mut pruned, &mut count);
    loop {
        let Some(top) = heap.pop() else {
            return Outcome {
                bound: pruned,
                witness,
                worst: root,
                boxes: count,
                converged: true,
            };
        };
        let gap = top.upper - witness;
        let converged = gap <= tolerance * witness.abs();
        if converged || count + 2 > boxes.max(1) {
            return Outcome {
                bound: top.upper.max(pruned),
                witness,
                worst: top.cell,
                boxes: count,
                converged,
            };
        }
        let (a, b) = top.cell.split(&root, split_w, top.hint);
        push(a, &mut heap, &mut witness, &mut pruned, &mut count);
        push(b, &mut heap, &mut witness, &mut pruned, &mut count);
        // pruning the heap itself is not needed: cells below the witness
        // are never popped before the search stops
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::enclosure::Enclose;

    #[test]
    fn finds_the_maximum_of_a_concave_function() {
        // f(x, y) = 1 − x² − (y − 0.3)² over [−1, 1]²: max 1 at (0, 0.3)
        let iv = |a, b| Interval::new(a, b).unwrap();
        let root = Cell {
            q: [iv(-1.0, 1.0)],
            w: [iv(-1.0, 1.0)],
        };
        let out = maximize(root, true, 10_000, 1e-3, |c| {
            let f = |x: Interval, y: Interval| {
                Interval::point(1.0) - x.powi(2) - (y - Interval::point(0.3)).powi(2)
            };
            let (x, y) = (c.q[0].mid(), c.w[0].mid());
            let value = f(Interval::point(x), Interval::point(y)).lo();
            (f(c.q[0], c.w[0]).hi(), Some(value), None)
        });
        assert!(out.converged);
        assert!(out.bound >= 1.0 && out.bound <= 1.0 + 1e-3, "{out:?}");
        assert!(out.witness <= 1.0 && out.witness >= 1.0 - 1e-3);
        assert!(out.worst.q[0].contains(0.0) || out.worst.q[0].width() < 0.1);
        // a tiny budget stops early, still with a bound
        let out = maximize(root, true, 3, 0.0, |c| {
            let f = |x: Interval| Interval::point(1.0) - (x - Interval::point(0.3)).powi(2);
            let at = f(Interval::point(c.q[0].mid())).lo();
            (f(c.q[0]).hi(), Some(at), None)
        });
        assert!(!out.converged && out.bound >= 1.0 && out.boxes <= 3);
    }
}
