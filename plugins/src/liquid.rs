//! The simulated liquid of the particle-fluid pipeline (two-way coupling to the channel
//! solver of `magsep_systems::fluid::channel`). Registered by the pipeline always; it does
//! nothing unless the scene's spawner inserted a [`ChannelLiquid`] resource (a scene with
//! `[liquid] solver = { kind = "channel", ... }` and a coupling other than one-way).
//!
//! | set | system | touches |
//! |---|---|---|
//! | `Prepare` | `sample_liquid` | `FluidSample`, `LiquidCoupling` |
//! | `Mobility` (before / after `update_velocities`) | `remember_step_start_velocity`, `compute_feedback` | `LiquidCoupling` |
//! | `Integrate` (after `integrate_positions`) | `advance_liquid` | `ChannelLiquid`, `Health` |
//! | `Record` | [`record_liquid`] | `Recorder`: channels [`SLICE_TOPIC`], [`MIDPLANE_TOPIC`], [`STATE_TOPIC`] |
//!
//! Recording: every `record_every` steps (default: the recording's interval) a vertical x-z
//! slice through the middle of the channel (fields `u`, `v`, `w`, `speed` [m/s]) and a
//! horizontal x-y slice at mid-height (`w`, the particle-induced wall-normal velocity) as
//! `foxglove.Grid` messages, resampled to uniform rows for display; and the solver's complete
//! state, lossless (`magsep.ChannelState`, raw little-endian bytes, see
//! `ChannelSolver::state_bytes`), from which a coupled run can restart; with `step_every > 1`
//! the state is written only at the recorded steps that complete a liquid step.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::prelude::*;
use magsep_systems::fluid::channel::grid::ChannelGrid;
use magsep_systems::fluid::channel::systems::{
    ChannelLiquid, LiquidCoupling, advance_liquid, compute_feedback, remember_step_start_velocity,
    sample_liquid,
};
use magsep_systems::fluid::systems::{integrate_positions, update_velocities};
use magsep_systems::sets::SimSystems;

use crate::app::{SimApp, SimPlugin};
use crate::record::ChannelHandle;
use crate::record::grid::{GridSlice, add_grid_channel};
use crate::recorder::Recorder;

/// Topic of the vertical slice (`foxglove.Grid`).
pub const SLICE_TOPIC: &str = "/liquid/slice";
/// Topic of the mid-height slice (`foxglove.Grid`).
pub const MIDPLANE_TOPIC: &str = "/liquid/midplane";
/// Topic of the solver state (schema name [`STATE_SCHEMA`], raw bytes).
pub const STATE_TOPIC: &str = "/liquid/state";
/// Schema name of the solver-state messages.
pub const STATE_SCHEMA: &str = "magsep.ChannelState";
/// Message encoding of the solver-state messages.
pub const STATE_ENCODING: &str = "magsep.channel_state.v1";
/// Schema encoding of the solver-state channel: the schema data is a plain-text description.
pub const STATE_SCHEMA_ENCODING: &str = "text/plain";
/// The schema data of the solver-state channel.
pub const STATE_LAYOUT: &str = "magsep.ChannelState v1: the lossless state of the channel \
solver (magsep_systems::fluid::channel::ChannelSolver::state_bytes): a header (magic, version, \
grid, lengths, viscosity, time step, time, steps) and the spectral wall-normal velocity, \
wall-normal vorticity and mean profiles as little-endian f64; restore with \
ChannelSolver::from_state_bytes.";

/// The liquid's systems (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct LiquidPlugin;

impl SimPlugin for LiquidPlugin {
    fn build(&self, app: &mut SimApp) {
        if !app.world.contains_resource::<ChannelLiquid>() {
            return;
        }
        app.insert_on_particles(LiquidCoupling::default());
        app.schedule.add_systems((
            sample_liquid.in_set(SimSystems::Prepare),
            remember_step_start_velocity
                .before(update_velocities)
                .in_set(SimSystems::Mobility),
            compute_feedback
                .after(update_velocities)
                .in_set(SimSystems::Mobility),
            advance_liquid
                .after(integrate_positions)
                .in_set(SimSystems::Integrate),
            record_liquid
                .after(crate::recorder::record_frame)
                .in_set(SimSystems::Record),
        ));
    }
}

/// Handles of the liquid's channels, once added.
#[derive(Default)]
pub struct LiquidChannels(Option<[ChannelHandle; 3]>);

