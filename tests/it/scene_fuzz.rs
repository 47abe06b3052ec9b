//! Property test over the scene parser, validator and spawner: the shipped small scenes of
//! every pipeline, mutated at random (a number replaced by an extreme value, a line
//! dropped or doubled, an unknown key added, a string changed), never make magsep panic:
//! parsing returns a scene or errors at key paths, and a scene that validates and fits a
//! small memory budget builds and takes a few steps. 256 cases in the default tier
//! (`PROPTEST_CASES` raises it).

use magsep::prelude::*;
use magsep::scene::{memory, parse_scene};
use proptest::prelude::*;

const BASES: [&str; 3] = [
    include_str!("../../scenes/small_mixture.toml"),
    include_str!("../data/brownian_short.toml"),
    include_str!("../data/levitation_short.toml"),
];

/// Values that broke magsep before (huge, tiny, denormal, non-finite, negative, 64-bit
/// overflow) and some ordinary ones.
const EXTREMES: [&str; 16] = [
    "0",
    "-1",
    "1e300",
    "-1e300",
    "5e-324",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "99999999999999999999",
    "9223372036854775807",
    "0.5",
    "2",
    "1e7",
    "3",
    "\"x\"",
];

#[derive(Debug, Clone)]
enum Mutation {
    Number { nth: usize, value: usize },
    DropLine(usize),
    DoubleLine(usize),
    UnknownKey(usize),
    String { nth: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (0..64usize, 0..EXTREMES.len()).prop_map(|(nth, value)| Mutation::Number { nth, value }),
        1 => (0..64usize).prop_map(Mutation::DropLine),
        1 => (0..64usize).prop_map(Mutation::DoubleLine),
        1 => (0..64usize).prop_map(Mutation::UnknownKey),
        1 => (0..64usize).prop_map(|nth| Mutation::String { nth }),
    ]
}

/// Byte ranges of the numbers outside comments.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let b = code.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let starts = (b[i].is_ascii_digit() || b[i] == b'-')
                && (i == 0 || matches!(b[i - 1], b' ' | b'[' | b'=' | b','));
            if starts {
                let mut j = i + 1;
                while j < b.len() && (b[j].is_ascii_alphanumeric() || b"+-._".contains(&b[j])) {
                    j += 1;
                }
                out.push((offset + i, offset + j));
                i = j;
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    out
}

fn apply(text: &str, m: &Mutation) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let pick = |k: usize| k % lines.len().max(1);
    match *m {
        Mutation::Number { nth, value } => {
            let spans = numbers(text);
            let Some(&(a, b)) = spans.get(nth % spans.len().max(1)) else {
                return text.to_string();
            };
            format!("{}{}{}", &text[..a], EXTREMES[value], &text[b..])
        }
        Mutation::DropLine(k) => {
            let k = pick(k);
            lines
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
        }
        Mutation::DoubleLine(k) => {
            let k = pick(k);
            let mut out: Vec<&str> = lines.clone();
            out.insert(k, lines[k]);
            out.join("\n")
        }
        Mutation::UnknownKey(k) => {
            let k = pick(k);
            let mut out: Vec<&str> = lines.clone();
            out.insert(k + 1, "bogus_key = 1");
            out.join("\n")
        }
        Mutation::String { nth } => {
            let quoted: Vec<usize> = text.match_indices('"').map(|(i, _)| i).collect();
            let k = (nth % (quoted.len() / 2).max(1)) * 2;
            match (quoted.get(k), quoted.get(k + 1)) {
                (Some(&a), Some(&b)) => format!("{}\"zz\"{}", &text[..a], &text[b + 1..]),
                _ => text.to_string(),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_scenes_never_panic(
        base in 0..BASES.len(),
        m1 in mutation(),
        m2 in proptest::option::of(mutation()),
    ) {
        let once = apply(BASES[base], &m1);
        let text = match &m2 {
            Some(m) => apply(&once, m),
            None => once,
        };
        let registry = Registry::default();
        match parse_scene(&text, &registry) {
            Err(errors) => {
                prop_assert!(!errors.0.is_empty());
                for e in &errors.0 {
                    prop_assert!(!e.path.is_empty(), "an error without a key path: {e}");
                    prop_assert!(e.message.len() <= 2 * magsep::error::MAX_MESSAGE_CHARS);
                }
            }
            Ok(scene) => {
                // a valid scene that fits 256 MiB builds and steps without a panic
                if memory::check(&scene, 256 << 20).is_ok()
                    && let Ok(mut sim) = Simulation::builder(&scene).build()
                {
                    for _ in 0..3 {
                        if sim.is_finished() {
                            break;
                        }
                        sim.step();
                    }
                }
            }
        }
    }
}
