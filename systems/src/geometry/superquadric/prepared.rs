//! Per-call constants of one superquadric and the hot kernels built on them: inside function,
//! gradient and diagonal second derivatives in one pass (3 powers per point), the support
//! map and the radial projection onto the surface.
//!
//! Support map. For a body-frame direction w the support point maximises w . x subject to
//! sum |x_i/a_i|^g_i <= 1. With c_i = |w_i| a_i, y_i = |x_i|/a_i and the dual exponents
//! p_i = g_i/(g_i - 1), the Lagrange conditions give y_i = (c_i mu / g_i)^(1/(g_i - 1)) with
//! mu solving sum_i (c_i mu / g_i)^p_i = 1. Equal exponents: y_i = (c_i / ||c||_p)^(p - 1),
//! closed form. Unequal exponents: psi(t) = ln sum_i exp(p_i (ln(c_i/g_i) + t)), t = ln mu, is
//! convex and increasing (slope in [p_min, p_max] within (1, 2]); Newton from any start lands
//! right of the root after one step and then decreases monotonically to it, so the iteration
//! cannot diverge or cycle.

use glam::DVec3;

/// How y^(g - 2) is evaluated on one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Pow {
    /// g = 2: y^0 = 1.
    One,
    /// Integer g - 2 (up to 16): repeated multiplication.
    Int(i32),
    /// General exponent g - 2: `powf`.
    Real(f64),
}

impl Pow {
    fn new(e: f64) -> Self {
        if e == 0.0 {
            Pow::One
        } else if e.fract() == 0.0 && e <= 16.0 {
            Pow::Int(e as i32)
        } else {
            Pow::Real(e)
        }
    }

    #[inline(always)]
    fn apply(self, y: f64) -> f64 {
        match self {
            Pow::One => 1.0,
            // y^1 and y^2 as the compiler's `powi` computes them (bit for bit, no call)
            Pow::Int(1) => y,
            Pow::Int(2) => y * y,
            Pow::Int(n) => y.powi(n),
            Pow::Real(e) => y.powf(e),
        }
    }
}

/// x^e for x >= 0 and e in (0, 1], with square- and cube-root fast paths for e = 1/2, 1/3,
/// 1/4, 1/8 (1/3: the superballs of g = 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Root {
    One,
    Half,
    Third,
    Quarter,
    Eighth,
    Real(f64),
}

impl Root {
    fn new(e: f64) -> Self {
        if e == 1.0 {
            Root::One
        } else if e == 0.5 {
            Root::Half
        } else if e == 1.0 / 3.0 {
            Root::Third
        } else if e == 0.25 {
            Root::Quarter
        } else if e == 0.125 {
            Root::Eighth
        } else {
            Root::Real(e)
        }
    }

    #[inline(always)]
    fn apply(self, x: f64) -> f64 {
        match self {
            Root::One => x,
            Root::Half => x.sqrt(),
            Root::Third => x.cbrt(),
            Root::Quarter => x.sqrt().sqrt(),
            Root::Eighth => x.sqrt().sqrt().sqrt(),
            Root::Real(e) => x.powf(e),
        }
    }
}

/// Inside function, gradient (eq. 4.6) and diagonal second derivatives (eq. 4.33) at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Eval {
    /// F = sum |x_i/a_i|^g_i - 1.
    pub f: f64,
    /// dF/dx (unnormalised outward normal).
    pub grad: DVec3,
    /// d^2F/dx_i^2 (the Hessian is diagonal).
    pub hess: DVec3,
}

/// Constants of one superquadric used in the hot loops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Prepared {
    pub a: DVec3,
    pub inv_a: DVec3,
    pub g: DVec3,
    pub pow: [Pow; 3],
    pub equal: bool,
    /// x^(1/(g-1)) (equal exponents; the support map).
    dual: Root,
    /// x^(1/g) (equal exponents; support normalisation and radial projection).
    inv_g: Root,
    /// The largest semi-axis and a_max^(-3/2) (the support value at g = 3).
    a_max: f64,
    inv_amax_p: f64,
}

