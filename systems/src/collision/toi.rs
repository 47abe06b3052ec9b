//! Time of impact (TOI) and contact geometry of ballistically moving hard particles.
//!
//! Within a solver step the linear and angular velocities change only through collisions
//! ([T002 §4.2.1.3]), so between two events each particle moves ballistically:
//! `x(t) = x₀ + v t`, and a spheroid would also rotate at constant Ω.
//!
//! **Sphere–sphere** (Hoomans et al. 1996; [T002 §4.2.1.3]: "found analytically by solving a
//! quadratic equation"). With `Δx = x_b − x_a`, `Δv = v_b − v_a` and `s = r_a + r_b`, contact is
//! `|Δx + Δv t|² = s²`, i.e. `a t² + 2 b t + c = 0` with `a = Δv·Δv`, `b = Δx·Δv`,
//! `c = Δx·Δx − s²`. The pair approaches iff `b < 0`. The earliest root is evaluated in the
//! cancellation-free form `t = c / (−b + √(b² − a c))` (both terms of the denominator are
//! non-negative), which is also well defined for `a → 0`.
//! * already touching or overlapping (`c ≤ 0`) and approaching: `t = 0`;
//! * touching or overlapping and separating (`b ≥ 0`): no impact (the pair is leaving);
//! * discriminant `< 0`: the paths miss; `= 0`: a grazing touch, reported with zero approach speed
//!   (the caller filters events by approach speed).
//!
//! **Sphere–plane.** The plane is a point and a unit normal pointing into the fluid side. With the
//! signed centre distance `δ = n_w·(x − p)` the gap is `g(t) = δ + (v·n_w) t − r`, so
//! `t = (δ − r)/(−v·n_w)` while approaching (`v·n_w < 0`); a sphere touching or penetrating the
//! plane and approaching gets `t = 0`.
//!
//! **Contact geometry** ([`ContactGeometry`]): the unit normal points from body *a* to body *b*
//! (thesis Fig. 4.2b), the lever arms run from each centre to *one common* contact point (this is
//! what makes the impulse conserve angular momentum exactly, see [`super::impulse`]). For two
//! spheres the common point divides the centre line in the ratio of the radii
//! (`r_a = r_a |Δx|/s · n`, `r_b = −r_b |Δx|/s · n`), which is the touching point at contact and
//! stays symmetric for a slightly overlapping pair. For a particle and a wall the particle is body
//! *a*, the normal is `−n_w` and the lever arm is `−r n_w` (exactly the radius, so rolling relations
//! hold); the wall's lever arm is irrelevant (it has zero inverse mass and inertia) and is set to
//! the contact point relative to the plane's reference point.
//!
//! **Periodic images** are the caller's job: pass the minimum-image `Δx`.
//!
//! **Spheroids** (thesis ch. 4) are handled by [`super::spheroid`] (common-normal contact,
//! closed-form spheroid–plane gap, conservative-advancement TOI with rotation); the engine calls
//! it directly from its shape arrays. [`CollisionShape`] stays the sphere-only enum of this
//! module; the sphere paths stay analytic.

use glam::{DQuat, DVec3};

/// A static planar wall: a reference point and the unit normal pointing into the fluid side.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::Plane;
/// let floor = Plane::new(DVec3::ZERO, DVec3::new(0.0, 2.0, 0.0));
/// assert_eq!(floor.normal, DVec3::Y);
/// assert_eq!(floor.signed_distance(DVec3::new(1.0, 0.5, 0.0)), 0.5);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    /// A point on the plane \[m\].
    pub point: DVec3,
    /// Unit normal pointing into the fluid (allowed) side [-].
    pub normal: DVec3,
}

impl Plane {
    /// A plane through `point` with the normal `normal` (normalised here; a zero or non-finite
    /// normal gives a NaN normal, which makes every TOI test fail, i.e. an inert wall).
    pub fn new(point: DVec3, normal: DVec3) -> Self {
        Self {
            point,
            normal: normal / normal.length(),
        }
    }

