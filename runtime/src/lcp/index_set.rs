//! A set of constraint indices `0..K`.

use core::fmt;
use core::iter::FusedIterator;

/// A set of constraint indices `{i₁ < i₂ < …}` drawn from `0..K`, the `K`
/// constraints of a model: one flag per constraint, so it holds any `K`
/// the type system allows (nothing is silently dropped, whatever the number
/// of constraints).
///
/// This is the index set of one time step: the constraints that take part in
/// the step's LCP (see [`Lcp::solve`](crate::Lcp::solve)). It is `Copy`,
/// iterates in increasing index order and never allocates.
///
/// Indices `≥ K` are not constraints: [`insert`](Self::insert) leaves the set
/// unchanged for them (and says so), [`contains`](Self::contains) answers
/// `false` and [`from_indices`](Self::from_indices) answers `None`.
///
/// ```
/// use moreau_runtime::IndexSet;
///
/// let mut active = IndexSet::<4>::new();
/// assert!(active.insert(3));
/// assert!(active.insert(0));
/// assert!(!active.insert(3)); // already there
/// assert!(!active.insert(4)); // not a constraint of a model with K = 4
/// assert_eq!(active.len(), 2);
/// assert!(active.contains(0) && !active.contains(1));
/// assert_eq!(active.iter().collect::<Vec<_>>(), [0, 3]);
/// assert_eq!(active, IndexSet::from_indices(&[3, 0]).unwrap());
/// assert_eq!(format!("{active:?}"), "{0, 3}");
/// assert_eq!(IndexSet::<4>::full(3).bits(), Some(0b111));
/// // any number of constraints: the 40th of 40
/// let mut wide = IndexSet::<40>::new();
/// assert!(wide.insert(39));
/// assert_eq!(wide.first(), Some(39));
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct IndexSet<const K: usize>([bool; K]);

impl<const K: usize> Default for IndexSet<K> {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl<const K: usize> IndexSet<K> {
    /// The number of indices a set can hold: `0..K`.
    pub const CAPACITY: usize = K;

    /// The empty set `{}`.
    pub const EMPTY: Self = Self([false; K]);

    /// The empty set `{}`.
    #[inline]
    #[must_use]
    pub const fn new() -> Self {
        Self::EMPTY
    }

    /// The set `{0, 1, …, n − 1}`, or all of `0..K` when `n ≥ K`.
    #[inline]
    #[must_use]
    pub const fn full(n: usize) -> Self {
        let mut s = [false; K];
        let mut i = 0;
        while i < K && i < n {
            s[i] = true;
            i += 1;
        }
        Self(s)
    }

    /// The set whose members are the set bits of `bits` (bit `i` ⇔ index
    /// `i`), or `None` if a bit at `K` or above is set.
    #[must_use]
    pub const fn from_bits(bits: u64) -> Option<Self> {
        let mut s = [false; K];
        let mut i = 0;
        while i < 64 {
            if (bits >> i) & 1 == 1 {
                if i >= K {
                    return None;
                }
                s[i] = true;
            }
            i += 1;
        }
        Some(Self(s))
    }

    /// The set of the given indices, or `None` if one is `≥ K`. Repeated
    /// indices are kept once.
    #[must_use]
    pub const fn from_indices(indices: &[usize]) -> Option<Self> {
        let mut s = [false; K];
        let mut k = 0;
        while k < indices.len() {
            if indices[k] >= K {
                return None;
            }
            s[indices[k]] = true;
            k += 1;
        }
        Some(Self(s))
    }

    /// The set as bits (bit `i` set ⇔ `i` in the set), or `None` if it holds
    /// an index of 64 or more.
    #[must_use]
    pub const fn bits(self) -> Option<u64> {
        let mut bits = 0u64;
        let mut i = 0;
        while i < K {
            if self.0[i] {
                if i >= 64 {
                    return None;
                }
                bits |= 1 << i;
            }
            i += 1;
        }
        Some(bits)
    }

    /// Number of indices in the set, `|S|`.
    #[inline]
    #[must_use]
    pub const fn len(self) -> usize {
        let mut n = 0;
        let mut i = 0;
        while i < K {
            if self.0[i] {
                n += 1;
            }
            i += 1;
        }
        n
    }

    /// Whether the set is `{}`.
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.first().is_none()
    }

    /// Whether `index ∈ S` (always `false` for `index ≥ K`).
    #[inline]
    #[must_use]
    pub const fn contains(self, index: usize) -> bool {
        index < K && self.0[index]
    }

    /// Adds `index`: `S ← S ∪ {index}`. Returns whether the set changed, i.e.
    /// `false` if `index` was already there or is `≥ K` (then the set is
    /// left as it was).
    #[inline]
    pub fn insert(&mut self, index: usize) -> bool {
        if index >= K || self.0[index] {
            return false;
        }
        self.0[index] = true;
        true
    }

    /// Removes `index`: `S ← S ∖ {index}`. Returns whether it was there.
    #[inline]
    pub fn remove(&mut self, index: usize) -> bool {
        if !self.contains(index) {
            return false;
        }
        self.0[index] = false;
        true
    }

    /// The smallest index in the set, if any.
    #[inline]
    #[must_use]
    pub const fn first(self) -> Option<usize> {
        let mut i = 0;
        while i < K {
            if self.0[i] {
                return Some(i);
            }
            i += 1;
        }
        None
    }

