//! The committed corpus of bad recordings (`tests/data/bad_recordings/`): each file is run
//! through `magsep info`, and `magsep replay` / `replay --resume` where its manifest entry says,
//! with a 1 GiB address-space limit (`ulimit -v`), checking the exit code, a fragment of the
//! output, fragments that must not appear, and that nothing panics or aborts. The files are
//! regenerated from `base.mcap` by `generate::corpus`; set `MAGSEP_WRITE_BAD_RECORDINGS=1` to
//! write them (see the manifest's header).

#![cfg(unix)]

mod generate;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde::Deserialize;

const DIR: &str = "tests/data/bad_recordings";

/// Address-space limit of every run [KiB]: 1 GiB. An allocation beyond what the reader's
/// bounds allow (a zstd bomb, a crafted length) aborts the process, failing the test.
const ULIMIT_KIB: u64 = 1 << 20;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    case: Vec<Case>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    /// File in `tests/data/bad_recordings/`.
    file: String,
    /// What is wrong with it.
    what: String,
    info: Expect,
    #[serde(default)]
    replay: Option<Expect>,
    #[serde(default)]
    resume: Option<Expect>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Expect {
    /// Exit code.
    exit: i32,
    /// A fragment of stdout + stderr.
    contains: String,
    /// Fragments that must not appear (e.g. the bytes of a file that is not a recording).
    #[serde(default)]
    absent: Vec<String>,
}

fn manifest() -> Manifest {
    let text = std::fs::read_to_string(Path::new(DIR).join("manifest.toml")).unwrap();
    toml::from_str(&text).unwrap()
}

/// `magsep args` under the address-space limit; one glibc malloc arena per two threads keeps
/// the virtual size of the thread pools small.
fn limited(args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {ULIMIT_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_magsep"))
        .args(args)
        .env("MALLOC_ARENA_MAX", "2")
        .output()
        .expect("sh runs")
}

fn check(case: &Case, command: &str, args: &[&str], expect: &Expect) {
    let o = limited(args);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let at = format!("{} ({}), {command}", case.file, case.what);
    assert_eq!(o.status.code(), Some(expect.exit), "{at}: {text}");
    // a failed allocation reported gracefully is still an over-allocation
    for bad in ["panicked", "out of memory", "memory allocation"] {
        assert!(!text.contains(bad), "{at}: {text}");
    }
    assert!(
        text.contains(&expect.contains),
        "{at}: expected {:?} in: {text}",
        expect.contains
    );
    for a in &expect.absent {
        assert!(!text.contains(a.as_str()), "{at}: {a:?} in: {text}");
    }
}

#[test]
fn bad_recordings_give_their_exit_codes_and_messages_in_bounded_memory() {
    let m = manifest();
    assert!(m.case.len() >= 20, "{} cases", m.case.len());
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad_recordings");
    let _ = std::fs::remove_dir_all(&out_dir);
    std::fs::create_dir_all(&out_dir).unwrap();
    for case in &m.case {
        let path: PathBuf = Path::new(DIR).join(&case.file);
        let p = path.to_str().unwrap();
        assert!(path.is_file(), "{p} is missing: regenerate the corpus");
        check(case, "info", &["info", p], &case.info);
        if let Some(e) = &case.replay {
            check(case, "replay", &["replay", p], e);
        }
        if let Some(e) = &case.resume {
            let out = out_dir.join(&case.file);
            let args = ["replay", p, "--resume", "--quiet", "--record"];
            check(
                case,
                "resume",
                &[&args[..], &[out.to_str().unwrap()]].concat(),
                e,
            );
        }
    }
}

#[test]
fn bad_recordings_corpus_is_reproducible() {
    let base = std::fs::read(Path::new(DIR).join("base.mcap")).unwrap();
    let corpus = generate::corpus(&base);
    let write = std::env::var_os("MAGSEP_WRITE_BAD_RECORDINGS").is_some();
    let listed: Vec<String> = manifest().case.into_iter().map(|c| c.file).collect();
    for (name, bytes) in &corpus {
        let path = Path::new(DIR).join(name);
        if write {
            std::fs::write(&path, bytes).unwrap();
        }
        let committed = std::fs::read(&path).unwrap_or_default();
        assert!(
            committed == *bytes,
            "{name} differs from what generate.rs makes of base.mcap: regenerate the corpus"
        );
        assert!(
            listed.contains(&name.to_string()),
            "{name} is not in the manifest"
        );
    }
    for name in &listed {
        let made = name == "base.mcap" || corpus.iter().any(|(n, _)| n == name);
        assert!(made, "{name} is listed but not generated");
    }
}
