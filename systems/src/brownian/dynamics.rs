//! The physics behind the stepper: forces from the [`ForceModel`] and the user's external
//! force kernels ([`ExternalForces`], re-evaluated at every sub-step with the sub-step's
//! positions and time), mobility (free draining or a prepared RPY [`Mobility`] over the free
//! particles), hard cores and capture.

use glam::DVec3;
use magsep_components::brownian::BrownianStats;
use magsep_components::brownian::{CaptureEvent, MomentModel};
use magsep_components::shape::Shape;
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

use crate::forces::{ExternalForces, ParticleState};

use super::contact::{remove_overlaps, swept_capture_cached};
use super::fibre_flow::FibreFlow;
use super::hydro::Mobility;
use super::model::{ForceModel, ForceParts, PairLists, ParticleView};
use super::parts::{part_bounds, run_parts, split_at_bounds};
use super::stepper::multirate::LocalDynamics;
use super::stepper::{Dynamics, PARTICLE_CHUNK, normal3};

/// Hydrodynamic interactions among the free particles: the prepared mobility and the particle
/// index of each of its rows.
pub struct HydroState {
    /// Mobility of the free particles at the start of the step.
    pub mobility: Mobility,
    /// Particle index of each mobility row.
    pub rows: Vec<usize>,
}

/// The liquid's velocity at `x` \[m/s\]: mean flow `flow` and, with a flow field `ff`, the
/// fibres' perturbation.
fn liquid_at(ff: Option<&FibreFlow>, flow: DVec3, x: DVec3) -> DVec3 {
    match ff {
        Some(ff) => ff.velocity(flow, x),
        None => flow,
    }
}

/// `f(i, &mut out[i])` for every particle, in parallel chunks of [`PARTICLE_CHUNK`] from two
/// chunks on (every element is its own computation: bitwise the same for any thread count).
fn per_particle(out: &mut [DVec3], f: impl Fn(usize, &mut DVec3) + Sync + Send) {
    if out.len() < 2 * PARTICLE_CHUNK {
        out.iter_mut().enumerate().for_each(|(i, o)| f(i, o));
    } else {
        out.par_iter_mut()
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(i, o)| f(i, o));
    }
}

/// One step's view of the pipeline state as [`Dynamics`].
pub struct PipelineDynamics<'a> {
    /// Force model.
    pub model: &'a ForceModel,
    /// Radii \[m\].
    pub radii: &'a [f64],
    /// Moment laws.
    pub laws: &'a [MomentModel],
    /// Free particles (cleared on capture).
    pub mobile: Vec<bool>,
    /// Whether captured particles keep exerting pair forces.
    pub captured_interact: bool,
    /// Forces from contributions outside the model and the kernels (a user's
    /// `ForceContribution` components, accepted only with fixed steps, where no sub-step
    /// evaluates forces), held over the step \[N\].
    pub extra: &'a [DVec3],
    /// External force kernels, evaluated at every drift (None: none registered).
    pub kernels: Option<&'a ExternalForces>,
    /// `ParticleId`s and shapes (SI) that the kernels see.
    pub ids: &'a [u64],
    /// Shapes \[m\].
    pub shapes: &'a [Shape],
    /// Time at the start of the step \[s\] and the step dt \[s\].
    pub time: (f64, f64),
    /// Fraction of the step of the next drift evaluation.
    pub fraction: f64,
    /// Kernel scratch (force \[N\], torque [N m]).
    pub kernel_out: Vec<(DVec3, DVec3)>,
    /// Viscosity [Pa s].
    pub viscosity: f64,
    /// Thermal energy \[J\].
    pub kt: f64,
    /// Mean velocity of the liquid u \[m/s\]: it advects every free particle (added to the
    /// drift after the mobility, so with hydrodynamic interactions too each particle moves
    /// with u on top of `μ F`).
    pub flow: DVec3,
    /// The flow's perturbation around the fibres (None: the mean flow everywhere).
    pub flow_field: Option<&'a FibreFlow>,
    /// Hydrodynamic interactions (None: free draining).
    pub hydro: Option<&'a HydroState>,
    /// Neighbour lists of the pair forces (cached across evaluations).
    pub lists: &'a mut PairLists,
    /// Moments at the step start [A m²] (held for the particles a multirate sub-step does
    /// not move).
    pub start_moments: &'a [DVec3],
    /// Neighbour-list rebuilds in this step.
    pub list_builds: u64,
    /// Hard cores.
    pub hard_core: bool,
    /// Step being taken (for capture events).
    pub step: u64,
    /// Capture events of this step.
    pub captures: Vec<(usize, CaptureEvent)>,
    /// Force evaluation scratch.
    pub parts: ForceParts,
    /// Hard-core sweeps used.
    pub sweeps: u64,
    /// First Krylov/TEA failure met.
    pub failure: Option<String>,
}

