//! Inertial particles in a (magnetised) liquid: velocities, mass properties, the fluid sampled
//! at each particle, and one force contribution per term of the extended Maxey-Riley
//! equation (thesis 002, eq. 2.26 corrected; [T002 §2.2.4.1]; errata in docs/references.md).
//! SI units throughout. Gravity acts along −z: magsep's vertical is z (Foxglove's up), the
//! thesis's y.
//!
//! The contributions are summed into `NetForce`/`NetTorque` in registration order. Two terms
//! are partly implicit in the integrator: the drag (its stiffness is stored beside the
//! force) and the newest weight of the Basset history; the added mass −½ ρ_f V dv/dt is part
//! of the effective mass and has no component of its own.

use bevy_ecs::prelude::*;
use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::forces::ForceContribution;

/// Translational velocity v [m/s].
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Velocity(pub DVec3);

/// Angular velocity Ω [rad/s] (lab frame).
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AngularVelocity(pub DVec3);

/// Mass properties of a rigid particle.
///
/// ```
/// use magsep_components::fluid::InertialBody;
/// let b = InertialBody::sphere(2.5e-3, 1434.0);
/// assert!((b.volume - 6.544984694978735e-8).abs() < 1e-20);
/// assert!((b.inertia.x - 0.4 * b.mass * 2.5e-3 * 2.5e-3).abs() < 1e-20);
/// ```
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InertialBody {
    /// Mass density ρ_p [kg/m³].
    pub density: f64,
    /// Volume V \[m³\].
    pub volume: f64,
    /// Mass m = ρ_p V \[kg\].
    pub mass: f64,
    /// Volume-equivalent diameter d_p \[m\] (the sphere's diameter; d_e of a spheroid).
    pub diameter: f64,
    /// Principal moments of inertia about the body axes [kg m²].
    pub inertia: DVec3,
}

impl InertialBody {
    /// A homogeneous sphere of `radius` \[m\] and `density` [kg/m³].
    pub fn sphere(radius: f64, density: f64) -> Self {
        let volume = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        let mass = density * volume;
        Self {
            density,
            volume,
            mass,
            diameter: 2.0 * radius,
            inertia: DVec3::splat(0.4 * mass * radius * radius),
        }
    }

    /// A homogeneous spheroid of equatorial semi-axis `a` and polar semi-axis `c` (symmetry
    /// axis body z) \[m\] and `density` [kg/m³]: V = 4/3 π a² c, d_p = 2 (a² c)^{1/3} (the
    /// volume-equivalent diameter d_e = d_major w^{1/3} for an oblate spheroid),
    /// I_x = I_y = m (a² + c²)/5, I_z = 2 m a²/5.
    ///
    /// ```
    /// use magsep_components::fluid::InertialBody;
    /// // spheroid p1 of thesis 002, Table 4.1: 5 mm x 2.5 mm, V = 32.73 mm³, d_e = 3.969 mm
    /// let b = InertialBody::spheroid(2.5e-3, 1.25e-3, 1434.0);
    /// assert!((b.volume * 1e9 - 32.725).abs() < 1e-3);
    /// assert!((b.diameter * 1e3 - 3.969).abs() < 1e-3);
    /// assert!(b.inertia.z > b.inertia.x);
    /// ```
    pub fn spheroid(a: f64, c: f64, density: f64) -> Self {
        let volume = 4.0 / 3.0 * std::f64::consts::PI * a * a * c;
        let mass = density * volume;
        let ix = mass * (a * a + c * c) / 5.0;
        Self {
            density,
            volume,
            mass,
            diameter: 2.0 * (a * a * c).cbrt(),
            inertia: DVec3::new(ix, ix, 0.4 * mass * a * a),
        }
    }
}

/// The undisturbed fluid at the particle's centre, sampled in `Prepare`.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FluidSample {
    /// Fluid velocity u [m/s].
    pub velocity: DVec3,
    /// Material acceleration Du/Dt [m/s²].
    pub acceleration: DVec3,
    /// Vorticity ω = ∇ × u [1/s].
    pub vorticity: DVec3,
}

