//! One impulse law for the instantaneous collision of any two rigid bodies: Poisson restitution,
//! optional tangential restitution and Coulomb friction (thesis 002, ch. 4 eq. 4.12–4.15, which
//! reduces to the ch. 2 hard-sphere model of Hoomans et al., eq. 2.33–2.35).
//!
//! **Bodies and contact.** Each body has an inverse mass `1/m` [1/kg], an inverse inertia tensor in
//! the world frame `I⁻¹` [1/(kg m²)], a velocity `v` and an angular velocity `Ω`. A wall (static
//! body) has zero inverse mass and inertia. The contact has the unit normal `n` from *a* to *b* and
//! lever arms `r_a`, `r_b` from the centres to one common contact point
//! ([`super::toi::ContactGeometry`]).
//!
//! **Relative contact velocity** (sign convention D-002-8 of docs/references.md, the only one that
//! makes 4.12 and 4.14 consistent): `v_ab = (v_b + Ω_b×r_b) − (v_a + Ω_a×r_a)`; the bodies approach
//! iff `v_ab·n < 0`. The impulse `J` acts on *b* and `−J` on *a* (4.12):
//! `v_b += J/m_b`, `Ω_b += I_b⁻¹(r_b×J)`, `v_a −= J/m_a`, `Ω_a −= I_a⁻¹(r_a×J)`, so
//! `Δv_ab = K J` with
//! `K = (1/m_a + 1/m_b) 𝕀 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×` (symmetric positive definite
//! unless both bodies are static).
//!
//! **Law.** Target post-collision contact velocity `v⁺ = −e_n (v⁻·n) n − e_t v⁻_t`
//! (`v⁻_t = v⁻ − (v⁻·n) n`).
//! * Stick (4.14): `J = K⁻¹ (v⁺ − v⁻)`, accepted if `|J − (J·n) n| ≤ μ J·n` (4.15; the printed
//!   "‖J − J·n‖" means the tangential part).
//! * Slide (4.15, closed form D-002-8): `J = J_n (n + μ t)`, `t = −v⁻_t/|v⁻_t|`,
//!   `J_n = −(1 + e_n)(v⁻·n) / (n·K(n + μ t))`. Both regimes meet `v⁺·n = −e_n v⁻·n` exactly.
//! * Separating or grazing pairs (`v⁻·n ≥ 0`) get no impulse.
//!
//! `e_t` is Hoomans' tangential restitution; `e_t = 0` is the ch. 4 model (no tangential
//! restitution: sticking ends with zero tangential contact velocity). Static and dynamic friction
//! are not distinguished ([T002 §4.2.1.3]). External loads during the impact are neglected (ibid.).
//!
//! **Reduction to Hoomans (ch. 2).** For solid spheres `r_a ∥ r_b ∥ n`, so `K` is
//! `(1/m_ab) n nᵀ + (7/2)(1/m_ab)(𝕀 − n nᵀ)` (`m_ab = m_a m_b/(m_a + m_b)`): the stick impulse is
//! `J_n = −(1 + e_n) m_ab v⁻·n` (2.34) and `J_t = −(2/7)(1 + e_t) m_ab v⁻_t` (2.35, stick), the slide
//! impulse has `|J_t| = μ J_n` (2.35, slide), and the Coulomb test is Hoomans'. Erratum E-002-9b: the printed
//! (2.33) `m_a(v_a⁺ − v_a⁻) = −m_b(v_b⁻ − v_b⁺) = J` gives both spheres the same impulse and does not
//! conserve momentum; the consistent form `m_a Δv_a = J_H = −m_b Δv_b` is used (Hoomans' `J_H` is our
//! `−J`, his normal points from *b* to *a*). The restitution ratios printed after (2.34) and (2.35) (erratum E-002-9c) are
//! inverted; `e = −(v⁺·n)/(v⁻·n)` is meant.
//!
//! **Choices where the thesis is silent.**
//! * If `v⁻_t` vanishes (below `1e-12 |v⁻|`) but the stick impulse leaves the friction cone (only
//!   possible for non-spherical bodies, whose `K` couples normal and tangential directions), the
//!   slide direction `t` is that of the stick impulse's tangential part (friction saturates while
//!   trying to prevent the sliding that the coupling induces).
//! * If `n·K(n + μ t) ≤ 0` (a Painlevé-type inconsistency of rigid-body Coulomb friction, impossible
//!   for spheres where `n·K t = 0`) or `K` is singular (e.g. a body with zero inverse mass but
//!   non-zero inverse inertia), the frictionless impulse `J = −(1 + e_n)(v⁻·n)/(n·K n) n` is used and
//!   reported as [`FrictionRegime::Frictionless`]. The stick impulse of such bodies can also have
//!   `J·n < 0` (it would pull); it then fails the Coulomb test and the slide branch is used.
//!
//! **Energy.** `ΔE = J·(v⁻ + v⁺)/2`. For spheres (any `e_n, e_t ∈ [0, 1]`, both regimes) and for any
//! bodies with `e_n = e_t ≤ 1` in the stick regime, `ΔE ≤ 0`. For non-spherical bodies with
//! `e_n ≠ e_t`, Poisson/Newton restitution in the stick regime can *gain* energy (the classic
//! eccentric-impact defect): with `e_t = 0` the stick branch gains energy for some `v⁻_t` iff
//! `e_n² (n·K⁻¹n)(n·K n) > 1`, i.e. only for strongly eccentric contacts where `n` is far from an
//! eigenvector of `K` (see the tests, which also construct such a case).

