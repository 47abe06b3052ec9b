//! The two-way coupled liquid through the particle-fluid pipeline: the momentum budget of the
//! coupled system, one-way coupling leaving runs unchanged, the settling sphere against the
//! Stokes velocity with and without the self-induced-velocity correction, and a recorded
//! liquid restarting bit for bit.

use glam::DVec3;
use magsep::prelude::*;
use magsep::scene::parse_scene;
use magsep::studies::liquid::settling::{settle, stokes_velocity};
use magsep_systems::fluid::channel::systems::ChannelLiquid;

fn simulation(text: &str) -> Simulation {
    let scene = parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}"));
    Simulation::from_scene(&scene, RunOptions::default()).unwrap()
}

/// A sphere launched sideways in a small channel without gravity or magnet.
fn launched(solver: &str, history: bool) -> String {
    launched_at(solver, history, 1.0)
}

fn launched_at(solver: &str, history: bool, speed: f64) -> String {
    format!(
        r#"[simulation]
pipeline = "particle_fluid"
seed = 3

[particle_fluid]
time_step = 1e-3
duration = 0.03
gravity = 0.0
terms = {{ collisions = false, history = {history} }}

[liquid]
density = 1000.0
viscosity = 1e-2
{solver}

[container]
kind = "channel"
side = [0.032, 0.024]
height = 0.03

[[particles]]
count = 1
shape = {{ kind = "sphere", radius = 2e-3 }}
density = 2500.0
velocity = [{vx}, {vy}, 0.0]
placement = {{ kind = "points", positions = [[0.0161, 0.0117, 0.0149]] }}
"#,
        vx = 0.02 * speed,
        vy = -0.01 * speed,
    )
}

/// Horizontal momentum [kg m/s] of the particles (true mass) and of the liquid.
fn momenta(sim: &mut Simulation) -> (DVec3, DVec3) {
    let w = &mut sim.app.world;
    let particles: DVec3 = w
        .query::<(&Velocity, &InertialBody)>()
        .iter(w)
        .map(|(v, b)| b.mass * v.0)
        .sum();
    let l = w.resource::<ChannelLiquid>();
    let g = *l.grid();
    let zw = g.z_quadrature_weights();
    let rho = w
        .resource::<magsep_systems::fluid::config::ParticleFluidConfig>()
        .liquid
        .density;
    let u = l.solver.velocity();
    let mut fluid = DVec3::ZERO;
    for (k, wk) in zw.iter().enumerate() {
        for i in 0..g.nx {
            for j in 0..g.ny {
                let n = g.index(i, j, k);
                fluid += DVec3::new(u[0][n], u[1][n], u[2][n]) * (rho * g.dx() * g.dy() * wk);
            }
        }
    }
    (particles, fluid)
}

#[test]
fn the_coupled_momentum_budget_closes() {
    // every newton the particle loses goes into the liquid: after 20 steps the horizontal
    // momentum of particle + liquid has changed by what crossed the walls, about 1e-6 of the
    // particle's momentum (the viscous flux of the Chebyshev mean mode through the walls; it
    // scales with the forcing, not its square, so it is not an error of the nonlinear terms).
    // The wall-normal component is taken up by the pressure (no net flow through the walls).
    // with `step_every = 3` the liquid takes the average of three steps' reactions at once
    let mut finals = Vec::new();
    for (history, every) in [(false, 1), (true, 1), (true, 3)] {
        let mut sim = simulation(&launched(
            &format!(
                r#"solver = {{ kind = "channel", grid = [16, 12, 25], coupling = "two_way", step_every = {every} }}"#
            ),
            history,
        ));
        let (p0, f0) = momenta(&mut sim);
        assert_eq!(f0, DVec3::ZERO);
        let mut worst: f64 = 0.0;
        let mut transferred: f64 = 0.0;
        for _ in 0..20 {
            sim.step();
            if sim.app.world.resource::<ChannelLiquid>().pending != 0 {
                continue; // part of the particle's loss is still waiting for the liquid step
            }
            let (p, f) = momenta(&mut sim);
            let total = p + f - p0;
            worst = worst.max(total.truncate().length() / p0.truncate().length());
            transferred = f.truncate().length() / p0.truncate().length();
        }
        let (p, _) = momenta(&mut sim);
        assert!(p.x < p0.x, "the particle must slow down");
        // the liquid took up a measurable share; the budget closes four orders of magnitude below it
        assert!(transferred > 0.01, "transferred {transferred:e}");
        assert!(
            worst < 1e-4 * transferred,
            "history {history}, step_every {every}: momentum error {worst:e}"
        );
        finals.push(p - p0);
    }
    // sub-cycling the liquid changes the particle's deceleration little (the liquid lags by at
    // most two particle steps): within 1 % of the velocity lost, but not bit-identical
    let lost = finals[1].length();
    let diff = (finals[2] - finals[1]).length();
    assert!(
        diff > 0.0 && diff < 0.01 * lost,
        "diff {diff:e}, lost {lost:e}"
    );
}