crate::force_contribution!(
    /// Weight −ρ_p V g e_z \[N\] (F_G of eq. 2.26).
    GravityForce
);
crate::force_contribution!(
    /// Hydrostatic buoyancy ρ_f V g e_z \[N\] (the non-magnetic part of F_B, eq. 2.12).
    BuoyancyForce
);
crate::force_contribution!(
    /// Magnetic buoyancy −μ₀ V M ∇H \[N\] of the paramagnetic liquid (eq. 2.11): the
    /// magnetic part of F_B, pushing particles towards low field.
    MagneticBuoyancyForce
);
crate::force_contribution!(
    /// Force of the undisturbed flow and the fluid part of the added mass,
    /// (ρ_f V + ½ ρ_f V) Du/Dt \[N\] (F_U and the Du/Dt term of F_AM, eq. 2.26).
    UndisturbedFlowForce
);
crate::force_contribution!(
    /// The explicit part of the Basset history force \[N\]: c_H times the history integral of
    /// all completed steps (and a step change's jump term). With the implicit integrator the
    /// newest step's part is added in `Mobility`; after the step this holds the whole force.
    HistoryForce
);

crate::force_contribution!(
    /// Shape-induced lift of a spheroid at incidence \[N\] (F_PL of thesis 002, eq. 4.6, with
    /// the corrected direction): perpendicular to the slip, in the plane of the slip and the
    /// symmetry axis.
    LiftForce
);
crate::torque_contribution!(
    /// Pitching torque of a spheroid at incidence [N m] (T_P of eq. 4.9, corrected direction):
    /// turns the symmetry axis towards the slip (broadside).
    PitchingTorque
);
crate::torque_contribution!(
    /// Magnetic-buoyancy torque [N m] on a non-magnetic spheroid in a paramagnetic liquid
    /// (T_MB of eq. 4.9, sign corrected): aligns the symmetry axis with the field gradient,
    /// i.e. turns a flake flat (horizontal) in the thesis's 1-D fields.
    MagneticTorque
);

/// Steady drag F_D = k (u − v) \[N\] at the start-of-step velocity (Schiller-Naumann or Stokes
/// for spheres, the shape correlation for spheroids), with its stiffness k [kg/s] so that the
/// integrator can treat it implicitly.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DragForce {
    /// Force \[N\].
    pub force: DVec3,
    /// Stiffness k = −∂F/∂v [kg/s] (the drag's linearisation about the current slip).
    pub stiffness: f64,
}

impl ForceContribution for DragForce {
    fn force(&self) -> DVec3 {
        self.force
    }
    fn clear(&mut self) {
        *self = Self::default();
    }
}

/// Rotational drag torque [N m] with its stiffness [kg m²/s] for the implicit integrator:
/// Dennis et al. for spheres (eq. 2.31 corrected), T = C_T ½ ρ_f R⁵ |Δ| Δ with Δ = ½ω − Ω;
/// Zastawny et al.'s rotational resistance T_R of eq. 4.9 for spheroids.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotationalDragTorque {
    /// Torque [N m].
    pub torque: DVec3,
    /// Stiffness −∂T/∂Ω [kg m²/s].
    pub stiffness: f64,
}

impl ForceContribution for RotationalDragTorque {
    fn force(&self) -> DVec3 {
        DVec3::ZERO
    }
    fn torque(&self) -> DVec3 {
        self.torque
    }
    fn clear(&mut self) {
        *self = Self::default();
    }
}

/// Equilibrium and levitation bookkeeping of a particle in a magnetised liquid.
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Levitation {
    /// Equilibrium height z_e \[m\] (world) where the apparent density equals ρ_p (NaN if none).
    pub equilibrium_height: f64,
    /// Last time \[s\] the particle was farther than the tolerance from y_e (its levitation
    /// time t_l once it has settled; [T002 §2.5.1.1]).
    pub last_outside: f64,
}

/// Counters of a particle-fluid run (a resource).
#[derive(Resource, Debug, Default, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParticleFluidStats {
    /// Collisions between particles.
    pub particle_collisions: u64,
    /// Collisions with walls.
    pub wall_collisions: u64,
    /// Collisions that ended sticking (Coulomb).
    pub sticking: u64,
    /// Collisions that ended sliding.
    pub sliding: u64,
    /// Approaches slower than the rest speed, treated as fully inelastic.
    pub resting: u64,
    /// Contact impulses of the resting-contact solve (touching pairs at the start of a step;
    /// not counted in `particle_collisions`, but each is a collision for the Basset history).
    #[serde(default)]
    pub resting_contacts: u64,
    /// Steps whose collision-event budget ran out.
    pub capped_steps: u64,
    /// Largest overlap left after a step, relative to the pair's mean diameter.
    pub max_overlap: f64,
    /// Largest translational Reynolds number seen.
    pub max_reynolds: f64,
}
