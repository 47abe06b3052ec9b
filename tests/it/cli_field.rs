//! `magsep field`: points CSV in, CSV out (with gradients), maps, and bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn magsep(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_magsep"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run magsep")
}

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp_path("cli_field", name)
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn field_points_csv_matches_the_library_and_is_thread_independent() {
    let o = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        "scenes/points_example.csv",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = stdout(&o);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,bx,by,bz"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5);
    // against the library directly
    let scene = magsep::scene::load_scene("scenes/fibres_three.toml".as_ref(), &Default::default())
        .unwrap();
    let fs = magsep::fieldtool::FieldScene::from_scene(&scene);
    for r in &rows {
        let b = fs.b(glam::DVec3::new(r[0], r[1], r[2]));
        assert_eq!([b.x, b.y, b.z], [r[3], r[4], r[5]]);
    }
    // gradient columns; one thread gives the same bytes
    let g1 = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        "scenes/points_example.csv",
        "--gradient",
        "--threads",
        "1",
    ]);
    let g2 = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        "scenes/points_example.csv",
        "--gradient",
        "--threads",
        "2",
    ]);
    assert_eq!(g1.status.code(), Some(0));
    assert_eq!(g1.stdout, g2.stdout);
    let t = stdout(&g1);
    let header = t.lines().next().unwrap();
    assert_eq!(header.split(',').count(), 15);
    assert!(header.ends_with("dbz_dx,dbz_dy,dbz_dz"));
}

#[test]
fn field_map_and_capture_contour() {
    let out = tmp("map.svg");
    let o = magsep(&[
        "field",
        "scenes/fibre_thesis.toml",
        "--slice",
        "y=0",
        "--extent",
        "-8e-3,8e-3,-8e-3,8e-3",
        "--resolution",
        "40",
        "--moment",
        "8.7e-17",
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let summary: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(
        summary["capture_area_m2"].as_f64().unwrap() > 0.0,
        "{summary}"
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg") && !svg.contains("NaN"));
}

#[test]
fn field_bad_input_exits_2() {
    let bad = tmp("bad.csv");
    std::fs::write(&bad, "x,y,z\n1,2,3\n1,oops,3\n4,5\n").unwrap();
    let o = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 3") && err.contains("line 4"), "{err}");
    for args in [
        vec!["field", "scenes/fibres_three.toml"],
        vec![
            "field",
            "scenes/fibres_three.toml",
            "--slice",
            "w=0",
            "--extent",
            "0,1,0,1",
            "--out",
            "x.svg",
        ],
        vec![
            "field",
            "scenes/fibres_three.toml",
            "--slice",
            "z=0",
            "--extent",
            "1,0,0,1",
            "--out",
            "x.svg",
        ],
        vec![
            "field",
            "scenes/missing.toml",
            "--points",
            "scenes/points_example.csv",
        ],
        vec!["run", "scenes/fibres_three.toml"],
    ] {
        let o = magsep(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// `--out` in points mode writes the CSV file (the same bytes as stdout), never over an input;
/// options of the other mode are refused with exit 2 instead of being ignored.
#[test]
fn field_points_out_writes_the_file_and_options_of_the_other_mode_are_refused() {
    let scene = "scenes/fibres_three.toml";
    let points = "scenes/points_example.csv";
    let to_stdout = magsep(&["field", scene, "--points", points]);
    assert_eq!(to_stdout.status.code(), Some(0));
    let out = tmp("points_out.csv");
    let _ = std::fs::remove_file(&out);
    let o = magsep(&[
        "field",
        scene,
        "--points",
        points,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(std::fs::read(&out).unwrap(), to_stdout.stdout);
    let said: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(said["points"], 5);
    // an existing file needs --force; an input never
    let again = magsep(&[
        "field",
        scene,
        "--points",
        points,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(again.status.code(), Some(2));
    let over = magsep(&[
        "field", scene, "--points", points, "--out", points, "--force",
    ]);
    assert_eq!(over.status.code(), Some(2));
    for extra in [
        &["--moment", "1e-15"][..],
        &["--resolution", "50"],
        &["--cutoff", "1e-15"],
        &["--extent=-1,1,-1,1"],
    ] {
        let o = magsep(&[&["field", scene, "--points", points][..], extra].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(extra[0].split('=').next().unwrap()), "{err}");
        assert!(o.stdout.is_empty(), "{extra:?}");
    }
    let map = tmp("refused_map.svg");
    let slice = [
        "field",
        scene,
        "--slice",
        "z=0",
        "--extent=-1e-3,1e-3,-1e-3,1e-3",
    ];
    for extra in [&["--cutoff", "1e-15"][..], &["--gradient"]] {
        let args = [&slice[..], &["--out", map.to_str().unwrap()], extra].concat();
        let o = magsep(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(extra[0]), "{err}");
        assert!(!map.exists());
    }
}

/// A points CSV saved by Excel starts with a UTF-8 byte-order mark: accepted.
#[test]
fn field_points_with_a_byte_order_mark_are_read() {
    let csv = tmp("bom.csv");
    std::fs::write(&csv, "\u{feff}x,y,z\r\n1e-3,0,0\r\n").unwrap();
    let o = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(stdout(&o).lines().count(), 2);
}
