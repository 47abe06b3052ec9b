//! The compression driver ([T000 §2.2.1, §3.2]): volume steps with revert and halving.
//!
//! Each step saves the last overlap-free state, removes a volume dV from the container by an
//! affine scaling of all centres along the container's compressed axes (all three for the
//! periodic cube and the closed box; z only for the cylinder, the wedge and the slab, whose
//! walls keep their size: [T000 §2.2.4]), and removes the overlaps within the attempt
//! budget. On failure the saved state is restored and the step refined.
//!
//! * `Fixed` (the thesis): dV constant; after a failure dV /= 2; the run stops at the failure
//!   that follows `step_halvings` halvings, i.e. a failure at dV_min = dV_0 / 2^h.
//! * `Adaptive` (default): dV = f * V_free (V_free = V_box - V_particles), clamped to at least
//!   dV_min. While steps need no overlap removal at all, f doubles (up to 1/4); when a step
//!   spends more than a quarter of the budget and dV > dV_0, f halves; after a failure f halves
//!   and never grows again. It stops on a failure at dV_min: the same final criterion as `Fixed`, so
//!   both rules end in statistically the same state (see `magsep chart packing`), but the
//!   adaptive rule crosses the dilute regime in tens instead of tens of thousands of steps.

use magsep_components::packing::{PackingConfig, PackingStatus, StopReason, VolumeStepRule};
use rand::Rng;

use super::external::PackingKernels;
use super::moves::MoveRule;
use super::neighbour::NeighbourList;
use super::removal::{RemovalOutcome, remove_overlaps};
use super::state::PackingState;
use super::walls::compressed_axes;
use glam::DVec3;

/// Driver parameters in reduced units (lengths / D, volumes / D^3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverParams {
    /// Move rule.
    pub rule: MoveRule,
    /// Step rule.
    pub step_rule: VolumeStepRule,
    /// Initial (fixed) volume step / D^3.
    pub volume_step: f64,
    /// Halvings before the stop.
    pub step_halvings: u32,
    /// Initial free-volume fraction of the adaptive rule.
    pub adaptive_initial_fraction: f64,
    /// Attempt budget per compression step.
    pub max_attempts: u64,
    /// Overlap tolerance / D.
    pub tolerance: f64,
    /// Safety limit on compression steps.
    pub max_compression_steps: u64,
}

impl DriverParams {
    /// From a validated [`PackingConfig`] with reference diameter `d` \[m\].
    pub fn from_config(c: &PackingConfig, d: f64) -> Self {
        let rule = match c.scheme {
            magsep_components::packing::OverlapRemovalScheme::Revised => {
                MoveRule::Revised { dt: c.revised_dt }
            }
            magsep_components::packing::OverlapRemovalScheme::Fire => MoveRule::Fire,
            magsep_components::packing::OverlapRemovalScheme::Original => MoveRule::Original {
                beta: c.original_beta,
                xi: c.original_xi.map(|x| x / (d * d)),
            },
        };
        Self {
            rule,
            step_rule: c.volume_step_rule,
            volume_step: c.volume_step / d.powi(3),
            step_halvings: c.step_halvings,
            adaptive_initial_fraction: c.adaptive_initial_fraction,
            max_attempts: c.max_attempts,
            tolerance: c.overlap_tolerance,
            max_compression_steps: c.max_compression_steps,
        }
    }

    /// The finest volume step dV_0 / 2^h / D^3.
    pub fn min_volume_step(&self) -> f64 {
        self.volume_step / 2f64.powi(self.step_halvings as i32)
    }
}

/// A fresh status for a run starting from `state`.
pub fn initial_status(p: &DriverParams, state: &PackingState) -> PackingStatus {
    PackingStatus {
        compression_steps: 0,
        failed_steps: 0,
        halvings: 0,
        volume_step: p.volume_step,
        adaptive_fraction: p.adaptive_initial_fraction,
        may_grow: true,
        attempts: 0,
        last_attempts: 0,
        packing_fraction: state.packing_fraction(),
        stopped: None,
        contact_evaluations: 0,
        contact_fallbacks: 0,
    }
}

