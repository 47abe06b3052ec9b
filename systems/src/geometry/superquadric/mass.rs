//! Volume, principal moments of inertia and circumscribed radius of a superquadric
//! |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 (thesis 000, App. 4.A and 4.C).
//!
//! With eps_i = 2/g_i the thesis writes (eq. 4.21)
//!
//! V = a1 a2 a3 eps1 eps2 eps3 G(eps1/2) G(eps2/2) G(eps3/2) / G(1 + eps1/2 + eps2/2 + eps3/2).
//!
//! Using eps G(eps/2) = 2 G(1 + 1/g) this is evaluated in the equivalent form
//!
//! V = 8 a1 a2 a3 G(1 + 1/g1) G(1 + 1/g2) G(1 + 1/g3) / G(1 + 1/g1 + 1/g2 + 1/g3),
//!
//! whose Gamma arguments all lie in [1, 4], so the cube limit g -> infinity (V = 8 a1 a2 a3)
//! is as accurate as the sphere. The moments (eqs. 4.29-4.31) become, with
//! T(p, q, r) = G(1 + p/g1) G(1 + q/g2) G(1 + r/g3) / G(1 + p/g1 + q/g2 + r/g3),
//!
//! I_xx = (8/3) a1 a2 a3 (a2^2 T(1, 3, 1) + a3^2 T(1, 1, 3)),
//! I_yy = (8/3) a1 a2 a3 (a1^2 T(3, 1, 1) + a3^2 T(1, 1, 3)),
//! I_zz = (8/3) a1 a2 a3 (a1^2 T(3, 1, 1) + a2^2 T(1, 3, 1)),
//!
//! at unit density (eps G(3 eps/2) = (2/3) G(1 + 3/g)). Sphere: 4 pi/3 and 8 pi/15; cube of
//! side 2a: 8 a^3 and 16 a^5/3.
//!
//! Circumscribed radius (App. 4.C). Erratum E-000-7: eq. 4.35 says "minimize"; the radius is the
//! *maximum* of |x| on the surface. With u_i = (x_i/a_i)^2 the problem is
//! max sum a_i^2 u_i subject to sum u_i^(g_i/2) <= 1, a linear objective on a convex set.
//! Equal exponents: Hoelder gives eq. 4.38, r^2 = || (a_i^2) ||_q with q = g/(g - 2), i.e.
//! r^2 = (sum (a_i^2)^(1/(1-eps)))^(1-eps), evaluated after dividing by max a_i^2 so that the
//! g = 2 singularity of eq. 4.38 (eps = 1) becomes the limit r = max a_i without overflow;
//! superball eq. 4.39, r^2 = 3^(1-eps) a^2. Unequal exponents (no closed form, [T000 App. 4.C]): the
//! Lagrange dual D(lambda) = lambda + sum_i sup_u (a_i^2 u - lambda u^(g_i/2)) is a convex
//! function of one variable whose value at *any* lambda is an upper bound of r^2 (weak
//! duality); it is minimised by bisection on its derivative 1 - sum u_i*(lambda)^(g_i/2), so the
//! returned radius is an upper bound of every surface point's distance, tight to round-off.
//!
//! Gamma is evaluated by upward recurrence to x >= 12 and the Stirling series (relative error
//! ~5e-15 on [1, 4]), and exactly (to a few ulp) at integers and half-integers, so the
//! sphere, ellipsoid and box limits are exact to round-off.

use glam::DVec3;
use std::f64::consts::PI;

/// ln Gamma(x) for x > 0 (recurrence to x >= 12, then 8 terms of the Stirling series;
/// products from G(1) or G(1/2) at integers and half-integers up to 30). NaN otherwise.
///
/// ```
/// use magsep_systems::geometry::superquadric::ln_gamma;
/// assert!((ln_gamma(0.5).exp() - std::f64::consts::PI.sqrt()).abs() < 1e-14);
/// assert!((ln_gamma(5.0).exp() - 24.0).abs() < 1e-12);
/// ```
pub fn ln_gamma(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return f64::NAN;
    }
    if (2.0 * x).fract() == 0.0 && x <= 30.0 {
        // integer or half-integer: exact recurrence from G(1) = 1, G(1/2) = sqrt(pi)
        let (mut z, mut g) = if x.fract() == 0.0 {
            (1.0, 1.0)
        } else {
            (0.5, PI.sqrt())
        };
        while z < x {
            g *= z;
            z += 1.0;
        }
        return g.ln();
    }
    let mut z = x;
    let mut prod = 1.0;
    while z < 12.0 {
        prod *= z;
        z += 1.0;
    }
    let zi = 1.0 / z;
    let zi2 = zi * zi;
    // Stirling: B_2k / (2k (2k-1) z^(2k-1)), k = 1..8
    let series = zi
        * (1.0 / 12.0
            + zi2
                * (-1.0 / 360.0
                    + zi2
                        * (1.0 / 1260.0
                            + zi2
                                * (-1.0 / 1680.0
                                    + zi2
                                        * (1.0 / 1188.0
                                            + zi2
                                                * (-691.0 / 360_360.0
                                                    + zi2
                                                        * (1.0 / 156.0
                                                            - zi2 * 3617.0 / 122_400.0)))))));
    (z - 0.5) * z.ln() - z + 0.5 * (2.0 * PI).ln() + series - prod.ln()
}

/// T(p, q, r) = G(1+p/g1) G(1+q/g2) G(1+r/g3) / G(1 + p/g1 + q/g2 + r/g3).
fn beta3(g: DVec3, p: f64, q: f64, r: f64) -> f64 {
    let (x, y, z) = (p / g.x, q / g.y, r / g.z);
    (ln_gamma(1.0 + x) + ln_gamma(1.0 + y) + ln_gamma(1.0 + z) - ln_gamma(1.0 + x + y + z)).exp()
}