impl Prepared {
    pub fn new(a: DVec3, g: DVec3) -> Self {
        Self {
            a,
            inv_a: a.recip(),
            g,
            pow: [
                Pow::new(g.x - 2.0),
                Pow::new(g.y - 2.0),
                Pow::new(g.z - 2.0),
            ],
            equal: g.x == g.y && g.y == g.z,
            dual: Root::new(1.0 / (g.x - 1.0)),
            inv_g: Root::new(1.0 / g.x),
            a_max: a.max_element(),
            inv_amax_p: 1.0 / (a.max_element() * a.max_element().sqrt()),
        }
    }

    /// F, gradient and diagonal Hessian at `x` (three powers).
    #[inline]
    pub fn eval(&self, x: DVec3) -> Eval {
        let mut f = -1.0;
        let mut grad = DVec3::ZERO;
        let mut hess = DVec3::ZERO;
        for i in 0..3 {
            let y = x[i].abs() * self.inv_a[i];
            let ym2 = self.pow[i].apply(y);
            let ym1 = ym2 * y;
            f += ym1 * y;
            let g = self.g[i];
            grad[i] = (g * self.inv_a[i] * ym1).copysign(x[i]);
            hess[i] = g * (g - 1.0) * self.inv_a[i] * self.inv_a[i] * ym2;
        }
        Eval { f, grad, hess }
    }

    /// F at `x`.
    #[inline]
    pub fn inside(&self, x: DVec3) -> f64 {
        let mut f = -1.0;
        for i in 0..3 {
            let y = x[i].abs() * self.inv_a[i];
            f += self.pow[i].apply(y) * y * y;
        }
        f
    }

    /// The surface point on the ray through `x` (`x` unchanged if it is the centre or not
    /// finite). `s` = sum |x_i/a_i|^g_i = F + 1 if already known.
    pub fn project_radial(&self, x: DVec3, s: f64) -> DVec3 {
        if !(s.is_finite() && s > 0.0) {
            return x;
        }
        if self.equal {
            return x * (1.0 / self.inv_g.apply(s));
        }
        // sum_i w_i l^g_i = 1 with w_i = |x_i/a_i|^g_i: Newton on ln sum exp(ln w_i + g_i tau)
        let mut lw = [f64::NEG_INFINITY; 3];
        for i in 0..3 {
            let y = x[i].abs() * self.inv_a[i];
            if y > 0.0 {
                lw[i] = self.g[i] * y.ln();
            }
        }
        let tau = monotone_log_newton(&lw, &[self.g.x, self.g.y, self.g.z], 0.0);
        x * tau.exp()
    }

    /// The support function h(w) = max over the body of w . x (body frame), for bounds: equal
    /// to `w.dot(self.support(w))` up to a relative 1e-15 or so (for equal exponents of 3 the
    /// cube root is a polynomial start and Halley steps instead of `cbrt`: one step for unit
    /// directions and equal semi-axes, where its argument lies in a narrow interval, else two).
    #[inline]
    pub fn support_value(&self, w: DVec3) -> f64 {
        if !(self.equal && self.inv_g == Root::Third) {
            return w.dot(self.support(w));
        }
        // h = ||c||_p, c_i = |w_i| a_i, p = 3/2. For a unit w and equal semi-axes
        // sigma = sum c_i^p / a_max^p lies in [1, 3^(1/4)] and h = a_max sigma^(2/3): one
        // Halley step from a cubic (no division by max c, one division in all)
        let c = (w * self.a).abs();
        let sigma = (c.x * c.x.sqrt() + c.y * c.y.sqrt() + c.z * c.z.sqrt()) * self.inv_amax_p;
        if (NARROW_LO..=NARROW_HI).contains(&sigma) {
            return self.a_max * cube_root_narrow(sigma).powi(2);
        }
        // otherwise with z = c / max c and S = sum z_i^p in [1, 3], h = max c cbrt(S)^2
        let cmax = c.max_element();
        if !(cmax.is_finite() && cmax > 0.0) {
            return 0.0;
        }
        let z = c * (1.0 / cmax);
        let sum = z.x * z.x.sqrt() + z.y * z.y.sqrt() + z.z * z.z.sqrt();
        cmax * cube_root_1_3(sum).powi(2)
    }

