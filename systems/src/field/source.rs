//! A magnetised cylinder with any pose (world frame) and the superposition of many.
//!
//! [`CylinderSource`] precomputes a cylinder's body frame and multipole coefficients. For a
//! point it evaluates the exterior multipole expansion where the expansion's error bound
//! ([`multipole::truncation_bound`]) is within the requested relative tolerance, else the
//! closed form (or its near-axis branch). With the default tolerance [`EXACT`] the multipole is
//! used beyond ~2 circumscribed radii `a`, where it is more accurate than the closed form (whose
//! two end terms cancel there: error ~1e-16 (r/a)², and ~1e-16 r³/(R² L) beyond the ends of a
//! long fibre).

use glam::{DMat3, DVec3};

use super::batch;
use super::cylinder::{hess_parts, inside_indicator};
use super::multipole;
use super::real::{Dual3, Real};

/// Magnetic constant μ0 [T m/A] (CODATA 2018).
pub const MU0: f64 = 1.256_637_062_12e-6;

/// Tolerance at which the kernel is as exact as double precision allows.
pub const EXACT: f64 = 1e-15;

/// A uniformly magnetised finite circular cylinder in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CylinderSource {
    /// Centre \[m\].
    pub center: DVec3,
    /// Body frame: columns are `e1`, `e2`, `e3 = axis` (unit).
    frame: DMat3,
    /// Radius R \[m\].
    pub radius: f64,
    /// Half length L \[m\] (the thesis's ch. 5 `L`).
    pub half_length: f64,
    /// Magnetisation [A/m], world frame.
    pub magnetisation: DVec3,
    m_body: [f64; 3],
    q: Vec<f64>,
    /// Circumscribed radius `√(L² + R²)` \[m\].
    pub circumradius: f64,
}

/// Field at a point: `H` [A/m] and `B` \[T\] of one source (or a sum).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FieldValue {
    /// Magnetic field strength H [A/m].
    pub h: DVec3,
    /// Flux density B \[T\] (`μ0 (H + M)` inside a source, `μ0 H` outside).
    pub b: DVec3,
}

/// Field and gradient: `grad_b.col(j) = ∂B/∂x_j` [T/m].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FieldGradient {
    /// Flux density B \[T\].
    pub b: DVec3,
    /// Jacobian of B: column `j` is `∂B/∂x_j` [T/m] (symmetric outside all sources).
    pub grad_b: DMat3,
}

impl CylinderSource {
    /// A cylinder centred at `center` with axis direction `axis` (normalised here), radius and
    /// half length \[m\], and magnetisation [A/m]. Inputs must be finite with `radius > 0`,
    /// `half_length > 0` and `axis != 0` (scene validation checks this).
    pub fn new(
        center: DVec3,
        axis: DVec3,
        radius: f64,
        half_length: f64,
        magnetisation: DVec3,
    ) -> Self {
        let e3 = axis.normalize();
        let e1 = e3.any_orthonormal_vector();
        let e2 = e3.cross(e1);
        let frame = DMat3::from_cols(e1, e2, e3);
        let mb = frame.transpose() * magnetisation;
        Self {
            center,
            frame,
            radius,
            half_length,
            magnetisation,
            m_body: mb.to_array(),
            q: multipole::coefficients(radius, half_length),
            circumradius: (radius * radius + half_length * half_length).sqrt(),
        }
    }

    /// Unit axis.
    pub fn axis(&self) -> DVec3 {
        self.frame.z_axis
    }