impl PipelineDynamics<'_> {
    /// The external force kernels' (force \[N\], torque [N m]) on the particles with
    /// `wanted[i]`, at the time of the next drift (zero for the others; empty without kernels).
    fn kernel_forces(&mut self, x: &[DVec3], wanted: &[bool]) -> &[(DVec3, DVec3)] {
        let Some(k) = self.kernels else {
            return &[];
        };
        let t = self.time.0 + self.fraction * self.time.1;
        self.kernel_out.resize(x.len(), (DVec3::ZERO, DVec3::ZERO));
        let (ids, shapes) = (self.ids, self.shapes);
        k.evaluate_dense(
            |i| {
                wanted[i].then(|| ParticleState {
                    id: ids[i],
                    position: x[i],
                    orientation: glam::DQuat::IDENTITY,
                    shape: shapes[i],
                    time: t,
                })
            },
            &mut self.kernel_out,
        );
        &self.kernel_out
    }

    fn exerts(&self) -> Vec<bool> {
        self.mobile
            .iter()
            .map(|&m| m || self.captured_interact)
            .collect()
    }

    /// The liquid's velocity at `x` \[m/s\]: the mean flow and, with a flow field, the
    /// fibres' perturbation.
    pub fn liquid(&self, x: DVec3) -> DVec3 {
        liquid_at(self.flow_field, self.flow, x)
    }

    /// Velocities at positions `x` from forces `f` (masked to the free particles), plus the
    /// liquid's velocity ([`PipelineDynamics::liquid`]) for the free particles.
    pub fn velocities(&self, x: &[DVec3], f: &[DVec3], v: &mut [DVec3]) {
        match self.hydro {
            None => {
                let (mobile, radii, eta) = (&self.mobile, self.radii, self.viscosity);
                let (ff, flow) = (self.flow_field, self.flow);
                per_particle(&mut v[..f.len()], |i, vi| {
                    *vi = if mobile[i] {
                        f[i] / (6.0 * std::f64::consts::PI * eta * radii[i])
                            + liquid_at(ff, flow, x[i])
                    } else {
                        DVec3::ZERO
                    };
                });
            }
            Some(h) => {
                let fs: Vec<DVec3> = h.rows.iter().map(|&i| f[i]).collect();
                let mut vs = vec![DVec3::ZERO; fs.len()];
                h.mobility.apply(&fs, &mut vs);
                v.fill(DVec3::ZERO);
                for (k, &i) in h.rows.iter().enumerate() {
                    if self.mobile[i] {
                        v[i] = vs[k] + self.liquid(x[i]);
                    }
                }
            }
        }
    }
}

