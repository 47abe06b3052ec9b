//! `[brownian.flow]`: the mean flow of the liquid that carries the particles through a fibre
//! column (thesis 000, ch. 7: the liquid flows through the magnetised packing; ch. 6 leaves
//! net flow out of the equations of motion and notes it "can be incorporated with an additional
//! linear term").
//!
//! ```toml
//! [brownian.flow]
//! kind = "uniform"
//! velocity = [0.0, 0.0, -1e-3]   # u [m/s], the interstitial (pore) velocity
//! ```
//!
//! Each free particle's overdamped update becomes `dx = (u + μF) dt + noise`; with hydrodynamic
//! interactions the flow advects every particle with u (the mean flow is not passed through the
//! mobility matrix). Captured particles do not move. The velocity is the *interstitial* one,
//! the mean velocity of the liquid in the pores, because that is what carries a particle; a
//! superficial (Darcy) velocity q = Q/A of a column of packing fraction φ corresponds to
//! u = q / (1 − φ).
//!
//! What it neglects: the flow field around each fibre (no stagnation points, no boundary layer:
//! the liquid moves with u everywhere, through the fibres' surfaces too) and any pressure or
//! velocity gradient along the column.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::scene::SceneError;

/// The largest flow speed accepted \[m/s\]. Magnetic filters run at mm/s to cm/s (the thesis's
/// gravity-driven column passed its liquid in minutes). At 1 m/s the Reynolds number of the
/// thesis's 0.4 mm fibres in water, ρ u D / η, is already 400: far beyond the laminar, creeping
/// flow in which a mean (Darcy) velocity describes a packing. A larger value is a unit mistake.
pub const MAX_FLOW_SPEED: f64 = 1.0;

/// A prescribed mean flow of the liquid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BrownianFlow {
    /// The same velocity everywhere and at all times.
    Uniform {
        /// The interstitial velocity u \[m/s\].
        velocity: [f64; 3],
    },
}

impl BrownianFlow {
    /// The mean velocity u \[m/s\] that advects the particles.
    pub fn velocity(&self) -> DVec3 {
        match *self {
            Self::Uniform { velocity } => DVec3::from_array(velocity),
        }
    }
}

/// Check `brownian.flow`: finite components, a speed of at most [`MAX_FLOW_SPEED`].
pub fn validate_flow(flow: &BrownianFlow, errors: &mut Vec<SceneError>) {
    match flow {
        BrownianFlow::Uniform { velocity } => {
            let mut finite = true;
            for (k, v) in velocity.iter().enumerate() {
                if !v.is_finite() {
                    finite = false;
                    errors.push(SceneError::new(
                        format!("brownian.flow.velocity[{k}]"),
                        format!("must be a finite number [m/s], got {v}"),
                    ));
                }
            }
            let speed = DVec3::from_array(*velocity).length();
            if finite && speed > MAX_FLOW_SPEED {
                errors.push(SceneError::new(
                    "brownian.flow.velocity",
                    format!(
                        "speed must be at most {MAX_FLOW_SPEED} m/s (laminar flow through a \
                         filter), got {speed:e} m/s"
                    ),
                ));
            }
        }
    }
}
