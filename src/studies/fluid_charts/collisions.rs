//! `magsep chart collisions --out DIR [--quick]`: binary collisions of a sinking PVC-U and a
//! rising POM sphere in the thesis's rig (thesis 002, §2.5.2.2, fig. 2.12), derived from
//! `scenes/binary_collision.toml` (compiled in): the impact factor I (lateral centre
//! distance over d) is rewritten, and each particle is also run alone.
//!
//! The delay of a particle is t_l(pair)/t_l(alone) − 1 (levitation time with the scene's
//! 0.5 mm tolerance). It is computed for both Basset-history rules at a collision: the
//! thesis's `reset` (pre-collision history discarded, jump term kept, eq. 2.29) and `keep`
//! (the collision's velocity change enters the history like any other). Charts:
//! * `collisions_trajectories.svg`: height y/L against time of both particles, alone and in
//!   the pair, for I = 0.02, 0.41, 0.78 and both rules.
//! * `collisions_delays.svg`: the delays against I with the thesis's experimental values at
//!   I = 0.02 (+15 % sinking, +45 % rising).

use std::path::Path;

use rayon::prelude::*;
use serde_json::{Value, json};

use super::runtime;
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use magsep_components::prelude::*;

/// The shipped scene.
const SCENE: &str = include_str!("../../../scenes/binary_collision.toml");
/// L of the rig [m] (y = z − L).
const HALF_HEIGHT: f64 = 0.075;
/// The thesis's delays at I = 0.02 (experiment, [T002 §2.5.2.2, Fig. 2.12]): sinking PVC-U, rising POM.
const THESIS_DELAYS: (f64, f64) = (0.15, 0.45);

/// One run: the sampled heights y/L of every particle and their levitation times [s].
struct RunOut {
    times: Vec<f64>,
    heights: Vec<Vec<f64>>,
    levitation: Vec<Option<f64>>,
}

fn run(text: &str) -> Result<RunOut, BenchError> {
    let mut sim = super::simulation(text)?;
    let mut out = RunOut {
        times: Vec::new(),
        heights: Vec::new(),
        levitation: Vec::new(),
    };
    let mut step = 0u64;
    let summary = sim
        .run(|w| {
            step += 1;
            if !step.is_multiple_of(20) {
                return;
            }
            let mut rows: Vec<(ParticleId, f64)> = w
                .iter_entities()
                .filter_map(|e| Some((*e.get::<ParticleId>()?, e.get::<Position>()?.0.z)))
                .collect();
            rows.sort_by_key(|r| r.0);
            out.heights.resize(rows.len(), Vec::new());
            for (k, r) in rows.iter().enumerate() {
                out.heights[k].push((r.1 - HALF_HEIGHT) / HALF_HEIGHT);
            }
            out.times.push(w.resource::<StepClock>().time());
        })
        .map_err(runtime)?;
    out.levitation = summary["particle_details"]
        .as_array()
        .map(|a| a.iter().map(|p| p["levitation_time"].as_f64()).collect())
        .unwrap_or_default();
    Ok(out)
}

/// The scene text for impact factor `impact`, history rule `rule`, duration `duration`,
/// keeping only particle group `only` if given (0: PVC-U, 1: POM).
fn variant(impact: f64, rule: &str, duration: f64, only: Option<usize>) -> String {
    let s = SCENE
        .replace("duration = 12.0 ", &format!("duration = {duration} "))
        .replace(
            "friction = 0.005",
            &format!("friction = 0.005\nhistory = \"{rule}\""),
        )
        .replace(
            "[[0.0751, 0.075, 0.0075]]",
            &format!("[[{}, 0.075, 0.0075]]", 0.075 + impact * 5e-3),
        );
    match only {
        Some(k) => only_group(&s, k),
        None => s,
    }
}

/// A binary-collision scene (groups marked `# sinking` and `# rising`, then `[record]`) with
/// only group `k` kept (0: sinking, 1: rising).
pub(super) fn only_group(s: &str, k: usize) -> String {
    let i0 = s
        .find("[[particles]]                # sinking")
        .unwrap_or(0);
    let i1 = s.find("[[particles]]                # rising").unwrap_or(0);
    let rec = s.find("[record]").unwrap_or(s.len());
    if k == 0 {
        format!("{}{}", &s[..i1], &s[rec..])
    } else {
        format!("{}{}", &s[..i0], &s[i1..])
    }
}

