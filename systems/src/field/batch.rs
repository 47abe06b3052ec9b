//! Four points at a time: the closed form of [`super::cylinder`] and the fused `cel` iteration
//! of [`super::cel`] on four-lane vectors, for evaluating one cylinder at many points.
//!
//! Hand-written because it is the hot kernel of every field map and benchmark: the scalar
//! kernel is bound by the latency of its square roots and divisions, which four independent
//! points (eight moduli in lockstep) hide, and which AVX2 executes four at a time. The lanes
//! are plain `[f64; 4]` arrays whose element-wise loops the compiler turns into vector
//! instructions; the kernel is compiled twice, for the baseline target and with AVX2 (chosen
//! at run time where the processor has it). Rust never fuses a multiply and an add on its own,
//! so every lane does the scalar kernel's arithmetic operation for operation; the only
//! difference is that a lane keeps iterating until all eight moduli of its group have
//! converged, which changes results at the level of the last bit (tested to 1e-15).
//!
//! A group of four goes through here only when every point is off the axis (`ρ ≥
//! AXIS_SWITCH · R`), off the surface (`ρ ≠ R`, `|z| ≠ L`) and finite; otherwise, and for the
//! multipole far field, [`super::source::CylinderSource::field_batch`] evaluates its points
//! one by one with the scalar kernel.

use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::cel::KC_MIN;
use super::cylinder::AXIS_SWITCH;

/// Four lanes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct F4([f64; 4]);

macro_rules! lanes {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                let mut r = [0.0; 4];
                for l in 0..4 {
                    r[l] = self.0[l] $op o.0[l];
                }
                F4(r)
            }
        }
        impl $tr<f64> for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: f64) -> F4 {
                let mut r = [0.0; 4];
                for l in 0..4 {
                    r[l] = self.0[l] $op o;
                }
                F4(r)
            }
        }
    };
}
lanes!(Add, add, +);
lanes!(Sub, sub, -);
lanes!(Mul, mul, *);
lanes!(Div, div, /);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        F4(self.0.map(|v| -v))
    }
}

impl F4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        F4([v; 4])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F4(self.0.map(f64::sqrt))
    }
    #[inline(always)]
    fn recip(self) -> Self {
        F4::splat(1.0) / self
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F4(self.0.map(f64::abs))
    }
    /// `max(self, KC_MIN)` lane by lane (the scalar kernel's clamp of a non-negative `kc`).
    #[inline(always)]
    fn clamp_kc(self) -> Self {
        F4(self.0.map(|v| if v.abs() < KC_MIN { KC_MIN } else { v }))
    }
    /// Whether every lane has `|self - other| <= |self| tol`.
    #[inline(always)]
    fn converged(self, other: Self, tol: f64) -> bool {
        (0..4).all(|l| (self.0[l] - other.0[l]).abs() <= self.0[l].abs() * tol)
    }
}

/// One `(p, two numerators)` track of the Landen iteration (as `cel::Track` for `p > 0`).
#[derive(Clone, Copy)]
struct Track {
    pp: F4,
    cc: [F4; 2],
    ss: [F4; 2],
}

impl Track {
    #[inline(always)]
    fn new(p: F4, c: [F4; 2], s: [F4; 2]) -> Self {
        let pp = p.sqrt();
        Self {
            pp,
            cc: c,
            ss: [s[0] / pp, s[1] / pp],
        }
    }
    #[inline(always)]
    fn step(&mut self, kk: F4) {
        let inv = self.pp.recip();
        let g = kk * inv;
        for i in 0..2 {
            let f = self.cc[i];
            self.cc[i] = f + self.ss[i] * inv;
            self.ss[i] = (self.ss[i] + f * g) * 2.0;
        }
        self.pp = g + self.pp;
    }
    #[inline(always)]
    fn finish(&self, em: F4) -> [F4; 2] {
        let den = em * (em + self.pp);
        [
            (self.ss[0] + self.cc[0] * em) * FRAC_PI_2 / den,
            (self.ss[1] + self.cc[1] * em) * FRAC_PI_2 / den,
        ]
    }
}

const ERRTOL: f64 = 1e-8;
const MAX_ITER: usize = 40;