/// Linear resampling of the Chebyshev levels onto `rows` uniform levels: (lower level,
/// weight of the upper one) per row.
fn uniform_rows(grid: &ChannelGrid, rows: usize) -> Vec<(usize, f64)> {
    (0..rows)
        .map(|r| {
            let z = grid.height * r as f64 / (rows - 1) as f64;
            let k = grid.level_below(z).unwrap_or(0).min(grid.nz - 2);
            let (z0, z1) = (grid.z(k), grid.z(k + 1));
            (k, ((z - z0) / (z1 - z0)).clamp(0.0, 1.0))
        })
        .collect()
}

/// The vertical x-z slice at the middle row `j = ny/2`, rows resampled uniformly.
fn vertical_slice(grid: &ChannelGrid, u: [&[f64]; 3]) -> ([Vec<f64>; 4], usize) {
    let rows = grid.nz;
    let j = grid.ny / 2;
    let map = uniform_rows(grid, rows);
    let mut out = [
        Vec::with_capacity(rows * grid.nx),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    ];
    for &(k, t) in &map {
        for i in 0..grid.nx {
            let (a, b) = (grid.index(i, j, k), grid.index(i, j, k + 1));
            let v = DVec3::new(
                (1.0 - t) * u[0][a] + t * u[0][b],
                (1.0 - t) * u[1][a] + t * u[1][b],
                (1.0 - t) * u[2][a] + t * u[2][b],
            );
            out[0].push(v.x);
            out[1].push(v.y);
            out[2].push(v.z);
            out[3].push(v.length());
        }
    }
    (out, rows)
}

/// Write the liquid's slices and state every `record_every` steps (`Record`).
pub fn record_liquid(
    liquid: Res<ChannelLiquid>,
    clock: Res<StepClock>,
    mut recorder: ResMut<Recorder>,
    mut channels: Local<LiquidChannels>,
) {
    let every = liquid.spec.record_every.unwrap_or(recorder.every).max(1);
    if !clock.step.is_multiple_of(every) {
        return;
    }
    let Some(writer) = recorder.writer.as_mut() else {
        return;
    };
    let handles = match channels.0 {
        Some(h) => h,
        None => {
            let added = add_grid_channel(writer, SLICE_TOPIC).and_then(|a| {
                let b = add_grid_channel(writer, MIDPLANE_TOPIC)?;
                let c = writer.add_channel(
                    STATE_TOPIC,
                    STATE_SCHEMA,
                    STATE_SCHEMA_ENCODING,
                    STATE_LAYOUT.as_bytes(),
                    STATE_ENCODING,
                )?;
                Ok([a, b, c])
            });
            match added {
                Ok(h) => {
                    channels.0 = Some(h);
                    h
                }
                Err(e) => {
                    recorder.fail(format!("adding the liquid's channels: {e}"));
                    return;
                }
            }
        }
    };
    let grid = *liquid.grid();
    let u = liquid.solver.velocity();
    let t = clock.time();
    let log_time_ns = if t == 0.0 {
        clock.step
    } else {
        (t * 1e9).round() as u64
    };
    let (slices, rows) = vertical_slice(&grid, u);
    let [su, sv, sw, speed] = &slices;
    let vertical = GridSlice {
        log_time_ns,
        origin: DVec3::new(0.0, grid.y(grid.ny / 2), 0.0),
        rotation: DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2),
        cell_size: [grid.dx(), grid.height / (rows - 1) as f64],
        columns: grid.nx,
        rows,
        fields: &[("u", su), ("v", sv), ("w", sw), ("speed", speed)],
    };
    let kmid = uniform_rows(&grid, 3)[1];
    let mid: Vec<f64> = (0..grid.ny)
        .flat_map(|j| {
            (0..grid.nx).map(move |i| {
                let (k, t) = kmid;
                (1.0 - t) * u[2][grid.index(i, j, k)] + t * u[2][grid.index(i, j, k + 1)]
            })
        })
        .collect();
    let horizontal = GridSlice {
        log_time_ns,
        origin: DVec3::new(0.0, 0.0, 0.5 * grid.height),
        rotation: DQuat::IDENTITY,
        cell_size: [grid.dx(), grid.dy()],
        columns: grid.nx,
        rows: grid.ny,
        fields: &[("w", &mid)],
    };
    // the state only where no particle step is half-way into the next liquid step
    let state = (liquid.pending == 0).then(|| liquid.solver.state_bytes());
    let result = vertical.encode().and_then(|a| {
        let b = horizontal.encode()?;
        let mut messages = vec![
            (handles[0], log_time_ns, &a[..]),
            (handles[1], log_time_ns, &b[..]),
        ];
        if let Some(s) = &state {
            messages.push((handles[2], log_time_ns, &s[..]));
        }
        writer.write_messages(&messages)
    });
    if let Err(e) = result {
        recorder.fail(format!("writing the liquid at step {}: {e}", clock.step));
    }
}
