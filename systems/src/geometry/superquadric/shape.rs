//! The [`Superquadric`] shape in its body frame: inside function (eq. 4.4), gradient (eq. 4.6),
//! diagonal second derivatives (eq. 4.33), support map, parametric surface (eq. 4.5) and the
//! parry3d-f64 [`SupportMap`] implementation used by GJK/EPA.

use glam::DVec3;
use magsep_components::shape::Shape;
use parry3d_f64::shape::SupportMap;

use super::mass::{superquadric_bounding_radius, superquadric_inertia, superquadric_volume};
use super::prepared::Prepared;

/// Largest shape exponent the contact solver accepts (|x/a|^g must not overflow for points
/// a few semi-axes away from the centre).
pub const MAX_EXPONENT: f64 = 100.0;

/// A superquadric |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 in its body frame (thesis 000,
/// eq. 4.3): superballs (equal a and g), supercuboids (equal g), ellipsoids (g = 2).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::superquadric::Superquadric;
/// let s = Superquadric::superball(1.0, 4.0);
/// assert!(s.inside(DVec3::new(1.0, 0.0, 0.0)).abs() < 1e-15);
/// assert!(s.inside(DVec3::ZERO) < 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Superquadric {
    /// Semi-axes (a1, a2, a3) along body x, y, z \[m\]; each > 0.
    pub semi_axes: DVec3,
    /// Exponents (g1, g2, g3), each in [2, [`MAX_EXPONENT`]] (strictly convex).
    pub exponents: DVec3,
}

impl Superquadric {
    /// A superball of radius `a` and exponent `g`.
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// assert_eq!(Superquadric::superball(2.0, 2.0).semi_axes.x, 2.0);
    /// ```
    pub fn superball(a: f64, g: f64) -> Self {
        Self {
            semi_axes: DVec3::splat(a),
            exponents: DVec3::splat(g),
        }
    }

    /// The superquadric of a [`Shape`]: a superquadric as is, a sphere as the superquadric
    /// with exponents 2; `None` for a spherocylinder.
    ///
    /// ```
    /// use magsep_components::shape::Shape;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric::from_shape(&Shape::Sphere { radius: 0.5 }).unwrap();
    /// assert_eq!(s, Superquadric::superball(0.5, 2.0));
    /// ```
    pub fn from_shape(shape: &Shape) -> Option<Self> {
        match *shape {
            Shape::Superquadric {
                semi_axes,
                exponents,
            } => Some(Self {
                semi_axes,
                exponents,
            }),
            Shape::Sphere { radius } => Some(Self::superball(radius, 2.0)),
            Shape::Spheroid { .. } => shape.as_superquadric().map(|(semi_axes, exponents)| Self {
                semi_axes,
                exponents,
            }),
            Shape::Spherocylinder { .. } => None,
        }
    }

    /// Whether the semi-axes are finite and positive and the exponents lie in
    /// [2, [`MAX_EXPONENT`]] (the domain of the contact solver).
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// assert!(Superquadric::superball(1.0, 3.0).is_valid());
    /// assert!(!Superquadric::superball(1.0, 1.5).is_valid());
    /// ```
    pub fn is_valid(&self) -> bool {
        let a = self.semi_axes;
        let g = self.exponents;
        a.is_finite()
            && a.min_element() > 0.0
            && g.min_element() >= 2.0
            && g.max_element() <= MAX_EXPONENT
    }

    pub(crate) fn prepared(&self) -> Prepared {
        Prepared::new(self.semi_axes, self.exponents)
    }

    /// Inside function F(x) = sum |x_i/a_i|^g_i - 1 (eq. 4.4): negative inside, zero on the
    /// surface, positive outside. This power form (not its g-th root) is the one the Newton system uses; its
    /// gradient on the surface has magnitude between about g/(3a) and sqrt(3) g/a, so the
    /// equations F = 0 stay well scaled up to the largest exponents allowed.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric::superball(1.0, 2.0);
    /// assert!((s.inside(DVec3::new(0.0, 2.0, 0.0)) - 3.0).abs() < 1e-15);
    /// ```
    pub fn inside(&self, x: DVec3) -> f64 {
        self.prepared().inside(x)
    }

