//! Validation of brownian scenes: every error with its key path.

use super::*;
use crate::scene::parse_scene;

const GOOD: &str = r#"
[simulation]
pipeline = "brownian"
[external_field]
flux_density = [1.0, 0.0, 0.0]
[[fibres]]
kind = "cylinder"
radius = 300e-6
half_length = 6e-3
axis = [0.0, 0.0, 1.0]
saturation_magnetisation = 985e3
[brownian]
time_step = 5e-5
duration = 1.0
runs = 3
[[particles]]
count = 10
shape = { kind = "sphere", radius = 75e-9 }
moment = { kind = "saturated", moment = 0.87e-16 }
placement = { kind = "fibre_top", fibre = 0, gap = 1e-6, height = 300e-6 }
[[particles]]
count = 10
shape = { kind = "sphere", radius = 75e-9 }
moment = { kind = "langevin", moment = 0.87e-16, domain_moment = 2.3e-19 }
placement = { kind = "fibre_side", fibre = 0, gap = 1e-6, thickness = 300e-6 }
"#;

fn errors(text: &str) -> Vec<SceneError> {
    parse_scene(text, &Default::default()).unwrap_err().0
}

fn paths(text: &str) -> Vec<String> {
    errors(text).into_iter().map(|e| e.path).collect()
}

#[test]
fn good_scene_parses_with_defaults_and_region_volumes() {
    let s = parse_scene(GOOD, &Default::default()).unwrap();
    let b = s.section::<BrownianSection>().unwrap();
    let c = b.config();
    assert_eq!(c.steps, 20_000);
    assert_eq!(c.dipole_cutoff, Some(30.0));
    assert_eq!(c.observe_every, 100);
    assert_eq!(b.runs(), 3);
    let top = region_volume(&s, 0);
    let pi = std::f64::consts::PI;
    assert!((top - pi * 300e-6f64.powi(2) * 300e-6).abs() < 1e-20);
    let side = region_volume(&s, 1);
    let (r0, r1) = (301e-6f64, 601e-6f64);
    assert!((side - pi * (r1 * r1 - r0 * r0) * 12e-3).abs() < 1e-18);
}

#[test]
fn every_problem_is_reported_with_its_key_path() {
    let bad = GOOD
        .replace("time_step = 5e-5", "time_step = -1.0")
        .replace("runs = 3", "runs = 0")
        .replace(
            "fibre = 0, gap = 1e-6, height",
            "fibre = 4, gap = 1e-9, height",
        )
        .replace("moment = 0.87e-16 }", "moment = -1.0 }")
        .replace("domain_moment = 2.3e-19", "domain_moment = 0.0");
    let p = paths(&bad);
    for want in [
        "brownian.time_step",
        "brownian.runs",
        "particles[0].placement.fibre",
        "particles[0].placement.gap",
        "particles[0].moment.moment",
        "particles[1].moment.domain_moment",
    ] {
        assert!(p.iter().any(|x| x == want), "{want} missing in {p:?}");
    }
}

#[test]
fn pipeline_specific_keys_are_checked() {
    // container is not allowed (unbounded fluid); [brownian] is required
    let p = paths(&GOOD.replace(
        "[brownian]",
        "[container]\nkind = \"periodic_box\"\n[brownian]",
    ));
    assert!(p.contains(&"container".to_string()), "{p:?}");
    let p = paths(&GOOD.replace(
        "[brownian]\ntime_step = 5e-5\nduration = 1.0\nruns = 3\n",
        "",
    ));
    assert!(p.contains(&"brownian".to_string()), "{p:?}");
    // placement is required, spheres only
    let p = paths(&GOOD.replace(
        "placement = { kind = \"fibre_top\", fibre = 0, gap = 1e-6, height = 300e-6 }",
        "",
    ));
    assert!(p.contains(&"particles[0].placement".to_string()), "{p:?}");
    let p = paths(&GOOD.replacen(
        "shape = { kind = \"sphere\", radius = 75e-9 }",
        "shape = { kind = \"spherocylinder\", radius = 75e-9, cylinder_length = 1e-7 }",
        1,
    ));
    assert!(p.contains(&"particles[0].shape.kind".to_string()), "{p:?}");
    // typos in nested tables name the key
    let p = paths(&GOOD.replace("runs = 3", "runs = 3\nstep_control = { kind = \"adaptive\", tolerance = 1e-3, max_displacement = 0.2, max_depht = 3 }"));
    assert!(
        p.iter().any(|x| x.starts_with("brownian.step_control")),
        "{p:?}"
    );
    // points must match the count
    let p = paths(&GOOD.replace(
        "placement = { kind = \"fibre_top\", fibre = 0, gap = 1e-6, height = 300e-6 }",
        "placement = { kind = \"points\", positions = [[0.0, 0.0, 1.0]] }",
    ));
    assert!(
        p.contains(&"particles[0].placement.positions".to_string()),
        "{p:?}"
    );
    // moment and placement belong to the brownian pipeline only
    let packing = "[simulation]\npipeline = \"packing\"\n[container]\nkind = \"periodic_box\"\n[[particles]]\ncount = 3\nshape = { kind = \"sphere\", radius = 1.0 }\nmoment = { kind = \"saturated\", moment = 1.0 }\n";
    assert!(paths(packing).contains(&"particles[0].moment".to_string()));
}

