//! Drag, lift, pitching-torque and rotational-resistance correlations for oblate spheroids
//! ([T002 App. 4.A], Table 4.4; \[Sanjeevi2018\]; \[Zastawny2012\]).
//!
//! All coefficients use the volume-equivalent sphere: `Re = ρ_f |u − v| d_e / μ`, reference area
//! `π d_e²/4`, torque reference length d_e (the normalisation of the original papers; the Stokes
//! limits confirm it, D-002-10). φ is the incidence: 0 edge-on, 90° broadside.
//!
//! Sanjeevi et al. 2:5 oblate (used for w = 0.5 and 0.4), [T002 eq. 4.28-4.32]:
//!
//! * `C_D = C_D0 + (C_D90 − C_D0) sin²φ`,
//!   `C_D0 = (a1/Re + a2/Re^a3) e^{−a4 Re} + a5 (1 − e^{−a4 Re})`,
//!   `C_D90 = (a6/Re + a7/Re^a8) e^{−a9 Re} + a10 (1 − e^{−a9 Re})`. Erratum E-002-22b: Table 4.4
//!   labels the last drag entry "a9 = 1.469"; it is a10.
//! * `C_L = (b1/Re + b2/Re^b3 + b4/Re^b5) sin φ^{1 + b6 Re^b7} cos φ^{1 + b8 Re^b9}`. Erratum
//!   E-002-22a: eq. 4.31 prints `b2/Re^b2` and `b5 Re^b7`, leaving b3 and b6 unused; the form above
//!   uses each of b1..b9 once.
//! * `C_T = (c1/Re^c2 + c3/Re^c4) sin φ^{1 + c5 Re^c6} cos φ^{1 + c7 Re^c8}`. Erratum E-002-22a:
//!   eq. 4.32 prints the sine exponent as `1 + c5 Re^c5`.
//!
//! Zastawny et al. 1:5 oblate (used for w = 0.2), [T002 eq. 4.33-4.37]:
//!
//! * `C_D = C_D0 + (C_D90 − C_D0) sin^{a0} φ`, `C_D0 = a1/Re^a2 + a3/Re^a4`,
//!   `C_D90 = a5/Re^a6 + a7/Re^a8`. Erratum E-002-22a: eq. 4.34 prints `a1/Re^a1`.
//! * `C_L = (b1/Re^b2 + b3/Re^b4) sin φ^{b5 + b6 Re^b7} cos φ^{b8 + b9 Re^b10}`. Erratum E-002-22a:
//!   eq. 4.36 copies the 9-coefficient Sanjeevi lift onto a 10-coefficient set; the form above has
//!   the structure of eq. 4.37 and uses b1..b10 once.
//! * `C_T = (c1/Re^c2 + c3/Re^c4) sin φ^{c5 + c6 Re^c7} cos φ^{c8 + c9 Re^c10}` (eq. 4.37).
//!
//! Rotational resistance, Zastawny mode 2 (rotation about an equatorial axis), eq. 4.38:
//! `C_R = r1 Re_r^r2 + r3 / Re_r^r4`, `Re_r = ρ_f d_e² |½ω − Ω| / μ` ([T002 §4.2] refers to a
//! definition it does not give, erratum E-002-29; this is the sphere's, eq. 2.31, with d_e), and
//! `T_R = (1/64) ρ_f C_R |½ω − Ω| (½ω − Ω) d_e⁵` (ρ_f: eq. 4.9 prints a bare ρ). The 5:2 prolate
//! fit is the thesis's stand-in for 1:2 spheroids, the 1:5 oblate fit for 1:10.
//!
//! Ranges: Sanjeevi's fits cover 0.1 <= Re <= 2000, Zastawny's 0.1 <= Re <= 300. Where the thesis
//! is silent magsep continues them as follows (D-002-11) ([`STOKES_FLOOR`], [`range`]): below Re =
//! 0.1 drag and lift follow Stokes scaling (C·Re constant, force ∝ |u − v|), the pitching torque
//! coefficient is held (torque ∝ |u − v|², the first inertial order; a fore-aft symmetric body has
//! no Stokes torque; erratum E-002-18) and C_R Re_r is held (Stokes rotational drag); above the
//! upper limit the coefficients are frozen. The magnitudes returned here are >= 0 for every Re in
//! range; the loads take the directions from the geometry.

