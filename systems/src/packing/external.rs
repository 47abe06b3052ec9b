//! External force kernels ([`crate::forces::ExternalForce`]) in the FIRE minimiser's reduced
//! units.
//!
//! **Positions.** The kernels see SI data: the centre x = x̃ D \[m\] (x̃ the reduced centre, D
//! the reference diameter; in a periodic box the centre as the minimiser holds it, which may
//! lie outside the box), the particle's SI shape, its orientation and the step's time.
//!
//! **Forces.** The MCM packs hard particles: it has no SI stiffness, and the minimiser's
//! overlap energy Σ δ̃²/2 (δ̃ = δ / D) is a penalty that stands for the hard core. In the
//! hard-particle limit the configuration an external potential U pushes the particles into
//! (its minimum subject to no overlap) does not depend on U's magnitude, only on its shape.
//! So the kernels' forces are scaled by one factor s [1/N] per minimisation, chosen so that
//! the total load Σ_i |F_i| at the start of the minimisation becomes `tolerance / 2` in reduced
//! units: any contact, which carries at most the total load, then overlaps by about
//! `tolerance / 2` at equilibrium, and the penalty acts as a hard core. Reduced force
//! f̃ = s F, reduced torque t̃ = s T / D. Ratios between kernels and between particles are
//! kept; the kernels' absolute magnitude is not a packing parameter.

use glam::DVec3;
use magsep_components::shape::Shape;

use super::state::PackingState;
use crate::forces::{ExternalForces, ParticleState};

/// The registered kernels and what they need to see SI particles.
#[derive(Clone, Copy)]
pub struct PackingKernels<'a> {
    /// Kernels in registration order.
    pub kernels: &'a ExternalForces,
    /// Reference diameter D \[m\].
    pub d: f64,
    /// SI shapes in dense order.
    pub shapes: &'a [Shape],
    /// `ParticleId`s in dense order.
    pub ids: &'a [u64],
    /// Time of the step \[s\].
    pub time: f64,
}

impl PackingKernels<'_> {
    /// SI forces \[N\] and torques [N m] at configuration `state`.
    pub fn si(&self, state: &PackingState, out: &mut [(DVec3, DVec3)]) {
        self.kernels.evaluate_dense(
            |i| {
                Some(ParticleState {
                    id: self.ids.get(i).copied().unwrap_or(i as u64),
                    position: state.positions[i] * self.d,
                    orientation: state.orientations[i],
                    shape: self.shapes.get(i).copied()?,
                    time: self.time,
                })
            },
            out,
        );
    }

    /// The scale s [1/N] of the hard-particle limit at configuration `state` for overlap
    /// tolerance `tolerance` / D, and the largest reduced force there, s max |F_i| (both 0
    /// when the kernels exert no finite force there).
    pub fn scale(&self, state: &PackingState, tolerance: f64) -> (f64, f64) {
        let mut out = vec![(DVec3::ZERO, DVec3::ZERO); state.len()];
        self.si(state, &mut out);
        let load: f64 = out.iter().map(|(f, _)| f.length()).sum();
        let max = out.iter().map(|(f, _)| f.length()).fold(0.0, f64::max);
        if load > 0.0 && load.is_finite() {
            let s = 0.5 * tolerance / load;
            (s, s * max)
        } else {
            (0.0, 0.0)
        }
    }

    /// Add the reduced forces and torques (scale `s` [1/N]) at `state` to `force`, `torque`.
    pub fn add_reduced(
        &self,
        state: &PackingState,
        s: f64,
        scratch: &mut Vec<(DVec3, DVec3)>,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        scratch.resize(state.len(), (DVec3::ZERO, DVec3::ZERO));
        self.si(state, scratch);
        for (i, (f, t)) in scratch.iter().enumerate() {
            force[i] += s * *f;
            torque[i] += (s / self.d) * *t;
        }
    }
}