impl PipelineDynamics<'_> {
    /// The fixed Ermak-McCammon step with free-draining mobility and no hard cores in one
    /// pass over the particles: for each, its Wiener increment from its own stream, drift from
    /// the step-start force `force(i)` \[N\], noise and update, then capture. The same
    /// expressions, in the same order per particle, as [`super::stepper::advance`] with
    /// [`StepControl::Fixed`](magsep_components::brownian::StepControl::Fixed) after
    /// [`PipelineDynamics::velocities`] (its reference, tested bit for bit): one parallel region
    /// over the parts of the pair forces ([`super::parts`]) instead of four. Returns the first
    /// particle whose new position is not finite (each part checks its own particles, so the
    /// caller need not scan them again on one thread).
    pub fn fixed_free_step(
        &mut self,
        x: &mut [DVec3],
        force: impl Fn(usize) -> DVec3 + Sync + Clone,
        dt: f64,
        rngs: &mut [Xoshiro256PlusPlus],
        stats: &mut BrownianStats,
    ) -> Option<usize> {
        let (mobile, radii, eta, kt) =
            (self.mobile.as_slice(), self.radii, self.viscosity, self.kt);
        let (ff, flow) = (self.flow_field, self.flow);
        let s = dt.sqrt();
        // a `move` closure of plain values: each part runs its own copy (see `run_parts`)
        let step = move |(i, (xi, rng)): (usize, (&mut DVec3, &mut Xoshiro256PlusPlus))| {
            let (v, b) = if mobile[i] {
                let w = normal3(rng) * s;
                let v = force(i) / (6.0 * std::f64::consts::PI * eta * radii[i])
                    + liquid_at(ff, flow, *xi);
                let mu = 1.0 / (6.0 * std::f64::consts::PI * eta * radii[i]);
                (v, w * (2.0 * kt * mu).sqrt())
            } else {
                (DVec3::ZERO, DVec3::ZERO)
            };
            *xi += v * dt + b;
        };
        // capture needs the step's start only near fibres
        let from = (!self.model.sources.is_empty()).then(|| x.to_vec());
        let n = x.len().min(rngs.len()).min(mobile.len());
        // the parts of the pair forces (each thread updates the particles whose forces it
        // summed, see `super::parts`)
        let bounds = part_bounds(self.lists, n);
        let items: Vec<_> = split_at_bounds(&mut x[..n], &bounds)
            .into_iter()
            .zip(split_at_bounds(&mut rngs[..n], &bounds))
            .collect();
        // per part: its mobile particles and its first non-finite position
        let bounds = bounds.as_slice();
        let found = run_parts(items, move |p, (xs, rs)| {
            let a = bounds[p];
            xs.iter_mut()
                .zip(rs.iter_mut())
                .enumerate()
                .for_each(|(k, v)| step((a + k, v)));
            let moved = mobile[a..a + xs.len()].iter().filter(|&&m| m).count() as u64;
            let bad = xs.iter().position(|v| !v.is_finite()).map(|k| a + k);
            (moved, bad)
        });
        let (moved, mut bad) = found
            .into_iter()
            .fold((0, None), |(n, b), (m, c)| (n + m, b.or(c)));
        if let Some(from) = from {
            self.accept(&from, x, 1.0);
            // a capture may have put a particle somewhere else
            bad = x.iter().position(|v| !v.is_finite());
        }
        stats.substeps += 1;
        stats.particle_substeps += moved;
        bad
    }
}

impl Dynamics for PipelineDynamics<'_> {
    fn radii(&self) -> &[f64] {
        self.radii
    }

    fn mobile(&self) -> &[bool] {
        &self.mobile
    }

    fn drift(&mut self, x: &[DVec3], v: &mut [DVec3]) {
        let exerts = self.exerts();
        let view = ParticleView {
            radii: self.radii,
            moments: self.laws,
            mobile: &self.mobile,
            exerts: &exerts,
        };
        let mut parts = std::mem::take(&mut self.parts);
        let before = self.lists.builds();
        self.model.evaluate(x, &view, self.lists, &mut parts);
        self.list_builds += self.lists.builds() - before;
        let mut f: Vec<DVec3> = (0..x.len())
            .map(|i| parts.total(i) + self.extra[i])
            .collect();
        self.parts = parts;
        if self.kernels.is_some() {
            let mobile = self.mobile.clone();
            let out = self.kernel_forces(x, &mobile);
            for (fi, (fk, _)) in f.iter_mut().zip(out) {
                *fi += *fk;
            }
        }
        self.velocities(x, &f, v);
    }

    fn at_time(&mut self, t: f64) {
        self.fraction = t;
    }

    fn noise(&mut self, w: &[DVec3], out: &mut [DVec3]) {
        match self.hydro {
            None => {
                let (mobile, radii, eta, kt) = (&self.mobile, self.radii, self.viscosity, self.kt);
                per_particle(&mut out[..w.len()], |i, o| {
                    *o = if mobile[i] {
                        let mu = 1.0 / (6.0 * std::f64::consts::PI * eta * radii[i]);
                        w[i] * (2.0 * kt * mu).sqrt()
                    } else {
                        DVec3::ZERO
                    };
                });
            }
            Some(h) => {
                let ws: Vec<DVec3> = h.rows.iter().map(|&i| w[i]).collect();
                let mut ys = vec![DVec3::ZERO; ws.len()];
                if let Err(e) = h.mobility.noise(&ws, &mut ys)
                    && self.failure.is_none()
                {
                    self.failure = Some(e.to_string());
                }
                let s = (2.0 * self.kt).sqrt();
                out.fill(DVec3::ZERO);
                for (k, &i) in h.rows.iter().enumerate() {
                    if self.mobile[i] {
                        out[i] = ys[k] * s;
                    }
                }
            }
        }
    }

    fn constrain(&mut self, _from: &[DVec3], x: &mut [DVec3]) {
        if self.hard_core {
            let mobile = self.mobile.clone();
            self.sweeps += remove_overlaps(x, self.radii, &mobile, 1000) as u64;
        }
    }

    fn accept(&mut self, from: &[DVec3], x: &mut [DVec3], _t: f64) {
        self.capture_swept(from, x, 0..x.len());
    }

    fn accept_moved(&mut self, from: &[DVec3], x: &mut [DVec3], moved: &[usize], _t: f64) {
        self.capture_swept(from, x, moved.iter().copied());
    }
}