    /// Support point in the body frame for the (not necessarily unit) direction `w`; the
    /// centre for a zero or non-finite direction.
    #[inline]
    pub fn support(&self, w: DVec3) -> DVec3 {
        let c = (w * self.a).abs();
        let cmax = c.max_element();
        if !(cmax.is_finite() && cmax > 0.0) {
            return DVec3::ZERO;
        }
        let z = c * (1.0 / cmax); // in [0, 1], max 1
        let y = if self.equal {
            // y_i = z_i^(p-1) / ||z||_p^(p-1), p - 1 = 1/(g-1), ||z||_p^(p-1) = (sum z^p)^(1/g)
            let e = DVec3::new(
                self.dual.apply(z.x),
                self.dual.apply(z.y),
                self.dual.apply(z.z),
            );
            let zp = e * z;
            e * (1.0 / self.inv_g.apply(zp.x + zp.y + zp.z))
        } else {
            let mut lc = [f64::NEG_INFINITY; 3];
            let mut lb = [f64::NEG_INFINITY; 3];
            let mut p = [0.0; 3];
            for i in 0..3 {
                p[i] = self.g[i] / (self.g[i] - 1.0);
                if z[i] > 0.0 {
                    lc[i] = (z[i] / self.g[i]).ln();
                    lb[i] = p[i] * lc[i];
                }
            }
            let t = monotone_log_newton(&lb, &p, 0.0);
            let mut y = DVec3::ZERO;
            for i in 0..3 {
                if z[i] > 0.0 {
                    y[i] = ((lc[i] + t) / (self.g[i] - 1.0)).exp();
                }
            }
            y
        };
        (y * self.a).copysign(w)
    }
}

/// The interval of [`cube_root_narrow`].
const NARROW_LO: f64 = 0.999;
const NARROW_HI: f64 = 1.32;

/// The cube root of `s` in [`NARROW_LO`, `NARROW_HI`] (relative error ~4e-16): the cubic
/// through the roots at the four Chebyshev nodes of the interval (error 2.3e-6), then one Halley
/// step (which cubes it).
#[inline]
pub(crate) fn cube_root_narrow(s: f64) -> f64 {
    const C: [f64; 4] = [
        1.000_002_013_803_363_8,
        0.333_116_177_348_255_3,
        -0.107_540_253_889_371_08,
        0.041_994_133_801_533_35,
    ];
    let t = s - 1.0;
    halley_cube_root_step(C[0] + t * (C[1] + t * (C[2] + t * C[3])), s)
}

/// One Halley step for y = cbrt(s): y (y^3 + 2s) / (2y^3 + s), which cubes the relative error.
#[inline(always)]
fn halley_cube_root_step(y: f64, s: f64) -> f64 {
    let y3 = y * y * y;
    y * ((y3 + 2.0 * s) / (2.0 * y3 + s))
}

/// The cube root of `s` in [1, 3] (relative error below 1e-15; outside the interval it
/// converges more slowly but stays finite for finite s > 0): the quadratic through the roots
/// of 1, 2 and 3, then two Halley steps (each cubes the relative error, 5e-3 -> 1e-7 -> 1e-16).
#[inline]
pub(crate) fn cube_root_1_3(s: f64) -> f64 {
    // cbrt(2), cbrt(3)
    const C2: f64 = 1.259_921_049_894_873_2;
    const C3: f64 = 1.442_249_570_307_408_3;
    let t = s - 1.0;
    let b = C2 - 1.0;
    let q = 0.5 * (C3 - 1.0) - b; // the second divided difference
    let mut y = 1.0 + t * (b + (t - 1.0) * q);
    for _ in 0..2 {
        y = halley_cube_root_step(y, s);
    }
    y
}

