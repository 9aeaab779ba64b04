//! A set of constraint indices, as a bitmask.

use core::fmt;
use core::iter::FusedIterator;

/// A set of constraint indices `{i₁ < i₂ < …}` drawn from `0..IndexSet::CAPACITY`,
/// stored as the bits of a `u32` (bit `i` set ⇔ `i` in the set).
///
/// This is the index set of one time step: the constraints that take part in
/// the step's LCP (see [`Lcp::solve`](crate::Lcp::solve)). It is `Copy`,
/// ordered by its bits, iterates in increasing index order and never
/// allocates.
///
/// Indices `≥ CAPACITY` can't be held: [`insert`](Self::insert) leaves the set
/// unchanged for them, [`contains`](Self::contains) answers `false` and
/// [`from_indices`](Self::from_indices) answers `None`.
///
/// ```
/// use moreau_runtime::IndexSet;
///
/// let mut active = IndexSet::new();
/// assert!(active.insert(3));
/// assert!(active.insert(0));
/// assert!(!active.insert(3)); // already there
/// assert_eq!(active.len(), 2);
/// assert!(active.contains(0) && !active.contains(1));
/// assert_eq!(active.iter().collect::<Vec<_>>(), [0, 3]);
/// assert_eq!(active, IndexSet::from_indices(&[3, 0]).unwrap());
/// assert_eq!(format!("{active:?}"), "{0, 3}");
/// assert_eq!(IndexSet::full(3).bits(), 0b111);
/// ```
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct IndexSet(u32);

impl IndexSet {
    /// The number of indices a set can hold: `0..32`.
    pub const CAPACITY: usize = 32;

    /// The empty set `{}`.
    pub const EMPTY: Self = Self(0);

    /// The empty set `{}`.
    #[inline]
    #[must_use]
    pub const fn new() -> Self {
        Self(0)
    }

    /// The set `{0, 1, …, n − 1}`, or all of `0..CAPACITY` when `n ≥ CAPACITY`.
    #[inline]
    #[must_use]
    pub const fn full(n: usize) -> Self {
        if n >= Self::CAPACITY {
            Self(u32::MAX)
        } else {
            Self((1u32 << n) - 1)
        }
    }

    /// The set whose members are the set bits of `bits` (bit `i` ⇔ index `i`).
    #[inline]
    #[must_use]
    pub const fn from_bits(bits: u32) -> Self {
        Self(bits)
    }

    /// The set of the given indices, or `None` if one is `≥ CAPACITY`.
    /// Repeated indices are kept once.
    #[must_use]
    pub const fn from_indices(indices: &[usize]) -> Option<Self> {
        let mut bits = 0u32;
        let mut k = 0;
        while k < indices.len() {
            if indices[k] >= Self::CAPACITY {
                return None;
            }
            bits |= 1 << indices[k];
            k += 1;
        }
        Some(Self(bits))
    }

    /// The bits of the set: bit `i` is set ⇔ `i` is in the set.
    #[inline]
    #[must_use]
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// Number of indices in the set, `|S|`.
    #[inline]
    #[must_use]
    pub const fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set is `{}`.
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether `index ∈ S` (always `false` for `index ≥ CAPACITY`).
    #[inline]
    #[must_use]
    pub const fn contains(self, index: usize) -> bool {
        index < Self::CAPACITY && (self.0 >> index) & 1 == 1
    }

    /// Adds `index`: `S ← S ∪ {index}`. Returns whether the set changed, i.e.
    /// `false` if `index` was already there or is `≥ CAPACITY` (then the set
    /// is left as it was).
    #[inline]
    pub fn insert(&mut self, index: usize) -> bool {
        if index >= Self::CAPACITY || self.contains(index) {
            return false;
        }
        self.0 |= 1 << index;
        true
    }

    /// Removes `index`: `S ← S ∖ {index}`. Returns whether it was there.
    #[inline]
    pub fn remove(&mut self, index: usize) -> bool {
        if !self.contains(index) {
            return false;
        }
        self.0 &= !(1 << index);
        true
    }

    /// The smallest index in the set, if any.
    #[inline]
    #[must_use]
    pub const fn first(self) -> Option<usize> {
        if self.0 == 0 {
            None
        } else {
            Some(self.0.trailing_zeros() as usize)
        }
    }

    /// The largest index in the set, if any.
    #[inline]
    #[must_use]
    pub const fn last(self) -> Option<usize> {
        if self.0 == 0 {
            None
        } else {
            Some(31 - self.0.leading_zeros() as usize)
        }
    }

    /// `S ∪ other`.
    #[inline]
    #[must_use]
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// `S ∩ other`.
    #[inline]
    #[must_use]
    pub const fn intersection(self, other: Self) -> Self {
        Self(self.0 & other.0)
    }

    /// `S ∖ other`.
    #[inline]
    #[must_use]
    pub const fn difference(self, other: Self) -> Self {
        Self(self.0 & !other.0)
    }

    /// Whether `S ⊆ other`.
    #[inline]
    #[must_use]
    pub const fn is_subset(self, other: Self) -> bool {
        self.0 & !other.0 == 0
    }

    /// The indices in increasing order.
    #[inline]
    pub const fn iter(self) -> Iter {
        Iter(self.0)
    }
}

impl fmt::Debug for IndexSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

impl IntoIterator for IndexSet {
    type Item = usize;
    type IntoIter = Iter;

    #[inline]
    fn into_iter(self) -> Iter {
        self.iter()
    }
}

/// The indices of an [`IndexSet`], in increasing order (from
/// [`IndexSet::iter`]).
#[derive(Clone, Copy, Debug)]
pub struct Iter(u32);

impl Iterator for Iter {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let index = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(index)
    }

    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.0.count_ones() as usize;
        (n, Some(n))
    }
}

impl ExactSizeIterator for Iter {}

impl FusedIterator for Iter {}

#[cfg(test)]
mod tests {
    use super::IndexSet;

    #[test]
    fn insert_remove_contains() {
        let mut s = IndexSet::new();
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
        assert_eq!(s.bits(), 1 << 31);
    }

    #[test]
    fn full_and_set_operations() {
        assert_eq!(IndexSet::full(0), IndexSet::EMPTY);
        assert_eq!(IndexSet::full(32).len(), 32);
        assert_eq!(IndexSet::full(100).len(), 32);
        let a = IndexSet::from_indices(&[0, 1, 2]).unwrap();
        let b = IndexSet::from_indices(&[2, 3]).unwrap();
        assert_eq!(a.union(b), IndexSet::full(4));
        assert_eq!(a.intersection(b), IndexSet::from_bits(0b100));
        assert_eq!(a.difference(b), IndexSet::from_bits(0b11));
        assert!(a.intersection(b).is_subset(a) && !a.is_subset(b));
        assert_eq!(IndexSet::from_indices(&[1, 32]), None);
        assert_eq!(IndexSet::EMPTY.first(), None);
        assert_eq!(IndexSet::EMPTY.last(), None);
    }

    #[test]
    fn iterates_in_increasing_order() {
        let s = IndexSet::from_bits(0b1010_0110);
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
}
