//! Bulirsch's generalised complete elliptic integral
//!
//! `cel(kc, p, a, b) = ∫₀^{π/2} (a cos²φ + b sin²φ) / ((cos²φ + p sin²φ) √(cos²φ + kc² sin²φ)) dφ`
//!
//! (Bulirsch 1965; the form of Derby & Olbert 2010 and D-000-1 in docs/references.md). The finite
//! cylinder's field needs it at two values of `p` (1 and γ²) and two numerators each, all with
//! the same `kc`: [`cel_cylinder_pair`] runs the shared Gauss-Landen iteration (the `kc` sequence and
//! its square roots) once for all four.
//!
//! `errtol = 1e-8` on the arithmetic-geometric mean gives full double precision because the
//! iteration converges quadratically (tested against quadrature below). For [`Dual3`](super::Dual3)
//! the loop also waits for the derivatives to converge.

use super::real::Real;

/// Relative tolerance of the mean iteration (quadratic convergence: the result is ~1e-16).
const ERRTOL: f64 = 1e-8;
/// Iteration cap (convergence takes < 10 steps for kc >= 1e-150; guards against NaN input).
const MAX_ITER: usize = 40;
/// Smallest modulus: `kc` is clamped here (exactly on a rim, where the field diverges
/// logarithmically, the kernel returns the value at a distance ~1e-150 radii).
pub const KC_MIN: f64 = 1e-150;

/// One `(p, numerators)` track of the iteration.
#[derive(Clone, Copy)]
struct Track<T, const N: usize> {
    pp: T,
    cc: [T; N],
    ss: [T; N],
}

impl<T: Real, const N: usize> Track<T, N> {
    /// Bulirsch's set-up for parameter `p` and numerators `(c[i], s[i])`.
    fn new(kc: T, p: T, c: [T; N], s: [T; N]) -> Self {
        if p.val() > 0.0 {
            let pp = p.sqrt();
            let mut ss = s;
            for v in &mut ss {
                *v = *v / pp;
            }
            Self { pp, cc: c, ss }
        } else {
            let f0 = kc * kc;
            let g = -p + 1.0;
            let f = f0 - p;
            let pp = (f / g).sqrt();
            let mut cc = c;
            let mut ss = s;
            for i in 0..N {
                let q = (-f0 + 1.0) * (s[i] - c[i] * p);
                cc[i] = (c[i] - s[i]) / g;
                ss[i] = -q / (g * g * pp) + cc[i] * pp;
            }
            Self { pp, cc, ss }
        }
    }

    /// One Landen step with `g = kk / pp` (first step: `k / pp`).
    #[inline(always)]
    fn step(&mut self, kk: T) {
        let inv = self.pp.recip();
        let g = kk * inv;
        for i in 0..N {
            let f = self.cc[i];
            self.cc[i] = f + self.ss[i] * inv;
            self.ss[i] = (self.ss[i] + f * g) * 2.0;
        }
        self.pp = g + self.pp;
    }

    fn finish(&self, em: T) -> [T; N] {
        let den = em * (em + self.pp);
        let mut out = self.cc;
        for (o, (s, c)) in out.iter_mut().zip(self.ss.iter().zip(&self.cc)) {
            *o = (*s + *c * em) * std::f64::consts::FRAC_PI_2 / den;
        }
        out
    }
}

/// Runs the mean iteration for `L` moduli in lockstep (until all have converged; extra steps
/// after convergence leave a result unchanged), driving two tracks per modulus. Returns the
/// final `em` of each modulus.
fn iterate<T: Real, const L: usize, const N: usize, const M: usize>(
    kc: [T; L],
    a: &mut [Track<T, N>; L],
    b: &mut [Track<T, M>; L],
) -> [T; L] {
    let mut k = kc.map(|v| v.abs());
    let mut em = [T::cst(1.0); L];
    let mut g = em;
    let mut kk = k;
    for l in 0..L {
        a[l].step(k[l]);
        b[l].step(k[l]);
        em[l] = k[l] + em[l];
    }
    for _ in 0..MAX_ITER {
        if (0..L).all(|l| g[l].converged(k[l], ERRTOL)) {
            break;
        }
        for l in 0..L {
            k[l] = kk[l].sqrt() * 2.0;
            kk[l] = k[l] * em[l];
            a[l].step(kk[l]);
            b[l].step(kk[l]);
            g[l] = em[l];
            em[l] = k[l] + em[l];
        }
    }
    em
}

/// `cel(kc, p, a, b)` for one numerator (reference form; `kc` is clamped at [`KC_MIN`]).
///
/// ```
/// use magsep_systems::field::cel::cel;
/// // K(m = 1/2) = cel(sqrt(1/2), 1, 1, 1)
/// let k = cel(0.5f64.sqrt(), 1.0, 1.0, 1.0);
/// assert!((k - 1.854_074_677_301_372).abs() < 1e-15);
/// ```
pub fn cel<T: Real>(kc: T, p: T, a: T, b: T) -> T {
    let kc = clamp_kc(kc);
    let mut t = [Track::<T, 1>::new(kc, p, [a], [b])];
    let mut none = [Track::<T, 0>::new(kc, T::cst(1.0), [], [])];
    let [em] = iterate([kc], &mut t, &mut none);
    t[0].finish(em)[0]
}