    /// The largest index in the set, if any.
    #[inline]
    #[must_use]
    pub const fn last(self) -> Option<usize> {
        let mut i = K;
        while i > 0 {
            i -= 1;
            if self.0[i] {
                return Some(i);
            }
        }
        None
    }

    /// `S ∪ other`.
    #[inline]
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self(core::array::from_fn(|i| self.0[i] || other.0[i]))
    }

    /// `S ∩ other`.
    #[inline]
    #[must_use]
    pub fn intersection(self, other: Self) -> Self {
        Self(core::array::from_fn(|i| self.0[i] && other.0[i]))
    }

    /// `S ∖ other`.
    #[inline]
    #[must_use]
    pub fn difference(self, other: Self) -> Self {
        Self(core::array::from_fn(|i| self.0[i] && !other.0[i]))
    }

    /// Whether `S ⊆ other`.
    #[inline]
    #[must_use]
    pub fn is_subset(self, other: Self) -> bool {
        (0..K).all(|i| !self.0[i] || other.0[i])
    }

    /// The indices in increasing order, each below `K` (so they index a
    /// `K`-vector without a check of their own).
    #[inline]
    pub const fn iter(self) -> Iter<K> {
        Iter { set: self, next: 0 }
    }
}

impl<const K: usize> fmt::Debug for IndexSet<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

impl<const K: usize> IntoIterator for IndexSet<K> {
    type Item = usize;
    type IntoIter = Iter<K>;

    #[inline]
    fn into_iter(self) -> Iter<K> {
        self.iter()
    }
}

/// The indices of an [`IndexSet`], in increasing order (from
/// [`IndexSet::iter`]).
#[derive(Clone, Copy, Debug)]
pub struct Iter<const K: usize> {
    set: IndexSet<K>,
    next: usize,
}

impl<const K: usize> Iterator for Iter<K> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        while self.next < K {
            let i = self.next;
            self.next += 1;
            if self.set.0[i] {
                return Some(i);
            }
        }
        None
    }

    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = (self.next..K).filter(|&i| self.set.0[i]).count();
        (n, Some(n))
    }
}

impl<const K: usize> ExactSizeIterator for Iter<K> {}

impl<const K: usize> FusedIterator for Iter<K> {}

#[cfg(test)]
mod tests {
    use super::IndexSet;

    #[test]
    fn insert_remove_contains() {
        let mut s = IndexSet::<32>::new();
        assert!(s.is_empty());
        assert!(s.insert(5));
        assert!(s.insert(31));
        assert!(!s.insert(32));
        assert!(!s.insert(usize::MAX));
        assert_eq!(s.len(), 2);
        assert!(s.contains(31) && !s.contains(32) && !s.contains(usize::MAX));
        assert_eq!((s.first(), s.last()), (Some(5), Some(31)));
        assert!(s.remove(5));
        assert!(!s.remove(5));
        assert!(!s.remove(40));
        assert_eq!(s.bits(), Some(1 << 31));
    }

    #[test]
    fn full_and_set_operations() {
        assert_eq!(IndexSet::<32>::full(0), IndexSet::EMPTY);
        assert_eq!(IndexSet::<32>::full(32).len(), 32);
        assert_eq!(IndexSet::<32>::full(100).len(), 32);
        let a = IndexSet::<32>::from_indices(&[0, 1, 2]).unwrap();
        let b = IndexSet::from_indices(&[2, 3]).unwrap();
        assert_eq!(a.union(b), IndexSet::full(4));
        assert_eq!(a.intersection(b), IndexSet::from_bits(0b100).unwrap());
        assert_eq!(a.difference(b), IndexSet::from_bits(0b11).unwrap());
        assert!(a.intersection(b).is_subset(a) && !a.is_subset(b));
        assert_eq!(IndexSet::<32>::from_indices(&[1, 32]), None);
        assert_eq!(IndexSet::<32>::EMPTY.first(), None);
        assert_eq!(IndexSet::<32>::EMPTY.last(), None);
    }

    #[test]
    fn iterates_in_increasing_order() {
        let s = IndexSet::<8>::from_bits(0b1010_0110).unwrap();
        let mut it = s.iter();
        assert_eq!(it.len(), 4);
        assert_eq!(it.next(), Some(1));
        assert_eq!(it.len(), 3);
        let mut seen = [0usize; 4];
        for (k, i) in s.into_iter().enumerate() {
            seen[k] = i;
        }
        assert_eq!(seen, [1, 2, 5, 7]);
    }

    /// Any `K`: the 33rd and 70th of 70 constraints are held, not dropped.
    #[test]
    fn holds_any_number_of_constraints() {
        let mut s = IndexSet::<70>::new();
        assert!(s.insert(32) && s.insert(69) && s.insert(0));
        assert!(!s.insert(70));
        assert_eq!(s.iter().collect::<Vec<_>>(), [0, 32, 69]);
        assert_eq!((s.first(), s.last(), s.len()), (Some(0), Some(69), 3));
        assert_eq!(s.bits(), None);
        assert_eq!(IndexSet::<70>::full(70).len(), 70);
        assert_eq!(
            IndexSet::<40>::from_bits(1 << 39).unwrap().first(),
            Some(39)
        );
        assert_eq!(IndexSet::<40>::from_bits(1 << 40), None);
    }
}
