//! `[[fibre_packings]] pack = {...}`: a fibre column packed by mechanical contraction when the
//! scene is read (see [`super::fibre_packing`] for the keys). The packing itself is the kernel
//! [`magsep_systems::packing::column::pack_rod_column`]; this module checks the keys and keeps
//! the columns already packed in this process, so the points of a sweep that share a packing
//! (same values, same seed) pack it once.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use magsep_components::packing::PackingConfig;
use magsep_systems::packing::column::{PackedColumn, RodColumn, pack_rod_column};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use super::SceneError;
use super::checks::{LENGTH_RANGE, check, within};

/// The most fibres of one packed column (its packing runs when the scene is read).
pub const MAX_PACKED_FIBRES: u64 = 5000;

/// Columns kept per process; beyond it the memo starts afresh (bounded memory).
const MEMO_CAPACITY: usize = 256;

/// `pack`: the column to pack.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackSpec {
    /// Number of fibres. Range 1..=5000. Or `height`.
    #[serde(default)]
    pub count: Option<u64>,
    /// Height of the packed column \[m\] instead of `count`: the count that fills it at
    /// `packing_fraction`, `round(φ π R_col² H / V_fibre)` (the packing stops at the target, so
    /// the height reached is within a fibre's share of this).
    #[serde(default)]
    pub height: Option<f64>,
    /// Fibre radius R \[m\].
    pub radius: f64,
    /// Length of a fibre's cylindrical part L \[m\] (the spherocylinder's caps add 2R).
    pub cylinder_length: f64,
    /// Radius of the tube \[m\]. Range: > 2R.
    pub column_radius: f64,
    /// Target packing fraction φ. Range (0, 0.7]; a packing that jams first stops there.
    pub packing_fraction: f64,
    /// Packing fraction of the random start. Default 0.01. Range [0.001, 0.3], below the target.
    #[serde(default)]
    pub initial_packing_fraction: Option<f64>,
    /// Seed of the packing. Default: `simulation.seed` as written in the scene.
    #[serde(default)]
    pub seed: Option<u64>,
}

impl PackSpec {
    /// Check the keys, reporting under `prefix` (`fibre_packings[i].pack`).
    pub fn validate(&self, prefix: &str, errors: &mut Vec<SceneError>) {
        let key = |k: &str| format!("{prefix}.{k}");
        let (lo, hi) = LENGTH_RANGE;
        let before = errors.len();
        within(errors, &key("radius"), self.radius, lo, hi, "m");
        within(
            errors,
            &key("column_radius"),
            self.column_radius,
            lo,
            hi,
            "m",
        );
        check(
            errors,
            self.cylinder_length.is_finite()
                && self.cylinder_length >= 0.0
                && self.cylinder_length <= 1e4 * self.radius.abs(),
            &key("cylinder_length"),
            || {
                format!(
                    "must be in [0, 1e4 radius] m, got {} (radius {})",
                    self.cylinder_length, self.radius
                )
            },
        );
        if self.radius.is_finite() && self.column_radius.is_finite() {
            check(
                errors,
                self.column_radius > 2.0 * self.radius,
                &key("column_radius"),
                || {
                    format!(
                        "must exceed the fibre diameter {} m, got {}",
                        2.0 * self.radius,
                        self.column_radius
                    )
                },
            );
        }
        check(
            errors,
            self.packing_fraction.is_finite()
                && self.packing_fraction > 0.0
                && self.packing_fraction <= 0.7,
            &key("packing_fraction"),
            || format!("must be in (0, 0.7], got {}", self.packing_fraction),
        );
        if let Some(phi0) = self.initial_packing_fraction {
            within(
                errors,
                &key("initial_packing_fraction"),
                phi0,
                1e-3,
                0.3,
                "",
            );
            check(
                errors,
                phi0.is_nan() || phi0 < self.packing_fraction,
                &key("initial_packing_fraction"),
                || {
                    format!(
                        "must be below packing_fraction {}, got {phi0}",
                        self.packing_fraction
                    )
                },
            );
        }
        match (self.count, self.height) {
            (Some(n), None) => check(
                errors,
                (1..=MAX_PACKED_FIBRES).contains(&n),
                &key("count"),
                || format!("must be in 1..={MAX_PACKED_FIBRES}, got {n}"),
            ),
            (None, Some(h)) => {
                within(errors, &key("height"), h, lo, hi, "m");
                let n = self.fibre_count();
                check(
                    errors,
                    errors.len() > before || (1..=MAX_PACKED_FIBRES).contains(&n),
                    &key("height"),
                    || {
                        let n = if n > MAX_PACKED_FIBRES {
                            format!("more than {MAX_PACKED_FIBRES}")
                        } else {
                            n.to_string()
                        };
                        format!(
                            "holds {n} fibres at packing_fraction {}: must be 1..={MAX_PACKED_FIBRES}",
                            self.packing_fraction
                        )
                    },
                );
            }
            _ => errors.push(SceneError::new(
                prefix,
                "give exactly one of count (fibres) or height [m] (of the column)",
            )),
        }
    }

