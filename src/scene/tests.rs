//! Scene parsing and validation tests.

use super::*;

const GOOD: &str = r#"
[simulation]
pipeline = "packing"
seed = 1
[container]
kind = "periodic_box"
[[particles]]
count = 500
shape = { kind = "spherocylinder", radius = 0.5, cylinder_length = 4.0 }
[packing]
scheme = "revised"
initial_packing_fraction = 0.05
volume_step = 0.1
max_attempts = 100000
step_halvings = 4
"#;

fn errors(text: &str) -> Vec<SceneError> {
    parse_scene(text, &Registry::default())
        .expect_err("must be invalid")
        .0
}

fn has(errs: &[SceneError], path: &str) -> bool {
    errs.iter().any(|e| e.path == path)
}

#[test]
fn the_issue_example_parses_with_defaults_resolved() {
    let s = parse_scene(GOOD, &Registry::default()).unwrap();
    assert_eq!(s.total_particles(), 500);
    let c = crate::packing::packing_config(&s);
    assert_eq!(c.max_attempts, 100_000);
    assert_eq!(
        c.scheme,
        magsep_components::packing::OverlapRemovalScheme::Revised
    );
    assert_eq!(s.shapes()[0].half_length(), 2.0);
    // omitted [packing]: documented defaults
    let bare = GOOD.split("[packing]").next().unwrap();
    let c = crate::packing::packing_config(&parse_scene(bare, &Registry::default()).unwrap());
    assert_eq!(c.max_attempts, 20_000 * 500);
    assert!((c.volume_step - 0.1).abs() < 1e-15);
}

#[test]
fn each_bad_input_names_its_key() {
    assert!(has(
        &errors(&GOOD.replace("seed = 1", "seed = 1\nsed = 2")),
        "simulation.sed"
    ));
    assert!(has(
        &errors(&GOOD.replace("radius = 0.5", "radius = -1e-9")),
        "particles[0].shape.radius"
    ));
    assert!(has(
        &errors(&GOOD.replace(
            "initial_packing_fraction = 0.05",
            "initial_packing_fraction = 1.5"
        )),
        "packing.initial_packing_fraction"
    ));
    assert!(has(
        &errors(&GOOD.replace("count = 500", "count = 0")),
        "particles[0].count"
    ));
    assert!(has(
        &errors(&GOOD.replace("count = 500", "count = \"abc\"")),
        "particles[0].count"
    ));
    assert!(has(
        &errors(&GOOD.replace("radius = 0.5,", "radiu = 0.5,")),
        "particles[0].shape.radiu"
    ));
    assert!(has(
        &errors(&GOOD.replace("\"spherocylinder\"", "\"cube\"")),
        "particles[0].shape.kind"
    ));
    assert!(has(
        &errors(&format!("{GOOD}\n[magnets]\nx = 1\n")),
        "magnets"
    ));
    assert!(has(
        &errors(&GOOD.replace("[container]\nkind = \"periodic_box\"", "")),
        "container"
    ));
    let syntax = errors("[simulation\npipeline = 1");
    assert!(syntax[0].path.starts_with("(syntax, line 1"), "{syntax:?}");
}

#[test]
fn all_errors_are_reported_at_once() {
    let text = GOOD
        .replace("count = 500", "count = 0")
        .replace("step_halvings = 4", "step_halvings = 99")
        .replace("volume_step = 0.1", "volume_step = -2.0");
    let errs = errors(&text);
    for p in [
        "particles[0].count",
        "packing.step_halvings",
        "packing.volume_step",
    ] {
        assert!(has(&errs, p), "{p} missing in {errs:?}");
    }
    let shown = SceneErrors(errs).to_string();
    assert!(
        shown.contains("got -2") && shown.contains("got 99"),
        "{shown}"
    );
}

struct Magnets;
impl SceneKind for Magnets {
    fn key(&self) -> &str {
        "magnets"
    }
    fn validate(&self, value: &toml::Value, path: &str, errors: &mut Vec<SceneError>) {
        if value
            .get("strength")
            .and_then(|v| v.as_float())
            .is_none_or(|s| s <= 0.0)
        {
            errors.push(SceneError::new(
                format!("{path}.strength"),
                "must be a number > 0",
            ));
        }
    }
    fn spawn(&self, value: &toml::Value, world: &mut World) -> Result<(), SpawnError> {
        let strength = value.get("strength").and_then(|v| v.as_float());
        world.insert_resource(MagnetStrength(strength.unwrap_or(f64::NAN)));
        Ok(())
    }
}