/// Volume of the superquadric with semi-axes `a` and exponents `g` (eq. 4.21) [m^3]. An
/// infinite exponent is allowed (a box along that axis).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::superquadric::superquadric_volume;
/// let v = superquadric_volume(DVec3::ONE, DVec3::splat(2.0));
/// assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 1e-13);
/// ```
pub fn superquadric_volume(a: DVec3, g: DVec3) -> f64 {
    8.0 * a.x * a.y * a.z * beta3(g, 1.0, 1.0, 1.0)
}

/// Principal moments of inertia (I_xx, I_yy, I_zz) at unit density (eqs. 4.29-4.31) [m^5].
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::superquadric::superquadric_inertia;
/// let i = superquadric_inertia(DVec3::ONE, DVec3::splat(2.0));
/// assert!((i.x - 8.0 * std::f64::consts::PI / 15.0).abs() < 1e-13);
/// ```
pub fn superquadric_inertia(a: DVec3, g: DVec3) -> DVec3 {
    let pre = 8.0 / 3.0 * a.x * a.y * a.z;
    let tx = a.x * a.x * beta3(g, 3.0, 1.0, 1.0);
    let ty = a.y * a.y * beta3(g, 1.0, 3.0, 1.0);
    let tz = a.z * a.z * beta3(g, 1.0, 1.0, 3.0);
    DVec3::new(pre * (ty + tz), pre * (tx + tz), pre * (tx + ty))
}

/// Closed form eqs. 4.38/4.39 for equal exponents `g` (>= 2; `g = 2` gives max a_i, an
/// infinite `g` the box corner |a|).
fn bounding_radius_equal(a: DVec3, g: f64) -> f64 {
    let amax = a.max_element();
    if g <= 2.0 {
        return amax;
    }
    let eps = 2.0 / g; // 0 for g = infinity
    if a.x == a.y && a.y == a.z {
        return amax * 3f64.powf(0.5 * (1.0 - eps)); // superball, eq. 4.39
    }
    let e = 1.0 / (1.0 - eps);
    let w = a / amax;
    let s = (w.x * w.x).powf(e) + (w.y * w.y).powf(e) + (w.z * w.z).powf(e);
    amax * s.powf(0.5 * (1.0 - eps))
}

/// Dual value and derivative at `lambda` (c = a_i^2 / max, p = g_i / 2).
fn dual(c: [f64; 3], p: [f64; 3], lambda: f64) -> (f64, f64) {
    let (mut value, mut sum) = (lambda, 0.0);
    for i in 0..3 {
        if c[i] == 0.0 {
            continue;
        }
        if p[i] <= 1.0 {
            // g = 2: sup_u (c - lambda) u is 0 for lambda >= c (callers keep lambda >= c)
            continue;
        }
        let u = (c[i] / (lambda * p[i])).powf(1.0 / (p[i] - 1.0));
        value += c[i] * u * (1.0 - 1.0 / p[i]);
        sum += u.powf(p[i]);
    }
    (value, 1.0 - sum)
}

/// Numerical maximisation for unequal exponents via the 1-D Lagrange dual (an upper bound).
pub(crate) fn bounding_radius_numeric(a: DVec3, g: DVec3) -> f64 {
    let amax2 = a.max_element().powi(2);
    let c = [a.x * a.x / amax2, a.y * a.y / amax2, a.z * a.z / amax2];
    let p = [0.5 * g.x, 0.5 * g.y, 0.5 * g.z];
    // lambda must stay >= c_i for every g_i = 2 axis
    let floor = (0..3)
        .filter(|&i| p[i] <= 1.0)
        .map(|i| c[i])
        .fold(0.0, f64::max);
    let mut lo = if floor > 0.0 { floor } else { 1e-300 };
    if dual(c, p, lo).1 >= 0.0 {
        return (amax2 * dual(c, p, lo).0).sqrt() * (1.0 + 1e-14);
    }
    let mut hi = lo.max(1.0);
    while dual(c, p, hi).1 < 0.0 && hi < 1e300 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
        if !(mid > lo && mid < hi) {
            break;
        }
        if dual(c, p, mid).1 < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let best = dual(c, p, lo).0.min(dual(c, p, hi).0);
    (amax2 * best).sqrt() * (1.0 + 1e-14)
}

/// Radius of the smallest centred sphere containing the superquadric (App. 4.C) [m]: the
/// closed form 4.38/4.39 for equal exponents, a numerical upper bound (tight to round-off)
/// otherwise. An exponent that is not finite gives the box bound |a|.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::superquadric::superquadric_bounding_radius;
/// // superball g = 4: 3^((1 - 1/2)/2)
/// let r = superquadric_bounding_radius(DVec3::ONE, DVec3::splat(4.0));
/// assert!((r - 3f64.powf(0.25)).abs() < 1e-14);
/// assert_eq!(superquadric_bounding_radius(DVec3::new(1.0, 2.0, 0.5), DVec3::splat(2.0)), 2.0);
/// ```
pub fn superquadric_bounding_radius(a: DVec3, g: DVec3) -> f64 {
    if g.x == g.y && g.y == g.z {
        return bounding_radius_equal(a, g.x);
    }
    if !g.is_finite() {
        return a.length();
    }
    bounding_radius_numeric(a, g)
}

/// A cheap circumscribed radius: exact for equal exponents, otherwise the exact radius of
/// the superquadric with all exponents equal to the largest one (which contains this one,
/// because |y|^g decreases with g for |y| <= 1).
pub(crate) fn bounding_radius_cheap(a: DVec3, g: DVec3) -> f64 {
    bounding_radius_equal(a, g.max_element())
}
