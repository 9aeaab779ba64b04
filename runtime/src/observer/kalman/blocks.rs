//! `2N × 2N` matrices over the state `(q, v)`, kept as their four `N × N`
//! blocks (stable Rust has no `SMatrix<T, {2 * N}, {2 * N}>`).

use nalgebra::{RealField, SMatrix, SVector};

/// A `2N × 2N` matrix over the state `x = (q, v)`, as its four `N × N`
/// blocks:
///
/// $$B = \begin{pmatrix} B_{qq} & B_{qv} \\ B_{vq} & B_{vv} \end{pmatrix}.$$
///
/// The estimator's covariance `P` (with `vq = qvᵀ`), the transition of one
/// piece of flight `Φ` and the saltation matrix `Ξ` of an impact are all of
/// this type.
///
/// ```
/// use moreau_runtime::Blocks;
/// use nalgebra::Matrix2;
///
/// // the flow of q' = v, v' = 0 over τ = 0.5
/// let phi = Blocks { qq: Matrix2::identity(), qv: Matrix2::identity() * 0.5,
///                    vq: Matrix2::zeros(), vv: Matrix2::identity() };
/// assert_eq!(phi.entry(0, 2), 0.5);
/// assert_eq!(phi.mul(&phi).entry(1, 3), 1.0);
/// let p = Blocks::<f64, 2>::identity();
/// assert_eq!(phi.congruence(&p).entry(0, 0), 1.25);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocks<T: RealField + Copy, const N: usize> {
    /// Rows of `q`, columns of `q`.
    pub qq: SMatrix<T, N, N>,
    /// Rows of `q`, columns of `v`.
    pub qv: SMatrix<T, N, N>,
    /// Rows of `v`, columns of `q`.
    pub vq: SMatrix<T, N, N>,
    /// Rows of `v`, columns of `v`.
    pub vv: SMatrix<T, N, N>,
}

impl<T: RealField + Copy, const N: usize> Blocks<T, N> {
    /// The identity.
    pub fn identity() -> Self {
        Self {
            qq: SMatrix::identity(),
            qv: SMatrix::zeros(),
            vq: SMatrix::zeros(),
            vv: SMatrix::identity(),
        }
    }

    /// The block-diagonal matrix `diag(qq, vv)`.
    pub fn diagonal(qq: SMatrix<T, N, N>, vv: SMatrix<T, N, N>) -> Self {
        Self {
            qq,
            qv: SMatrix::zeros(),
            vq: SMatrix::zeros(),
            vv,
        }
    }

    /// Entry `(i, j)` of the `2N × 2N` matrix, `0 ≤ i, j < 2N` (`q` first);
    /// `None` out of range.
    pub fn get(&self, i: usize, j: usize) -> Option<T> {
        if i >= 2 * N || j >= 2 * N {
            return None;
        }
        let block = match (i < N, j < N) {
            (true, true) => &self.qq,
            (true, false) => &self.qv,
            (false, true) => &self.vq,
            (false, false) => &self.vv,
        };
        Some(block[(i % N, j % N)])
    }

    /// Entry `(i, j)`, zero out of range.
    pub fn entry(&self, i: usize, j: usize) -> T {
        self.get(i, j).unwrap_or_else(T::zero)
    }

    /// The product `self · other`.
    #[must_use]
    pub fn mul(&self, o: &Self) -> Self {
        Self {
            qq: self.qq * o.qq + self.qv * o.vq,
            qv: self.qq * o.qv + self.qv * o.vv,
            vq: self.vq * o.qq + self.vv * o.vq,
            vv: self.vq * o.qv + self.vv * o.vv,
        }
    }

    /// The product `self · (a, b)` with the stacked vector `(a, b)`, as its
    /// position and velocity parts.
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    /// use nalgebra::Vector1;
    ///
    /// let phi = Blocks { qq: Vector1::new(1.0), qv: Vector1::new(0.5), vq: Vector1::new(0.0), vv: Vector1::new(1.0) };
    /// assert_eq!(phi.apply(&Vector1::new(1.0), &Vector1::new(2.0)), (Vector1::new(2.0), Vector1::new(2.0)));
    /// ```
    #[must_use]
    #[inline]
    pub fn apply(&self, a: &SVector<T, N>, b: &SVector<T, N>) -> (SVector<T, N>, SVector<T, N>) {
        (self.qq * a + self.qv * b, self.vq * a + self.vv * b)
    }

    /// The transpose.
    #[must_use]
    pub fn transpose(&self) -> Self {
        Self {
            qq: self.qq.transpose(),
            qv: self.vq.transpose(),
            vq: self.qv.transpose(),
            vv: self.vv.transpose(),
        }
    }

