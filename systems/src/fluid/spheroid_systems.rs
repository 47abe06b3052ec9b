//! Thin ECS glue of the spheroid terms of the particle-fluid pipeline (thesis 002, ch. 4): each
//! system reads components, calls a kernel of [`super::spheroid`] and writes its own
//! contribution. Spheres keep the systems of [`super::systems`]; a particle is a spheroid when
//! it carries [`SpheroidFluid`].
//!
//! * `Forces::Fluid`: [`compute_spheroid_loads`] writes `DragForce` (with its stiffness),
//!   `LiftForce` and `PitchingTorque`; [`compute_spheroid_rotational_drag`] writes
//!   `RotationalDragTorque`.
//! * `Forces::Field`: [`compute_magnetic_torque`] writes `MagneticTorque` from the curvature of
//!   the magnetic static pressure at the centre.
//!
//! The added mass and the Basset history use the volume-equivalent sphere (`InertialBody`'s
//! `diameter` is d_e), as the thesis does ("models for non-spherical particles do not yet
//! exist", §4.2.1.2); gravity, buoyancy and magnetic buoyancy are the point forces of the
//! sphere systems.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;

use super::config::ParticleFluidConfig;
use super::spheroid::{SpheroidHydro, magnetic_torque, rotational_resistance, spheroid_loads};

/// The hydrodynamic description of a spheroid particle (correlations, diameters, densities)
/// and its semi-axes (a, c) \[m\].
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct SpheroidFluid {
    /// Correlations and the quantities they need.
    pub hydro: SpheroidHydro,
    /// Equatorial semi-axis a \[m\].
    pub equatorial_radius: f64,
    /// Polar semi-axis c \[m\].
    pub polar_radius: f64,
}

/// Drag, lift and pitching torque of each spheroid at the start-of-step slip (`Forces::Fluid`).
#[allow(clippy::type_complexity)]
pub fn compute_spheroid_loads(
    mut stats: ResMut<ParticleFluidStats>,
    mut q: Query<(
        &Velocity,
        &FluidSample,
        &Orientation,
        &SpheroidFluid,
        Option<&mut DragForce>,
        Option<&mut LiftForce>,
        Option<&mut PitchingTorque>,
    )>,
) {
    let mut re_max = stats.max_reynolds;
    for (v, s, o, sp, drag, lift, pitch) in &mut q {
        let loads = spheroid_loads(&sp.hydro, s.velocity - v.0, o.0 * DVec3::Z);
        if let Some(mut d) = drag {
            d.force = loads.drag;
            d.stiffness = loads.drag_stiffness;
        }
        if let Some(mut l) = lift {
            l.0 = loads.lift;
        }
        if let Some(mut t) = pitch {
            t.0 = loads.pitching_torque;
        }
        if loads.reynolds.is_finite() {
            re_max = re_max.max(loads.reynolds);
        }
    }
    stats.max_reynolds = re_max;
}

/// Rotational resistance of each spheroid (`Forces::Fluid`).
pub fn compute_spheroid_rotational_drag(
    mut q: Query<(
        &AngularVelocity,
        &FluidSample,
        &SpheroidFluid,
        &mut RotationalDragTorque,
    )>,
) {
    crate::par_for_each_mut!(q, |(w, s, sp, mut t)| {
        let (torque, k) = rotational_resistance(&sp.hydro, 0.5 * s.vorticity - w.0);
        t.torque = torque;
        t.stiffness = k;
    });
}

/// Magnetic-buoyancy torque of each spheroid (`Forces::Field`).
pub fn compute_magnetic_torque(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<(&Position, &Orientation, &SpheroidFluid, &mut MagneticTorque)>,
) {
    let chi = cfg.liquid.susceptibility;
    crate::par_for_each_mut!(q, |(x, o, sp, mut t)| {
        let curvature = cfg
            .magnet
            .static_pressure_curvature(chi, cfg.magnet_y(x.0.z));
        t.0 = magnetic_torque(
            sp.equatorial_radius,
            sp.polar_radius,
            curvature,
            o.0 * DVec3::Z,
        );
    });
}