fn delay(pair: Option<f64>, alone: Option<f64>) -> Option<f64> {
    Some(pair? / alone? - 1.0)
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_collisions(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let duration = if quick { 4.0 } else { 45.0 };
    let impacts: Vec<f64> = if quick {
        vec![0.02]
    } else {
        vec![0.02, 0.2, 0.41, 0.6, 0.78]
    };
    let rules = ["reset", "keep"];
    // alone: the rule does not matter without collisions
    let alone: Vec<RunOut> = [0usize, 1]
        .par_iter()
        .map(|&k| run(&variant(0.02, "reset", duration, Some(k))))
        .collect::<Result<_, _>>()?;
    let jobs: Vec<(f64, &str)> = rules
        .iter()
        .flat_map(|r| impacts.iter().map(move |&i| (i, *r)))
        .collect();
    let pairs: Vec<RunOut> = jobs
        .par_iter()
        .map(|(i, r)| run(&variant(*i, r, duration, None)))
        .collect::<Result<_, _>>()?;
    let (t_pvc, t_pom) = (alone[0].levitation[0], alone[1].levitation[0]);
    let mut rows = Vec::new();
    for ((impact, rule), p) in jobs.iter().zip(&pairs) {
        let (a, b) = (p.levitation[0], p.levitation[1]);
        rows.push(json!({
            "impact_factor": impact, "history": rule,
            "levitation_time_sinking_pvc": a, "levitation_time_rising_pom": b,
            "delay_sinking": delay(a, t_pvc), "delay_rising": delay(b, t_pom),
        }));
    }
    // trajectories for the three thesis impact factors
    let mut fig = Figure::new(
        format!(
            "Binary collisions, 5 mm PVC-U (sinking) and POM (rising), table 2.1 rig{}",
            if quick { " (quick: 4 s)" } else { "" }
        ),
        2,
    );
    let shown: Vec<f64> = impacts
        .iter()
        .copied()
        .filter(|i| [0.02, 0.41, 0.78].contains(i))
        .collect();
    for rule in rules {
        for &impact in &shown {
            let k = jobs
                .iter()
                .position(|j| j.0 == impact && j.1 == rule)
                .unwrap_or(0);
            let p = &pairs[k];
            let mut c = Chart::new(format!("I = {impact}, history {rule}"))
                .x_label("t [s]")
                .y_label("y / L")
                .legend(LegendPosition::TopRight);
            for (j, name) in ["PVC-U", "POM"].into_iter().enumerate() {
                let series = |o: &RunOut, idx: usize| {
                    o.times
                        .iter()
                        .copied()
                        .zip(o.heights.get(idx).cloned().unwrap_or_default())
                        .collect::<Vec<_>>()
                };
                c = c
                    .series(Series::new(format!("{name} pair"), series(p, j)).style(Style::Line))
                    .line(Line::new(format!("{name} alone"), series(&alone[j], 0)).dashed(true));
            }
            fig = fig.panel(c);
        }
    }
    let path = out.join("collisions_trajectories.svg");
    write_svg(&path, &fig.to_svg(520.0, 360.0)).map_err(runtime)?;
    let mut d = Chart::new("Levitation delay by one collision against the impact factor")
        .x_label("impact factor I = LCD / d")
        .y_label("t_l(pair) / t_l(alone) - 1")
        .legend(LegendPosition::TopRight);
    for rule in rules {
        for (k, name) in [(0usize, "sinking PVC-U"), (1, "rising POM")] {
            let pts: Vec<(f64, f64)> = jobs
                .iter()
                .zip(&pairs)
                .filter(|(j, _)| j.1 == rule)
                .filter_map(|(j, p)| {
                    let alone_t = if k == 0 { t_pvc } else { t_pom };
                    delay(p.levitation[k], alone_t).map(|x| (j.0, x))
                })
                .collect();
            d = d.series(Series::new(format!("{name}, {rule}"), pts));
        }
    }
    d = d
        .series(
            Series::new("thesis, sinking (exp.)", vec![(0.02, THESIS_DELAYS.0)])
                .style(Style::Markers),
        )
        .series(
            Series::new("thesis, rising (exp.)", vec![(0.02, THESIS_DELAYS.1)])
                .style(Style::Markers),
        );
    let path_d = out.join("collisions_delays.svg");
    write_svg(&path_d, &d.to_svg(640.0, 420.0)).map_err(runtime)?;
    let summary: Value = json!({
        "charts": [path.display().to_string(), path_d.display().to_string()],
        "duration_s": duration,
        "levitation_time_alone": {"sinking_pvc": t_pvc, "rising_pom": t_pom},
        "thesis_delays_at_0.02": {"sinking": THESIS_DELAYS.0, "rising": THESIS_DELAYS.1},
        "runs": rows,
    });
    crate::studies::bench::say(summary)
}