#[test]
fn one_way_coupling_and_no_solver_give_the_same_run() {
    let run = |solver: &str| {
        let mut sim = simulation(&launched(solver, true));
        let summary = sim.run(|_| {}).unwrap();
        let x: Vec<DVec3> = sim
            .app
            .world
            .query::<&Position>()
            .iter(&sim.app.world)
            .map(|p| p.0)
            .collect();
        (x, summary)
    };
    let (a, sa) = run("");
    let (b, sb) =
        run(r#"solver = { kind = "channel", grid = [16, 12, 25], coupling = "one_way" }"#);
    assert_eq!(a, b);
    assert!(sa["liquid_solver"].is_null());
    assert_eq!(sb["liquid_solver"]["solved"], false);
    // two-way coupling changes the run and reports the liquid
    let (c, sc) = run(r#"solver = { kind = "channel", grid = [16, 12, 25] }"#);
    assert_ne!(a, c);
    assert_eq!(sc["liquid_solver"]["solved"], true);
    assert!(sc["liquid_solver"]["max_divergence"].as_f64().unwrap() < 1e-8);
}

#[test]
fn a_settling_sphere_approaches_stokes_with_the_self_induced_correction() {
    // d/Δ = 1 and 2 in a box of 16 diameters: the uncorrected point particle is carried by its
    // own disturbance and settles 50-70 % too fast, increasingly so as the grid resolves the
    // filter; with the correction it settles within the hindrance of the walls (8 diameters
    // away) and of the periodic images (about 10 %) of Stokes, and in a box twice as large it
    // moves towards Stokes
    let v = stokes_velocity();
    assert!((v - 2.18e-5).abs() < 1e-7);
    let raw: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| settle(n, 16.0, false, 0.2).unwrap().ratio)
        .collect();
    let fixed: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| settle(n, 16.0, true, 0.2).unwrap().ratio)
        .collect();
    eprintln!("uncorrected {raw:?}, corrected {fixed:?}");
    assert!(raw[0] > 1.3 && raw[1] > raw[0], "uncorrected {raw:?}");
    for r in &fixed {
        assert!((0.85..1.0).contains(r), "corrected {fixed:?}");
    }
    let wide = settle(32, 32.0, true, 0.2).unwrap().ratio;
    eprintln!("corrected, box of 32 diameters: {wide}");
    assert!(wide > fixed[0] && wide < 1.02, "{wide}");
}

#[test]
#[ignore = "release tier: settling convergence up to d/Δ = 3 (about a minute)"]
fn settling_converges_as_the_grid_resolves_the_filter() {
    let rows: Vec<_> = [16, 32, 48]
        .iter()
        .map(|&n| {
            (
                settle(n, 16.0, false, 0.2).unwrap(),
                settle(n, 16.0, true, 0.2).unwrap(),
            )
        })
        .collect();
    for (raw, fixed) in &rows {
        eprintln!(
            "d/dx {:.2}: uncorrected {:.4}, corrected {:.4}",
            raw.diameter_over_spacing, raw.ratio, fixed.ratio
        );
    }
    // corrected: converged to within 2 % between d/Δ = 2 and 3, within the confinement
    // hindrance of Stokes; uncorrected: far off and still drifting (the chart goes to d/Δ = 4)
    let (a, b) = (rows[1].1.ratio, rows[2].1.ratio);
    assert!((a - b).abs() < 0.02, "{a} {b}");
    assert!((0.85..1.0).contains(&b), "{b}");
    assert!(rows[2].0.ratio > 1.5 && rows[2].0.ratio > rows[1].0.ratio);
}

