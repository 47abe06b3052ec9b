//! Models of the 1:10 database ([`super::disc_table`], [T002 Tables 3.3-3.5]) in place of the
//! thesis's neural network (3 × 300 ReLU, trained on 236 of the 266 points; its weights are not
//! published, [T002 §3.4]).
//!
//! The run-time model (D-002-12; [`DiscMethod::Spline`], [`disc_coefficients`]) is the
//! tensor-product cubic spline in `(x, φ) = (ln(1 + Re_e), φ)` through all 266 nodes, stored as
//! bicubic Hermite patches whose node derivatives come from 1-D splines (so it interpolates every
//! node exactly and is C² in each variable). Interpolated quantities: `C_D Re_e`, `C_L Re_e` and
//! `C_T`, the forms that tend to constants in the Stokes limit (C_D Re_e grows only from 35 to 108
//! over the table at 0°, while C_D varies 40-fold). The abscissa ln(1 + Re_e) is ≈ Re_e in the
//! Stokes-Oseen range, where `C Re_e ≈ A + B Re_e`, and ≈ ln Re_e above; it was chosen over ln Re_e
//! and over C_L, C_T Re_e by the held-out errors (leave one Re column out: max 0.65 / 2.6 / 1.9 %
//! for drag / lift / torque against 0.73 / 3.4 / 2.5 % with ln Re_e). End conditions: natural in x;
//! in φ, zero slope for drag (even about 0° and 90°) and natural for lift and torque (odd about 0°
//! and 90°, where they vanish: a natural spline is exactly the odd continuation). Lift and torque
//! nodes at φ = 0° and 90° (printed 0.01-0.08, noise) are set to 0.
//!
//! Held-out accuracy ([`super::disc_validation`], refits without the held-out nodes): leaving out
//! one Re column at a time, mean errors 0.14 / 0.45 / 0.28 %; leaving out one angle row at a time,
//! 0.08 / 0.35 / 0.49 % with maxima of 1.4 / 12 / 16 % at the 85° row and Re_e = 55.7, where lift
//! and torque drop steeply to 0 at 90° (a feature no interpolant can recover from the 80° and 90°
//! rows alone). The thesis's network: mean 1.5 % (drag), < 3 % (lift, torque) on 30 random held-out
//! points.
//!
//! Outside the table (D-002-11): below Re_e = 0.464 drag and lift follow Stokes scaling (C·Re_e
//! held, force ∝ |u − v|) and the torque coefficient is held (torque ∝ |u − v|², a fore-aft
//! symmetric body has no Stokes torque, erratum E-002-18). Deviation: a constant lift coefficient
//! (lift ∝ |u − v|²) would be inconsistent with the table itself, whose 0.464 column already has
//! the Stokes ratio C_L/C_D = (C_D90 − C_D0)/(C_D90 + C_D0) at 45° (0.196 against 0.185). Above
//! Re_e = 55.7 (the steady-wake limit Re ≈ 120-130 of the database) the coefficients are frozen at
//! the last column. φ is clamped to [0, π/2].
//!
//! The spline is hand-written: 14 × 19 nodes need a 60-line tridiagonal solver, and the
//! per-direction end conditions above are not offered by the small interpolation crates.
//! [`DiscMethod::Bilinear`] and [`DiscMethod::LeastSquares`] (Chebyshev polynomials of degree 5 in
//! x times four Fourier modes in φ, 24 coefficients per quantity) are the alternatives compared by
//! `magsep chart spheroid-model` (one Re column held out, mean errors drag / lift / torque:
//! bilinear 1.4 / 4.0 / 0.44 % at ≈ 50 ns per evaluation of all three, spline 0.14 / 0.45 / 0.28 %
//! at ≈ 85 ns, least squares 0.44 / 2.4 / 0.59 % at ≈ 250 ns).

use super::correlations::Coefficients;
use super::disc_table::{DRAG, LIFT, PHI_DEG, TORQUE, re_e};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// How the database is modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscMethod {
    /// Bilinear in (ln Re_e, φ).
    Bilinear,
    /// Tensor-product cubic spline in (ln Re_e, φ) (the run-time model).
    Spline,
    /// Least-squares fit: Chebyshev (degree 5) in ln Re_e × 4 Fourier modes in φ.
    LeastSquares,
}

