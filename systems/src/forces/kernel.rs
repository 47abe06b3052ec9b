//! External force kernels: user forces as functions of a particle's state, which every
//! pipeline can evaluate wherever it needs forces (at every adaptive sub-step of the brownian
//! stepper, at every FIRE iteration of the packing, once per step in the particle-fluid
//! pipeline).
//!
//! A kernel implements [`ExternalForce`]; [`ExternalForces`] (a resource) holds the registered
//! kernels in registration order, and [`ExternalForces::force_torque`] sums them for one
//! particle in that order, so the sum is bitwise reproducible at any thread count.
//! [`compute_kernel_forces`] writes the sum at the step start into the built-in contribution
//! [`KernelForce`], so `NetForce` shows it like any other contribution.
//!
//! Units: positions \[m\], times \[s\], forces \[N\], torques about the particle's centre [N m].
//!
//! ```
//! use glam::DVec3;
//! use magsep_systems::forces::{ExternalForce, ExternalForces, ParticleState};
//! use std::sync::Arc;
//!
//! /// Harmonic trap F = -k (x - c).
//! struct Trap { k: f64, centre: DVec3 }
//! impl ExternalForce for Trap {
//!     fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
//!         (-self.k * (p.position - self.centre), DVec3::ZERO)
//!     }
//! }
//! let mut kernels = ExternalForces::default();
//! kernels.push("trap", Arc::new(Trap { k: 2.0, centre: DVec3::ZERO }));
//! let p = ParticleState::sphere(0, DVec3::X, 0.5, 0.0);
//! assert_eq!(kernels.force_torque(&p).0, DVec3::new(-2.0, 0.0, 0.0));
//! ```

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::clock::StepClock;
use magsep_components::forces::KernelForce;
use magsep_components::particle::{Orientation, ParticleId, Position};
use magsep_components::shape::Shape;

/// What a kernel may read about one particle (all SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleState {
    /// The particle's `ParticleId`.
    pub id: u64,
    /// Centre \[m\]. Periodic pipelines may pass unwrapped centres (outside the box): wrap
    /// them yourself if the force is periodic.
    pub position: DVec3,
    /// Orientation (body z = rod axis; identity for spheres that do not track it).
    pub orientation: DQuat,
    /// Shape (lengths \[m\]).
    pub shape: Shape,
    /// Time \[s\] (the start of the step, or of the sub-step being evaluated).
    pub time: f64,
}

impl ParticleState {
    /// A sphere of radius `radius` \[m\] at `position` \[m\], time `time` \[s\].
    pub fn sphere(id: u64, position: DVec3, radius: f64, time: f64) -> Self {
        Self {
            id,
            position,
            orientation: DQuat::IDENTITY,
            shape: Shape::Sphere { radius },
            time,
        }
    }

    /// The radius R \[m\] of the shape (smallest semi-axis for superquadrics).
    pub fn radius(&self) -> f64 {
        self.shape.radius()
    }
}

/// A force (and torque) on a particle as a function of its state: the extension point for
/// user forces that every pipeline evaluates where it needs them.
///
/// Implementations must be pure (same input, same output) so that re-evaluation at sub-steps
/// and runs at any thread count agree.
pub trait ExternalForce: Send + Sync {
    /// Force \[N\] and torque about the centre [N m] on particle `p`.
    fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3);
}

/// The registered kernels in registration order (a resource).
#[derive(Resource, Clone, Default)]
pub struct ExternalForces {
    kernels: Vec<(String, Arc<dyn ExternalForce>)>,
}

impl std::fmt::Debug for ExternalForces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.names()).finish()
    }
}

impl ExternalForces {
    /// Append `kernel` under `name` (names need not be unique; order is summation order).
    pub fn push(&mut self, name: impl Into<String>, kernel: Arc<dyn ExternalForce>) {
        self.kernels.push((name.into(), kernel));
    }

    /// Names in registration order.
    pub fn names(&self) -> Vec<&str> {
        self.kernels.iter().map(|k| k.0.as_str()).collect()
    }

    /// Whether no kernel is registered.
    pub fn is_empty(&self) -> bool {
        self.kernels.is_empty()
    }

    /// Number of kernels.
    pub fn len(&self) -> usize {
        self.kernels.len()
    }

    /// Sum of all kernels on `p` in registration order: force \[N\], torque [N m].
    pub fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
        let (mut f, mut t) = (DVec3::ZERO, DVec3::ZERO);
        for (_, k) in &self.kernels {
            let (fk, tk) = k.force_torque(p);
            f += fk;
            t += tk;
        }
        (f, t)
    }
}