#[test]
fn the_recorded_liquid_restarts_bit_for_bit_and_shows_in_foxglove() {
    use foxglove::Decode;
    use magsep::prelude::RunOptions;
    use magsep_plugins::liquid::{MIDPLANE_TOPIC, SLICE_TOPIC, STATE_TOPIC};
    use magsep_plugins::record::RecordingReader;
    use magsep_systems::fluid::channel::{ChannelParams, ChannelSolver};
    let text = launched(
        r#"solver = { kind = "channel", grid = [16, 12, 25], record_every = 5 }"#,
        true,
    );
    let dir = std::env::temp_dir().join(format!("magsep_liquid_rec_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("coupled.mcap");
    let scene = parse_scene(&text, &Default::default()).unwrap();
    let mut rec = Simulation::from_scene(
        &scene,
        RunOptions {
            record: Some(path.clone()),
            ..Default::default()
        },
    )
    .unwrap();
    rec.run(|_| {}).unwrap();
    // the same run, live, up to step 10
    let mut live = simulation(&text);
    for _ in 0..10 {
        live.step();
    }
    let l = live.app.world.resource::<ChannelLiquid>();
    let mut reader = RecordingReader::open(&path).unwrap();
    let states: Vec<_> = reader
        .messages(Some(STATE_TOPIC))
        .map(|m| m.unwrap())
        .collect();
    // steps 5, 10, ..., 30
    assert_eq!(states.len(), 6);
    assert_eq!(states[0].schema_name, "magsep.ChannelState");
    let params: ChannelParams = *l.solver.params();
    let restored = ChannelSolver::from_state_bytes(params, &states[1].data).unwrap();
    assert_eq!(restored.steps(), 10);
    for c in 0..3 {
        assert_eq!(
            restored.velocity()[c],
            l.solver.velocity()[c],
            "component {c}"
        );
    }
    // a truncated state is an error, not a panic
    let cut = &states[1].data[..states[1].data.len() / 2];
    assert!(ChannelSolver::from_state_bytes(params, cut).is_err());
    // the slices are foxglove.Grid messages of the grid's size
    for (topic, cells) in [(SLICE_TOPIC, 16 * 25), (MIDPLANE_TOPIC, 16 * 12)] {
        let m = reader.messages(Some(topic)).next().unwrap().unwrap();
        assert_eq!(m.schema_name, "foxglove.Grid");
        let g = foxglove::messages::Grid::decode(m.data.as_slice()).unwrap();
        let stride = g.cell_stride as usize;
        assert_eq!(g.data.len(), cells * stride);
        assert!(g.fields.iter().any(|f| f.name == "w"));
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The part of the momentum budget that does not close (relative to the momentum the liquid
/// took up) on a grid of `nz` Chebyshev levels.
fn budget_defect(nz: usize) -> f64 {
    let mut sim = simulation(&launched(
        &format!(r#"solver = {{ kind = "channel", grid = [16, 12, {nz}], coupling = "two_way" }}"#),
        false,
    ));
    let (p0, _) = momenta(&mut sim);
    let (mut worst, mut transferred) = (0.0f64, 0.0);
    for _ in 0..20 {
        sim.step();
        let (p, f) = momenta(&mut sim);
        worst = worst.max((p + f - p0).truncate().length() / p0.truncate().length());
        transferred = f.truncate().length() / p0.truncate().length();
    }
    worst / transferred
}

#[test]
fn the_momentum_defect_is_a_discretisation_error_that_falls_with_resolution() {
    // The residual of the budget is the collocation's viscous flux at the wall nodes of the
    // mean mode (their rows are boundary conditions, so the quadrature of ∂²u misses them);
    // the wall itself is 7 viscous lengths away, so the physical flux is nil. It falls with
    // the wall-normal resolution (3.7e-4 at nz = 17, 2.7e-6 at nz = 49), so it is the
    // method's truncation error, not a leak.
    let (coarse, fine) = (budget_defect(17), budget_defect(49));
    assert!(coarse < 1e-3, "{coarse:e}");
    assert!(fine < coarse / 50.0, "{coarse:e} -> {fine:e}");
}