/// Sanjeevi 2:5 drag a1..a10 (Table 4.4).
pub const SANJEEVI_DRAG: [f64; 10] = [
    24.66, 4.059, 0.349, 0.0007, 0.278, 30.18, 4.396, 0.156, 0.0073, 1.469,
];
/// Sanjeevi 2:5 lift b1..b9.
pub const SANJEEVI_LIFT: [f64; 9] = [
    5.28, 8.96, 0.2348, -8.095, 0.325, -0.004, 0.352, -0.002, 0.273,
];
/// Sanjeevi 2:5 pitching torque c1..c8.
pub const SANJEEVI_TORQUE: [f64; 8] = [3.643, 0.178, -1.252, 0.319, -0.018, 0.387, 0.004, 0.349];
/// Zastawny 1:5 drag a0..a8.
pub const ZASTAWNY_DRAG: [f64; 9] = [1.96, 5.82, 0.44, 15.56, 1.068, 35.41, 0.96, 3.63, 0.05];
/// Zastawny 1:5 lift b1..b10.
pub const ZASTAWNY_LIFT: [f64; 10] = [
    12.11, 1.036, 3.887, 0.109, 0.812, 0.249, -0.198, 5.821, -4.717, 0.007,
];
/// Zastawny 1:5 pitching torque c1..c10.
pub const ZASTAWNY_TORQUE: [f64; 10] = [
    3.872, 0.237, 2.351, 0.236, -0.394, 1.615, -0.044, -0.537, 1.805, -0.037,
];
/// Zastawny 5:2 prolate rotational resistance, mode 2: r1..r4.
pub const ZASTAWNY_ROT_PROLATE52: [f64; 4] = [71.03, 0.069, 773.04, 0.67];
/// Zastawny 1:5 oblate rotational resistance, mode 2: r1..r4.
pub const ZASTAWNY_ROT_OBLATE15: [f64; 4] = [13.31, 0.189, 783.05, 0.628];

/// Lower end of the fitted ranges (Re and Re_r); below it Stokes scaling is used.
pub const STOKES_FLOOR: f64 = 0.1;

/// Drag, lift and pitching-torque coefficients (magnitudes, volume-equivalent basis).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coefficients {
    /// C_D.
    pub drag: f64,
    /// C_L (>= 0).
    pub lift: f64,
    /// C_T (>= 0).
    pub torque: f64,
}

/// `s^p` for s in [0, 1], 0 at s = 0 whatever p (the loads are zeroed there anyway), and never
/// NaN.
fn pow_unit(s: f64, p: f64) -> f64 {
    if s > 0.0 {
        let v = s.min(1.0).powf(p);
        if v.is_finite() { v } else { 0.0 }
    } else {
        0.0
    }
}

/// Sanjeevi 2:5 coefficients at Re (> 0) and incidence `phi` \[rad\], raw formulas.
///
/// ```
/// use magsep_systems::fluid::spheroid::correlations::sanjeevi;
/// let edge = sanjeevi(1.0, 0.0);
/// let broad = sanjeevi(1.0, std::f64::consts::FRAC_PI_2);
/// assert!((edge.drag - 28.7).abs() < 0.05 && (broad.drag - 34.3).abs() < 0.05);
/// ```
pub fn sanjeevi(re: f64, phi: f64) -> Coefficients {
    let a = SANJEEVI_DRAG;
    let b = SANJEEVI_LIFT;
    let c = SANJEEVI_TORQUE;
    let (s, co) = (phi.sin().abs(), phi.cos().abs());
    let e0 = (-a[3] * re).exp();
    let e90 = (-a[8] * re).exp();
    let cd0 = (a[0] / re + a[1] / re.powf(a[2])) * e0 + a[4] * (1.0 - e0);
    let cd90 = (a[5] / re + a[6] / re.powf(a[7])) * e90 + a[9] * (1.0 - e90);
    let drag = cd0 + (cd90 - cd0) * s * s;
    let lift = (b[0] / re + b[1] / re.powf(b[2]) + b[3] / re.powf(b[4]))
        * pow_unit(s, 1.0 + b[5] * re.powf(b[6]))
        * pow_unit(co, 1.0 + b[7] * re.powf(b[8]));
    let torque = (c[0] / re.powf(c[1]) + c[2] / re.powf(c[3]))
        * pow_unit(s, 1.0 + c[4] * re.powf(c[5]))
        * pow_unit(co, 1.0 + c[6] * re.powf(c[7]));
    Coefficients {
        drag,
        lift: lift.max(0.0),
        torque: torque.max(0.0),
    }
}

/// Prefactor of the Sanjeevi lift, `b1/Re + b2/Re^b3 + b4/Re^b5` (1.92 at Re = 10).
pub fn sanjeevi_lift_prefactor(re: f64) -> f64 {
    let b = SANJEEVI_LIFT;
    b[0] / re + b[1] / re.powf(b[2]) + b[3] / re.powf(b[4])
}