    /// Signed distance of `x` from the plane, positive on the fluid side \[m\].
    pub fn signed_distance(&self, x: DVec3) -> f64 {
        self.normal.dot(x - self.point)
    }
}

/// Contact frame of a pair: unit normal from *a* to *b*, lever arms to the common contact point and
/// the surface gap.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::sphere_sphere_contact;
/// let c = sphere_sphere_contact(DVec3::new(3.0, 0.0, 0.0), 1.0, 2.0);
/// assert_eq!(c.normal, DVec3::X);
/// assert_eq!((c.r_a, c.r_b, c.gap), (DVec3::X, DVec3::new(-2.0, 0.0, 0.0), 0.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Unit contact normal pointing from body *a* to body *b* [-].
    pub normal: DVec3,
    /// Lever arm of *a*: from its centre to the contact point \[m\].
    pub r_a: DVec3,
    /// Lever arm of *b*: from its centre to the contact point \[m\].
    pub r_b: DVec3,
    /// Surface gap along the normal, negative when overlapping \[m\].
    pub gap: f64,
}

/// Earliest `t ∈ [0, horizon]` at which two spheres moving with constant velocities touch while
/// approaching.
///
/// `dx = x_b − x_a` (minimum image) \[m\], `dv = v_b − v_a` [m/s], `sum_radii = r_a + r_b` \[m\],
/// `horizon` \[s\]. Returns `Some(0.0)` for a touching or overlapping approaching pair and `None` for a
/// separating pair, a miss, or an impact after `horizon`. A grazing touch (zero approach speed) can
/// be returned; filter by approach speed if needed.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::sphere_sphere_toi;
/// // gap 1 m closed at 2 m/s
/// let t = sphere_sphere_toi(DVec3::new(3.0, 0.0, 0.0), DVec3::new(-2.0, 0.0, 0.0), 2.0, 1.0);
/// assert_eq!(t, Some(0.5));
/// ```
pub fn sphere_sphere_toi(dx: DVec3, dv: DVec3, sum_radii: f64, horizon: f64) -> Option<f64> {
    let b = dx.dot(dv);
    if b >= 0.0 || b.is_nan() {
        return None;
    }
    let c = dx.length_squared() - sum_radii * sum_radii;
    if c <= 0.0 {
        return Some(0.0);
    }
    let a = dv.length_squared();
    let disc = b * b - a * c;
    if disc < 0.0 || disc.is_nan() {
        return None;
    }
    let t = c / (disc.sqrt() - b);
    (t <= horizon).then_some(t)
}

/// Earliest `t ∈ [0, horizon]` at which a sphere of radius `radius` \[m\] at `x` \[m\] moving with `v`
/// [m/s] touches `plane` while approaching it; `Some(0.0)` if it already touches or penetrates and
/// approaches, `None` otherwise.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::{Plane, sphere_plane_toi};
/// let floor = Plane::new(DVec3::ZERO, DVec3::Y);
/// let t = sphere_plane_toi(DVec3::new(0.0, 3.0, 0.0), DVec3::new(1.0, -2.0, 0.0), 1.0, &floor, 5.0);
/// assert_eq!(t, Some(1.0));
/// ```
pub fn sphere_plane_toi(
    x: DVec3,
    v: DVec3,
    radius: f64,
    plane: &Plane,
    horizon: f64,
) -> Option<f64> {
    let vn = v.dot(plane.normal);
    if vn >= 0.0 || vn.is_nan() {
        return None;
    }
    let gap = plane.signed_distance(x) - radius;
    if gap <= 0.0 {
        return Some(0.0);
    }
    let t = gap / -vn;
    (t <= horizon).then_some(t)
}

/// Contact geometry of spheres *a* and *b* with centre offset `dx = x_b − x_a` (minimum image) \[m\]
/// and radii \[m\]; coincident centres get the normal `+z` (a deterministic, arbitrary choice).
pub fn sphere_sphere_contact(dx: DVec3, radius_a: f64, radius_b: f64) -> ContactGeometry {
    let dist = dx.length();
    let normal = if dist > 0.0 { dx / dist } else { DVec3::Z };
    let sum = radius_a + radius_b;
    let scale = if sum > 0.0 { dist / sum } else { 0.0 };
    ContactGeometry {
        normal,
        r_a: normal * (radius_a * scale),
        r_b: -normal * (radius_b * scale),
        gap: dist - sum,
    }
}

