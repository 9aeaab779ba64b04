//! The one output layout: which quantities a model provides, their shapes,
//! and where each stored entry sits in the flat list of outputs.
//!
//! Everything downstream walks this list: the macro schedules
//! [`Mechanics::outputs`](super::Mechanics::outputs) once, cuts one
//! sub-schedule per generated method with [`Layout::indices`], and names
//! each entry from its [`Slot`]. Adding a quantity means adding a variant
//! here and its expressions in [`Mechanics::derive`](super::Mechanics::derive);
//! nothing else lists the quantities.

/// One of the quantities a model provides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Quantity {
    /// The mass matrix `M` (`N × N`, symmetric: only `row ≤ col` is stored).
    Mass,
    /// The Coriolis matrix `C` (`N × N`).
    Coriolis,
    /// The gravity vector `G = ∂V/∂q` (`N`).
    Gravity,
    /// The total force `F = C v + G − Q` (`N`).
    Force,
    /// The gaps `h` (`K`).
    Gap,
    /// The gap Jacobian `J = ∂h/∂q` (`K × N`).
    Jacobian,
    /// `∂F/∂q` (`N × N`), row `i` = `∇_q F_i`.
    ForceDq,
    /// `∂F/∂v` (`N × N`), row `i` = `∇_v F_i`.
    ForceDv,
    /// `∂(M(q) v)/∂q` at fixed `v` (`N × N`): entry `(i, j)` is
    /// `Σ_k ∂M_ik/∂q_j v_k`. With `v` replaced by any vector `w`, the
    /// derivative of `M(q) w` that the Jacobian of `M⁻¹(q)(…)` needs.
    MassDq,
    /// `∂(J(q) v)/∂q` at fixed `v` (`K × N`): entry `(i, j)` is
    /// `Σ_k ∂²h_i/∂q_j ∂q_k v_k`, what the saltation matrix of Newton's
    /// impact law needs.
    JacobianDq,
}

impl Quantity {
    /// Every quantity, in the order of the flat output list.
    pub const ALL: [Quantity; 10] = [
        Quantity::Mass,
        Quantity::Coriolis,
        Quantity::Gravity,
        Quantity::Force,
        Quantity::Gap,
        Quantity::Jacobian,
        Quantity::ForceDq,
        Quantity::ForceDv,
        Quantity::MassDq,
        Quantity::JacobianDq,
    ];

    /// The quantities of the fused evaluation `eval`: `M`, `C`, `G`, `F`,
    /// `h`, `J`.
    pub const EVAL: [Quantity; 6] = [
        Quantity::Mass,
        Quantity::Coriolis,
        Quantity::Gravity,
        Quantity::Force,
        Quantity::Gap,
        Quantity::Jacobian,
    ];

    /// `(rows, cols)` for a model of `n` coordinates and `k` constraints
    /// (vectors are one column).
    #[must_use]
    pub fn shape(self, n: usize, k: usize) -> (usize, usize) {
        match self {
            Quantity::Mass
            | Quantity::Coriolis
            | Quantity::ForceDq
            | Quantity::ForceDv
            | Quantity::MassDq => (n, n),
            Quantity::Gravity | Quantity::Force => (n, 1),
            Quantity::Gap => (k, 1),
            Quantity::Jacobian | Quantity::JacobianDq => (k, n),
        }
    }

    /// Whether the quantity is a symmetric matrix stored by its upper
    /// triangle.
    #[must_use]
    pub fn is_symmetric(self) -> bool {
        self == Quantity::Mass
    }

    /// Whether the quantity is a vector (entries indexed by row only).
    #[must_use]
    pub fn is_vector(self) -> bool {
        matches!(self, Quantity::Gravity | Quantity::Force | Quantity::Gap)
    }

    /// A short lowercase stem for names of its entries (`m` for `M`,
    /// `dfdq` for `∂F/∂q`).
    #[must_use]
    pub fn stem(self) -> &'static str {
        match self {
            Quantity::Mass => "m",
            Quantity::Coriolis => "c",
            Quantity::Gravity => "g",
            Quantity::Force => "f",
            Quantity::Gap => "h",
            Quantity::Jacobian => "j",
            Quantity::ForceDq => "dfdq",
            Quantity::ForceDv => "dfdv",
            Quantity::MassDq => "dmdq",
            Quantity::JacobianDq => "djdq",
        }
    }
}

/// Where one output belongs: a quantity and an entry (`col` is 0 for
/// vectors).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Slot {
    /// The quantity.
    pub quantity: Quantity,
    /// The row (the index for vectors).
    pub row: usize,
    /// The column (0 for vectors).
    pub col: usize,
}