    /// Multipole order used at `p` for relative tolerance `tol`, or `None` for the closed form.
    ///
    /// At a loose tolerance the expansion is used wherever an order up to
    /// [`multipole::FAST_ORDER`] meets it (cheaper than the closed form). Otherwise it is used
    /// where the closed form's estimated rounding error (its two end terms cancel far away:
    /// `~1e-16 (r/a)² max(50, r a/R²)`) exceeds 1e-13, at the smallest order meeting `tol`, or
    /// failing that the closed form's error.
    pub fn multipole_order(&self, p: DVec3, tol: f64) -> Option<usize> {
        let tol = tol.max(EXACT);
        let r2 = (p - self.center).length_squared();
        let a2 = self.circumradius * self.circumradius;
        if a2 >= r2 {
            return None;
        }
        let r = r2.sqrt();
        let x = self.circumradius / r;
        // a loose tolerance buys speed while the expansion is cheaper than the closed form
        if tol > EXACT
            && let Some(n) = multipole::order_for(x, tol, multipole::FAST_ORDER)
        {
            return Some(n);
        }
        // the closed form's rounding error from its cancelling end terms (conservative):
        // ~1e-16 (r/a)² max(50, r a / R²)
        let closed_error =
            1e-16 * (r2 / a2) * (r * self.circumradius / (self.radius * self.radius)).max(50.0);
        if closed_error <= tol.max(1e-13) {
            return None;
        }
        multipole::order_for(x, tol, multipole::MAX_ORDER)
            .or_else(|| multipole::order_for(x, closed_error, multipole::MAX_ORDER))
    }

    /// Body-frame `H` (generic: `f64` or [`Dual3`]) and `χ`.
    fn h_body<T: Real>(&self, pb: [T; 3], order: Option<usize>) -> ([T; 3], f64) {
        match order {
            Some(n) => (multipole::field(&self.q, n, pb, self.m_body), 0.0),
            None => {
                let parts = hess_parts(pb[0], pb[1], pb[2], self.radius, self.half_length);
                (parts.apply(pb[0], pb[1], self.m_body), parts.chi)
            }
        }
    }

    /// `H` [A/m] and `B` \[T\] at `p` \[m\] to relative tolerance `tol` ([`EXACT`] for full
    /// precision).
    pub fn field(&self, p: DVec3, tol: f64) -> FieldValue {
        self.field_with(p, self.multipole_order(p, tol))
    }

    /// `H` and `B` at many points, `out[i]` at `points[i]`, as [`field`](Self::field) gives them
    /// (to the last bit or two: groups of four points that all take the closed form off the
    /// axis and the surface go through the four-lane kernel of [`super::batch`], the others
    /// one by one). The fast way to evaluate one cylinder on a field map.
    ///
    /// # Panics
    /// If `out` is shorter than `points`.
    pub fn field_batch(&self, points: &[DVec3], tol: f64, out: &mut [FieldValue]) {
        let out = &mut out[..points.len()];
        let ft = self.frame.transpose();
        for (pts, res) in points.chunks(4).zip(out.chunks_mut(4)) {
            let mut lanes = [[0.0; 4]; 3];
            let mut chi = [0.0; 4];
            let mut fast = pts.len() == 4;
            for (l, &p) in pts.iter().enumerate() {
                if !fast {
                    break;
                }
                let d = (ft * (p - self.center)).to_array();
                match batch::lane_chi(d, self.radius, self.half_length) {
                    Some(c) if self.multipole_order(p, tol).is_none() => {
                        chi[l] = c;
                        for a in 0..3 {
                            lanes[a][l] = d[a];
                        }
                    }
                    _ => fast = false,
                }
            }
            if !fast {
                for (p, r) in pts.iter().zip(res.iter_mut()) {
                    *r = self.field(*p, tol);
                }
                continue;
            }
            let h = batch::h_body4(lanes, chi, self.radius, self.half_length, self.m_body);
            for (l, r) in res.iter_mut().enumerate() {
                let h = self.frame * DVec3::new(h[0][l], h[1][l], h[2][l]);
                *r = FieldValue {
                    h,
                    b: (h + self.magnetisation * chi[l]) * MU0,
                };
            }
        }
    }

    /// `H` and `B` at `p` by a given method: the multipole expansion through `order`, or with
    /// `None` the closed form (for comparisons; [`field`](Self::field) chooses by itself).
    pub fn field_with(&self, p: DVec3, order: Option<usize>) -> FieldValue {
        let d = self.frame.transpose() * (p - self.center);
        let (h, chi) = self.h_body(d.to_array(), order);
        let h = self.frame * DVec3::from_array(h);
        FieldValue {
            h,
            b: (h + self.magnetisation * chi) * MU0,
        }
    }