/// Contact geometry of a sphere (body *a*, centre `x` \[m\], radius \[m\]) and a wall (body *b*).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::{Plane, sphere_plane_contact};
/// let c = sphere_plane_contact(DVec3::new(0.0, 1.5, 0.0), 1.0, &Plane::new(DVec3::ZERO, DVec3::Y));
/// assert_eq!((c.normal, c.r_a, c.gap), (-DVec3::Y, -DVec3::Y, 0.5));
/// ```
pub fn sphere_plane_contact(x: DVec3, radius: f64, plane: &Plane) -> ContactGeometry {
    let normal = -plane.normal;
    let r_a = normal * radius;
    ContactGeometry {
        normal,
        r_a,
        r_b: x + r_a - plane.point,
        gap: plane.signed_distance(x) - radius,
    }
}

/// Ballistic state of a body at the start of a TOI search: it moves as
/// `x(t) = position + velocity t` and rotates at the constant `angular_velocity`.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::Ballistic;
/// let b = Ballistic::translating(DVec3::ZERO, DVec3::X);
/// assert_eq!(b.position_at(2.0), DVec3::new(2.0, 0.0, 0.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ballistic {
    /// Centre position \[m\].
    pub position: DVec3,
    /// Body-to-world rotation [-] (unused by spheres).
    pub orientation: DQuat,
    /// Centre velocity [m/s].
    pub velocity: DVec3,
    /// Angular velocity in the world frame [rad/s] (unused by spheres).
    pub angular_velocity: DVec3,
}

impl Ballistic {
    /// A body at `position` \[m\] moving with `velocity` [m/s], identity orientation, no spin.
    pub fn translating(position: DVec3, velocity: DVec3) -> Self {
        Self {
            position,
            orientation: DQuat::IDENTITY,
            velocity,
            angular_velocity: DVec3::ZERO,
        }
    }

    /// Centre position after `t` \[s\] of ballistic motion \[m\].
    pub fn position_at(&self, t: f64) -> DVec3 {
        self.position + self.velocity * t
    }
}

/// Shape of a hard particle for the analytic sphere kernels (spheroids: [`super::spheroid`]).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::toi::{Ballistic, CollisionShape};
/// let s = CollisionShape::Sphere { radius: 0.5 };
/// let a = Ballistic::translating(DVec3::ZERO, DVec3::X);
/// let b = Ballistic::translating(DVec3::new(3.0, 0.0, 0.0), DVec3::ZERO);
/// assert_eq!(s.time_of_impact(&a, &s, &b, 10.0), Some(2.0));
/// assert_eq!(s.contact(&a, &s, &b).gap, 2.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum CollisionShape {
    /// A sphere.
    Sphere {
        /// Radius \[m\].
        radius: f64,
    },
}