/// `cel_cylinder_pair` on four points: per modulus `[P₁, X, P₂, Y]`.
#[inline(always)]
fn cel_pair4(kc: [F4; 2], gamma: F4) -> [[F4; 4]; 2] {
    let kc = kc.map(F4::clamp_kc);
    let one = F4::splat(1.0);
    let zero = F4::splat(0.0);
    let p2 = gamma * gamma;
    let mut t1 = [Track::new(one, [one, zero], [-one, one]); 2];
    let mut t2 = [Track::new(p2, [one, zero], [-gamma, one]); 2];
    let mut k = kc.map(F4::abs);
    let mut em = [one; 2];
    let mut g = em;
    let mut kk = k;
    for l in 0..2 {
        t1[l].step(k[l]);
        t2[l].step(k[l]);
        em[l] = k[l] + em[l];
    }
    for _ in 0..MAX_ITER {
        if (0..2).all(|l| g[l].converged(k[l], ERRTOL)) {
            break;
        }
        for l in 0..2 {
            k[l] = kk[l].sqrt() * 2.0;
            kk[l] = k[l] * em[l];
            t1[l].step(kk[l]);
            t2[l].step(kk[l]);
            g[l] = em[l];
            em[l] = k[l] + em[l];
        }
    }
    let mut out = [[zero; 4]; 2];
    for l in 0..2 {
        let [p1, x] = t1[l].finish(em[l]);
        let [q2, y] = t2[l].finish(em[l]);
        out[l] = [p1, x, q2, y];
    }
    out
}

/// `H = Hess(Ψ) · m` at four body-frame points (closed form; see the module's conditions).
#[inline(always)]
fn h4(
    p: [[f64; 4]; 3],
    chi: [f64; 4],
    radius: f64,
    half_length: f64,
    m: [f64; 3],
) -> [[f64; 4]; 3] {
    let (x, y, z) = (F4(p[0]), F4(p[1]), F4(p[2]));
    let chi = F4(chi);
    let rho = (x * x + y * y).sqrt();
    // cylinder::closed_form, operation for operation
    let sp = rho + radius;
    let dm = rho - radius;
    let gamma = dm / sp;
    let xi = [z + half_length, z - half_length];
    let alpha = [
        (xi[0] * xi[0] + sp * sp).sqrt().recip(),
        (xi[1] * xi[1] + sp * sp).sqrt().recip(),
    ];
    let kc = [
        (xi[0] * xi[0] + dm * dm).sqrt() * alpha[0],
        (xi[1] * xi[1] + dm * dm).sqrt() * alpha[1],
    ];
    let [[p1a, xa, p2a, ya], [p1b, xb, p2b, yb]] = cel_pair4(kc, gamma);
    let (beta_a, beta_b) = (xi[0] * alpha[0], xi[1] * alpha[1]);
    let g2 = gamma * gamma;
    let psi_rz = alpha[0] * p1a - alpha[1] * p1b;
    let bz = beta_a * p2a - beta_b * p2b;
    let p3 = beta_a * (xa - g2 * ya) - beta_b * (xb - g2 * yb);
    let psi_rz = psi_rz * (radius / PI);
    let pzz = bz * radius / (sp * PI) - chi;
    let b = -(p3 * radius / (rho * PI));
    let a = -(pzz + b) - chi;
    let rho2 = rho * rho;
    let u = psi_rz / rho;
    let e = (a - b) / rho2;
    // HessParts::apply
    let exy = e * x * y;
    let ux = u * x;
    let uy = u * y;
    [
        ((b + e * x * x) * m[0] + exy * m[1] + ux * m[2]).0,
        (exy * m[0] + (b + e * y * y) * m[1] + uy * m[2]).0,
        (ux * m[0] + uy * m[1] + pzz * m[2]).0,
    ]
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn h4_avx2(
    p: [[f64; 4]; 3],
    chi: [f64; 4],
    radius: f64,
    half_length: f64,
    m: [f64; 3],
) -> [[f64; 4]; 3] {
    h4(p, chi, radius, half_length, m)
}

/// Whether a body-frame point may go through [`h_body4`], and its `χ` (1 inside, 0 outside).
#[inline]
pub fn lane_chi(p: [f64; 3], radius: f64, half_length: f64) -> Option<f64> {
    let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
    let (dr, dz) = (rho - radius, p[2].abs() - half_length);
    let ok = p.iter().all(|v| v.is_finite()) && rho >= AXIS_SWITCH * radius;
    if !ok || dr == 0.0 || dz == 0.0 {
        return None;
    }
    Some(if dr < 0.0 && dz < 0.0 { 1.0 } else { 0.0 })
}

/// `H` (body frame, per unit of the body-frame magnetisation `m`) at four body-frame points
/// `p[axis][lane]` with their `χ` from [`lane_chi`] (which must have accepted every lane).
pub fn h_body4(
    p: [[f64; 4]; 3],
    chi: [f64; 4],
    radius: f64,
    half_length: f64,
    m: [f64; 3],
) -> [[f64; 4]; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2 (checked just above).
            return unsafe { h4_avx2(p, chi, radius, half_length, m) };
        }
    }
    h4(p, chi, radius, half_length, m)
}