#[test]
fn step_control_keys_default_one_by_one() {
    let control = |table: &str| {
        let text = GOOD.replace("runs = 3\n", &format!("runs = 3\nstep_control = {table}\n"));
        let s = parse_scene(&text, &Default::default()).unwrap();
        s.section::<BrownianSection>()
            .unwrap()
            .config()
            .step_control
    };
    assert_eq!(control("{ kind = \"adaptive\" }"), StepControl::default());
    assert_eq!(
        control("{ kind = \"multirate\", tolerance = 0.05 }"),
        StepControl::Multirate {
            tolerance: 0.05,
            max_displacement: 0.5,
            max_depth: 24
        }
    );
    assert_eq!(
        paths(&GOOD.replace(
            "runs = 3\n",
            "runs = 3\nstep_control = { kind = \"adaptive\", max_depth = 99 }\n"
        )),
        ["brownian.step_control.max_depth"]
    );
}

#[test]
fn a_box_region_volume_leaves_out_the_fibre_inside_it() {
    // the fibre (axis z, R = 300 um, half length 6 mm) crosses the 2 x 2 x 4 mm box
    let text = GOOD.replace(
        "placement = { kind = \"fibre_top\", fibre = 0, gap = 1e-6, height = 300e-6 }",
        "placement = { kind = \"box\", min = [-1e-3, -1e-3, -2e-3], max = [1e-3, 1e-3, 2e-3] }",
    );
    let s = parse_scene(&text, &Default::default()).unwrap();
    let v = region_volume(&s, 0);
    let pi = std::f64::consts::PI;
    let exact = 2e-3 * 2e-3 * 4e-3 - pi * 300e-6f64.powi(2) * 4e-3;
    assert!((v - exact).abs() < 1e-13 * exact, "{v} against {exact}");
    // a box inside the fibre is refused at its placement, naming the fibre
    let inside = GOOD.replace(
        "placement = { kind = \"fibre_top\", fibre = 0, gap = 1e-6, height = 300e-6 }",
        "placement = { kind = \"box\", min = [-1e-4, -1e-4, 0.0], max = [1e-4, 1e-4, 1e-3] }",
    );
    let e = errors(&inside);
    let hit = e
        .iter()
        .find(|e| e.path == "particles[0].placement")
        .expect("an error at the placement");
    assert!(hit.message.contains("inside fibre 0"), "{}", hit.message);
}

#[test]
fn crossing_fibres_are_left_out_of_a_box_region_once() {
    // a second fibre of the same radius along x crosses the first (axis z) at the origin,
    // inside the box: their common part is Steinmetz's solid 16 R³ / 3, subtracted once
    let text = GOOD
        .replace(
            "placement = { kind = \"fibre_top\", fibre = 0, gap = 1e-6, height = 300e-6 }",
            "placement = { kind = \"box\", min = [-1e-3, -1e-3, -2e-3], max = [1e-3, 1e-3, 2e-3] }",
        )
        .replace(
            "[brownian]",
            "[[fibres]]\nkind = \"cylinder\"\nradius = 300e-6\nhalf_length = 6e-3\naxis = [1.0, 0.0, 0.0]\nsaturation_magnetisation = 985e3\n[brownian]",
        );
    let s = parse_scene(&text, &Default::default()).unwrap();
    assert_eq!(s.fibres.len(), 2);
    let v = region_volume(&s, 0);
    let (pi, r) = (std::f64::consts::PI, 300e-6f64);
    let exact = 2e-3 * 2e-3 * 4e-3 - pi * r * r * 4e-3 - pi * r * r * 2e-3 + 16.0 * r.powi(3) / 3.0;
    assert!((v - exact).abs() < 1e-10 * exact, "{v} against {exact}");
}

/// The region volume \[m³\] of the scene's particle group `k`.
fn region_volume(s: &Scene, k: usize) -> f64 {
    s.particles[k]
        .placement
        .as_ref()
        .unwrap()
        .volume(&s.fibres)
        .unwrap()
}