const NX: usize = 14;
const NY: usize = 19;
/// Number of Chebyshev terms in x of the least-squares fit.
const LS_NX: usize = 6;
/// Number of Fourier terms in φ of the least-squares fit.
const LS_NY: usize = 4;

/// Whether quantity q (0 drag, 1 lift, 2 torque) is interpolated as C·Re_e (else C).
const TIMES_RE: [bool; 3] = [true, true, false];
/// The abscissa is `ln(Re_e + X_SHIFT)`: ln(1 + Re_e).
const X_SHIFT: f64 = 1.0;

/// How the run-time model parametrises the table: which quantities are multiplied by Re_e,
/// and the shift s of the abscissa ln(Re_e + s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    /// C·Re_e (true) or C (false) for drag, lift, torque.
    pub times_re: [bool; 3],
    /// Shift of the abscissa.
    pub x_shift: f64,
    /// If > 0, the abscissa is `Re_e^x_power` instead of the logarithm.
    pub x_power: f64,
}

impl Variant {
    /// The abscissa of Re_e.
    pub fn abscissa(&self, re: f64) -> f64 {
        if self.x_power > 0.0 {
            re.powf(self.x_power)
        } else {
            (re + self.x_shift).ln()
        }
    }
}

impl Default for Variant {
    fn default() -> Self {
        Self {
            times_re: TIMES_RE,
            x_shift: X_SHIFT,
            x_power: 0.0,
        }
    }
}

/// The quantity of table `q` (0 drag, 1 lift, 2 torque) at node (row i, column j): C, or C Re_e
/// when `times_re`, with lift and torque set to 0 at φ = 0° and 90°.
pub fn node_value(q: usize, i: usize, j: usize, times_re: bool) -> f64 {
    if q > 0 && (i == 0 || i == NY - 1) {
        return 0.0;
    }
    table_coefficient(q, i, j) * if times_re { re_e(j) } else { 1.0 }
}

/// The printed coefficient C of table `q` at node (i, j).
pub fn table_coefficient(q: usize, i: usize, j: usize) -> f64 {
    match q {
        0 => DRAG[i][j],
        1 => LIFT[i][j],
        _ => TORQUE[i][j],
    }
}

#[derive(Debug, Clone)]
enum Surface {
    /// Node values and derivatives, row-major `[row][col]` over the kept nodes.
    Grid {
        f: Vec<f64>,
        fx: Vec<f64>,
        fy: Vec<f64>,
        fxy: Vec<f64>,
    },
    /// Least-squares coefficients `[kx * LS_NY + ky]`.
    Ls(Vec<f64>),
}

/// A model of the database fitted to a subset of its columns and rows.
#[derive(Debug, Clone)]
pub struct DiscModel {
    method: DiscMethod,
    variant: Variant,
    re_range: (f64, f64),
    xs: Vec<f64>,
    ys: Vec<f64>,
    surfaces: Vec<Surface>,
}

#[derive(Clone, Copy)]
enum End {
    Natural,
    ZeroSlope,
}

/// Node slopes of the cubic spline through (x, f) (tridiagonal solve, Thomas algorithm).
fn spline_slopes(x: &[f64], f: &[f64], end: End) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|i| (f[i + 1] - f[i]) / h[i]).collect();
    let (mut lo, mut di, mut up, mut rhs) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    match end {
        End::Natural => {
            di[0] = 2.0;
            up[0] = 1.0;
            rhs[0] = 3.0 * d[0];
            lo[n - 1] = 1.0;
            di[n - 1] = 2.0;
            rhs[n - 1] = 3.0 * d[n - 2];
        }
        End::ZeroSlope => {
            di[0] = 1.0;
            di[n - 1] = 1.0;
        }
    }
    for i in 1..n - 1 {
        lo[i] = h[i];
        di[i] = 2.0 * (h[i - 1] + h[i]);
        up[i] = h[i - 1];
        rhs[i] = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i]);
    }
    for i in 1..n {
        let m = lo[i] / di[i - 1];
        di[i] -= m * up[i - 1];
        rhs[i] -= m * rhs[i - 1];
    }
    let mut s = vec![0.0; n];
    s[n - 1] = rhs[n - 1] / di[n - 1];
    for i in (0..n - 1).rev() {
        s[i] = (rhs[i] - up[i] * s[i + 1]) / di[i];
    }
    s
}

