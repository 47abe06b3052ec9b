//! The mean flow of the liquid in the brownian pipeline (`[brownian.flow]`): the overdamped
//! update `dx = (u + μF) dt + noise` in every step control, checked against its physics: free
//! particles drift by `u t` and still spread by `2 D t` per axis, pure advection is exact in
//! every step control (also with hydrodynamic interactions, where u is not passed through the
//! mobility), and a magnetised fibre captures less of what a faster flow sweeps past it
//! (thesis 000, ch. 7: near-complete capture at slow flow, capture falling with flow rate).

use glam::DVec3;
use magsep::brownian::run_ensemble;
use magsep::prelude::*;
use magsep::scene::{Scene, parse_scene};
use magsep_components::brownian::{BrownianStats, Captured};
use magsep_systems::field::source::CylinderSource;
use serde_json::Value;

use crate::common::sorted_positions as positions;

const KT: f64 = 1.380649e-23 * 298.0;
const ETA: f64 = 1e-3;

fn scene(text: &str) -> Scene {
    parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn flow_line(u: DVec3) -> String {
    format!(
        "flow = {{ kind = \"uniform\", velocity = [{:e}, {:e}, {:e}] }}",
        u.x, u.y, u.z
    )
}

/// Non-interacting particles of radius `radius` in a 1 mm box, with `extra` lines in
/// `[brownian]`.
fn free_scene(n: u64, radius: f64, dt: f64, steps: u64, extra: &str) -> String {
    format!(
        r#"
[simulation]
pipeline = "brownian"
seed = 23
[brownian]
time_step = {dt:e}
duration = {duration:e}
contact = {{ kind = "none" }}
dipole_cutoff = 0
{extra}
[[particles]]
count = {n}
shape = {{ kind = "sphere", radius = {radius:e} }}
placement = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [1e-3, 1e-3, 1e-3] }}
"#,
        duration = dt * steps as f64
    )
}

/// Start and end positions of a run of `text` (sorted by particle id), and its stats.
fn start_and_end(text: &str) -> (Vec<DVec3>, Vec<DVec3>, BrownianStats) {
    let s = scene(text);
    let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
    let x0 = positions(&mut sim);
    sim.run(|_| {}).unwrap();
    let x1 = positions(&mut sim);
    let stats = sim.app.world.resource::<BrownianStats>().clone();
    (x0, x1, stats)
}

/// With noise and no forces, the mean displacement after t is u t within 4 standard errors
/// on each axis, and the variance about it is still 2 D t per axis (relative standard error
/// sqrt(2/N) = 1 % for N = 2e4; 5 % allowed), for the fixed, adaptive and multirate steps.
/// The flow (3 µm over the run) is 14 times the spread sqrt(2Dt) = 0.21 µm, so a missing or
/// doubled flow fails by hundreds of standard errors.
#[test]
fn flow_shifts_the_mean_and_keeps_the_variance() {
    let (n, a, dt, steps) = (20_000u64, 100e-9, 1e-3, 10u64);
    let t = dt * steps as f64;
    let u = DVec3::new(3e-4, -2e-4, 1e-4);
    let d = KT / (6.0 * std::f64::consts::PI * ETA * a);
    for control in [
        r#"{ kind = "fixed" }"#,
        r#"{ kind = "adaptive", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }"#,
        r#"{ kind = "multirate", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }"#,
    ] {
        let extra = format!(
            "mobility = \"free_draining\"\nstep_control = {control}\n{}",
            flow_line(u)
        );
        let (x0, x1, _) = start_and_end(&free_scene(n, a, dt, steps, &extra));
        let dx: Vec<DVec3> = x0.iter().zip(&x1).map(|(a, b)| *b - *a).collect();
        let nf = dx.len() as f64;
        let mean = dx.iter().copied().sum::<DVec3>() / nf;
        let var = dx.iter().map(|v| (*v - mean) * (*v - mean)).sum::<DVec3>() / (nf - 1.0);
        let se = (2.0 * d * t / nf).sqrt();
        eprintln!(
            "{control}: mean displacement {mean:?} vs u t {:?} (SE {se:.2e} m); variance / 2Dt {:?}",
            u * t,
            var / (2.0 * d * t)
        );
        for k in 0..3 {
            assert!(
                (mean[k] - u[k] * t).abs() < 4.0 * se,
                "{control}: axis {k}: mean {} vs u t {}",
                mean[k],
                u[k] * t
            );
            let r = var[k] / (2.0 * d * t);
            assert!(
                (r - 1.0).abs() < 0.05,
                "{control}: axis {k}: var / 2Dt = {r}"
            );
        }
    }
}