impl Slot {
    /// The entry in mathematical notation: `M[0,1] = M[1,0]`, `G[2]`,
    /// `∂F[0]/∂q[1]`.
    #[must_use]
    pub fn describe(self) -> String {
        let (i, j) = (self.row, self.col);
        match self.quantity {
            Quantity::Mass if i == j => format!("M[{i},{j}]"),
            Quantity::Mass => format!("M[{i},{j}] = M[{j},{i}]"),
            Quantity::Coriolis => format!("C[{i},{j}]"),
            Quantity::Gravity => format!("G[{i}]"),
            Quantity::Force => format!("F[{i}]"),
            Quantity::Gap => format!("h[{i}]"),
            Quantity::Jacobian => format!("J[{i},{j}]"),
            Quantity::ForceDq => format!("∂F[{i}]/∂q[{j}]"),
            Quantity::ForceDv => format!("∂F[{i}]/∂v[{j}]"),
            Quantity::MassDq => format!("∂(M v)[{i}]/∂q[{j}]"),
            Quantity::JacobianDq => format!("∂(J v)[{i}]/∂q[{j}]"),
        }
    }
}

/// The flat list of outputs of a model with `n` coordinates and `k`
/// constraints: every quantity of [`Quantity::ALL`] in order, each by its
/// stored entries (row by row; `M` by its upper triangle).
///
/// ```
/// use moreau_sym::{Layout, Quantity, Slot};
/// let layout = Layout::new(2, 1);
/// // M is stored as M[0,0], M[0,1], M[1,1]; C follows.
/// assert_eq!(layout.len(Quantity::Mass), 3);
/// let m10 = Slot { quantity: Quantity::Mass, row: 1, col: 0 };
/// assert_eq!(layout.index(m10), 1);
/// assert_eq!(layout.slot(3), Slot { quantity: Quantity::Coriolis, row: 0, col: 0 });
/// assert_eq!(layout.indices(&[Quantity::Gap]), vec![layout.start(Quantity::Gap)]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Number of coordinates `N`.
    pub n: usize,
    /// Number of constraints `K`.
    pub k: usize,
}

impl Layout {
    /// The layout of a model with `n` coordinates and `k` constraints.
    #[must_use]
    pub fn new(n: usize, k: usize) -> Layout {
        Layout { n, k }
    }

    /// Number of stored entries of `q`.
    #[must_use]
    pub fn len(&self, q: Quantity) -> usize {
        let (rows, cols) = q.shape(self.n, self.k);
        if q.is_symmetric() {
            rows * (rows + 1) / 2
        } else {
            rows * cols
        }
    }

    /// Number of outputs of every quantity together.
    #[must_use]
    pub fn total(&self) -> usize {
        Quantity::ALL.iter().map(|&q| self.len(q)).sum()
    }

    /// Index of the first entry of `q`.
    #[must_use]
    pub fn start(&self, q: Quantity) -> usize {
        Quantity::ALL
            .iter()
            .take_while(|&&o| o != q)
            .map(|&o| self.len(o))
            .sum()
    }

    /// The index of `slot` (for `M`, `(i, j)` and `(j, i)` are one entry).
    #[must_use]
    pub fn index(&self, slot: Slot) -> usize {
        let (rows, cols) = slot.quantity.shape(self.n, self.k);
        let offset = if slot.quantity.is_symmetric() {
            let (i, j) = (slot.row.min(slot.col), slot.row.max(slot.col));
            i * rows - i * (i + 1) / 2 + j
        } else {
            slot.row * cols + slot.col
        };
        self.start(slot.quantity) + offset
    }

    /// The stored entries of `q`, in order.
    pub fn slots(&self, q: Quantity) -> impl Iterator<Item = Slot> + use<> {
        let (rows, cols) = q.shape(self.n, self.k);
        let symmetric = q.is_symmetric();
        (0..rows).flat_map(move |row| {
            let first = if symmetric { row } else { 0 };
            (first..cols).map(move |col| Slot {
                quantity: q,
                row,
                col,
            })
        })
    }

    /// The slot stored at `index` (the inverse of [`Layout::index`], giving
    /// `row ≤ col` for `M`).
    ///
    /// # Panics
    /// If `index ≥` [`Layout::total`].
    #[must_use]
    pub fn slot(&self, index: usize) -> Slot {
        let q = Quantity::ALL
            .into_iter()
            .find(|&q| index < self.start(q) + self.len(q))
            .expect("output index out of range");
        self.slots(q)
            .nth(index - self.start(q))
            .expect("index within the quantity")
    }

    /// The indices of every stored entry of `qs`, quantity by quantity.
    #[must_use]
    pub fn indices(&self, qs: &[Quantity]) -> Vec<usize> {
        qs.iter()
            .flat_map(|&q| {
                let start = self.start(q);
                start..start + self.len(q)
            })
            .collect()
    }
}