use glam::{DMat3, DVec3};

use super::toi::ContactGeometry;

/// Rigid-body state entering a collision.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::impulse::RigidBody;
/// let s = RigidBody::solid_sphere(2.0, 0.5, DVec3::X, DVec3::Z);
/// assert_eq!(s.inv_mass, 0.5);
/// assert_eq!(s.point_velocity(DVec3::Y * 0.5), DVec3::new(0.5, 0.0, 0.0));
/// assert_eq!(RigidBody::fixed().inv_mass, 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBody {
    /// Inverse mass `1/m` [1/kg]; 0 for a wall.
    pub inv_mass: f64,
    /// Inverse inertia tensor about the centre of mass, world frame [1/(kg m²)]; 0 for a wall.
    pub inv_inertia: DMat3,
    /// Centre-of-mass velocity [m/s].
    pub velocity: DVec3,
    /// Angular velocity, world frame [rad/s].
    pub angular_velocity: DVec3,
}

impl RigidBody {
    /// A homogeneous solid sphere of `mass` [kg] and `radius` [m] (`I = (2/5) m r²`).
    pub fn solid_sphere(mass: f64, radius: f64, velocity: DVec3, angular_velocity: DVec3) -> Self {
        Self {
            inv_mass: 1.0 / mass,
            inv_inertia: DMat3::from_diagonal(DVec3::splat(1.0 / (0.4 * mass * radius * radius))),
            velocity,
            angular_velocity,
        }
    }

    /// A static body (wall): zero inverse mass and inertia, at rest.
    pub fn fixed() -> Self {
        Self {
            inv_mass: 0.0,
            inv_inertia: DMat3::ZERO,
            velocity: DVec3::ZERO,
            angular_velocity: DVec3::ZERO,
        }
    }

    /// Velocity of the material point at lever arm `r` [m] from the centre: `v + Ω×r` [m/s].
    pub fn point_velocity(&self, r: DVec3) -> DVec3 {
        self.velocity + self.angular_velocity.cross(r)
    }
}

/// Restitution and friction coefficients of one collision.
///
/// ```
/// use magsep_systems::collision::impulse::CollisionLaw;
/// let law = CollisionLaw { normal_restitution: 0.1, tangential_restitution: 0.0, friction: 0.05 };
/// assert_eq!(CollisionLaw::frictionless(1.0).friction, 0.0);
/// # let _ = law;
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionLaw {
    /// Normal restitution `e_n = −(v⁺·n)/(v⁻·n)` [-]. Range: [0, 1].
    pub normal_restitution: f64,
    /// Tangential restitution `e_t` in the stick regime, `v⁺_t = −e_t v⁻_t` [-]; 0 in the ch. 4
    /// model. Range: [−1, 1] (−1 leaves the tangential contact velocity unchanged).
    pub tangential_restitution: f64,
    /// Coulomb friction coefficient μ (static = dynamic) [-]. Range: ≥ 0.
    pub friction: f64,
}

impl CollisionLaw {
    /// Smooth bodies (`μ = 0`, `e_t = 0`) with normal restitution `e_n`.
    pub fn frictionless(normal_restitution: f64) -> Self {
        Self {
            normal_restitution,
            tangential_restitution: 0.0,
            friction: 0.0,
        }
    }
}