/// The four integrals of the cylinder field at the two moduli `k₊`, `k₋` of a point
/// (`γ² = p`): per modulus `[cel(kc,1,1,-1), cel(kc,1,0,1), cel(kc,γ²,1,-γ), cel(kc,γ²,0,1)]`,
/// i.e. `[P₁, (K-E)/(1-k²), P₂, (Π-K)/(1-γ²)]` in the notation of the thesis (eqs. 5.4, 5.20).
/// One shared mean iteration per modulus serves all four, and the two moduli run in lockstep,
/// which hides the latency of their square roots and divisions.
#[inline]
pub fn cel_cylinder_pair<T: Real>(kc: [T; 2], gamma: T) -> [[T; 4]; 2] {
    let kc = kc.map(clamp_kc);
    let one = T::cst(1.0);
    let zero = T::cst(0.0);
    let p2 = gamma * gamma;
    let mut t1 = kc.map(|k| Track::<T, 2>::new(k, one, [one, zero], [-one, one]));
    let mut t2 = kc.map(|k| Track::<T, 2>::new(k, p2, [one, zero], [-gamma, one]));
    let em = iterate(kc, &mut t1, &mut t2);
    let mut out = [[zero; 4]; 2];
    for l in 0..2 {
        let [p1, x] = t1[l].finish(em[l]);
        let [q2, y] = t2[l].finish(em[l]);
        out[l] = [p1, x, q2, y];
    }
    out
}

fn clamp_kc<T: Real>(kc: T) -> T {
    if kc.val().abs() < KC_MIN {
        T::cst(KC_MIN)
    } else {
        kc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defining integral by Gauss-Legendre on [0, π/2] (smooth for moderate kc, p).
    fn cel_quad(kc: f64, p: f64, a: f64, b: f64) -> f64 {
        let h = std::f64::consts::FRAC_PI_2;
        crate::field::demag::gauss_legendre_01(200)
            .iter()
            .map(|&(x, w)| {
                let phi = h * x;
                let (s, c) = phi.sin_cos();
                let (s2, c2) = (s * s, c * c);
                w * h * (a * c2 + b * s2) / ((c2 + p * s2) * (c2 + kc * kc * s2).sqrt())
            })
            .sum()
    }

    #[test]
    fn cel_matches_quadrature_and_known_values() {
        for &(kc, p, a, b) in &[
            (0.3, 0.5, 1.0, -1.0),
            (0.9, 1.0, 1.0, 1.0),
            (0.5, 0.09, 1.0, -0.3),
            (0.2, 2.0, 0.0, 1.0),
        ] {
            let (c, q) = (cel(kc, p, a, b), cel_quad(kc, p, a, b));
            assert!(
                (c - q).abs() <= 5e-15 * q.abs().max(1.0),
                "{kc} {p}: {c} vs {q}"
            );
        }
        // E(m = 1/2) = cel(kc, 1, 1, kc^2)
        let kc = 0.5f64.sqrt();
        assert!((cel(kc, 1.0, 1.0, 0.5) - 1.350_643_881_047_675_5).abs() < 1e-15);
        // erratum E-000-15: P2 = C(k, γ², 1, -γ) at k = 0.5, γ = 0.3 is -0.6505 (the printed +γ gives 3.668)
        let p2 = cel(0.5, 0.09, 1.0, -0.3);
        assert!((p2 - (-0.6505)).abs() < 5e-5, "{p2}");
        assert!(cel(KC_MIN * 0.0, 1.0, 1.0, 1.0).is_finite());
        // p = 0 (exactly on the lateral surface, γ = 0): cel(kc, 0, 1, 0) = K
        let kc = 0.37;
        assert!((cel(kc, 0.0, 1.0, 0.0) - cel(kc, 1.0, 1.0, 1.0)).abs() < 1e-15);
    }

    #[test]
    fn pair_equals_single() {
        let single = |kc: f64, g: f64| {
            [
                cel(kc, 1.0, 1.0, -1.0),
                cel(kc, 1.0, 0.0, 1.0),
                cel(kc, g * g, 1.0, -g),
                cel(kc, g * g, 0.0, 1.0),
            ]
        };
        for &(a, b, g) in &[
            (0.3, 0.9, 0.4),
            (1e-9, 0.999, -0.99),
            (0.5, 0.5, 0.0),
            (1e-150, 1.0, 0.2),
            (0.3, 0.999, 0.4),
            (1e-6, 0.8, 0.001),
            (0.8, 0.8, 0.0),
        ] {
            let pair = cel_cylinder_pair([a, b], g);
            let (fa, fb) = (single(a, g), single(b, g));
            for i in 0..4 {
                assert!(
                    (pair[0][i] - fa[i]).abs() <= 1e-15 * fa[i].abs().max(1.0),
                    "{a} {i}"
                );
                assert!(
                    (pair[1][i] - fb[i]).abs() <= 1e-15 * fb[i].abs().max(1.0),
                    "{b} {i}"
                );
            }
        }
    }
}