    /// `B` \[T\] and its exact gradient [T/m] at `p` (forward-mode differentiation through the
    /// same kernel).
    pub fn field_gradient(&self, p: DVec3, tol: f64) -> FieldGradient {
        let order = self.multipole_order(p, tol);
        let [x, y, z] = Dual3::seed(p - self.center);
        let f = self.frame;
        let pb = [
            x * f.x_axis.x + y * f.x_axis.y + z * f.x_axis.z,
            x * f.y_axis.x + y * f.y_axis.y + z * f.y_axis.z,
            x * f.z_axis.x + y * f.z_axis.y + z * f.z_axis.z,
        ];
        let (hb, chi) = self.h_body(pb, order);
        let mut b = DVec3::ZERO;
        let mut rows = [DVec3::ZERO; 3];
        for (i, row) in rows.iter_mut().enumerate() {
            // world component i = Σ_k frame[k][i] hb[k]
            let mut v = 0.0;
            let mut d = DVec3::ZERO;
            for (k, hk) in hb.iter().enumerate() {
                let c = f.col(k)[i];
                v += c * hk.v;
                d += hk.d * c;
            }
            b[i] = (v + chi * self.magnetisation[i]) * MU0;
            *row = d * MU0;
        }
        FieldGradient {
            b,
            grad_b: DMat3::from_cols(rows[0], rows[1], rows[2]).transpose(),
        }
    }

    /// Whether `p` is inside the solid cylinder (surface counts as inside).
    pub fn contains(&self, p: DVec3) -> bool {
        let d = self.frame.transpose() * (p - self.center);
        let rho = (d.x * d.x + d.y * d.y).sqrt();
        inside_indicator(rho, d.z, self.radius, self.half_length) > 0.0
    }

    /// The point of the solid cylinder closest to `p` (`p` itself inside).
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        let d = p - self.center;
        let axis = self.axis();
        let z = d.dot(axis);
        let radial = d - axis * z;
        let rl = radial.length();
        let radial = if rl > self.radius {
            radial * (self.radius / rl)
        } else {
            radial
        };
        self.center + axis * z.clamp(-self.half_length, self.half_length) + radial
    }

    /// Distance \[m\] from `p` to the solid cylinder (0 inside).
    pub fn distance(&self, p: DVec3) -> f64 {
        (p - self.closest_point(p)).length()
    }
}

/// [`total_field`] at many points: `out[i]` is the flux density \[T\] at `points[i]` \[m\],
/// one source at a time over all points ([`CylinderSource::field_batch`]).
///
/// # Panics
/// If `out` is shorter than `points`.
pub fn total_field_batch(
    sources: &[CylinderSource],
    b_ext: DVec3,
    points: &[DVec3],
    tol: f64,
    out: &mut [DVec3],
) {
    let out = &mut out[..points.len()];
    out.fill(b_ext);
    let mut buf = vec![FieldValue::default(); points.len().min(1024)];
    for s in sources {
        for (pts, res) in points.chunks(1024).zip(out.chunks_mut(1024)) {
            let buf = &mut buf[..pts.len()];
            s.field_batch(pts, tol, buf);
            for (o, f) in res.iter_mut().zip(buf.iter()) {
                *o += f.b;
            }
        }
    }
}

/// Sum of the fields of `sources` plus a uniform external flux density `b_ext` \[T\].
pub fn total_field(sources: &[CylinderSource], b_ext: DVec3, p: DVec3, tol: f64) -> FieldValue {
    let mut out = FieldValue {
        h: b_ext / MU0,
        b: b_ext,
    };
    for s in sources {
        let f = s.field(p, tol);
        out.h += f.h;
        out.b += f.b;
    }
    out
}

/// Sum of the fields and gradients of `sources` plus a uniform `b_ext` \[T\].
pub fn total_field_gradient(
    sources: &[CylinderSource],
    b_ext: DVec3,
    p: DVec3,
    tol: f64,
) -> FieldGradient {
    let mut out = FieldGradient {
        b: b_ext,
        grad_b: DMat3::ZERO,
    };
    for s in sources {
        let f = s.field_gradient(p, tol);
        out.b += f.b;
        out.grad_b += f.grad_b;
    }
    out
}