/// Friction regime of a collision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionRegime {
    /// The sticking impulse lies inside the Coulomb cone.
    Stick,
    /// The impulse lies on the cone.
    Slide,
    /// The rigid-body friction problem was inconsistent (`n·K(n + μ t) ≤ 0`, Painlevé-type) or `K`
    /// singular: the frictionless impulse was used. Never happens for spheres.
    Frictionless,
}

/// Result of [`collision_impulse`]: the impulse and the velocity changes it causes.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::impulse::{CollisionLaw, FrictionRegime, RigidBody, collision_impulse};
/// use magsep_systems::collision::toi::sphere_sphere_contact;
/// let mut a = RigidBody::solid_sphere(1.0, 0.5, DVec3::X, DVec3::ZERO);
/// let mut b = RigidBody::solid_sphere(1.0, 0.5, -DVec3::X, DVec3::ZERO);
/// let contact = sphere_sphere_contact(DVec3::X, 0.5, 0.5);
/// let hit = collision_impulse(&a, &b, &contact, &CollisionLaw::frictionless(1.0)).unwrap();
/// assert_eq!(hit.regime, FrictionRegime::Stick);
/// assert!((hit.impulse - DVec3::new(2.0, 0.0, 0.0)).length() < 1e-15);
/// hit.apply(&mut a, &mut b);
/// assert!((a.velocity + DVec3::X).length() < 1e-15 && (b.velocity - DVec3::X).length() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionImpulse {
    /// Impulse on body *b* (body *a* receives `−impulse`) [N s].
    pub impulse: DVec3,
    /// Stick or slide.
    pub regime: FrictionRegime,
    /// Normal approach speed before the impact, `−v⁻_ab·n > 0` [m/s].
    pub approach_speed: f64,
    /// Velocity change of *a* [m/s].
    pub delta_velocity_a: DVec3,
    /// Angular-velocity change of *a* [rad/s].
    pub delta_angular_velocity_a: DVec3,
    /// Velocity change of *b* [m/s].
    pub delta_velocity_b: DVec3,
    /// Angular-velocity change of *b* [rad/s].
    pub delta_angular_velocity_b: DVec3,
}

impl CollisionImpulse {
    /// Adds the velocity changes to the two bodies.
    pub fn apply(&self, a: &mut RigidBody, b: &mut RigidBody) {
        a.velocity += self.delta_velocity_a;
        a.angular_velocity += self.delta_angular_velocity_a;
        b.velocity += self.delta_velocity_b;
        b.angular_velocity += self.delta_angular_velocity_b;
    }
}

/// Relative velocity of *b*'s contact point with respect to *a*'s, `v_ab` [m/s].
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::impulse::{RigidBody, relative_contact_velocity};
/// use magsep_systems::collision::toi::sphere_sphere_contact;
/// let a = RigidBody::solid_sphere(1.0, 1.0, DVec3::X, DVec3::ZERO);
/// let b = RigidBody::fixed();
/// let c = sphere_sphere_contact(DVec3::X * 2.0, 1.0, 1.0);
/// assert_eq!(relative_contact_velocity(&a, &b, &c), -DVec3::X);
/// ```
pub fn relative_contact_velocity(a: &RigidBody, b: &RigidBody, contact: &ContactGeometry) -> DVec3 {
    b.point_velocity(contact.r_b) - a.point_velocity(contact.r_a)
}

/// `−[r]× I⁻¹ [r]×` as a matrix (columns `−r × (I⁻¹ (r × e_k))`).
fn rotational_term(inv_inertia: DMat3, r: DVec3) -> DMat3 {
    let col = |e: DVec3| -r.cross(inv_inertia * r.cross(e));
    DMat3::from_cols(col(DVec3::X), col(DVec3::Y), col(DVec3::Z))
}

/// The collision matrix `K` of (4.14): `Δv_ab = K J` for an impulse `J` on *b* [1/kg].
///
/// ```
/// use glam::{DMat3, DVec3};
/// use magsep_systems::collision::impulse::{RigidBody, collision_matrix};
/// use magsep_systems::collision::toi::sphere_sphere_contact;
/// // solid sphere on a wall: K = (1/m)(n nᵀ + 7/2 (𝕀 − n nᵀ))
/// let a = RigidBody::solid_sphere(2.0, 1.0, DVec3::ZERO, DVec3::ZERO);
/// let c = sphere_sphere_contact(DVec3::Z * 1.0, 1.0, 0.0);
/// let k = collision_matrix(&a, &RigidBody::fixed(), &c);
/// assert!((k.z_axis.z - 0.5).abs() < 1e-15 && (k.x_axis.x - 1.75).abs() < 1e-15);
/// ```
pub fn collision_matrix(a: &RigidBody, b: &RigidBody, contact: &ContactGeometry) -> DMat3 {
    DMat3::from_diagonal(DVec3::splat(a.inv_mass + b.inv_mass))
        + rotational_term(a.inv_inertia, contact.r_a)
        + rotational_term(b.inv_inertia, contact.r_b)
}

