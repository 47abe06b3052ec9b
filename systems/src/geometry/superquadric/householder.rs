//! Tangent and binormal of a surface normal m by a Householder reflection (eqs. 4.14, 4.15,
//! 4.32) and their derivatives with respect to m (eq. 4.34), in closed form.
//!
//! The thesis reflects along h = m + |m| e_x, which is singular when m points along -x
//! (h = 0). Here the axis is the coordinate axis e_k with the largest |m_k| and the sign
//! sigma = sgn(m_k): h = m + sigma |m| e_k, so |h|^2 = 2 |m| (|m| + |m_k|) >= 2 |m|^2 > 0.
//! With beta = 2/|h|^2 and the two other axes j1, j2 (cyclic after k), the reflected axes
//!
//! t = e_j1 - beta m_j1 h,   b = e_j2 - beta m_j2 h
//!
//! are unit, orthogonal to each other and to m (for k = x, sigma = +1 this is eq. 4.32, whose
//! factors h_x/h_x are 1: erratum E-000-10). Derivatives (v any vector, j = j1 or j2):
//!
//! v^T dt/dm = beta^2 (v.h) m_j (2 m + sigma |m| e_k + |m_k| m^) - beta (v.h) e_j
//!             - beta m_j (v + sigma v_k m^),
//!
//! from dh/dm = I + sigma e_k m^^T and dbeta/dm = -beta^2 (2 m + sigma |m| e_k + |m_k| m^).
//! This is the thesis's eq. 4.34 with the prefactor 2 n_y/|h|^2 multiplied in: no 1/n_y or
//! 1/n_z appears, so there is no 0/0 at n_y = 0 or n_z = 0.

use glam::DVec3;

/// Tangent frame of a normal and what is needed for its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Frame {
    /// First tangent (thesis t_j).
    pub t: DVec3,
    /// Second tangent (thesis b_j).
    pub b: DVec3,
    /// Reflection axis k (0, 1, 2).
    pub axis: usize,
    m: DVec3,
    m_hat: DVec3,
    h: DVec3,
    beta: f64,
    sigma: f64,
    /// 2 m + sigma |m| e_k + |m_k| m^ (times beta^2 below).
    w: DVec3,
}

impl Frame {
    /// Frame of `m` reflected along the axis where |m_k| is largest; `None` for a zero or
    /// non-finite `m`.
    #[inline]
    pub fn new(m: DVec3) -> Option<Self> {
        let am = m.abs();
        let axis = if am.x >= am.y && am.x >= am.z {
            0
        } else if am.y >= am.z {
            1
        } else {
            2
        };
        Self::with_axis(m, axis)
    }

    /// Frame of `m` reflected along axis `axis` (needs m_axis != 0 unless the other two
    /// components are nonzero; `None` when |h| = 0 or anything is not finite).
    #[inline]
    pub fn with_axis(m: DVec3, axis: usize) -> Option<Self> {
        let mn = m.length();
        if !(mn.is_finite() && mn > 0.0) {
            return None;
        }
        let sigma = if m[axis] >= 0.0 { 1.0 } else { -1.0 };
        let mut h = m;
        h[axis] += sigma * mn;
        let h2 = h.length_squared();
        if h2.is_nan() || h2 <= 0.0 {
            return None;
        }
        let beta = 2.0 / h2;
        let (j1, j2) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut t = -beta * m[j1] * h;
        t[j1] += 1.0;
        let mut b = -beta * m[j2] * h;
        b[j2] += 1.0;
        let m_hat = m / mn;
        let mut w = 2.0 * m + m[axis].abs() * m_hat;
        w[axis] += sigma * mn;
        Some(Self {
            t,
            b,
            axis,
            m,
            m_hat,
            h,
            beta,
            sigma,
            w,
        })
    }

    #[inline]
    fn d_col(&self, j: usize, v: DVec3) -> DVec3 {
        let vh = v.dot(self.h);
        let mj = self.m[j];
        let bb = self.beta;
        let mut r = (bb * bb * vh * mj) * self.w
            - (bb * mj) * (v + (self.sigma * v[self.axis]) * self.m_hat);
        r[j] -= bb * vh;
        r
    }

    /// v^T dt/dm.
    #[inline]
    pub fn dt(&self, v: DVec3) -> DVec3 {
        self.d_col((self.axis + 1) % 3, v)
    }

    /// v^T db/dm.
    #[inline]
    pub fn db(&self, v: DVec3) -> DVec3 {
        self.d_col((self.axis + 2) % 3, v)
    }
}