#[cfg(test)]
mod tests {
    use crate::field::{CylinderSource, EXACT, FieldValue, MU0};
    use glam::DVec3;

    #[test]
    fn four_lanes_agree_with_the_scalar_kernel() {
        // random points around a fibre, mixed with points on its axis, surface, rims and far
        // away (which must leave the four-lane path for the scalar one within their group)
        let (r, l) = (0.7, 1.3);
        let mut pts = Vec::new();
        let mut s = 0x1234_5678_u64;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..4000 {
            pts.push(DVec3::new(
                -3.0 + 6.0 * next(),
                -3.0 + 6.0 * next(),
                -4.0 + 8.0 * next(),
            ));
        }
        for (i, special) in [
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::new(r, 0.0, 0.2),
            DVec3::new(0.3, 0.2, l),
            DVec3::new(r, 0.0, -l),
            DVec3::new(1e-3, 0.0, 2.0),
            DVec3::new(40.0, 3.0, 1.0),
        ]
        .into_iter()
        .enumerate()
        {
            pts[97 * i + 1] = special;
        }
        for m in [DVec3::Z, DVec3::X, DVec3::new(0.6, -0.3, 0.8)] {
            let src = CylinderSource::new(
                DVec3::new(0.1, -0.2, 0.3),
                DVec3::new(0.2, 0.1, 1.0),
                r,
                l,
                m * 1e6,
            );
            let mut out = vec![FieldValue::default(); pts.len()];
            src.field_batch(&pts, EXACT, &mut out);
            let scale = MU0 * 1e6;
            for (p, f) in pts.iter().zip(&out) {
                let g = src.field(*p, EXACT);
                let err = (f.b - g.b).length() / scale;
                assert!(err <= 1e-15, "{p}: {} vs {} ({err:e})", f.b, g.b);
                assert!((f.h - g.h).length() * MU0 / scale <= 1e-15);
            }
        }
    }

    #[test]
    fn the_lane_kernel_is_the_closed_form_and_refuses_the_delicate_places() {
        use super::{h_body4, lane_chi};
        use crate::field::cylinder::hess_parts;
        let (r, l) = (1.0, 2.0);
        let m = [0.3, -0.5, 0.8];
        let pts = [
            [0.3, 0.4, 0.1],
            [1.5, -0.2, 2.5],
            [-0.05, 0.9, -2.0001],
            [2.0, 2.0, -0.3],
        ];
        let mut lanes = [[0.0; 4]; 3];
        let mut chi = [0.0; 4];
        for (i, p) in pts.iter().enumerate() {
            chi[i] = lane_chi(*p, r, l).expect("an ordinary point");
            for a in 0..3 {
                lanes[a][i] = p[a];
            }
        }
        assert_eq!(chi, [1.0, 0.0, 0.0, 0.0]);
        let h = h_body4(lanes, chi, r, l, m);
        for (i, p) in pts.iter().enumerate() {
            let parts = hess_parts(p[0], p[1], p[2], r, l);
            let want = parts.apply(p[0], p[1], m);
            for a in 0..3 {
                assert!(
                    (h[a][i] - want[a]).abs() <= 1e-15,
                    "{i} {a}: {} vs {}",
                    h[a][i],
                    want[a]
                );
            }
        }
        // the axis, the lateral surface, an end face and non-finite points stay scalar
        for p in [
            [0.01, 0.0, 0.3],
            [1.0, 0.0, 0.5],
            [0.6, 0.0, -2.0],
            [f64::NAN, 1.0, 0.0],
        ] {
            assert_eq!(lane_chi(p, r, l), None, "{p:?}");
        }
    }
}
