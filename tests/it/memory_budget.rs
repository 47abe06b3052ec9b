//! The memory budget: the largest scenes the README states for a 16 GiB budget (a 24 GiB
//! machine) fit it, and 10 % more does not, for every pipeline; the estimate names the key
//! that drives it.

use magsep::scene::{Registry, memory, parse_scene};

const BUDGET: u64 = 16 << 30;

/// A scene text for a particle count.
type SceneOf<'a> = &'a dyn Fn(u64) -> String;

fn packing(n: u64) -> String {
    format!(
        "[simulation]\npipeline = \"packing\"\n[container]\nkind = \"periodic_box\"\n\
         [[particles]]\ncount = {n}\nshape = {{ kind = \"sphere\", radius = 0.5 }}\n"
    )
}

fn brownian(n: u64, mobility: &str) -> String {
    format!(
        "[simulation]\npipeline = \"brownian\"\n[brownian]\ntime_step = 5e-5\nduration = 0.5\n\
         mobility = \"{mobility}\"\n[[particles]]\ncount = {n}\n\
         shape = {{ kind = \"sphere\", radius = 75e-9 }}\n\
         placement = {{ kind = \"box\", min = [-1e-3, -1e-3, -1e-3], max = [1e-3, 1e-3, 1e-3] }}\n"
    )
}

fn fluid(n: u64, history: bool) -> String {
    format!(
        "[simulation]\npipeline = \"particle_fluid\"\n[particle_fluid]\ntime_step = 1e-3\n\
         duration = 2.0\nhistory = {{ kind = \"window\", window = 0.2 }}\nterms = {{ history = {history} }}\n\
         [liquid]\ndensity = 1403.0\nviscosity = 5.54e-3\nsusceptibility = 7e-4\n\
         [container]\nkind = \"tank\"\nedges = [10.0, 10.0, 10.0]\n[[particles]]\ncount = {n}\n\
         shape = {{ kind = \"sphere\", radius = 1e-3 }}\ndensity = 1434.0\n\
         placement = {{ kind = \"box\", min = [0.01, 0.01, 0.01], max = [9.9, 9.9, 9.9] }}\n"
    )
}

/// (fits, the key an over-budget error names) for `text`.
fn fits(text: &str) -> (bool, String) {
    let scene = parse_scene(text, &Registry::default()).expect("a valid scene");
    match memory::check(&scene, BUDGET) {
        Ok(_) => (true, String::new()),
        Err(e) => (false, e.path),
    }
}

#[test]
fn the_readme_limits_fit_a_16_gib_budget_and_ten_percent_more_does_not() {
    let cases: [(&str, u64, SceneOf, &str); 5] = [
        ("packing", 4_000_000, &packing, "particles"),
        (
            "brownian free draining",
            3_300_000,
            &|n| brownian(n, "free_draining"),
            "particles",
        ),
        (
            "brownian krylov",
            15_000,
            &|n| brownian(n, "krylov"),
            "brownian.mobility",
        ),
        (
            "particle_fluid",
            4_100_000,
            &|n| fluid(n, false),
            "particles",
        ),
        (
            "particle_fluid history",
            580_000,
            &|n| fluid(n, true),
            "particle_fluid.history",
        ),
    ];
    for (name, limit, scene, key) in cases {
        let below = limit * 95 / 100;
        assert_eq!(
            fits(&scene(below)),
            (true, String::new()),
            "{name} at {below}"
        );
        let above = limit * 110 / 100;
        assert_eq!(
            fits(&scene(above)),
            (false, key.to_string()),
            "{name} at {above}"
        );
    }
}

#[test]
fn the_budget_comes_from_the_override_or_the_machine_and_refuses_nonsense() {
    assert_eq!(memory::budget(Some(2.0)), Ok(2 << 30));
    assert!(memory::budget(Some(-1.0)).is_err());
    assert!(memory::budget(Some(f64::NAN)).is_err());
    let default = memory::budget(None).expect("default");
    assert!(default <= memory::DEFAULT_BUDGET_BYTES && default > 0);
    if let Some(m) = memory::physical_memory() {
        assert!(default <= m / 4 * 3 + 1);
    }
}