#[derive(Resource, Debug, PartialEq)]
struct MagnetStrength(f64);

#[test]
fn plugins_register_new_scene_kinds() {
    let reg = Registry::default().with_kind(Magnets);
    let s = parse_scene(&format!("{GOOD}\n[magnets]\nstrength = 1.5\n"), &reg).unwrap();
    assert_eq!(s.extensions.len(), 1);
    // the kind's section is spawned with the scene (a plugin's build can read it)
    let mut world = World::new();
    crate::scene::spawn_scene(&s, &mut world, 1).unwrap();
    assert_eq!(
        world.get_resource::<MagnetStrength>(),
        Some(&MagnetStrength(1.5))
    );
    let e = parse_scene(&format!("{GOOD}\n[magnets]\nstrength = -1.0\n"), &reg).unwrap_err();
    assert_eq!(e.0[0].path, "magnets.strength");
    // without the kind: an unknown key, with a hint for a table (a plugin's section)
    let e = parse_scene(
        &format!("{GOOD}\n[magnets]\nstrength = 1.5\n"),
        &Registry::default(),
    )
    .unwrap_err();
    assert_eq!(e.0[0].path, "magnets");
    assert!(
        e.0[0].message.contains("built with that plugin"),
        "{}",
        e.0[0]
    );
    let e = parse_scene(&format!("magnets = 1.5\n{GOOD}"), &Registry::default()).unwrap_err();
    assert!(!e.0[0].message.contains("plugin"), "{}", e.0[0]);
}

#[test]
fn mutated_scenes_never_panic() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let chars: Vec<char> = GOOD.chars().collect();
    let lines: Vec<&str> = GOOD.lines().collect();
    for k in 0..400 {
        let text: String = if k % 2 == 0 {
            let mut c = chars.clone();
            for _ in 0..3 {
                let i = rng.random_range(0..c.len());
                if rng.random::<bool>() {
                    c.remove(i);
                } else {
                    let ch = c[rng.random_range(0..c.len())];
                    c.insert(i, ch);
                }
            }
            c.into_iter().collect()
        } else {
            let mut l = lines.clone();
            let i = rng.random_range(0..l.len());
            if rng.random::<bool>() {
                l.remove(i);
            } else {
                let x = l[rng.random_range(0..l.len())];
                l.insert(i, x);
            }
            l.join("\n")
        };
        let _ = parse_scene(&text, &Registry::default());
    }
}

#[test]
fn every_shipped_scene_is_valid() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut n = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            load_scene(&p, &Registry::default()).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            n += 1;
        }
    }
    assert!(n >= 4);
}