/// Zastawny 1:5 coefficients at Re (> 0) and incidence `phi` \[rad\], raw formulas.
///
/// ```
/// use magsep_systems::fluid::spheroid::correlations::zastawny;
/// let c = zastawny(10.0, std::f64::consts::FRAC_PI_4);
/// assert!((c.lift - 2.07).abs() < 0.01);
/// ```
pub fn zastawny(re: f64, phi: f64) -> Coefficients {
    let a = ZASTAWNY_DRAG;
    let b = ZASTAWNY_LIFT;
    let c = ZASTAWNY_TORQUE;
    let (s, co) = (phi.sin().abs(), phi.cos().abs());
    let cd0 = a[1] / re.powf(a[2]) + a[3] / re.powf(a[4]);
    let cd90 = a[5] / re.powf(a[6]) + a[7] / re.powf(a[8]);
    let drag = cd0 + (cd90 - cd0) * pow_unit(s, a[0]);
    let lift = (b[0] / re.powf(b[1]) + b[2] / re.powf(b[3]))
        * pow_unit(s, b[4] + b[5] * re.powf(b[6]))
        * pow_unit(co, b[7] + b[8] * re.powf(b[9]));
    let torque = (c[0] / re.powf(c[1]) + c[2] / re.powf(c[3]))
        * pow_unit(s, c[4] + c[5] * re.powf(c[6]))
        * pow_unit(co, c[7] + c[8] * re.powf(c[9]));
    Coefficients {
        drag,
        lift: lift.max(0.0),
        torque: torque.max(0.0),
    }
}

/// Zastawny mode-2 rotational resistance `C_R = r1 Re_r^r2 + r3/Re_r^r4` (raw formula).
///
/// ```
/// use magsep_systems::fluid::spheroid::correlations::{rotation_fit, ZASTAWNY_ROT_OBLATE15};
/// assert!((rotation_fit(&ZASTAWNY_ROT_OBLATE15, 1.0) - 796.36).abs() < 1e-9);
/// ```
pub fn rotation_fit(r: &[f64; 4], re_r: f64) -> f64 {
    r[0] * re_r.powf(r[1]) + r[2] / re_r.powf(r[3])
}

/// The fitted Re range of a correlation (lower, upper); `None` for the sphere and the 1:10
/// database (which have their own continuations).
pub fn range(correlation: super::Correlation) -> Option<(f64, f64)> {
    match correlation {
        super::Correlation::Sanjeevi25 => Some((STOKES_FLOOR, 2000.0)),
        super::Correlation::Zastawny15 => Some((STOKES_FLOOR, 300.0)),
        _ => None,
    }
}

/// Upper end of Zastawny's rotational fits (the data range of the paper).
pub const ROTATION_RE_MAX: f64 = 300.0;

/// `(C_D Re, C_L Re, C_T)` of a Table 4.4 correlation at any Re >= 0, continued outside its
/// range as described in the module header (finite for every input; 0 for NaN).
pub fn continued(correlation: super::Correlation, re: f64, phi: f64) -> (f64, f64, f64) {
    let Some((lo, hi)) = range(correlation) else {
        return (0.0, 0.0, 0.0);
    };
    if re.is_nan() || phi.is_nan() {
        return (0.0, 0.0, 0.0);
    }
    let f = match correlation {
        super::Correlation::Sanjeevi25 => sanjeevi,
        _ => zastawny,
    };
    let (out, scale) = if re < lo {
        (f(lo, phi), lo)
    } else if re > hi {
        (f(hi, phi), re)
    } else {
        (f(re, phi), re)
    };
    let fin = |x: f64| if x.is_finite() { x } else { 0.0 };
    (
        fin(out.drag * scale),
        fin(out.lift * scale),
        fin(out.torque),
    )
}

/// `C_R Re_r` of a Zastawny rotational fit at any Re_r >= 0, continued as in the module
/// header (held at its value at [`STOKES_FLOOR`] below, C_R frozen above [`ROTATION_RE_MAX`]).
pub fn rotation_continued(r: &[f64; 4], re_r: f64) -> f64 {
    if re_r.is_nan() {
        return 0.0;
    }
    let v = if re_r < STOKES_FLOOR {
        rotation_fit(r, STOKES_FLOOR) * STOKES_FLOOR
    } else if re_r > ROTATION_RE_MAX {
        rotation_fit(r, ROTATION_RE_MAX) * re_r
    } else {
        rotation_fit(r, re_r) * re_r
    };
    if v.is_finite() { v } else { 0.0 }
}