fn chebyshev(xi: f64, out: &mut [f64; LS_NX]) {
    out[0] = 1.0;
    out[1] = xi;
    for k in 2..LS_NX {
        out[k] = 2.0 * xi * out[k - 1] - out[k - 2];
    }
}

fn fourier(q: usize, phi: f64, out: &mut [f64; LS_NY]) {
    for (m, o) in out.iter_mut().enumerate() {
        *o = if q == 0 {
            (2.0 * m as f64 * phi).cos()
        } else {
            (2.0 * (m + 1) as f64 * phi).sin()
        };
    }
}

/// Solve the symmetric positive definite system `a x = b` (n × n, row-major) by Cholesky;
/// zeros if it is singular.
fn cholesky_solve(a: &mut [f64], b: &mut [f64], n: usize) {
    for j in 0..n {
        let mut s = a[j * n + j];
        for k in 0..j {
            s -= a[j * n + k] * a[j * n + k];
        }
        if s.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            b.iter_mut().for_each(|v| *v = 0.0);
            return;
        }
        let l = s.sqrt();
        a[j * n + j] = l;
        for i in j + 1..n {
            let mut t = a[i * n + j];
            for k in 0..j {
                t -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = t / l;
        }
    }
    for i in 0..n {
        let mut t = b[i];
        for k in 0..i {
            t -= a[i * n + k] * b[k];
        }
        b[i] = t / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut t = b[i];
        for k in i + 1..n {
            t -= a[k * n + i] * b[k];
        }
        b[i] = t / a[i * n + i];
    }
}

impl DiscModel {
    /// Fit `method` to the table columns `cols` and rows `rows` (indices, increasing; the
    /// grid methods need at least 2 of each, else the model returns zeros).
    pub fn fit(method: DiscMethod, cols: &[usize], rows: &[usize]) -> Self {
        Self::fit_variant(method, Variant::default(), cols, rows)
    }

    /// [`Self::fit`] with another parametrisation.
    pub fn fit_variant(
        method: DiscMethod,
        variant: Variant,
        cols: &[usize],
        rows: &[usize],
    ) -> Self {
        let cols: Vec<usize> = cols.iter().copied().filter(|&j| j < NX).collect();
        let rows: Vec<usize> = rows.iter().copied().filter(|&i| i < NY).collect();
        let xs: Vec<f64> = cols.iter().map(|&j| variant.abscissa(re_e(j))).collect();
        let re_range = match (cols.first(), cols.last()) {
            (Some(&a), Some(&b)) => (re_e(a), re_e(b)),
            _ => (f64::NAN, f64::NAN),
        };
        let ys: Vec<f64> = rows.iter().map(|&i| PHI_DEG[i].to_radians()).collect();
        let (nx, ny) = (xs.len(), ys.len());
        let surfaces = (0..3)
            .map(|q| {
                let f: Vec<f64> = rows
                    .iter()
                    .flat_map(|&i| {
                        cols.iter()
                            .map(move |&j| node_value(q, i, j, variant.times_re[q]))
                    })
                    .collect();
                match method {
                    DiscMethod::LeastSquares => Surface::Ls(Self::least_squares(q, &xs, &ys, &f)),
                    _ => Self::grid(q, &xs, &ys, f, nx, ny),
                }
            })
            .collect();
        Self {
            method,
            variant,
            re_range,
            xs,
            ys,
            surfaces,
        }
    }