    /// Volume of one fibre (a spherocylinder) \[m³\].
    pub fn fibre_volume(&self) -> f64 {
        let r = self.radius;
        std::f64::consts::PI * r * r * (self.cylinder_length + 4.0 / 3.0 * r)
    }

    /// The number of fibres: `count`, or the one that fills `height` at the target (beyond
    /// [`MAX_PACKED_FIBRES`] when the values are not usable).
    pub fn fibre_count(&self) -> u64 {
        if let Some(n) = self.count {
            return n;
        }
        let h = self.height.unwrap_or(0.0);
        let n = (self.packing_fraction * std::f64::consts::PI * self.column_radius.powi(2) * h
            / self.fibre_volume())
        .round();
        if n.is_finite() && n >= 0.0 && n <= (MAX_PACKED_FIBRES + 1) as f64 {
            n as u64
        } else {
            MAX_PACKED_FIBRES + 1
        }
    }

    /// The kernel's input with `seed` (the scene's) when the spec gives none.
    fn column(&self, seed: u64) -> RodColumn {
        RodColumn {
            count: self.fibre_count() as usize,
            radius: self.radius,
            cylinder_length: self.cylinder_length,
            column_radius: self.column_radius,
            packing_fraction: self.packing_fraction,
            initial_packing_fraction: self
                .initial_packing_fraction
                .unwrap_or(0.01f64.min(0.5 * self.packing_fraction)),
            seed: self.seed.unwrap_or(seed),
        }
    }
}

type Slot = Arc<OnceLock<Result<Arc<PackedColumn>, String>>>;

fn memo() -> &'static Mutex<HashMap<[u64; 7], Slot>> {
    static MEMO: OnceLock<Mutex<HashMap<[u64; 7], Slot>>> = OnceLock::new();
    MEMO.get_or_init(Default::default)
}

/// The column of a validated `spec` (scene seed `seed`), packed once per process.
pub fn packed(spec: &PackSpec, seed: u64) -> Result<Arc<PackedColumn>, String> {
    let c = spec.column(seed);
    let key = [
        c.count as u64,
        c.radius.to_bits(),
        c.cylinder_length.to_bits(),
        c.column_radius.to_bits(),
        c.packing_fraction.to_bits(),
        c.initial_packing_fraction.to_bits(),
        c.seed,
    ];
    let slot = {
        // a poisoned memo only means another thread panicked while inserting: the map is whole
        let mut map = memo().lock().unwrap_or_else(|p| p.into_inner());
        if map.len() >= MEMO_CAPACITY && !map.contains_key(&key) {
            map.clear();
        }
        map.entry(key).or_default().clone()
    };
    slot.get_or_init(|| {
        let config = PackingConfig::defaults_for(c.count, 2.0 * c.radius);
        pack_rod_column(&c, &config).map(Arc::new)
    })
    .clone()
}

/// The summary's record of the packed column of entry `index`.
pub fn report(index: usize, c: &PackedColumn) -> Value {
    json!({
        "index": index,
        "fibres": c.centres.len(),
        "packing_fraction": c.packing_fraction,
        "height": c.height,
        "compression_steps": c.steps,
        "jammed": c.jammed,
    })
}
