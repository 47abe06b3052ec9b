//! Hard-spheroid contact geometry and time of impact (thesis 002, ch. 4, §4.2.1.3: minimum
//! distance along the common normal after Jain et al. 2019, time of impact of ballistically
//! moving and rotating particles).
//!
//! **Shape.** A spheroid with equatorial semi-axis `a` and polar semi-axis `c` about its body z
//! axis; its lab symmetry axis is `e = q·ẑ` for the body→lab rotation `q`. Its shape matrix is
//! `E⁻¹ = R diag(a², a², c²) Rᵀ = a² 𝕀 + (c² − a²) e eᵀ` \[m²\], and its support function about
//! the centre is `h(u) = √(uᵀ E⁻¹ u)` with support point `E⁻¹ u / h(u)` (the surface point
//! whose outward normal is `u`). A sphere is the case `a = c`.
//!
//! **Minimum distance (common normal).** For two convex bodies with centre offset
//! `d = x_b − x_a`, the signed distance (the gap when apart, minus the penetration depth when
//! overlapping) is the maximum over unit `u` of the separating-axis function
//! `f(u) = u·d − h_a(u) − h_b(u)` (the support functions of centrally symmetric bodies are
//! even). At the maximiser `u*` the support points `p_a = x_a + E_a⁻¹u/h_a` and
//! `p_b = x_b − E_b⁻¹u/h_b` satisfy `p_b − p_a = f(u*) u*`: `u*` is the common normal of
//! Jain et al. (the shortest segment between the surfaces lies along the normals of both) and
//! points from *a* to *b*. [`spheroid_contact`] maximises `f` over the unit sphere by a
//! trust-region Newton iteration in the tangent plane (analytic gradient and Hessian of the
//! support functions; the Riemannian Hessian is `P H P − f P`). For separated pairs the
//! positive super-level sets of `f` are connected (`f` is concave and 1-homogeneous), so the
//! ascent from any seed with `f > 0` reaches the global maximum; at convergence the witness
//! distance `|p_b − p_a|` (an upper bound of the distance) equals `f` (a lower bound), which
//! certifies it. For overlapping pairs `−f` is a local penetration depth.
//!
//! **Deviations and choices where the thesis and Jain et al. are silent.**
//! * Jain et al. parametrise the two surface points and solve the common-normal equations; we
//!   solve for the normal alone (two unknowns instead of four, no surface parametrisation
//!   singularity at the poles, a scalar objective that makes the iteration monotone).
//! * Seeds: the warm start (the previous normal of the pair) if given, the centre line, and
//!   both symmetry axes (signed towards `d`); the iteration starts from the seed with the
//!   largest `f` and falls back to the others, then to the superquadric GJK/EPA + Newton
//!   contact of `crate::geometry::superquadric` (reported as not converged if that also fails).
//!   Solutions with `u·d < 0` (far side; never the global one for centrally symmetric bodies) are
//!   rejected.
//! * Convergence: tangential witness offset `|P(p_b − p_a)| ≤ 1e-12 (R_a + R_b)` (`R` the bounding
//!   radii), at most 60 iterations; the Hessian is shifted to be negative definite where needed
//!   (overlaps deeper than the sum of the radii of curvature, e.g. `2c²/a` at two rims).
//! * Contact frame: the normal is `u*` (from *a* to *b*), the common contact point is the
//!   midpoint of the two witness points and the lever arms run to it (this keeps the impulse
//!   momentum-conserving, see [`super::impulse`]); the gap is `f(u*)`.
//! * Spheroid–plane is closed form: with the unit plane normal `n_w` into the fluid,
//!   `gap = n_w·(x − x_w) − √(n_wᵀ E⁻¹ n_w)`, deepest point `x − E⁻¹ n_w/√(n_wᵀ E⁻¹ n_w)`.
//!
//! Time of impact: [`spheroid_pair_toi`] and [`spheroid_plane_toi`] (separating-axis
//! conservative advancement; their submodule header states the method and the tolerances).
//! Cost of one contact query: [`time_contact_queries`].
//!
//! All functions are NaN-safe: invalid shapes or non-finite poses give `None`.

mod bench;
mod contact;
mod toi;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_impulse;
#[cfg(test)]
mod tests_toi;

pub use bench::{ContactQueryTiming, time_contact_queries};
pub use contact::{SpheroidContact, spheroid_contact, spheroid_plane_contact};
pub use toi::{
    Impact, SPHEROID_CONTACT_TOLERANCE, SPHEROID_PENETRATION_TOLERANCE, spheroid_pair_toi,
    spheroid_plane_toi,
};

use glam::{DMat3, DQuat, DVec3};

/// Semi-axes of a spheroid about its body z axis (a sphere when they are equal).
///
/// ```
/// use magsep_systems::collision::spheroid::Spheroid;
/// let disc = Spheroid::new(1e-3, 1e-4);
/// assert_eq!(disc.bounding_radius(), 1e-3);
/// assert!(Spheroid::sphere(1.0).is_sphere() && !disc.is_sphere());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spheroid {
    /// Equatorial semi-axis `a` (body x and y) \[m\].
    pub equatorial: f64,
    /// Polar semi-axis `c` (body z, the symmetry axis) \[m\].
    pub polar: f64,
}

impl Spheroid {
    /// A spheroid with equatorial semi-axis `a` and polar semi-axis `c` \[m\].
    pub fn new(equatorial: f64, polar: f64) -> Self {
        Self { equatorial, polar }
    }