impl PipelineDynamics<'_> {
    /// Capture the free particles of `which` (ascending) whose path `from[i] → x[i]` comes
    /// within capture distance of a fibre: they stop at the capture point and are fixed.
    fn capture_swept(
        &mut self,
        from: &[DVec3],
        x: &mut [DVec3],
        which: impl Iterator<Item = usize>,
    ) {
        if self.model.sources.is_empty() {
            return;
        }
        let gaps = &mut self.lists.capture_gaps;
        gaps.resize(x.len(), None);
        for i in which {
            if !self.mobile[i] {
                continue;
            }
            let (sources, a) = (&self.model.sources, self.radii[i]);
            if let Some((k, p)) = swept_capture_cached(sources, from[i], x[i], a, &mut gaps[i]) {
                x[i] = p;
                self.mobile[i] = false;
                self.captures.push((
                    i,
                    CaptureEvent {
                        step: self.step,
                        fibre: k as u64,
                    },
                ));
            }
        }
    }
}

impl LocalDynamics for PipelineDynamics<'_> {
    /// The forces on the `active` particles only, with the moments of the others held at their
    /// step-start values; free-draining mobility (the multirate stepper is not used with
    /// hydrodynamic interactions), plus the liquid's mean velocity.
    fn drift_of(&mut self, x: &[DVec3], active: &[usize], v: &mut [DVec3]) {
        let exerts = self.exerts();
        let view = ParticleView {
            radii: self.radii,
            moments: self.laws,
            mobile: &self.mobile,
            exerts: &exerts,
        };
        self.list_builds += self.model.update_lists(x, &view, self.lists);
        let mut moments = self.start_moments.to_vec();
        moments.resize(x.len(), DVec3::ZERO);
        self.lists.patches.ensure(x.len());
        let mut f: Vec<DVec3> = active
            .iter()
            .map(|&i| {
                let slot = &mut self.lists.patches.slots[i];
                let (m, field) = self.model.moment_and_field_force(x, &view, i, slot);
                moments[i] = m;
                field + self.extra[i]
            })
            .collect();
        let (dr, cr) = (
            self.model.dipole_range(&view),
            self.model.contact_range(&view),
        );
        for (fi, &i) in f.iter_mut().zip(active) {
            *fi += self
                .model
                .dipole_force_on(x, &moments, &view, self.lists, dr, i)
                + self.model.contact_force_on(x, &view, self.lists, cr, i);
        }
        if self.kernels.is_some() {
            let mut wanted = vec![false; x.len()];
            for &i in active {
                wanted[i] = self.mobile[i];
            }
            let out = self.kernel_forces(x, &wanted);
            for (fi, &i) in f.iter_mut().zip(active) {
                *fi += out[i].0;
            }
        }
        for (fi, &i) in f.iter().zip(active) {
            v[i] = if self.mobile[i] {
                *fi / (6.0 * std::f64::consts::PI * self.viscosity * self.radii[i])
                    + self.liquid(x[i])
            } else {
                DVec3::ZERO
            };
        }
    }

    fn partners(&mut self, _x: &[DVec3], i: usize, f: &mut dyn FnMut(usize)) {
        for (j, _) in self.lists.dipole.entries(i) {
            f(j);
        }
        for (j, _) in self.lists.contact.entries(i) {
            f(j);
        }
    }
}

#[cfg(test)]
#[path = "dynamics_tests.rs"]
mod tests;