#[test]
fn fibre_scenes_parse_and_report_every_error() {
    let ok = r#"
[external_field]
flux_density = [1.0, 0.0, 0.0]
[[fibres]]
kind = "cylinder"
radius = 3e-4
half_length = 6e-3
axis = [1.0, 0.0, 1.0]
saturation_magnetisation = 985e3
"#;
    let scene = parse_scene(ok, &Registry::default()).unwrap();
    assert!(scene.is_field_only() && scene.fibres.len() == 1);
    let (sources, b, tol) = scene.field_sources();
    assert_eq!((b, tol), (glam::DVec3::X, magsep_systems::field::EXACT));
    // Stoner-Wohlfarth: L/D = 20 at α = 45° gives θ ≈ 30.3° from the axis (D-000-4 in docs/references.md)
    let m = sources[0].magnetisation;
    let theta = m
        .angle_between(glam::DVec3::new(1.0, 0.0, 1.0))
        .to_degrees();
    assert!(
        (m.length() - 985e3).abs() < 1e-6 && (theta - 30.3).abs() < 0.2,
        "{theta}"
    );
    let bad = r#"
[external_field]
flux_density = [0.0, 0.0, 0.0]
field_tolerance = 2.0
[[fibres]]
kind = "cylinder"
radius = -1.0
half_length = 1.0
axis = [0.0, 0.0, 0.0]
[[fibres]]
kind = "cylinder"
radius = 1.0
half_length = 1.0
axis = [0.0, 0.0, 1.0]
magnetisation = [1.0, 0.0, 0.0]
saturation_magnetisation = 1.0
[[fibres]]
kind = "cylinder"
radius = 1.0
half_length = 1.0
axis = [0.0, 0.0, 1.0]
saturation_magnetisation = 1.0
[[fibres]]
kind = "cube"
"#;
    let errs = parse_scene(bad, &Registry::default()).unwrap_err().0;
    let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
    for want in [
        "external_field.field_tolerance",
        "fibres[0].radius",
        "fibres[0].axis",
        "fibres[0].magnetisation",
        "fibres[1].magnetisation",
        "fibres[2].saturation_magnetisation",
        "fibres[3]",
    ] {
        assert!(
            paths.iter().any(|p| p.starts_with(want)),
            "{want} missing in {paths:?}"
        );
    }
    // fibres next to particles need the run tables as usual
    let mixed =
        format!("{ok}\n[[particles]]\ncount = 2\nshape = {{ kind = \"sphere\", radius = 1.0 }}\n");
    let errs = parse_scene(&mixed, &Registry::default()).unwrap_err().0;
    assert!(errs.iter().any(|e| e.path == "simulation"));
}

#[test]
fn fibres_are_spawned_as_entities_next_to_particles() {
    let fibres = r#"
[external_field]
flux_density = [0.0, 0.0, 1.0]
[[fibres]]
kind = "cylinder"
radius = 0.1
half_length = 1.0
axis = [0.0, 0.0, 2.0]
magnetisation = [0.0, 0.0, 1e5]
"#;
    let text = format!(
        r#"
[simulation]
pipeline = "brownian"
[brownian]
time_step = 1e-3
duration = 1e-2
mobility = "free_draining"
contact = {{ kind = "none" }}
dipole_cutoff = 0
[[particles]]
count = 2
shape = {{ kind = "sphere", radius = 100e-9 }}
placement = {{ kind = "box", min = [1.0, 1.0, 1.0], max = [1.001, 1.001, 1.001] }}
{fibres}"#
    );
    // a pipeline that would ignore them refuses them at their keys
    let packing = format!(
        "[simulation]\npipeline = \"packing\"\n[container]\nkind = \"periodic_box\"\n\
         [[particles]]\ncount = 4\nshape = {{ kind = \"sphere\", radius = 0.5 }}\n{fibres}"
    );
    let e = parse_scene(&packing, &Registry::default()).unwrap_err().0;
    let paths: Vec<&str> = e.iter().map(|e| e.path.as_str()).collect();
    assert_eq!(paths, ["fibres", "external_field"], "{e:?}");
    let scene = parse_scene(&text, &Registry::default()).unwrap_or_else(|e| panic!("{e}"));
    let mut world = bevy_ecs::prelude::World::new();
    crate::scene::spawn_scene(&scene, &mut world, 1).unwrap();
    let mut q = world.query::<(
        &magsep_components::fibre::FibreId,
        &magsep_components::fibre::Fibre,
    )>();
    let fibres: Vec<_> = q.iter(&world).map(|(i, f)| (i.0, *f)).collect();
    assert_eq!(fibres.len(), 1);
    assert_eq!(fibres[0].1.axis, glam::DVec3::Z);
    let ext = world.resource::<magsep_components::fibre::ExternalField>();
    assert_eq!(ext.flux_density, glam::DVec3::Z);
}

#[test]
fn an_error_in_simulation_does_not_disown_the_pipelines_sections() {
    for bad in ["bogus = 1\n", "seed = -1\n"] {
        let text = GOOD.replace("seed = 1\n", bad);
        let e = errors(&text);
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].path.starts_with("simulation"), "{e:?}");
    }
    // the packing sections are still checked: a real error beside it is reported too
    let text = GOOD
        .replace("seed = 1\n", "bogus = 1\n")
        .replace("step_halvings = 4", "step_halvings = 99");
    let e = errors(&text);
    assert!(has(&e, "packing.step_halvings"), "{e:?}");
    assert!(!has(&e, "container"), "{e:?}");
}