/// Pure advection (T = 1e-20 K: the noise is 3e-18 m over the run) is exact to rounding in
/// every step control: each particle ends at x0 + u t within 1e-15 m (3e-10 of its 3.7 µm
/// path). The flow is fast enough for the 20 nm particles to need bisection (u dt / 2 is 9
/// radii) and slow enough for the 500 nm ones not to, so the adaptive step bisects every
/// particle and the multirate step only the small ones (fewer particle sub-steps). With the
/// dense RPY mobility (cholesky) u is added after the mobility, so it is exact there too.
#[test]
fn advection_is_exact_in_every_step_control() {
    let u = DVec3::new(3e-4, -2e-4, 1e-4);
    let (dt, steps) = (1e-3, 10u64);
    let t = dt * steps as f64;
    let mut points = Vec::new();
    for k in 0..3 {
        points.push(format!("[{:e}, 0.0, 0.0]", 1e-4 * k as f64));
    }
    let small = points.join(", ");
    let big = points
        .iter()
        .map(|p| p.replace(", 0.0, 0.0]", ", 2e-4, 0.0]"))
        .collect::<Vec<_>>()
        .join(", ");
    let text = |mobility: &str, control: &str| {
        format!(
            r#"
[simulation]
pipeline = "brownian"
seed = 3
[brownian]
time_step = {dt:e}
duration = {t:e}
temperature = 1e-20
mobility = "{mobility}"
contact = {{ kind = "none" }}
dipole_cutoff = 0
step_control = {control}
{flow}
[[particles]]
count = 3
shape = {{ kind = "sphere", radius = 20e-9 }}
placement = {{ kind = "points", positions = [{small}] }}
[[particles]]
count = 3
shape = {{ kind = "sphere", radius = 500e-9 }}
placement = {{ kind = "points", positions = [{big}] }}
"#,
            flow = flow_line(u)
        )
    };
    let adaptive =
        r#"{ kind = "adaptive", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }"#;
    let multirate =
        r#"{ kind = "multirate", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }"#;
    let mut substeps = Vec::new();
    for (mobility, control) in [
        ("free_draining", r#"{ kind = "fixed" }"#),
        ("free_draining", adaptive),
        ("free_draining", multirate),
        ("cholesky", r#"{ kind = "fixed" }"#),
        ("cholesky", adaptive),
    ] {
        let (x0, x1, stats) = start_and_end(&text(mobility, control));
        let worst = x0
            .iter()
            .zip(&x1)
            .map(|(a, b)| (*b - (*a + u * t)).length())
            .fold(0.0f64, f64::max);
        eprintln!(
            "{mobility}, {control}: worst |x - (x0 + u t)| = {worst:e} m, {} particle sub-steps",
            stats.particle_substeps
        );
        assert!(worst < 1e-15, "{mobility}, {control}: {worst:e} m");
        substeps.push(stats.particle_substeps);
    }
    // fixed: 6 particles x 10 steps; adaptive: every particle bisected; multirate: fewer
    assert_eq!(substeps[0], 60);
    assert!(substeps[1] > 4 * substeps[0], "adaptive: {substeps:?}");
    assert!(substeps[2] < substeps[1], "multirate: {substeps:?}");
}

const FIBRE_RADIUS: f64 = 300e-6;
const HALF_LENGTH: f64 = 6e-3;

/// 16 particles (R = 125 nm, table 6.1 moment) in the slab 1-101 µm above the attracting end
/// face of a fibre magnetised along its axis (1 T), carried across the face by a flow along x,
/// 4 replicates of one seed set.
fn sweep_scene(speed: f64) -> String {
    format!(
        r#"
[simulation]
pipeline = "brownian"
seed = 11
[brownian]
time_step = 1e-3
duration = 0.5
runs = 4
mobility = "free_draining"
step_control = {{ kind = "adaptive", tolerance = 1e-2, max_displacement = 5.0, max_depth = 24 }}
observe_every = 10
{flow}
[external_field]
flux_density = [0.0, 0.0, 1.0]
[[fibres]]
kind = "cylinder"
radius = {FIBRE_RADIUS:e}
half_length = {HALF_LENGTH:e}
center = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
saturation_magnetisation = 985e3
[[particles]]
count = 16
shape = {{ kind = "sphere", radius = 125e-9 }}
moment = {{ kind = "saturated", moment = 5.151e-16 }}
placement = {{ kind = "fibre_top", fibre = 0, gap = 1e-6, height = 100e-6 }}
"#,
        flow = flow_line(DVec3::new(speed, 0.0, 0.0))
    )
}

fn captured_fraction(s: &Value) -> f64 {
    s["groups"][0]["captured_fraction"]["mean"]
        .as_f64()
        .expect("fraction")
}

/// Capture falls with the flow speed (thesis 000, ch. 7). The particles drift to the face at
/// ~400 µm/s, so they need about 0.1 s to fall 50 µm, while a flow u keeps them over the
/// 600 µm wide face for at most 0.6 mm / u: 0.6 s at 1 mm/s (all captured, as without flow),
/// 0.15 s at 4 mm/s, 0.04 s at 16 mm/s. Each step down must exceed twice the binomial standard
/// error of the difference (64 particles each). Captured particles do not move: they end
/// within one radius of the fibre's surface while the flow carries the others away.
#[test]
fn capture_falls_with_the_flow_speed() {
    let speeds = [0.0, 1e-3, 4e-3, 1.6e-2];
    let fractions: Vec<f64> = speeds
        .iter()
        .map(|&u| {
            let s = scene(&sweep_scene(u));
            run_ensemble(&s, 4, &RunOptions::default(), &|_| {}).expect("run")
        })
        .map(|s| captured_fraction(&s))
        .collect();
    eprintln!("flow speeds {speeds:?} m/s: captured fractions {fractions:?}");
    assert!(fractions[0] >= 0.95, "no flow: {fractions:?}");
    assert!(fractions[1] >= 0.95, "slow flow: {fractions:?}");
    for k in 1..speeds.len() - 1 {
        let (p, q) = (fractions[k], fractions[k + 1]);
        let se = ((p * (1.0 - p) + q * (1.0 - q)) / 64.0)
            .sqrt()
            .max(1.0 / 64.0);
        assert!(
            p - q > 2.0 * se,
            "capture must fall from {} to {} m/s: {fractions:?}",
            speeds[k],
            speeds[k + 1]
        );
    }

    // one run at the fastest flow: where the captured and the free particles end
    let s = scene(&sweep_scene(1.6e-2));
    let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
    sim.run(|_| {}).unwrap();
    let rows: Vec<(DVec3, bool)> = sim
        .app
        .world
        .query::<(&Position, &Captured)>()
        .iter(&sim.app.world)
        .map(|(p, c)| (p.0, c.0.is_some()))
        .collect();
    let fibre = CylinderSource::new(
        DVec3::ZERO,
        DVec3::Z,
        FIBRE_RADIUS,
        HALF_LENGTH,
        DVec3::new(0.0, 0.0, 985e3),
    );
    let (captured, free): (Vec<_>, Vec<_>) = rows.iter().partition(|r| r.1);
    assert!(!captured.is_empty() && !free.is_empty(), "{rows:?}");
    for (p, _) in &captured {
        let d = fibre.distance(*p);
        assert!(
            d <= 2.0 * 125e-9,
            "captured particle at {p:?}, {d:e} m off the fibre"
        );
    }
    for (p, _) in &free {
        // 0.5 s at 16 mm/s: 8 mm downstream, far past the 0.3 mm face
        assert!(p.x > 5e-3, "free particle not carried away: {p:?}");
    }
}

/// `kind = "darcy"` advects as the uniform flow of its interstitial velocity
/// `−k ∇P / (η (1 − φ))` (Kozeny-Carman k, the scene's viscosity): the same seed gives the
/// same positions to rounding, and the summary states the velocity.
#[test]
fn darcy_flow_is_the_uniform_flow_of_its_velocity() {
    use magsep::brownian::flow::kozeny_carman_permeability;
    let (eta, phi, grad) = (2e-3, 0.3, 2e3);
    let k = kozeny_carman_permeability(phi, 400e-6, Some(4e-3), 5.0);
    let u = DVec3::new(0.0, 0.0, -k * grad / (eta * (1.0 - phi)));
    let darcy = format!(
        "viscosity = {eta:e}\n[brownian.flow]\nkind = \"darcy\"\npressure_gradient = [0.0, 0.0, {grad:e}]\npacking_fraction = {phi}\nfibre_diameter = 400e-6\nfibre_length = 4e-3"
    );
    let uniform = format!("viscosity = {eta:e}\n{}", flow_line(u));
    let (x0, xd, _) = start_and_end(&free_scene(50, 100e-9, 1e-3, 10, &darcy));
    let (_, xu, _) = start_and_end(&free_scene(50, 100e-9, 1e-3, 10, &uniform));
    // equal to rounding (u is formed in another order here: a few ulps of the velocity)
    let worst = xd
        .iter()
        .zip(&xu)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0f64, f64::max);
    assert!(worst < 1e-17, "darcy and uniform differ by {worst:e} m");
    // the flow is visible: 0.01 s at |u| moves every particle by much more than its spread
    let mean_dz = x0.iter().zip(&xd).map(|(a, b)| b.z - a.z).sum::<f64>() / 50.0;
    assert!(
        (mean_dz / (u.z * 0.01) - 1.0).abs() < 0.1,
        "{mean_dz} vs {}",
        u.z * 0.01
    );
    let s = run_ensemble(
        &scene(&free_scene(5, 100e-9, 1e-3, 2, &darcy)),
        1,
        &RunOptions::default(),
        &|_| {},
    )
    .expect("run");
    let v = s["flow_velocity_m_s"][2]
        .as_f64()
        .expect("flow in the summary");
    assert!((v / u.z - 1.0).abs() < 1e-12, "{v} vs {}", u.z);
}

/// The Brownian criterion (thesis eq. 6.24: squared displacement below twice 6Dt) is about
/// motion relative to the liquid: with a flow that carries every particle 10 µm (far beyond
/// sqrt(12 D t) = 0.5 µm) the fraction of Brownian particles is the same as without flow
/// (fixed steps: the same noise), about P(χ²₃ < 6) = 0.89.
#[test]
fn brownian_criterion_is_relative_to_the_liquid() {
    let fraction = |extra: &str| {
        let text = free_scene(400, 100e-9, 1e-3, 20, extra);
        let s = run_ensemble(&scene(&text), 1, &RunOptions::default(), &|_| {}).expect("run");
        s["brownian_fraction"]["mean"].as_f64().expect("fraction")
    };
    let fixed = "step_control = { kind = \"fixed\" }\nmobility = \"free_draining\"";
    let still = fraction(fixed);
    let carried = fraction(&format!(
        "{fixed}\n{}",
        flow_line(DVec3::new(5e-4, 0.0, 0.0))
    ));
    eprintln!("Brownian fraction: no flow {still}, with flow {carried}");
    assert_eq!(still, carried);
    assert!((still - 0.89).abs() < 0.06, "{still}");
}
