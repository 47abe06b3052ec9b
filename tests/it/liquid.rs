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
    for k in 0..g.nz {
        for i in 0..g.nx {
            for j in 0..g.ny {
                let n = g.index(i, j, k);
                fluid += DVec3::new(u[0][n], u[1][n], u[2][n]) * (rho * g.dx() * g.dy() * zw[k]);
            }
        }
    }
    (particles, fluid)
}

#[test]
fn the_coupled_momentum_budget_closes() {
    // the particle's horizontal momentum goes into the liquid and nowhere else while the
    // disturbance has not reached the walls (the wall shear is then negligible); the
    // wall-normal component is taken up by the pressure (no net flow through the walls)
    for history in [false, true] {
        let mut sim = simulation(&launched(
            r#"solver = { kind = "channel", grid = [16, 12, 25], coupling = "two_way" }"#,
            history,
        ));
        let (p0, f0) = momenta(&mut sim);
        assert_eq!(f0, DVec3::ZERO);
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            sim.step();
            let (p, f) = momenta(&mut sim);
            let total = p + f - p0;
            worst = worst.max(total.truncate().length() / p0.truncate().length());
            // the liquid has picked up the particle's momentum
            assert!(f.truncate().length() > 0.0);
        }
        let (p, _) = momenta(&mut sim);
        assert!(p.x < p0.x, "the particle must slow down");
        assert!(worst < 1e-10, "history {history}: momentum error {worst:e}");
    }
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
    let (b, sb) = run(r#"solver = { kind = "channel", grid = [16, 12, 25], coupling = "one_way" }"#);
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
    // d/Δ = 1 and 2: without the correction the sphere feels its own disturbance and settles
    // too slowly, increasingly so as the grid resolves the filter; with it the velocity is
    // within the hindrance of walls and periodic images (a few per cent) of Stokes
    let v = stokes_velocity();
    assert!((v - 2.18e-5).abs() < 1e-7);
    let raw: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| settle(n, false, 0.2).unwrap().ratio)
        .collect();
    let fixed: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| settle(n, true, 0.2).unwrap().ratio)
        .collect();
    eprintln!("uncorrected {raw:?}, corrected {fixed:?}");
    assert!(raw[1] < raw[0] && raw[1] < 0.8, "uncorrected {raw:?}");
    for r in &fixed {
        assert!((r - 1.0).abs() < 0.12, "corrected {fixed:?}");
    }
    assert!((fixed[1] - 1.0).abs() < (raw[1] - 1.0).abs());
}

#[test]
#[ignore = "release tier: settling convergence up to d/Δ = 4 (about a minute)"]
fn settling_converges_as_the_grid_resolves_the_filter() {
    let rows: Vec<_> = [8, 16, 32, 48, 64]
        .iter()
        .map(|&n| (settle(n, false, 0.3).unwrap(), settle(n, true, 0.3).unwrap()))
        .collect();
    for (raw, fixed) in &rows {
        eprintln!(
            "d/dx {:.2}: uncorrected {:.4}, corrected {:.4}",
            raw.diameter_over_spacing, raw.ratio, fixed.ratio
        );
    }
    // corrected: converged to within 2 % between the two finest grids and within the
    // hindrance estimate of Stokes
    let (a, b) = (rows[3].1.ratio, rows[4].1.ratio);
    assert!((a - b).abs() < 0.02, "{a} {b}");
    assert!((b - 1.0).abs() < 0.1, "{b}");
}

#[test]
#[ignore = "diagnostic"]
fn momentum_budget_diagnostic() {
    for speed in [1.0, 0.01] {
        let mut sim = simulation(&launched_at(
            r#"solver = { kind = "channel", grid = [16, 12, 25], coupling = "two_way" }"#,
            false,
            speed,
        ));
        let (p0, _) = momenta(&mut sim);
        let mut shear = glam::DVec2::ZERO;
        for step in 0..20 {
            let before = {
                let l = sim.app.world.resource::<ChannelLiquid>();
                l.solver.wall_shear()
            };
            sim.step();
            let l = sim.app.world.resource::<ChannelLiquid>();
            let after = l.solver.wall_shear();
            let g = *l.grid();
            let area = g.lx * g.ly * 1000.0;
            // force of the walls on the liquid: ρ ν (−∂U/∂z at the bottom + ∂U/∂z at the top)·A,
            // i.e. −(top shear) ... trapezoid in time
            for c in 0..2 {
                let f0 = after[1][c] - after[0][c];
                let f1 = before[1][c] - before[0][c];
                shear[c] -= 0.5 * (f0 + f1) * area * 1e-3;
            }
            let (p, f) = momenta(&mut sim);
            let total = (p + f - p0).truncate();
            eprintln!(
                "speed {speed} step {step}: budget {:.3e} {:.3e}  wall impulse {:.3e} {:.3e}  rel {:.3e}",
                total.x, total.y, shear.x, shear.y, total.length() / p0.truncate().length()
            );
        }
    }
}