    /// The sum `self + other`.
    #[must_use]
    #[inline]
    pub fn add(&self, o: &Self) -> Self {
        Self {
            qq: self.qq + o.qq,
            qv: self.qv + o.qv,
            vq: self.vq + o.vq,
            vv: self.vv + o.vv,
        }
    }

    /// The product `c · self`.
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    ///
    /// let b = Blocks::<f64, 2>::identity().scaled(3.0);
    /// assert_eq!((b.entry(0, 0), b.entry(3, 3), b.entry(0, 2)), (3.0, 3.0, 0.0));
    /// ```
    #[must_use]
    #[inline]
    pub fn scaled(&self, c: T) -> Self {
        Self {
            qq: self.qq * c,
            qv: self.qv * c,
            vq: self.vq * c,
            vv: self.vv * c,
        }
    }

    /// The outer product `x xᵀ` of the stacked vector `x = (a, b)`.
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    /// use nalgebra::Vector1;
    ///
    /// let b = Blocks::outer(&Vector1::new(2.0), &Vector1::new(3.0));
    /// assert_eq!((b.entry(0, 0), b.entry(0, 1), b.entry(1, 0), b.entry(1, 1)), (4.0, 6.0, 6.0, 9.0));
    /// ```
    #[must_use]
    #[inline]
    pub fn outer(a: &SVector<T, N>, b: &SVector<T, N>) -> Self {
        let ab = a * b.transpose();
        Self {
            qq: a * a.transpose(),
            qv: ab,
            vq: ab.transpose(),
            vv: b * b.transpose(),
        }
    }

    /// `self · p · selfᵀ` for a symmetric `p`, made exactly symmetric.
    #[must_use]
    pub fn congruence(&self, p: &Self) -> Self {
        self.mul(p).mul(&self.transpose()).symmetrized()
    }

    /// `self · p · selfᵀ` for a positive semi-definite `p`, plus the
    /// diagonal that covers the rounding of computing it, so that the
    /// result is positive semi-definite as computed, not only in exact
    /// arithmetic.
    ///
    /// Each entry of `B P Bᵀ`, two products of length `2N`, is off by at
    /// most about `4N ε c_i c_k`, with `c_i = Σ_j |B_ij| √P_jj` (since
    /// `|P_jk| ≤ √(P_jj P_kk)`); for any `x`, `Σ |x_i x_k| c_i c_k ≤ 2N Σ
    /// x_i² c_i²`, so adding `δ_i = 8N² ε c_i²` on the diagonal covers the
    /// error in every direction. What it guards against is cancellation:
    /// a Kalman update that pins a state down from a diffuse prior (the
    /// first samples, exact ones above all) leaves a posterior many
    /// orders below the prior, and errors of `ε` times the prior. In
    /// `f32`, the double pendulum's first update on exact samples, a
    /// velocity variance of 400 (`C_v = 20`) brought to 3e-3, left a
    /// covariance 0.3 % indefinite; the process noise was too small to
    /// repair it, the negative direction grew with every update, and half
    /// a second later the variances themselves were negative and the
    /// filter diverged (`tests/kalman.rs`,
    /// `exact_samples_keep_the_covariance_positive_in_f32`). Elsewhere the
    /// cover is `8N² ε` of the variance, far below any noise.
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    /// use nalgebra::Matrix1;
    ///
    /// // (I − K H) P (I − K H)ᵀ of a unit variance measured with the gain
    /// // k = 1 − 1e-6: the cover is 8 N² ε (N = 1) times each row's c_i²
    /// let b = Blocks { qq: Matrix1::new(1e-6), qv: Matrix1::zeros(), vq: Matrix1::zeros(), vv: Matrix1::new(1.0) };
    /// let p = Blocks::<f64, 1>::identity();
    /// let (covered, exact) = (b.congruence_covered(&p), b.congruence(&p));
    /// let unit = 8.0 * f64::EPSILON;
    /// assert_eq!(covered.vv[(0, 0)], exact.vv[(0, 0)] + unit);
    /// assert!((covered.qq[(0, 0)] - exact.qq[(0, 0)] - unit * 1e-12).abs() < 0.1 * unit * 1e-12);
    /// ```
    #[must_use]
    pub fn congruence_covered(&self, p: &Self) -> Self {
        let (sd_q, sd_v) = p.deviations();
        let abs = self.abs();
        let c_q = abs.qq * sd_q + abs.qv * sd_v;
        let c_v = abs.vq * sd_q + abs.vv * sd_v;
        self.congruence(p).cover(&c_q, &c_v)
    }

