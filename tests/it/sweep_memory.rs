//! `magsep sweep --memory-budget`: points that together exceed the budget run fewer at once;
//! a point that alone exceeds it fails the sweep up front (exit 2) at its key path.

use crate::common::{magsep, stderr};
use std::path::Path;

use serde_json::Value;

use super::overrides::TRIVIAL;

fn sweep_in(name: &str, counts: &str) -> (String, String) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("base.toml"), TRIVIAL).unwrap();
    let text = format!(
        "scene = \"base.toml\"\ncollect = [\"particles\"]\n[[axes]]\nname = \"n\"\n\
         path = \"particles[0].count\"\nvalues = [{counts}]\n"
    );
    std::fs::write(dir.join("sweep.toml"), text).unwrap();
    let s = dir.join("sweep.toml").to_str().unwrap().to_string();
    (s, dir.join("out").to_str().unwrap().to_string())
}

#[test]
fn points_over_the_budget_together_run_fewer_at_once() {
    // each point needs the program's base (64 MiB) and a little per particle: two fit in
    // 1 GiB, but not in 0.1 GiB
    let (s, out) = sweep_in("sweep_memory_jobs", "2, 3, 4");
    let run = |budget: &str, out: &str| {
        let o = magsep(&[
            "sweep",
            &s,
            "--out",
            out,
            "--quiet",
            "--jobs",
            "2",
            "--memory-budget",
            budget,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<Value>(&o.stdout).unwrap()
    };
    let wide = run("1.0", &format!("{out}-wide"));
    assert_eq!(wide["jobs"], 2);
    assert_eq!(wide["jobs_limited_by_memory"], false);
    let narrow = run("0.1", &out);
    assert_eq!(narrow["jobs"], 1);
    assert_eq!(narrow["jobs_limited_by_memory"], true);
    assert_eq!(narrow["ok"], 3);
    let est = narrow["largest_point_memory_estimate_bytes"]
        .as_f64()
        .unwrap();
    assert!(est > 64.0 * 1048576.0 && est < 0.1 * 1073741824.0, "{est}");
}

#[test]
fn a_point_over_the_budget_alone_fails_up_front_at_its_key() {
    let (s, out) = sweep_in("sweep_memory_over", "2, 5000000");
    let o = magsep(&[
        "sweep",
        &s,
        "--out",
        &out,
        "--quiet",
        "--memory-budget",
        "1",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("point 1") && e.contains("particles") && e.contains("budget"),
        "{e}"
    );
    assert!(!Path::new(&out).join("points/0/summary.json").exists());
    // `magsep validate` of the sweep file finds the same point
    let v = magsep(&["validate", &s, "--memory-budget", "1"]);
    assert_eq!(v.status.code(), Some(2), "{}", stderr(&v));
    assert!(stderr(&v).contains("point 1"), "{}", stderr(&v));
}