impl CollisionShape {
    /// Radius of the smallest sphere about the centre that contains the shape \[m\].
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Self::Sphere { radius } => radius,
        }
    }

    /// Earliest time of impact within `[0, horizon]` \[s\] of this shape (state `a`) with `other`
    /// (state `b`); positions must already be minimum images of each other.
    pub fn time_of_impact(
        &self,
        a: &Ballistic,
        other: &CollisionShape,
        b: &Ballistic,
        horizon: f64,
    ) -> Option<f64> {
        match (*self, *other) {
            (Self::Sphere { radius: ra }, Self::Sphere { radius: rb }) => sphere_sphere_toi(
                b.position - a.position,
                b.velocity - a.velocity,
                ra + rb,
                horizon,
            ),
        }
    }

    /// Earliest time of impact within `[0, horizon]` \[s\] of this shape (state `a`) with a wall.
    pub fn time_of_impact_plane(&self, a: &Ballistic, plane: &Plane, horizon: f64) -> Option<f64> {
        match *self {
            Self::Sphere { radius } => {
                sphere_plane_toi(a.position, a.velocity, radius, plane, horizon)
            }
        }
    }

    /// Contact geometry of this shape (state `a`) with `other` (state `b`) at their current poses.
    pub fn contact(&self, a: &Ballistic, other: &CollisionShape, b: &Ballistic) -> ContactGeometry {
        match (*self, *other) {
            (Self::Sphere { radius: ra }, Self::Sphere { radius: rb }) => {
                sphere_sphere_contact(b.position - a.position, ra, rb)
            }
        }
    }

    /// Contact geometry of this shape (state `a`, body *a*) with a wall (body *b*).
    pub fn contact_plane(&self, a: &Ballistic, plane: &Plane) -> ContactGeometry {
        match *self {
            Self::Sphere { radius } => sphere_plane_contact(a.position, radius, plane),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn head_on_and_oblique_analytic_times() {
        // head on: gap 8, closing 4 m/s
        let t = sphere_sphere_toi(v(10.0, 0.0, 0.0), v(-4.0, 0.0, 0.0), 2.0, 5.0).unwrap();
        assert!((t - 2.0).abs() < 1e-15);
        // oblique: impact parameter 1, s = 2: contact when the x-separation is sqrt(3)
        let t = sphere_sphere_toi(v(10.0, 1.0, 0.0), v(-1.0, 0.0, 0.0), 2.0, 100.0).unwrap();
        assert!((t - (10.0 - 3f64.sqrt())).abs() < 1e-13);
        let d = v(10.0 - t, 1.0, 0.0).length();
        assert!((d - 2.0).abs() < 1e-14);
        // beyond the horizon
        assert_eq!(
            sphere_sphere_toi(v(10.0, 0.0, 0.0), v(-4.0, 0.0, 0.0), 2.0, 1.99),
            None
        );
        // separating or parallel
        assert_eq!(
            sphere_sphere_toi(v(10.0, 0.0, 0.0), v(4.0, 0.0, 0.0), 2.0, 9.0),
            None
        );
        assert_eq!(
            sphere_sphere_toi(v(10.0, 0.0, 0.0), v(0.0, 4.0, 0.0), 2.0, 9.0),
            None
        );
        assert_eq!(
            sphere_sphere_toi(v(10.0, 0.0, 0.0), DVec3::ZERO, 2.0, 9.0),
            None
        );
    }

    #[test]
    fn grazing_miss_and_tangent_at_end() {
        // impact parameter exactly s: grazing touch at t = 10 (zero approach speed there)
        let t = sphere_sphere_toi(v(10.0, 2.0, 0.0), v(-1.0, 0.0, 0.0), 2.0, 20.0).unwrap();
        assert!((t - 10.0).abs() < 1e-12);
        // impact parameter slightly larger: miss
        let dy = 2.0 + 1e-9;
        assert_eq!(
            sphere_sphere_toi(v(10.0, dy, 0.0), v(-1.0, 0.0, 0.0), 2.0, 20.0),
            None
        );
        // contact exactly at the end of the horizon is included, just after is not
        assert_eq!(
            sphere_sphere_toi(v(3.0, 0.0, 0.0), v(-1.0, 0.0, 0.0), 2.0, 1.0),
            Some(1.0)
        );
        let late = sphere_sphere_toi(v(3.0, 0.0, 0.0), v(-1.0, 0.0, 0.0), 2.0, 1.0 - 1e-12);
        assert_eq!(late, None);
        let floor = Plane::new(DVec3::ZERO, DVec3::Y);
        assert_eq!(
            sphere_plane_toi(v(0.0, 2.0, 0.0), v(0.0, -1.0, 0.0), 1.0, &floor, 1.0),
            Some(1.0)
        );
        assert_eq!(
            sphere_plane_toi(v(0.0, 2.0, 0.0), v(5.0, 0.0, 0.0), 1.0, &floor, 1.0),
            None
        );
    }

    #[test]
    fn fast_pair_that_would_tunnel_is_detected() {
        // 1 mm spheres 1 mm apart, closing at 200 m/s over a 1 ms step: end positions are 0.2 m apart
        // on the other side, but the impact at 5 µs is found.
        let dx = v(0.003, 0.0, 0.0);
        let dv = v(-200.0, 0.0, 0.0);
        let t = sphere_sphere_toi(dx, dv, 0.002, 1e-3).unwrap();
        assert!((t - 5e-6).abs() < 1e-18);
        assert!((dx + dv * 1e-3).length() > 0.002);
        let floor = Plane::new(DVec3::ZERO, DVec3::Y);
        let t = sphere_plane_toi(v(0.0, 0.002, 0.0), v(0.0, -500.0, 0.0), 0.001, &floor, 1e-3);
        assert!((t.unwrap() - 2e-6).abs() < 1e-18);
    }

    #[test]
    fn overlapping_and_touching_pairs() {
        // overlapping, approaching: immediate
        assert_eq!(
            sphere_sphere_toi(v(1.5, 0.0, 0.0), v(-1.0, 0.1, 0.0), 2.0, 1.0),
            Some(0.0)
        );
        // touching exactly, approaching: immediate
        assert_eq!(
            sphere_sphere_toi(v(2.0, 0.0, 0.0), v(-1.0, 0.0, 0.0), 2.0, 1.0),
            Some(0.0)
        );
        // overlapping, separating: none
        assert_eq!(
            sphere_sphere_toi(v(1.5, 0.0, 0.0), v(1.0, 0.0, 0.0), 2.0, 1.0),
            None
        );
        // overlapping, sliding tangentially: none
        assert_eq!(
            sphere_sphere_toi(v(1.5, 0.0, 0.0), v(0.0, 1.0, 0.0), 2.0, 1.0),
            None
        );
        let floor = Plane::new(DVec3::ZERO, DVec3::Y);
        assert_eq!(
            sphere_plane_toi(v(0.0, 0.5, 0.0), v(0.0, -1.0, 0.0), 1.0, &floor, 1.0),
            Some(0.0)
        );
        assert_eq!(
            sphere_plane_toi(v(0.0, 0.5, 0.0), v(0.0, 1.0, 0.0), 1.0, &floor, 1.0),
            None
        );
        // tiny closing speed from far away: the stable root form stays accurate
        let t = sphere_sphere_toi(v(1e3, 1.0, 0.0), v(-1e-12, 0.0, 0.0), 2.0, 1e20).unwrap();
        let exact = (1e3 - 3f64.sqrt()) * 1e12;
        assert!((t / exact - 1.0).abs() < 1e-13, "{t}");
    }

    #[test]
    fn contact_frames_share_one_point() {
        let xa = v(0.1, -0.2, 0.3);
        let dx = v(1.1, 0.4, -0.7);
        let c = sphere_sphere_contact(dx, 0.5, 0.9);
        assert!((xa + c.r_a - (xa + dx + c.r_b)).length() < 1e-15);
        assert!((c.normal.length() - 1.0).abs() < 1e-15);
        assert!((c.gap - (dx.length() - 1.4)).abs() < 1e-15);
        let coincident = sphere_sphere_contact(DVec3::ZERO, 1.0, 1.0);
        assert_eq!(coincident.normal, DVec3::Z);
        assert_eq!(coincident.gap, -2.0);
        let wall = Plane::new(v(0.0, 0.0, 1.0), -DVec3::Z);
        let c = sphere_plane_contact(v(0.3, 0.2, 0.25), 0.5, &wall);
        assert_eq!(c.normal, DVec3::Z);
        assert!((c.gap - 0.25).abs() < 1e-15);
        let shape = CollisionShape::Sphere { radius: 0.5 };
        let a = Ballistic::translating(v(0.3, 0.2, 0.25), v(0.0, 0.0, 1.0));
        assert_eq!(shape.contact_plane(&a, &wall), c);
        assert_eq!(shape.time_of_impact_plane(&a, &wall, 1.0), Some(0.25));
        assert_eq!(shape.bounding_radius(), 0.5);
    }
}
