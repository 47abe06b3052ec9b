//! Magnetometric demagnetising factors of a finite cylinder and the Stoner-Wohlfarth
//! magnetisation direction of a saturated fibre in an external field (D-000-4 in docs/references.md; the thesis
//! cites Stoner-Wohlfarth but gives no formula).
//!
//! **Demagnetising factor.** The magnetostatic energy of the end-face charges `±M` is
//! `(μ0/2) N_z M² V = (μ0 M²/4π)(S_self - S_mut(2L))`, with `S_self = 16πR³/3` the Coulomb
//! self-integral of a disc and `S_mut(h)` that of two coaxial discs a distance `h` apart. With
//! the distance density of two points in a disc this reduces to the smooth 1-D integral
//!
//! ```text
//! N_z = (2R/(πL)) ∫₀¹ w(t) [1 - t/√(t² + (L/R)²)] dt,   w(t) = acos t - t √(1 - t²),
//! ```
//!
//! evaluated by Gauss-Legendre after `t = 1 - s²` (which makes the integrand analytic);
//! `N_x = N_y = (1 - N_z)/2`. Limits: `N_z → 1` for a disc, `→ 0` for a needle.
//!
//! **Stoner-Wohlfarth.** A single domain with shape anisotropy, the field at angle `α` from
//! the axis: `e(θ) = (μ0/2) M_s² (N_z cos²θ + N_x sin²θ) - μ0 M_s H cos(α - θ)`; the magnetisation
//! angle `θ` is the global minimum on `[0, π/2]` (field folded into the first quadrant).

use glam::DVec3;

use super::source::MU0;