    /// The transition of a flow whose acceleration depends on neither `q`
    /// nor `v` over a time `h`: `Φ = (I, h I; 0, I)`.
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    ///
    /// let phi = Blocks::<f64, 2>::ballistic(0.5);
    /// assert_eq!((phi.entry(0, 2), phi.entry(1, 3), phi.entry(2, 0), phi.entry(3, 3)), (0.5, 0.5, 0.0, 1.0));
    /// ```
    pub fn ballistic(h: T) -> Self {
        Self {
            qq: SMatrix::identity(),
            qv: SMatrix::identity() * h,
            vq: SMatrix::zeros(),
            vv: SMatrix::identity(),
        }
    }

    /// [`congruence_covered`](Self::congruence_covered) by the
    /// [`ballistic`](Self::ballistic) transition `Φ = (I, h I; 0, I)`,
    /// `Φ P Φᵀ` of `P` (`self`), with the products by its exact `0`, `1`
    /// and `h I` blocks written out: each entry of a block product by them
    /// is one product of two numbers and exact zeros, so the result is the
    /// general form's to the bit (for finite entries). Four scaled
    /// additions of `N × N` blocks instead of sixteen block products, and
    /// no Jacobian to compute: the free flight of point masses under
    /// constant forces (Example 1, the three balls, the billiard), where
    /// the filter's propagation takes it (module `propagate`).
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    /// use nalgebra::Matrix2;
    ///
    /// let p = Blocks {
    ///     qq: Matrix2::new(2.0, 0.3, 0.3, 1.0),
    ///     qv: Matrix2::new(0.5, 0.1, -0.2, 0.4),
    ///     vq: Matrix2::new(0.5, -0.2, 0.1, 0.4),
    ///     vv: Matrix2::new(3.0, 0.2, 0.2, 2.0),
    /// };
    /// let h = 1e-3;
    /// let general = Blocks::ballistic(h).congruence_covered(&p);
    /// assert_eq!(p.ballistic_congruence_covered(h), general);
    /// ```
    #[must_use]
    pub fn ballistic_congruence_covered(&self, h: T) -> Self {
        // Φ P, its blocks: (P_qq + h P_vq, P_qv + h P_vv; P_vq, P_vv)
        let (x_qq, x_qv) = (self.qq + self.vq * h, self.qv + self.vv * h);
        // times Φᵀ = (I, 0; h I, I)
        let congruence = Self {
            qq: x_qq + x_qv * h,
            qv: x_qv,
            vq: self.vq + self.vv * h,
            vv: self.vv,
        }
        .symmetrized();
        // the cover of its rounding, `c = |Φ| √diag P`
        let (sd_q, sd_v) = self.deviations();
        congruence.cover(&(sd_q + sd_v * h), &sd_v)
    }

    /// The square roots of the diagonal (negative entries read as `0`),
    /// as its position and velocity parts.
    fn deviations(&self) -> (SVector<T, N>, SVector<T, N>) {
        let zero = T::zero();
        (
            self.qq.diagonal().map(|d| d.max(zero).sqrt()),
            self.vv.diagonal().map(|d| d.max(zero).sqrt()),
        )
    }

    /// `self`, a congruence `B P Bᵀ`, with the cover of its rounding added
    /// to the diagonal: `8N² ε c_i²`, `c = |B| √diag P` given as its
    /// position and velocity parts (see
    /// [`congruence_covered`](Self::congruence_covered)).
    fn cover(mut self, c_q: &SVector<T, N>, c_v: &SVector<T, N>) -> Self {
        let n: T = nalgebra::convert(N as f64);
        let unit = T::default_epsilon() * nalgebra::convert(8.0) * n * n;
        for i in 0..N {
            self.qq[(i, i)] += unit * c_q[i] * c_q[i];
            self.vv[(i, i)] += unit * c_v[i] * c_v[i];
        }
        self
    }