/// The volume to remove in the next step / D^3.
pub fn next_volume_step(p: &DriverParams, st: &PackingStatus, state: &PackingState) -> f64 {
    let v_box = state.container_volume();
    let v_free = v_box - state.particle_volume();
    let dv = match p.step_rule {
        VolumeStepRule::Fixed => st.volume_step,
        VolumeStepRule::Adaptive => (st.adaptive_fraction * v_free).max(p.min_volume_step()),
    };
    // never compress past the particle volume
    dv.min(0.5 * v_free)
}

/// Compress `state` by `dv` (/ D^3) along the container's compressed axes and tell the list.
/// Returns the scale factors per axis.
pub fn compress(state: &mut PackingState, list: &mut NeighbourList, dv: f64) -> DVec3 {
    let v = state.container_volume();
    let axes = compressed_axes(state.walls);
    let k = axes.iter().filter(|a| **a).count().max(1) as f64;
    let f = ((v - dv) / v).powf(1.0 / k);
    let s = DVec3::from_array(std::array::from_fn(|a| if axes[a] { f } else { 1.0 }));
    state.scale(s);
    list.note_compression(s);
    s
}

/// Update the status after a removal attempt at volume step `dv`; `restore` is called on
/// failure to revert the state. Sets `st.stopped` when the run ends.
pub fn settle_step(
    p: &DriverParams,
    st: &mut PackingStatus,
    dv: f64,
    out: RemovalOutcome,
    restore: impl FnOnce(),
) {
    st.attempts += out.attempts;
    st.last_attempts = out.attempts;
    st.contact_evaluations += out.contacts;
    st.contact_fallbacks += out.fallbacks;
    let at_finest = dv <= p.min_volume_step() * (1.0 + 1e-9);
    if out.success {
        st.compression_steps += 1;
        if p.step_rule == VolumeStepRule::Adaptive {
            if out.attempts == 0 && st.may_grow {
                st.adaptive_fraction = (st.adaptive_fraction * 2.0).min(0.25);
            } else if out.attempts > p.max_attempts / 4 && dv > p.volume_step {
                // expensive steps shrink the step down to the fixed rule's dV_0 only: below
                // it only failures refine it (as in the thesis); the cost of a removal grows
                // only slowly with dV, so smaller steps cost more per unit of compression
                st.adaptive_fraction *= 0.5;
            }
        }
    } else {
        restore();
        st.failed_steps += 1;
        match p.step_rule {
            VolumeStepRule::Fixed => {
                if st.halvings >= p.step_halvings {
                    st.stopped = Some(StopReason::Jammed);
                } else {
                    st.halvings += 1;
                    st.volume_step *= 0.5;
                }
            }
            VolumeStepRule::Adaptive => {
                st.may_grow = false;
                if at_finest {
                    st.stopped = Some(StopReason::Jammed);
                } else {
                    st.halvings += 1;
                    st.adaptive_fraction *= 0.5;
                }
            }
        }
        if st.stopped.is_some() && st.compression_steps == 0 {
            st.stopped = Some(StopReason::BudgetTooSmall);
        }
    }
    if st.stopped.is_none() && st.compression_steps + st.failed_steps >= p.max_compression_steps {
        st.stopped = Some(StopReason::StepLimit);
    }
}

/// Remove overlaps with the configured rule and budget.
pub fn run_removal(
    p: &DriverParams,
    state: &mut PackingState,
    list: &mut NeighbourList,
    rng: &mut impl Rng,
) -> RemovalOutcome {
    run_removal_with(p, state, list, rng, None)
}