/// Gauss-Legendre nodes and weights on [0, 1] (Newton on the Legendre recurrence).
pub(crate) fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            ((x + 1.0) / 2.0, 1.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Axial magnetometric demagnetising factor `N_z` of a cylinder (radius, half length).
///
/// ```
/// use magsep_systems::field::demag::axial_demag_factor;
/// // L/D = 1 (half length = radius): 0.31158 (D-000-3)
/// assert!((axial_demag_factor(1.0, 1.0) - 0.31158).abs() < 1e-5);
/// ```
pub fn axial_demag_factor(radius: f64, half_length: f64) -> f64 {
    let lr = half_length / radius;
    // the integrand varies on the scale t ~ L/R near t = 0 (flat discs): panels [0, L/R] and
    // then geometric up to 1/2
    let split = 0.5;
    let w = |t: f64| t.acos() - t * (1.0 - t * t).sqrt();
    let f = |t: f64| w(t) * (1.0 - t / (t * t + lr * lr).sqrt());
    let nodes = gauss_legendre_01(64);
    let panel = |a: f64, b: f64| -> f64 {
        nodes
            .iter()
            .map(|&(x, wt)| wt * (b - a) * f(a + (b - a) * x))
            .sum()
    };
    let mut sum = 0.0;
    let mut lo = 0.0;
    let mut hi = lr.min(split);
    loop {
        sum += panel(lo, hi);
        if hi >= split {
            break;
        }
        lo = hi;
        hi = (hi * 4.0).min(split);
    }
    // [split, 1] with t = 1 - s² (analytic integrand in s)
    let smax = (1.0 - split).sqrt();
    sum += nodes
        .iter()
        .map(|&(x, wt)| {
            let s = smax * x;
            wt * smax * 2.0 * s * f(1.0 - s * s)
        })
        .sum::<f64>();
    2.0 / (std::f64::consts::PI * lr) * sum
}

/// Stoner-Wohlfarth magnetisation angle `θ` [rad] from the axis, for a field at angle `alpha`
/// [rad] from the axis (folded into `[0, π/2]`), field strength `h` [A/m], saturation
/// magnetisation `ms` [A/m] and demagnetising factors `nz`, `nx`.
pub fn stoner_wohlfarth_angle(alpha: f64, h: f64, ms: f64, nz: f64, nx: f64) -> f64 {
    let e = |t: f64| {
        0.5 * ms * ms * (nz * t.cos().powi(2) + nx * t.sin().powi(2)) - ms * h * (alpha - t).cos()
    };
    let de = |t: f64| 0.5 * ms * ms * (nx - nz) * (2.0 * t).sin() - ms * h * (alpha - t).sin();
    let n = 2000;
    let half_pi = std::f64::consts::FRAC_PI_2;
    let (mut best, mut best_e) = (0.0, f64::INFINITY);
    for i in 0..=n {
        let t = half_pi * i as f64 / n as f64;
        let v = e(t);
        if v < best_e {
            best = t;
            best_e = v;
        }
    }
    // polish by bisection on de/dθ in the bracketing cell
    let step = half_pi / n as f64;
    let (mut lo, mut hi) = ((best - step).max(0.0), (best + step).min(half_pi));
    if de(lo) < 0.0 && de(hi) > 0.0 {
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if de(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        best = 0.5 * (lo + hi);
    }
    best
}

/// Magnetisation [A/m] of a saturated cylinder (axis `axis`, saturation `ms` [A/m]) in the
/// external flux density `b_ext` [T], by Stoner-Wohlfarth with the cylinder's demagnetising
/// factors. Zero field gives zero magnetisation (no remanent state is assumed).
pub fn stoner_wohlfarth_magnetisation(
    axis: DVec3,
    radius: f64,
    half_length: f64,
    ms: f64,
    b_ext: DVec3,
) -> DVec3 {
    let bmag = b_ext.length();
    if bmag == 0.0 {
        return DVec3::ZERO;
    }
    let mut a = axis.normalize();
    if a.dot(b_ext) < 0.0 {
        a = -a;
    }
    let bhat = b_ext / bmag;
    let cos_alpha = a.dot(bhat).clamp(-1.0, 1.0);
    let alpha = cos_alpha.acos();
    let nz = axial_demag_factor(radius, half_length);
    let nx = 0.5 * (1.0 - nz);
    let theta = stoner_wohlfarth_angle(alpha, bmag / MU0, ms, nz, nx);
    // direction in the plane of a and b̂, at θ from a towards b̂
    let perp = bhat - a * cos_alpha;
    let dir = if perp.length() < 1e-12 {
        a
    } else {
        a * theta.cos() + perp.normalize() * theta.sin()
    };
    dir * ms
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demag_factors_match_spec_table() {
        // D-000-3: L/D (full length / diameter) -> N_z
        for (ld, nz) in [
            (1.0, 0.31158),
            (5.0 / 3.0, 0.21148),
            (20.0 / 3.0, 0.06086),
            (10.0, 0.04119),
            (20.0, 0.02091),
        ] {
            let got = axial_demag_factor(1.0, ld);
            assert!(
                (got - nz).abs() < 1e-4 * 0.5 + 5e-6,
                "L/D {ld}: {got} vs {nz}"
            );
        }
        assert!((axial_demag_factor(1.0, 1e-6) - 1.0).abs() < 1e-5);
        assert!(axial_demag_factor(1.0, 1e6) < 1e-6);
    }

    #[test]
    fn stoner_wohlfarth_angles_match_spec_table() {
        let ms = 985e3;
        let h = 1.0 / MU0;
        // D-000-4, L/D = 20: α -> θ [deg]
        let nz = axial_demag_factor(1.0, 20.0);
        let nx = 0.5 * (1.0 - nz);
        for (a, t) in [
            (0.0, 0.0),
            (15.0, 9.6),
            (30.0, 19.5),
            (45.0, 30.3),
            (60.0, 43.2),
            (75.0, 60.7),
            (90.0, 90.0),
        ] {
            let got = stoner_wohlfarth_angle(f64::to_radians(a), h, ms, nz, nx).to_degrees();
            assert!((got - t).abs() < 0.2, "α {a}: θ {got} vs {t}");
        }
        let nz = axial_demag_factor(1.0, 5.0 / 3.0);
        let nx = 0.5 * (1.0 - nz);
        for (a, t) in [(15.0, 12.3), (45.0, 38.7), (75.0, 71.0)] {
            let got = stoner_wohlfarth_angle(f64::to_radians(a), h, ms, nz, nx).to_degrees();
            assert!((got - t).abs() < 0.2, "α {a}: θ {got} vs {t}");
        }
    }
}