    /// The Joseph form of a Kalman update of the covariance `P` (`self`)
    /// by a measurement of the position alone, `H = (I 0)`, with the gain
    /// `K = (K_q; K_v)` and the measurement noise `R`:
    ///
    /// $$P^+ = (I - KH)\,P\,(I - KH)^T + K R K^T,$$
    ///
    /// the congruence covered for its rounding as in
    /// [`congruence_covered`](Self::congruence_covered), the result made
    /// exactly symmetric. `I − KH = (I − K_q, 0; −K_v, I)` has a zero and
    /// an identity block, and the products by them are left out: 7
    /// products of `N × N` blocks for the congruence instead of 16, and 6
    /// for `K R Kᵀ` instead of 8. A product by an exact `0` or `1` adds
    /// nothing and changes no bit, so the result is the general form's to
    /// the bit (for finite entries).
    ///
    /// ```
    /// use moreau_runtime::Blocks;
    /// use nalgebra::Matrix2;
    ///
    /// let p = Blocks {
    ///     qq: Matrix2::new(2.0, 0.3, 0.3, 1.0),
    ///     qv: Matrix2::new(0.5, 0.1, -0.2, 0.4),
    ///     vq: Matrix2::new(0.5, -0.2, 0.1, 0.4),
    ///     vv: Matrix2::new(3.0, 0.2, 0.2, 2.0),
    /// };
    /// let r = Matrix2::identity() * 0.1;
    /// let s_inv = (p.qq + r).try_inverse().unwrap();
    /// let (k_q, k_v) = (p.qq * s_inv, p.vq * s_inv);
    /// // the general form: B P Bᵀ + K R Kᵀ with B = I − KH
    /// let b = Blocks { qq: Matrix2::identity() - k_q, qv: Matrix2::zeros(), vq: -k_v, vv: Matrix2::identity() };
    /// let noise = Blocks {
    ///     qq: k_q * r * k_q.transpose(),
    ///     qv: k_q * r * k_v.transpose(),
    ///     vq: k_v * r * k_q.transpose(),
    ///     vv: k_v * r * k_v.transpose(),
    /// };
    /// let general = b.congruence_covered(&p).add(&noise).symmetrized();
    /// assert_eq!(p.joseph_position_update(&k_q, &k_v, &r), general);
    /// ```
    #[must_use]
    pub fn joseph_position_update(
        &self,
        k_q: &SMatrix<T, N, N>,
        k_v: &SMatrix<T, N, N>,
        r: &SMatrix<T, N, N>,
    ) -> Self {
        let a = SMatrix::<T, N, N>::identity() - k_q;
        // (I − KH) P, its four blocks
        let ap_qq = a * self.qq;
        let ap_qv = a * self.qv;
        let m_vq = self.vq - k_v * self.qq;
        let m_vv = self.vv - k_v * self.qv;
        // times (I − KH)ᵀ = (Aᵀ, −K_vᵀ; 0, I)
        let congruence = Self {
            qq: ap_qq * a.transpose(),
            qv: ap_qv - ap_qq * k_v.transpose(),
            vq: m_vq * a.transpose(),
            vv: m_vv - m_vq * k_v.transpose(),
        }
        .symmetrized();
        // the cover of its rounding, `c = |I − KH| √diag P`
        let (sd_q, sd_v) = self.deviations();
        let covered = congruence.cover(&(a.abs() * sd_q), &(k_v.abs() * sd_q + sd_v));
        // K R Kᵀ
        let (kr_q, kr_v) = (k_q * r, k_v * r);
        let noise = Self {
            qq: kr_q * k_q.transpose(),
            qv: kr_q * k_v.transpose(),
            vq: kr_v * k_q.transpose(),
            vv: kr_v * k_v.transpose(),
        };
        covered.add(&noise).symmetrized()
    }

    /// The entrywise absolute value.
    fn abs(&self) -> Self {
        Self {
            qq: self.qq.abs(),
            qv: self.qv.abs(),
            vq: self.vq.abs(),
            vv: self.vv.abs(),
        }
    }

    /// `(B + Bᵀ)/2`: the diagonal blocks symmetric, `vq = qvᵀ` exactly.
    #[must_use]
    pub fn symmetrized(&self) -> Self {
        let half: T = nalgebra::convert(0.5);
        let off = (self.qv + self.vq.transpose()) * half;
        Self {
            qq: (self.qq + self.qq.transpose()) * half,
            qv: off,
            vq: off.transpose(),
            vv: (self.vv + self.vv.transpose()) * half,
        }
    }

    /// Whether every entry is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        [&self.qq, &self.qv, &self.vq, &self.vv]
            .iter()
            .all(|m| m.iter().all(|x| x.is_finite()))
    }

    /// The trace.
    pub fn trace(&self) -> T {
        self.qq.trace() + self.vv.trace()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;

    #[test]
    fn entries_follow_the_blocks_and_products_the_full_matrix() {
        let b = Blocks {
            qq: Matrix2::new(1.0, 2.0, 3.0, 4.0),
            qv: Matrix2::new(5.0, 6.0, 7.0, 8.0),
            vq: Matrix2::new(9.0, 10.0, 11.0, 12.0),
            vv: Matrix2::new(13.0, 14.0, 15.0, 16.0),
        };
        assert_eq!(b.entry(1, 0), 3.0);
        assert_eq!(b.entry(0, 3), 6.0);
        assert_eq!(b.entry(2, 1), 10.0);
        assert_eq!(b.entry(3, 3), 16.0);
        assert_eq!(b.get(4, 0), None);
        // the product against the full 4 × 4 product
        let full = |b: &Blocks<f64, 2>| nalgebra::Matrix4::from_fn(|i, j| b.entry(i, j));
        let c = b.transpose().add(&Blocks::identity());
        assert_eq!(full(&b.mul(&c)), full(&b) * full(&c));
        assert_eq!(full(&b.transpose()), full(&b).transpose());
    }
}