    fn grid(q: usize, xs: &[f64], ys: &[f64], f: Vec<f64>, nx: usize, ny: usize) -> Surface {
        let yend = if q == 0 { End::ZeroSlope } else { End::Natural };
        let mut fx = vec![0.0; nx * ny];
        let mut fy = vec![0.0; nx * ny];
        let mut fxy = vec![0.0; nx * ny];
        for r in 0..ny {
            let s = spline_slopes(xs, &f[r * nx..(r + 1) * nx], End::Natural);
            fx[r * nx..(r + 1) * nx].copy_from_slice(&s);
        }
        for c in 0..nx {
            let col: Vec<f64> = (0..ny).map(|r| f[r * nx + c]).collect();
            let colx: Vec<f64> = (0..ny).map(|r| fx[r * nx + c]).collect();
            let s = spline_slopes(ys, &col, yend);
            let sx = spline_slopes(ys, &colx, yend);
            for r in 0..ny {
                fy[r * nx + c] = s[r];
                fxy[r * nx + c] = sx[r];
            }
        }
        Surface::Grid { f, fx, fy, fxy }
    }

    fn least_squares(q: usize, xs: &[f64], ys: &[f64], f: &[f64]) -> Vec<f64> {
        let n = LS_NX * LS_NY;
        let (mut a, mut b) = (vec![0.0; n * n], vec![0.0; n]);
        let (x0, x1) = (xs.first().copied(), xs.last().copied());
        let (Some(x0), Some(x1)) = (x0, x1) else {
            return b;
        };
        let mut basis = vec![0.0; n];
        for (r, &y) in ys.iter().enumerate() {
            for (c, &x) in xs.iter().enumerate() {
                Self::ls_basis(q, x, y, x0, x1, &mut basis);
                let v = f[r * xs.len() + c];
                for i in 0..n {
                    b[i] += basis[i] * v;
                    for k in 0..n {
                        a[i * n + k] += basis[i] * basis[k];
                    }
                }
            }
        }
        // a tiny ridge keeps the system definite when fitted to few nodes
        for i in 0..n {
            a[i * n + i] += 1e-12 * (1.0 + a[i * n + i]);
        }
        cholesky_solve(&mut a, &mut b, n);
        b
    }

    fn ls_basis(q: usize, x: f64, y: f64, x0: f64, x1: f64, out: &mut [f64]) {
        let xi = if x1 > x0 {
            2.0 * (x - x0) / (x1 - x0) - 1.0
        } else {
            0.0
        };
        let (mut tx, mut ty) = ([0.0; LS_NX], [0.0; LS_NY]);
        chebyshev(xi, &mut tx);
        fourier(q, y, &mut ty);
        for (kx, vx) in tx.iter().enumerate() {
            for (ky, vy) in ty.iter().enumerate() {
                out[kx * LS_NY + ky] = vx * vy;
            }
        }
    }

    /// The method.
    pub fn method(&self) -> DiscMethod {
        self.method
    }

    /// The raw interpolated quantities (C_D Re_e, C_L Re_e, C_T, or C per [`Variant`]) at
    /// (x, y) inside the fitted grid; the cell and basis are found once for all three.
    fn surfaces_at(&self, x: f64, y: f64) -> [f64; 3] {
        let (nx, ny) = (self.xs.len(), self.ys.len());
        if nx < 2 || ny < 2 {
            return [0.0; 3];
        }
        if self.method == DiscMethod::LeastSquares {
            let (x0, x1) = (self.xs[0], self.xs[nx - 1]);
            let mut basis = [0.0; LS_NX * LS_NY];
            return [0, 1, 2].map(|q| {
                let Surface::Ls(coef) = &self.surfaces[q] else {
                    return 0.0;
                };
                Self::ls_basis(q, x, y, x0, x1, &mut basis);
                basis.iter().zip(coef).map(|(a, b)| a * b).sum()
            });
        }
        let c = self.xs.partition_point(|&v| v <= x).clamp(1, nx - 1) - 1;
        let r = self.ys.partition_point(|&v| v <= y).clamp(1, ny - 1) - 1;
        let (hx, hy) = (self.xs[c + 1] - self.xs[c], self.ys[r + 1] - self.ys[r]);
        let (t, u) = ((x - self.xs[c]) / hx, (y - self.ys[r]) / hy);
        let corners = [
            r * nx + c,
            r * nx + c + 1,
            (r + 1) * nx + c,
            (r + 1) * nx + c + 1,
        ];
        if self.method == DiscMethod::Bilinear {
            let w = [(1.0 - u) * (1.0 - t), (1.0 - u) * t, u * (1.0 - t), u * t];
            return [0, 1, 2].map(|q| match &self.surfaces[q] {
                Surface::Grid { f, .. } => corners.iter().zip(w).map(|(&k, w)| w * f[k]).sum(),
                Surface::Ls(_) => 0.0,
            });
        }
        // cubic Hermite basis: value and slope weights at the two ends
        let h = |s: f64| {
            let (s2, s3) = (s * s, s * s * s);
            [
                2.0 * s3 - 3.0 * s2 + 1.0,
                s3 - 2.0 * s2 + s,
                -2.0 * s3 + 3.0 * s2,
                s3 - s2,
            ]
        };
        let (bx, by) = (h(t), h(u));
        // per corner: weights of f, fx, fy, fxy
        let mut w = [[0.0; 4]; 4];
        for (k, wk) in w.iter_mut().enumerate() {
            let (dr, dc) = (k / 2, k % 2);
            let (pv, dv) = (by[2 * dr], by[2 * dr + 1]);
            let (pu, du) = (bx[2 * dc], bx[2 * dc + 1]);
            *wk = [pv * pu, pv * du * hx, dv * pu * hy, dv * du * hx * hy];
        }
        [0, 1, 2].map(|q| match &self.surfaces[q] {
            Surface::Grid { f, fx, fy, fxy } => corners
                .iter()
                .zip(&w)
                .map(|(&k, wk)| wk[0] * f[k] + wk[1] * fx[k] + wk[2] * fy[k] + wk[3] * fxy[k])
                .sum(),
            Surface::Ls(_) => 0.0,
        })
    }

