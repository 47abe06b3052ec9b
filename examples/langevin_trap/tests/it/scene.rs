//! Validation of `[trap]` and `start`: every error at its innermost key path, unknown keys,
//! and the keys of this pipeline in another pipeline's scene.

use crate::common;

use common::{parse, trap_scene};
use langevin_trap::{TrapScene, registry};
use magsep::glam::DVec3;
use magsep::scene::parse_scene;

/// The errors of `text` as "path: message" lines.
fn errors(text: &str) -> Vec<String> {
    match parse_scene(text, &registry()) {
        Ok(_) => panic!("scene unexpectedly valid:\n{text}"),
        Err(e) => e.0.iter().map(|e| e.to_string()).collect(),
    }
}

/// Whether an error is at `path` with `message` in its text.
fn has(errors: &[String], path: &str, message: &str) -> bool {
    errors
        .iter()
        .any(|e| e.starts_with(&format!("{path}: ")) && e.contains(message))
}

/// The standard scene with `key = value` of `[trap]` replaced.
fn with_trap(key: &str, value: &str) -> String {
    trap_scene(10, 1e-3, 100, 10, "")
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key} = ")) {
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

const PACKING: &str = r#"
[simulation]
pipeline = "packing"
[container]
kind = "periodic_box"
[[particles]]
count = 10
shape = { kind = "sphere", radius = 0.5 }
"#;

#[test]
fn the_test_scene_is_valid_and_keeps_start() {
    let scene = parse(&trap_scene(10, 1e-3, 100, 10, ""));
    let s = scene.section::<TrapScene>().unwrap();
    assert_eq!(s.starts, vec![DVec3::new(1.2e-6, -2e-6, 0.5e-6)]);
    assert_eq!(s.trap.stiffness, 1e-6);
    assert_eq!(scene.pipeline_name(), Some("langevin_trap"));
}

#[test]
fn bad_values_at_their_key_paths() {
    let e = errors(&with_trap("stiffness", "-1"));
    assert!(
        e.contains(&"trap.stiffness: must be a finite number > 0, got -1".to_string()),
        "{e:?}"
    );
    for (key, value) in [
        ("temperature", "0.0"),
        ("viscosity", "nan"),
        ("time_step", "-inf"),
        ("duration", "-2.0"),
    ] {
        let e = errors(&with_trap(key, value));
        assert!(
            has(&e, &format!("trap.{key}"), "must be a finite number > 0"),
            "{key}: {e:?}"
        );
    }
    let e = errors(&with_trap("centre", "[0.0, inf, 0.0]"));
    assert!(
        has(&e, "trap.centre[1]", "must be a finite number"),
        "{e:?}"
    );
    let e = errors(&with_trap("centre", "[0.0, 1.0]"));
    assert!(
        has(&e, "trap.centre", "array of 3 numbers [m], got 2 items"),
        "{e:?}"
    );
    let e = errors(&with_trap("centre", "[0.0, 1.0, \"x\"]"));
    assert!(
        has(&e, "trap.centre[2]", "must be a number, got a string"),
        "{e:?}"
    );
    let e = errors(&with_trap("stiffness", "\"stiff\""));
    assert!(has(&e, "trap.stiffness", "invalid type"), "{e:?}");
    let e = errors(&with_trap("record_every", "0"));
    assert!(has(&e, "trap.record_every", "must be >= 1"), "{e:?}");
    let e = errors(&with_trap("duration", "1e-5"));
    assert!(has(&e, "trap.duration", "between 1 and"), "{e:?}");
    // 5 γ/k = 47 ms of default equilibration leaves no time to sample in 20 ms
    let e = errors(&trap_scene(10, 1e-3, 20, 10, ""));
    assert!(
        has(&e, "trap.duration", "must exceed the default equilibration"),
        "{e:?}"
    );
    parse(&trap_scene(10, 1e-3, 20, 10, "equilibration = 0.0"));
    let e = errors(&trap_scene(10, 1e-3, 100, 10, "equilibration = 0.5"));
    assert!(has(&e, "trap.equilibration", "< duration"), "{e:?}");
}