    /// A sphere of `radius` \[m\].
    pub fn sphere(radius: f64) -> Self {
        Self::new(radius, radius)
    }

    /// Whether both semi-axes are equal.
    pub fn is_sphere(&self) -> bool {
        self.equatorial == self.polar
    }

    /// Whether both semi-axes are finite and positive.
    pub fn is_valid(&self) -> bool {
        self.equatorial.is_finite()
            && self.polar.is_finite()
            && self.equatorial > 0.0
            && self.polar > 0.0
    }

    /// Radius of the smallest centred sphere containing the spheroid, `max(a, c)` \[m\].
    pub fn bounding_radius(&self) -> f64 {
        self.equatorial.max(self.polar)
    }

    /// Smallest semi-axis `min(a, c)` \[m\].
    pub fn min_semi_axis(&self) -> f64 {
        self.equatorial.min(self.polar)
    }

    /// The lab shape matrix `E⁻¹ = R diag(a², a², c²) Rᵀ` for the body→lab rotation `q` \[m²\].
    ///
    /// ```
    /// use glam::{DQuat, DVec3};
    /// use magsep_systems::collision::spheroid::Spheroid;
    /// let m = Spheroid::new(2.0, 1.0).shape_matrix(DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2));
    /// assert!((m * DVec3::Y - DVec3::Y).length() < 1e-12); // the body z axis now lies along -y
    /// ```
    pub fn shape_matrix(&self, q: DQuat) -> DMat3 {
        let e = symmetry_axis(q);
        let a2 = self.equatorial * self.equatorial;
        let k = self.polar * self.polar - a2;
        DMat3::from_diagonal(DVec3::splat(a2)) + outer(e, e) * k
    }
}

/// The lab symmetry axis `q·ẑ` of a body with body→lab rotation `q` (normalised first).
pub fn symmetry_axis(q: DQuat) -> DVec3 {
    q.normalize() * DVec3::Z
}

/// World-frame inverse inertia `R diag(i_x, i_y, i_z) Rᵀ` from body-frame inverse principal
/// moments `inv_principal` [1/(kg m²)] and the body→lab rotation `q`. With `i_z = 0` (spin about
/// the symmetry axis suppressed, `I_z → ∞`) and `i_x = i_y` this is `i_x (𝕀 − e eᵀ)`.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::world_inverse_inertia;
/// let m = world_inverse_inertia(DVec3::new(2.0, 2.0, 0.0), DQuat::from_rotation_y(0.3));
/// let e = DQuat::from_rotation_y(0.3) * DVec3::Z;
/// assert!((m * e).length() < 1e-15 && ((m * DVec3::Y).y - 2.0).abs() < 1e-15);
/// ```
pub fn world_inverse_inertia(inv_principal: DVec3, q: DQuat) -> DMat3 {
    let r = DMat3::from_quat(q.normalize());
    r * DMat3::from_diagonal(inv_principal) * r.transpose()
}

/// `x yᵀ`.
pub(crate) fn outer(x: DVec3, y: DVec3) -> DMat3 {
    DMat3::from_cols(x * y.x, x * y.y, x * y.z)
}

/// A spheroid placed in the lab frame: centre, unit symmetry axis and semi-axes.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::{PosedSpheroid, Spheroid};
/// let p = PosedSpheroid::new(Spheroid::new(2.0, 0.5), DVec3::ZERO, DQuat::IDENTITY);
/// assert_eq!(p.support_value(DVec3::Z), 0.5);
/// assert_eq!(p.support_point(DVec3::X), DVec3::new(2.0, 0.0, 0.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosedSpheroid {
    /// Semi-axes.
    pub shape: Spheroid,
    /// Centre \[m\].
    pub centre: DVec3,
    /// Unit symmetry axis in the lab frame [-].
    pub axis: DVec3,
}

impl PosedSpheroid {
    /// `shape` at `centre` \[m\] with body→lab rotation `orientation`.
    pub fn new(shape: Spheroid, centre: DVec3, orientation: DQuat) -> Self {
        Self {
            shape,
            centre,
            axis: symmetry_axis(orientation),
        }
    }

    /// `a²` and `k = c² − a²` \[m²\].
    fn coefficients(&self) -> (f64, f64) {
        let a2 = self.shape.equatorial * self.shape.equatorial;
        (a2, self.shape.polar * self.shape.polar - a2)
    }

    /// `E⁻¹ u` \[m² × u\].
    pub fn shape_times(&self, u: DVec3) -> DVec3 {
        let (a2, k) = self.coefficients();
        u * a2 + self.axis * (k * self.axis.dot(u))
    }

    /// Support value about the centre, `h(u) = √(uᵀE⁻¹u)` for a unit `u` \[m\].
    pub fn support_value(&self, u: DVec3) -> f64 {
        let (a2, k) = self.coefficients();
        let eu = self.axis.dot(u);
        (a2 * u.length_squared() + k * eu * eu).max(0.0).sqrt()
    }

    /// Support point relative to the centre (surface point with outward normal `u`) \[m\].
    pub fn support_point(&self, u: DVec3) -> DVec3 {
        self.shape_times(u) / self.support_value(u)
    }

    /// Whether the shape and pose are finite and valid.
    pub fn is_valid(&self) -> bool {
        self.shape.is_valid() && self.centre.is_finite() && self.axis.is_finite()
    }
}