    /// `(C_D Re_e, C_L Re_e, C_T)` at any Re_e >= 0 and φ \[rad\], continued outside the
    /// fitted range as in the module header (clamped in Re_e and φ; zeros for NaN).
    pub fn continued(&self, re_e: f64, phi: f64) -> (f64, f64, f64) {
        let (re0, re1) = self.re_range;
        if re_e.is_nan() || phi.is_nan() || re0.is_nan() || re1.is_nan() {
            return (0.0, 0.0, 0.0);
        }
        let rc = re_e.clamp(re0, re1);
        let x = self.variant.abscissa(rc);
        let y = phi.clamp(0.0, std::f64::consts::FRAC_PI_2);
        // the coefficients C at the clamped Re_e
        let raw = self.surfaces_at(x, y);
        let [d, l, t] = [0, 1, 2].map(|q| {
            if self.variant.times_re[q] {
                raw[q] / rc
            } else {
                raw[q]
            }
        });
        // below the table C·Re_e is held (Stokes), above it C is frozen
        let re = if re_e < re0 { re0 } else { re_e };
        let fin = |v: f64| if v.is_finite() { v } else { 0.0 };
        (fin(d * re), fin(l.max(0.0) * re), fin(t.max(0.0)))
    }

    /// The coefficients C_D, C_L, C_T at Re_e > 0 (continued as [`Self::continued`]).
    pub fn coefficients(&self, re_e: f64, phi: f64) -> Coefficients {
        let (d, l, t) = self.continued(re_e, phi);
        let re = re_e.max(1e-300);
        Coefficients {
            drag: d / re,
            lift: l / re,
            torque: t,
        }
    }
}

/// The run-time model: the spline through all 266 nodes (built once).
pub fn disc_model() -> &'static DiscModel {
    static MODEL: OnceLock<DiscModel> = OnceLock::new();
    MODEL.get_or_init(|| {
        let cols: Vec<usize> = (0..NX).collect();
        let rows: Vec<usize> = (0..NY).collect();
        DiscModel::fit(DiscMethod::Spline, &cols, &rows)
    })
}

/// `(C_D Re_e, C_L Re_e, C_T)` of the run-time 1:10 model.
///
/// ```
/// use magsep_systems::fluid::spheroid::disc_model::disc_coefficients;
/// use magsep_systems::fluid::spheroid::disc_table::{re_e, DRAG};
/// let (cd_re, _, _) = disc_coefficients(re_e(3), 45f64.to_radians());
/// assert!((cd_re / re_e(3) - DRAG[9][3]).abs() < 1e-9);
/// ```
pub fn disc_coefficients(re_e: f64, phi: f64) -> (f64, f64, f64) {
    disc_model().continued(re_e, phi)
}