/// Root t of psi(t) = ln sum_i exp(lb_i + p_i t) (terms with lb_i = -inf are absent), for
/// p_i > 0: psi is convex and increasing, so Newton started anywhere is monotone after its
/// first step. Returns `t0` if every term is absent.
pub(crate) fn monotone_log_newton(lb: &[f64; 3], p: &[f64; 3], t0: f64) -> f64 {
    if lb.iter().all(|v| *v == f64::NEG_INFINITY) {
        return t0;
    }
    // shift by the largest lb for a stable log-sum-exp
    let mut t = t0;
    let mut last = f64::INFINITY;
    for it in 0..100 {
        let mut m = f64::NEG_INFINITY;
        for i in 0..3 {
            if lb[i] > f64::NEG_INFINITY {
                m = m.max(lb[i] + p[i] * t);
            }
        }
        let (mut s, mut ds) = (0.0, 0.0);
        for i in 0..3 {
            if lb[i] > f64::NEG_INFINITY {
                let e = (lb[i] + p[i] * t - m).exp();
                s += e;
                ds += p[i] * e;
            }
        }
        let psi = m + s.ln();
        let step = psi * s / ds;
        if !step.is_finite() {
            break;
        }
        // after the first step the iterates decrease monotonically to the root
        if it >= 2 && !(step > 0.0 && step < last) {
            break;
        }
        t -= step;
        last = step.abs();
        if last <= 1e-16 * (1.0 + t.abs()) {
            break;
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::{NARROW_HI, NARROW_LO, Pow, Prepared, cube_root_1_3, cube_root_narrow};
    use glam::DVec3;

    /// The support function against its reference `w . support(w)` (the Lagrange support
    /// point), and the cube root against `cbrt`, on a dense grid.
    #[test]
    fn support_value_equals_the_support_point_product() {
        let mut s = 1.0;
        while s <= 3.0 {
            let r = cube_root_1_3(s);
            assert!((r - s.cbrt()).abs() <= 1e-15 * r, "{s}: {r}");
            s += 1e-4;
        }
        let mut s = NARROW_LO;
        while s <= NARROW_HI {
            let r = cube_root_narrow(s);
            assert!((r - s.cbrt()).abs() <= 1e-15 * r, "{s}: {r}");
            s += 1e-6;
        }
        let shapes = [
            (DVec3::splat(0.5), DVec3::splat(3.0)),
            (DVec3::new(0.5, 0.3, 0.8), DVec3::splat(3.0)),
            (DVec3::splat(0.5), DVec3::splat(4.0)),
            (DVec3::new(0.5, 0.4, 0.7), DVec3::new(2.0, 3.0, 5.0)),
        ];
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for (a, g) in shapes {
            let p = Prepared::new(a, g);
            for case in 0..5000 {
                let mut w = DVec3::new(next(), next(), next());
                if case % 5 == 0 {
                    w.y = 0.0; // on a symmetry plane
                }
                if case % 2 == 1 {
                    // unit directions: the narrow path of g = 3 with equal semi-axes
                    w = w.normalize_or_zero();
                }
                let h = p.support_value(w);
                let reference = w.dot(p.support(w));
                assert!(
                    (h - reference).abs() <= 1e-14 * w.length(),
                    "{w}: {h} {reference}"
                );
            }
            assert_eq!(p.support_value(DVec3::ZERO), 0.0);
        }
    }

    /// The integer powers' fast paths equal `powi` (their reference) bit for bit.
    #[test]
    fn integer_powers_equal_powi() {
        let mut y = 1e-3;
        while y < 3.0 {
            for n in 1..=16 {
                assert_eq!(
                    Pow::Int(n).apply(y).to_bits(),
                    y.powi(n).to_bits(),
                    "{y}^{n}"
                );
            }
            y *= 1.013;
        }
    }
}