    /// Gradient of F, the unnormalised outward normal (eq. 4.6).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let n = Superquadric::superball(1.0, 2.0).gradient(DVec3::new(0.0, 0.0, 1.0));
    /// assert_eq!(n, DVec3::new(0.0, 0.0, 2.0));
    /// ```
    pub fn gradient(&self, x: DVec3) -> DVec3 {
        self.prepared().eval(x).grad
    }

    /// Diagonal second derivatives d^2F/dx_i^2 = g_i (g_i - 1) a_i^-g_i |x_i|^(g_i - 2)
    /// (eq. 4.33; the mixed derivatives vanish).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let h = Superquadric::superball(1.0, 4.0).normal_derivatives(DVec3::new(0.5, 0.0, 1.0));
    /// assert_eq!(h, DVec3::new(12.0 * 0.25, 0.0, 12.0));
    /// ```
    pub fn normal_derivatives(&self, x: DVec3) -> DVec3 {
        self.prepared().eval(x).hess
    }

    /// Support point: the surface point farthest along the body-frame direction `dir` (need
    /// not be unit); the centre for a zero direction. Closed form for equal exponents, a
    /// monotone 1-D Newton solve otherwise.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric::superball(1.0, 6.0);
    /// let p = s.support(DVec3::new(0.0, -3.0, 0.0));
    /// assert!((p - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-15);
    /// ```
    pub fn support(&self, dir: DVec3) -> DVec3 {
        self.prepared().support(dir)
    }

    /// Support function h(dir) = dir . support(dir) (the extent along a unit `dir`) \[m\].
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric { semi_axes: DVec3::new(1.0, 2.0, 3.0), exponents: DVec3::splat(2.0) };
    /// assert!((s.support_value(DVec3::Z) - 3.0).abs() < 1e-15);
    /// ```
    pub fn support_value(&self, dir: DVec3) -> f64 {
        dir.dot(self.support(dir))
    }

    /// The surface point on the ray from the centre through `x` (`x` itself for the centre).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric::superball(2.0, 2.0);
    /// assert!((s.project_radial(DVec3::new(1.0, 1.0, 0.0)).length() - 2.0).abs() < 1e-14);
    /// ```
    pub fn project_radial(&self, x: DVec3) -> DVec3 {
        let p = self.prepared();
        p.project_radial(x, p.inside(x) + 1.0)
    }

    /// Parametric surface point (eq. 4.5), u in [-pi, pi), v in [-pi/2, pi/2], with
    /// eps_i = 2/g_i.
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let s = Superquadric::superball(1.0, 3.0);
    /// assert!(s.inside(s.surface_point(0.3, 0.2)).abs() < 1e-14);
    /// ```
    pub fn surface_point(&self, u: f64, v: f64) -> DVec3 {
        let e = 2.0 / self.exponents;
        let sp = |c: f64, p: f64| c.abs().powf(p).copysign(c);
        let a = self.semi_axes;
        DVec3::new(
            a.x * sp(v.cos(), e.x) * sp(u.cos(), e.x),
            a.y * sp(v.cos(), e.y) * sp(u.sin(), e.y),
            a.z * sp(v.sin(), e.z),
        )
    }

    /// Volume (eq. 4.21) [m^3].
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// assert!((Superquadric::superball(1.0, 2.0).volume() - 4.18879020478639).abs() < 1e-13);
    /// ```
    pub fn volume(&self) -> f64 {
        superquadric_volume(self.semi_axes, self.exponents)
    }

    /// Principal moments of inertia at unit density (eqs. 4.29-4.31) [m^5].
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// let i = Superquadric::superball(1.0, 2.0).inertia_unit_density();
    /// assert!((i.z - 8.0 * std::f64::consts::PI / 15.0).abs() < 1e-13);
    /// ```
    pub fn inertia_unit_density(&self) -> DVec3 {
        superquadric_inertia(self.semi_axes, self.exponents)
    }

    /// Circumscribed (bounding) sphere radius about the centre (App. 4.C, erratum E-000-7) \[m\].
    ///
    /// ```
    /// use magsep_systems::geometry::superquadric::Superquadric;
    /// assert!((Superquadric::superball(1.0, 2.5).bounding_radius() - 1.11612).abs() < 5e-6);
    /// ```
    pub fn bounding_radius(&self) -> f64 {
        superquadric_bounding_radius(self.semi_axes, self.exponents)
    }
}

impl SupportMap for Superquadric {
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        self.support(dir)
    }
}

impl SupportMap for Prepared {
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        self.support(dir)
    }
}
