//! How much memory a scene needs, estimated before anything is allocated, and the budget it
//! is checked against (`magsep validate` prints both; `magsep run` refuses a scene over
//! budget with exit 2, naming the key that drives the estimate).
//!
//! Each pipeline estimates its own scenes ([`Pipeline::memory_estimate`](super::Pipeline::memory_estimate)); the default is
//! [`BASE_BYTES`] plus [`BYTES_PER_PARTICLE`] per particle. The per-particle figures are
//! twice the peak resident sizes measured with `/usr/bin/time -f %M` on 2,000 and 20,000
//! particle scenes (packing 1.6 KB, brownian free draining 2.5 KB, particle_fluid with a
//! 200-step history window 14 KB per particle), so they err on the safe side.
//!
//! The budget is [`DEFAULT_BUDGET_BYTES`] or three quarters of the machine's memory,
//! whichever is smaller; `--memory-budget <GiB>` or the environment variable
//! `MAGSEP_MEMORY_BUDGET` (GiB) override it.

use super::{Scene, SceneError};

/// Memory of the program with an empty scene, and margin \[bytes\].
pub const BASE_BYTES: f64 = 64.0 * 1024.0 * 1024.0;
/// Default memory per particle \[bytes\].
pub const BYTES_PER_PARTICLE: f64 = 4096.0;
/// The budget when the machine's memory is unknown or larger than 4/3 of it \[bytes\].
pub const DEFAULT_BUDGET_BYTES: u64 = 16 << 30;

/// A scene's estimated memory.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryEstimate {
    /// Estimated peak memory \[bytes\].
    pub bytes: f64,
    /// The scene key that drives the estimate (named by the over-budget error).
    pub key: String,
    /// What the estimate counts, in words.
    pub detail: String,
}

impl MemoryEstimate {
    /// [`BASE_BYTES`] + `per_particle` × the scene's particle count, driven by `particles`.
    pub fn per_particle(scene: &Scene, per_particle: f64) -> Self {
        let n = scene.total_particles() as f64;
        Self {
            bytes: BASE_BYTES + per_particle * n,
            key: "particles".into(),
            detail: format!("{n} particles at {} bytes each", per_particle.round()),
        }
    }
}

/// The default estimate of a pipeline that gives none.
pub fn default_estimate(scene: &Scene) -> MemoryEstimate {
    MemoryEstimate::per_particle(scene, BYTES_PER_PARTICLE)
}

/// Physical memory of this machine \[bytes\] (Linux `/proc/meminfo`; `None` elsewhere).
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The budget: `override_gib` if given, else `MAGSEP_MEMORY_BUDGET` (GiB), else
/// [`DEFAULT_BUDGET_BYTES`] or 3/4 of the physical memory, whichever is smaller.
///
/// # Errors
/// A message when the override (or the variable) is not a positive number.
pub fn budget(override_gib: Option<f64>) -> Result<u64, String> {
    let from_env = std::env::var("MAGSEP_MEMORY_BUDGET").ok();
    let given = match (override_gib, from_env) {
        (Some(g), _) => Some(("--memory-budget", g)),
        (None, Some(text)) => Some((
            "MAGSEP_MEMORY_BUDGET",
            text.trim().parse::<f64>().map_err(|_| {
                format!("MAGSEP_MEMORY_BUDGET must be a number of GiB, got {text:?}")
            })?,
        )),
        (None, None) => None,
    };
    match given {
        Some((name, g)) if !(g.is_finite() && g > 0.0 && g <= 1e6) => Err(format!(
            "{name} must be a number of GiB in (0, 1e6], got {g}"
        )),
        Some((_, g)) => Ok((g * (1u64 << 30) as f64) as u64),
        None => Ok(physical_memory()
            .map(|m| m / 4 * 3)
            .unwrap_or(DEFAULT_BUDGET_BYTES)
            .min(DEFAULT_BUDGET_BYTES)),
    }
}

/// The scene's estimate (its pipeline's, or [`BASE_BYTES`] for a field-only scene).
pub fn estimate(scene: &Scene) -> MemoryEstimate {
    match &scene.pipeline {
        Some(p) => p.memory_estimate(scene),
        None => MemoryEstimate {
            bytes: BASE_BYTES,
            key: "fibres".into(),
            detail: "a field-only scene".into(),
        },
    }
}

/// The scene's estimate, or an error at its key when it exceeds `budget` \[bytes\].
///
/// # Errors
/// A [`SceneError`] at the estimate's key, with both sizes and how to raise the budget.
pub fn check(scene: &Scene, budget: u64) -> Result<MemoryEstimate, SceneError> {
    let estimate = estimate(scene);
    if estimate.bytes > budget as f64 || !estimate.bytes.is_finite() {
        return Err(over_budget(&estimate, budget));
    }
    Ok(estimate)
}

/// The error of an `estimate` over `budget` \[bytes\], at the estimate's key.
pub fn over_budget(estimate: &MemoryEstimate, budget: u64) -> SceneError {
    SceneError::new(
        estimate.key.clone(),
        format!(
            "the scene needs about {} of memory ({}), more than the budget of {}; \
             make it smaller, or raise the budget with --memory-budget <GiB> \
             (or MAGSEP_MEMORY_BUDGET) if the machine has the memory",
            gib(estimate.bytes),
            estimate.detail,
            gib(budget as f64)
        ),
    )
}

/// `bytes` in GiB for messages.
pub fn gib(bytes: f64) -> String {
    format!("{:.2} GiB", bytes / (1u64 << 30) as f64)
}