/// Write the kernels' sum at the step start into every particle's [`KernelForce`]
/// (`Forces::Custom`; per particle, so parallel and order independent).
pub fn compute_kernel_forces(
    kernels: Res<ExternalForces>,
    clock: Option<Res<StepClock>>,
    mut q: Query<(
        &ParticleId,
        &Position,
        Option<&Orientation>,
        &Shape,
        &mut KernelForce,
    )>,
) {
    let time = clock.map(|c| c.time()).unwrap_or(0.0);
    crate::par_for_each_mut!(q, |(id, x, o, shape, mut k)| {
        let p = ParticleState {
            id: id.0,
            position: x.0,
            orientation: o.map(|o| o.0).unwrap_or(DQuat::IDENTITY),
            shape: *shape,
            time,
        };
        let (force, torque) = kernels.force_torque(&p);
        *k = KernelForce { force, torque };
    });
}

/// Whether a pipeline consumes something the user registered.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Consumption {
    /// Consumed: it acts on the particles.
    Consumed,
    /// Refused, with the reason and what to do instead (shown by `SimApp::finish`).
    Refused(String),
}

/// What the pipeline's integrator consumes (a resource declared by the integrator plugin and
/// checked by `SimApp::finish`, which refuses registrations that would be ignored).
#[derive(Resource, Debug, Clone, PartialEq, Eq)]
pub struct ForceUse {
    /// Type names of the contributions the pipeline registers and handles itself (e.g. the
    /// brownian field, dipole and contact forces, re-evaluated at every sub-step).
    pub builtin: Vec<String>,
    /// Any other registered `ForceContribution` (a user's component).
    pub contributions: Consumption,
    /// Registered [`ExternalForce`] kernels.
    pub kernels: Consumption,
}

impl Default for ForceUse {
    /// Nothing consumed (no integrator plugin declared its use).
    fn default() -> Self {
        let why = "no plugin of this app integrates forces (none declared a `ForceUse`)";
        Self {
            builtin: Vec::new(),
            contributions: Consumption::Refused(why.into()),
            kernels: Consumption::Refused(why.into()),
        }
    }
}

impl ForceUse {
    /// Check registered contribution type names `registered` and kernel names `kernels`
    /// against this declaration. [`KernelForce`] (the kernels' own contribution) is always
    /// accepted here; the kernels are checked instead.
    ///
    /// # Errors
    /// A message naming what is refused, why and what to do instead.
    pub fn check(&self, registered: &[String], kernels: &[&str]) -> Result<(), String> {
        let kernel_force = std::any::type_name::<KernelForce>();
        let user: Vec<&str> = registered
            .iter()
            .map(String::as_str)
            .filter(|n| *n != kernel_force && !self.builtin.iter().any(|b| b == n))
            .collect();
        let mut errors = Vec::new();
        if let (false, Consumption::Refused(why)) = (user.is_empty(), &self.contributions) {
            errors.push(format!(
                "force contribution(s) {} would be ignored: {why}",
                user.join(", ")
            ));
        }
        if let (false, Consumption::Refused(why)) = (kernels.is_empty(), &self.kernels) {
            errors.push(format!(
                "external force kernel(s) {} would be ignored: {why}",
                kernels.join(", ")
            ));
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors.join("; "))
        }
    }
}

impl ExternalForces {
    /// Evaluate the kernels on dense particles: `out[i]` = (force \[N\], torque [N m]) on the
    /// particle `state(i)` describes, zero where it returns `None`. Parallel above 512
    /// particles; every entry is a fixed-order sum, so the result does not depend on the
    /// thread count.
    pub fn evaluate_dense(
        &self,
        state: impl Fn(usize) -> Option<ParticleState> + Sync + Send,
        out: &mut [(DVec3, DVec3)],
    ) {
        use rayon::prelude::*;
        let f = |i: usize, o: &mut (DVec3, DVec3)| {
            *o = state(i).map_or((DVec3::ZERO, DVec3::ZERO), |p| self.force_torque(&p));
        };
        if out.len() < 512 {
            out.iter_mut().enumerate().for_each(|(i, o)| f(i, o));
        } else {
            out.par_iter_mut()
                .with_min_len(128)
                .enumerate()
                .for_each(|(i, o)| f(i, o));
        }
    }
}
