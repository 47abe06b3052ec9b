//! Hydrodynamic interactions through the pipeline: two spheres settling under equal forces
//! move with the Rotne-Prager-Yamakawa closed forms, for every HI method, and free draining
//! gives Stokes' law. The force is a user contribution in `ForceSystems::Custom`.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep::plugins::brownian::brownian_pipeline;
use magsep::prelude::*;
use magsep::scene::parse_scene;

use crate::common;
use common::sorted_positions;

#[derive(Component, Debug, Default, Clone, Copy)]
struct PushForce(DVec3);

impl ForceContribution for PushForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

const F0: f64 = 1e-14;

fn push(mut q: Query<&mut PushForce>) {
    for mut f in &mut q {
        f.0 = DVec3::new(0.0, 0.0, -F0);
    }
}

#[derive(Clone, Copy)]
struct PushPlugin;

impl SimPlugin for PushPlugin {
    fn build(&self, app: &mut SimApp) {
        app.insert_on_particles(PushForce::default());
        app.register_force::<PushForce>();
        app.schedule.add_systems(push.in_set(ForceSystems::Custom));
    }
}

/// Velocities of two spheres of radius `a` at `x1 - x0 = d` after one step (T ≈ 0: no noise).
fn velocities(mobility: &str, a: f64, d: DVec3) -> [DVec3; 2] {
    let dt = 1e-5;
    let text = format!(
        r#"
[simulation]
pipeline = "brownian"
[brownian]
time_step = {dt}
duration = {dt}
temperature = 1e-15
mobility = "{mobility}"
step_control = {{ kind = "fixed" }}
contact = {{ kind = "none" }}
dipole_cutoff = 0
[[particles]]
count = 2
shape = {{ kind = "sphere", radius = {a} }}
placement = {{ kind = "points", positions = [[0.0, 0.0, 0.0], [{}, {}, {}]] }}
"#,
        d.x, d.y, d.z
    );
    let scene = parse_scene(&text, &Default::default()).unwrap();
    let mut sim = Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(brownian_pipeline().add(PushPlugin)),
            ..Default::default()
        },
    )
    .unwrap();
    let x0 = sorted_positions(&mut sim);
    sim.run(|_| {}).unwrap();
    let x1 = sorted_positions(&mut sim);
    [(x1[0] - x0[0]) / dt, (x1[1] - x0[1]) / dt]
}

#[test]
fn two_spheres_settle_with_the_rpy_closed_forms() {
    let (a, eta) = (100e-9, 1e-3);
    let stokes = F0 / (6.0 * std::f64::consts::PI * eta * a);
    for r_over_a in [2.5, 4.0, 10.0] {
        let r = r_over_a * a;
        let x = a / r;
        let parallel = stokes * (1.0 + 1.5 * x - x.powi(3));
        let perpendicular = stokes * (1.0 + 0.75 * x + 0.5 * x.powi(3));
        for method in ["cholesky", "tea", "krylov"] {
            // line of centres along the force
            let v = velocities(method, a, DVec3::new(0.0, 0.0, r));
            for vi in v {
                assert!(
                    (vi.z + parallel).abs() < 1e-6 * parallel,
                    "{method} {r_over_a}: {vi}"
                );
                assert!(vi.x.abs() + vi.y.abs() < 1e-6 * parallel);
            }
            // line of centres across the force
            let v = velocities(method, a, DVec3::new(r, 0.0, 0.0));
            for vi in v {
                assert!(
                    (vi.z + perpendicular).abs() < 1e-6 * perpendicular,
                    "{method}: {vi}"
                );
            }
        }
        // no hydrodynamic interactions: Stokes' law for each
        let v = velocities("free_draining", a, DVec3::new(0.0, 0.0, r));
        assert!((v[0].z + stokes).abs() < 1e-6 * stokes);
    }
}

/// Uniform force kernel along -z \[N\].
struct Weight;

impl magsep::systems::forces::ExternalForce for Weight {
    fn force_torque(&self, _p: &magsep::systems::forces::ParticleState) -> (DVec3, DVec3) {
        (DVec3::new(0.0, 0.0, -F0), DVec3::ZERO)
    }
}

#[derive(Clone, Copy)]
struct WeightPlugin;

impl SimPlugin for WeightPlugin {
    fn build(&self, app: &mut SimApp) {
        app.add_external_force("weight", std::sync::Arc::new(Weight));
    }
}

#[test]
fn the_run_summary_names_every_force_a_plugin_added() {
    let text = r#"
[simulation]
pipeline = "brownian"
[brownian]
time_step = 1e-5
duration = 3e-5
temperature = 300
step_control = { kind = "fixed" }
[[particles]]
count = 2
shape = { kind = "sphere", radius = 1e-7 }
placement = { kind = "points", positions = [[0.0, 0.0, 0.0], [1e-6, 0.0, 0.0]] }
"#;
    let scene = parse_scene(text, &Default::default()).unwrap();
    let summary = |pipeline| {
        let options = RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        };
        let mut sim = Simulation::from_scene(&scene, options).unwrap();
        sim.run(|_| {}).unwrap()
    };
    let plain = summary(brownian_pipeline());
    assert_eq!(
        plain["force_contributions"],
        serde_json::json!(["FieldForce", "DipoleForce", "ContactForce"])
    );
    assert_eq!(plain["force_kernels"], serde_json::json!([]), "{plain}");
    let pushed = summary(brownian_pipeline().add(PushPlugin).add(WeightPlugin));
    assert_eq!(
        pushed["force_contributions"],
        serde_json::json!([
            "FieldForce",
            "DipoleForce",
            "ContactForce",
            "PushForce",
            "KernelForce"
        ])
    );
    assert_eq!(pushed["force_kernels"], serde_json::json!(["weight"]));
}