/// `K⁻¹ rhs`, or `None` if `K` is (numerically) singular or not finite.
fn solve(k: DMat3, rhs: DVec3) -> Option<DVec3> {
    let det = k.determinant();
    let trace = k.x_axis.x + k.y_axis.y + k.z_axis.z;
    if det <= 1e-12 * trace * trace * trace || !det.is_finite() || trace.is_nan() {
        return None;
    }
    let x = k.inverse() * rhs;
    x.is_finite().then_some(x)
}

/// Frictionless impulse `J = −(1 + e_n)(v⁻·n)/(n·K n) n`, or `None` if `n·K n ≤ 0`.
fn frictionless_impulse(k: DMat3, n: DVec3, vn: f64, e_n: f64) -> Option<DVec3> {
    let knn = n.dot(k * n);
    (knn > 0.0).then(|| n * (-(1.0 + e_n) * vn / knn))
}

/// Collision impulse of bodies *a* and *b* at `contact` under `law`; `None` if the contact points
/// are not approaching (`v_ab·n ≥ 0`, or non-finite input) or both bodies are static.
///
/// See the module header for the model; [`CollisionImpulse`] has an example.
pub fn collision_impulse(
    a: &RigidBody,
    b: &RigidBody,
    contact: &ContactGeometry,
    law: &CollisionLaw,
) -> Option<CollisionImpulse> {
    let n = contact.normal;
    let v = relative_contact_velocity(a, b, contact);
    let vn = v.dot(n);
    if vn >= 0.0 || vn.is_nan() {
        return None;
    }
    let vt = v - n * vn;
    let (e_n, e_t, mu) = (
        law.normal_restitution,
        law.tangential_restitution,
        law.friction,
    );
    let k = collision_matrix(a, b, contact);
    let target = -n * (e_n * vn) - vt * e_t;
    let (impulse, regime) = match solve(k, target - v) {
        Some(j) => {
            let jn = j.dot(n);
            let jt = j - n * jn;
            if jt.length() <= mu * jn {
                (j, FrictionRegime::Stick)
            } else {
                slide_impulse(k, n, vn, v, vt, jt, e_n, mu)?
            }
        }
        None => (
            frictionless_impulse(k, n, vn, e_n)?,
            FrictionRegime::Frictionless,
        ),
    };
    let dvb = impulse * b.inv_mass;
    let dwb = b.inv_inertia * contact.r_b.cross(impulse);
    let dva = -impulse * a.inv_mass;
    let dwa = -(a.inv_inertia * contact.r_a.cross(impulse));
    Some(CollisionImpulse {
        impulse,
        regime,
        approach_speed: -vn,
        delta_velocity_a: dva,
        delta_angular_velocity_a: dwa,
        delta_velocity_b: dvb,
        delta_angular_velocity_b: dwb,
    })
}

/// Sliding impulse `J_n (n + μ t)` (or the frictionless fallback, see the module header).
/// `μ = 0` counts as sliding.
#[allow(clippy::too_many_arguments)]
fn slide_impulse(
    k: DMat3,
    n: DVec3,
    vn: f64,
    v: DVec3,
    vt: DVec3,
    jt_stick: DVec3,
    e_n: f64,
    mu: f64,
) -> Option<(DVec3, FrictionRegime)> {
    if mu <= 0.0 || mu.is_nan() {
        return Some((frictionless_impulse(k, n, vn, e_n)?, FrictionRegime::Slide));
    }
    let vt_len = vt.length();
    let t = if vt_len > 1e-12 * v.length() {
        -vt / vt_len
    } else {
        jt_stick.normalize_or_zero()
    };
    let dir = n + t * mu;
    let den = n.dot(k * dir);
    if den > 0.0 && den.is_finite() {
        Some((dir * (-(1.0 + e_n) * vn / den), FrictionRegime::Slide))
    } else {
        Some((
            frictionless_impulse(k, n, vn, e_n)?,
            FrictionRegime::Frictionless,
        ))
    }
}

#[cfg(test)]
mod tests;