/// [`run_removal`] with external force kernels, which only the FIRE rule consumes (the
/// single-particle rules have no forces; the packing plugin refuses kernels with them).
pub fn run_removal_with(
    p: &DriverParams,
    state: &mut PackingState,
    list: &mut NeighbourList,
    rng: &mut impl Rng,
    kernels: Option<&PackingKernels>,
) -> RemovalOutcome {
    match p.rule {
        MoveRule::Fire => {
            let iterations = p.max_attempts / (state.len().max(1) as u64);
            super::fire::remove_overlaps_fire_with(
                state,
                list,
                super::fire::FireParams::for_state(state),
                p.tolerance,
                iterations.max(1),
                kernels,
            )
        }
        rule => remove_overlaps(state, list, rule, p.tolerance, p.max_attempts, rng),
    }
}

/// One full compression step (save, compress, remove, settle) on dense data.
pub fn compression_step(
    p: &DriverParams,
    st: &mut PackingStatus,
    state: &mut PackingState,
    list: &mut NeighbourList,
    rng: &mut impl Rng,
) {
    compression_step_to(p, st, state, list, rng, None);
}

/// [`compression_step`] that compresses no further than the packing fraction `target` (the
/// volume step is cut to reach it exactly); `None`: no limit.
pub fn compression_step_to(
    p: &DriverParams,
    st: &mut PackingStatus,
    state: &mut PackingState,
    list: &mut NeighbourList,
    rng: &mut impl Rng,
    target: Option<f64>,
) {
    if st.stopped.is_some() {
        return;
    }
    let saved = state.clone();
    let mut dv = next_volume_step(p, st, state);
    if let Some(phi) = target {
        dv = dv.min(state.container_volume() - state.particle_volume() / phi);
    }
    compress(state, list, dv);
    let out = run_removal(p, state, list, rng);
    settle_step(p, st, dv, out, || {
        *state = saved;
        list.invalidate();
    });
    st.packing_fraction = state.packing_fraction();
}

/// Run to the end; `progress` is called after every step.
pub fn run_to_end(
    p: &DriverParams,
    state: &mut PackingState,
    list: &mut NeighbourList,
    rng: &mut impl Rng,
    mut progress: impl FnMut(&PackingStatus),
) -> PackingStatus {
    let mut st = initial_status(p, state);
    while st.stopped.is_none() {
        compression_step(p, &mut st, state, list, rng);
        progress(&st);
    }
    st
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> DriverParams {
        DriverParams {
            rule: MoveRule::Revised { dt: 0.1 },
            step_rule: VolumeStepRule::Adaptive,
            volume_step: 0.1,
            step_halvings: 4,
            adaptive_initial_fraction: 0.01,
            max_attempts: 1000,
            tolerance: 1e-4,
            max_compression_steps: 100,
        }
    }

    fn success(attempts: u64) -> RemovalOutcome {
        RemovalOutcome {
            success: true,
            attempts,
            sweeps: 1,
            contacts: 0,
            fallbacks: 0,
        }
    }

    fn status(p: &DriverParams) -> PackingStatus {
        PackingStatus {
            compression_steps: 0,
            failed_steps: 0,
            halvings: 0,
            volume_step: p.volume_step,
            adaptive_fraction: 0.01,
            may_grow: false,
            attempts: 0,
            last_attempts: 0,
            packing_fraction: 0.5,
            stopped: None,
            contact_evaluations: 0,
            contact_fallbacks: 0,
        }
    }

    #[test]
    fn expensive_steps_shrink_the_adaptive_step_only_above_dv0() {
        let p = params();
        let mut st = status(&p);
        settle_step(&p, &mut st, 0.2, success(300), || {});
        assert_eq!(st.adaptive_fraction, 0.005, "dV > dV_0: halved");
        settle_step(&p, &mut st, 0.1, success(300), || {});
        assert_eq!(st.adaptive_fraction, 0.005, "dV = dV_0: kept");
        settle_step(&p, &mut st, 0.2, success(200), || {});
        assert_eq!(st.adaptive_fraction, 0.005, "cheap step: kept");
        assert_eq!(st.compression_steps, 3);
    }
}
