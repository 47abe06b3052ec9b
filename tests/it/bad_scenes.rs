//! The corpus of bad scenes in `tests/data/bad_scenes/`: each file says in its header what
//! `magsep` must do with it (`# expect-exit`, `# expect-command` validate or run,
//! `# expect-path` the innermost key path the error names, `# expect-message` a fragment,
//! `# expect-absent` a fragment that must not appear). Every case runs under a 4 GiB
//! address-space limit and a time limit, so an over-allocation or a run that never ends
//! fails the test instead of the machine.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Address space given to each case \[KiB\] (`ulimit -v`).
const MEMORY_LIMIT_KIB: u64 = 4 * 1024 * 1024;
/// Time given to each case.
const TIME_LIMIT: Duration = Duration::from_secs(60);

struct Expect {
    exit: i32,
    command: String,
    path: Option<String>,
    message: Option<String>,
    absent: Option<String>,
}

fn expectations(text: &str) -> Expect {
    let get = |key: &str| {
        text.lines()
            .filter_map(|l| l.strip_prefix(&format!("# expect-{key}: ")))
            .map(|v| v.trim().to_string())
            .next()
    };
    Expect {
        exit: get("exit")
            .and_then(|v| v.parse().ok())
            .expect("expect-exit"),
        command: get("command").unwrap_or_else(|| "validate".into()),
        path: get("path"),
        message: get("message"),
        absent: get("absent"),
    }
}

/// Run `magsep args...` limited in memory and time: (exit code, stdout, stderr).
pub fn limited(args: &[&str]) -> (Option<i32>, String, String) {
    let script = format!("ulimit -v {MEMORY_LIMIT_KIB}; exec \"$0\" \"$@\"");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_magsep"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn magsep");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = child.wait_with_output().expect("output");
    (
        status.and_then(|s| s.code()),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn corpus() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad_scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("the corpus")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// What is wrong with the outcome of one case (empty: as expected).
fn check_case(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).expect("read case");
    let e = expectations(&text);
    let path = file.to_str().expect("utf-8 path");
    let args: Vec<&str> = match e.command.as_str() {
        "run" => vec!["run", path, "--quiet"],
        _ => vec!["validate", path],
    };
    let (code, _, stderr) = limited(&args);
    let mut wrong = Vec::new();
    if code != Some(e.exit) {
        wrong.push(format!("exit {code:?}, expected {}", e.exit));
    }
    if stderr.contains("panicked") {
        wrong.push("panicked".into());
    }
    if let Some(p) = &e.path
        && !stderr.contains(&format!("{p}: "))
    {
        wrong.push(format!("no error at `{p}`"));
    }
    if let Some(m) = &e.message
        && !stderr.contains(m.as_str())
    {
        wrong.push(format!("no `{m}` in the message"));
    }
    if let Some(a) = &e.absent
        && stderr.contains(a.as_str())
    {
        wrong.push(format!("`{a}` in the message"));
    }
    if !wrong.is_empty() {
        wrong.push(format!("stderr: {}", stderr.trim()));
    }
    wrong
}

#[test]
fn every_bad_scene_of_the_corpus_gets_its_exit_code_and_innermost_key_path() {
    let files = corpus();
    assert!(files.len() >= 30, "the corpus holds {} scenes", files.len());
    let failures: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let wrong = check_case(f);
            (!wrong.is_empty()).then(|| {
                let name = f.file_name().unwrap_or_default().to_string_lossy();
                format!("{name}: {}", wrong.join("; "))
            })
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

#[test]
fn a_ten_megabyte_string_value_is_not_echoed_in_full() {
    let dir = std::env::temp_dir().join(format!("magsep-bad-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("huge_string.toml");
    let text = format!(
        "[simulation]\npipeline = \"packing\"\n[container]\nkind = \"{}\"\n\
         [[particles]]\ncount = 2\nshape = {{ kind = \"sphere\", radius = 0.5 }}\n",
        "x".repeat(10_000_000)
    );
    std::fs::write(&file, text).expect("write");
    let (code, _, stderr) = limited(&["validate", file.to_str().expect("utf-8")]);
    assert_eq!(code, Some(2), "{}", &stderr[..stderr.len().min(2000)]);
    assert!(
        stderr.contains("container.kind: "),
        "{}",
        &stderr[..stderr.len().min(2000)]
    );
    assert!(stderr.len() < 5000, "stderr holds {} bytes", stderr.len());
    std::fs::remove_dir_all(&dir).ok();
}