#[test]
fn unknown_and_missing_keys() {
    let e = errors(&trap_scene(10, 1e-3, 100, 10, "spring = 1.0"));
    assert!(has(&e, "trap.spring", "unknown key"), "{e:?}");
    let e = errors(&trap_scene(10, 1e-3, 100, 10, "").replace("stiffness = 1e-6\n", ""));
    assert!(has(&e, "trap.stiffness", "missing required key"), "{e:?}");
    let no_trap = trap_scene(10, 1e-3, 100, 10, "").replace("[trap]", "[other]");
    let e = errors(&no_trap);
    assert!(has(&e, "trap", "missing required table [trap]"), "{e:?}");
    let e = errors(&format!(
        "{}\n[record]\nevery = 5\n",
        trap_scene(10, 1e-3, 100, 10, "")
    ));
    assert!(
        has(&e, "trap.record_every", "conflicts with record.every = 5"),
        "{e:?}"
    );
}

#[test]
fn start_is_checked_at_its_path() {
    let scene = |start: &str| {
        trap_scene(10, 1e-3, 100, 10, "").replace(
            "start = [1.2e-6, -2e-6, 0.5e-6]",
            &format!("start = {start}"),
        )
    };
    let e = errors(&scene("[0.0, nan, 0.0]"));
    assert!(
        has(
            &e,
            "particles[0].start[1]",
            "must be a finite number, got NaN"
        ),
        "{e:?}"
    );
    let e = errors(&scene("\"origin\""));
    assert!(has(&e, "particles[0].start", "got a string"), "{e:?}");
    let e = errors(&scene("[1.0, 2.0]"));
    assert!(has(&e, "particles[0].start", "got 2 items"), "{e:?}");
    let e = errors(&scene("[1.0, 2.0, true]"));
    assert!(
        has(
            &e,
            "particles[0].start[2]",
            "must be a number, got a boolean"
        ),
        "{e:?}"
    );
    // integers are numbers too
    parse(&scene("[0, 0, 0]"));
    // without start the particles start at the centre
    let s = parse(&scene("[0, 0, 0]").replace("start = [0, 0, 0]", ""));
    assert_eq!(
        s.section::<TrapScene>().unwrap().starts,
        vec![DVec3::new(1e-6, -2e-6, 0.5e-6)]
    );
}

#[test]
fn spheres_only() {
    let text = trap_scene(10, 1e-3, 100, 10, "").replace(
        "{ kind = \"sphere\", radius = 0.5e-6 }",
        "{ kind = \"spherocylinder\", radius = 0.5e-6, cylinder_length = 1e-6 }",
    );
    let e = errors(&text);
    assert!(has(&e, "particles[0].shape.kind", "spheres only"), "{e:?}");
}

#[test]
fn trap_keys_belong_to_this_pipeline() {
    // the registry knows both pipelines: [trap] in a packing scene names its owner
    assert!(parse_scene(PACKING, &registry()).is_ok());
    let e = errors(&format!("{PACKING}\n[trap]\nstiffness = 1e-6\n"));
    assert!(
        has(&e, "trap", "only for pipeline = \"langevin_trap\""),
        "{e:?}"
    );
    let with_start = PACKING.replace("radius = 0.5 }", "radius = 0.5 }\nstart = [0.0, 0.0, 0.0]");
    let e = errors(&with_start);
    assert!(
        has(
            &e,
            "particles[0].start",
            "only for pipeline = \"langevin_trap\""
        ),
        "{e:?}"
    );
    // a key of another pipeline is refused here
    let e = errors(&format!(
        "{}\n[container]\nkind = \"periodic_box\"\n",
        trap_scene(10, 1e-3, 100, 10, "")
    ));
    assert!(
        has(&e, "container", "only for pipeline = \"packing\""),
        "{e:?}"
    );
}
