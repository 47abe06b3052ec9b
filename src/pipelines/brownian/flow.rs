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
//! Or the velocity from Darcy's law through a fibre packing with a Kozeny-Carman permeability
//! (thesis 000, eqs. 7.3-7.4):
//!
//! ```toml
//! [brownian.flow]
//! kind = "darcy"
//! pressure_gradient = [0.0, 0.0, 1e4]   # ∇P [Pa/m]; the liquid flows down the gradient
//! packing_fraction = 0.3                # φ of the fibres
//! fibre_diameter = 400e-6               # D [m]
//! fibre_length = 4e-3                   # L [m]; optional, default: long fibres (ν = D/4)
//! kozeny_carman = 5.0                   # C_KC; optional, default 5
//! ```
//!
//! `k = (1 − φ)³ ν² / (C_KC φ²)` with `ν = V/S` of one fibre (a cylinder: `ν = D L / (4 L + 2 D)`),
//! the superficial velocity `q = −(k/η) ∇P` (η: `brownian.viscosity`) and the interstitial
//! velocity `u = q / (1 − φ)`. The thesis gives no C_KC; 5 is the conventional value for
//! packed beds (Carman). Assumed: laminar, steady, incompressible flow through a homogeneous,
//! isotropic packing (no wall channelling, no alignment), fibres wet and fixed.
//!
//! Either kind takes `around_fibres = "potential"`: the liquid then flows around each fibre as
//! 2D potential flow past a cylinder, added to u (Watson's model of a magnetic filter's wire;
//! `magsep_systems::brownian::fibre_flow` states its limits: truncated at 8 fibre radii, ends
//! not modelled, perturbations of close fibres added). Without it (`none`, the default) both
//! neglect the flow field around each fibre (no stagnation points, no boundary
//! layer: the liquid moves with u everywhere, through the fibres' surfaces too, so that every
//! particle on a path through a fibre is captured at any speed) and any
//! variation of the velocity along the column.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::scene::SceneError;
use crate::scene::checks::{LENGTH_RANGE, within};

/// The largest flow speed accepted \[m/s\]. Magnetic filters run at mm/s to cm/s (the thesis's
/// gravity-driven column passed its liquid in minutes). At 1 m/s the Reynolds number of the
/// thesis's 0.4 mm fibres in water, ρ u D / η, is already 400: far beyond the laminar, creeping
/// flow in which a mean (Darcy) velocity describes a packing. A larger value is a unit mistake.
pub const MAX_FLOW_SPEED: f64 = 1.0;

/// The Kozeny-Carman constant when the scene gives none (Carman's value for packed beds; the
/// thesis gives no value).
pub const DEFAULT_KOZENY_CARMAN: f64 = 5.0;

/// A prescribed mean flow of the liquid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BrownianFlow {
    /// The same velocity everywhere and at all times.
    Uniform {
        /// The interstitial velocity u \[m/s\].
        velocity: [f64; 3],
        /// Through the fibres (`none`, default) or around them (`potential`).
        #[serde(default)]
        around_fibres: AroundFibres,
    },
    /// Darcy's law through a fibre packing with a Kozeny-Carman permeability.
    Darcy {
        /// Pressure gradient ∇P \[Pa/m\] (the liquid flows towards lower pressure).
        pressure_gradient: [f64; 3],
        /// Packing fraction φ of the fibres. Range [0.01, 0.9].
        packing_fraction: f64,
        /// Fibre diameter D \[m\].
        fibre_diameter: f64,
        /// Fibre length L \[m\] (cylindrical part); default: infinitely long (ν = D/4).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fibre_length: Option<f64>,
        /// Kozeny-Carman constant C_KC. Default 5. Range (0, 1000].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        kozeny_carman: Option<f64>,
        /// Through the fibres (`none`, default) or around them (`potential`).
        #[serde(default)]
        around_fibres: AroundFibres,
    },
}

/// How the liquid meets the fibres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AroundFibres {
    /// The mean velocity everywhere, through the fibres too.
    #[default]
    None,
    /// Potential flow past each fibre on top of the mean velocity (Watson's model of a
    /// magnetic filter's wire; see `magsep_systems::brownian::fibre_flow`).
    Potential,
}

/// Kozeny-Carman permeability \[m²\] of a packing of cylinders: `k = (1 − φ)³ ν² / (C φ²)`
/// with `ν = V/S = D L / (4 L + 2 D)` (end faces included; `L = None`: `D/4`).
///
/// ```
/// use magsep::brownian::flow::kozeny_carman_permeability;
/// // 4 mm x 0.4 mm fibres at φ = 0.2, C_KC = 5: 2.3e-8 m², the thesis's measured permeability
/// let k = kozeny_carman_permeability(0.2, 400e-6, Some(4e-3), 5.0);
/// assert!((k / 2.3e-8 - 1.0).abs() < 0.02);
/// ```
pub fn kozeny_carman_permeability(phi: f64, diameter: f64, length: Option<f64>, c: f64) -> f64 {
    let nu = match length {
        Some(l) => diameter * l / (4.0 * l + 2.0 * diameter),
        None => diameter / 4.0,
    };
    (1.0 - phi).powi(3) * nu * nu / (c * phi * phi)
}

impl BrownianFlow {
    /// Whether the liquid flows around the fibres (`around_fibres = "potential"`).
    pub fn around_fibres(&self) -> bool {
        let (Self::Uniform { around_fibres, .. } | Self::Darcy { around_fibres, .. }) = self;
        *around_fibres == AroundFibres::Potential
    }

    /// The mean interstitial velocity u \[m/s\] that advects the particles, in a liquid of
    /// viscosity `viscosity` \[Pa s\].
    pub fn velocity(&self, viscosity: f64) -> DVec3 {
        match *self {
            Self::Uniform { velocity, .. } => DVec3::from_array(velocity),
            Self::Darcy {
                pressure_gradient,
                packing_fraction: phi,
                fibre_diameter,
                fibre_length,
                kozeny_carman,
                ..
            } => {
                let c = kozeny_carman.unwrap_or(DEFAULT_KOZENY_CARMAN);
                let k = kozeny_carman_permeability(phi, fibre_diameter, fibre_length, c);
                let superficial = -DVec3::from_array(pressure_gradient) * (k / viscosity);
                superficial / (1.0 - phi)
            }
        }
    }
}

/// Finite components of the vector at `path`, each reported at its index.
fn finite_vector(path: &str, v: &[f64; 3], unit: &str, errors: &mut Vec<SceneError>) -> bool {
    let mut finite = true;
    for (k, x) in v.iter().enumerate() {
        if !x.is_finite() {
            finite = false;
            errors.push(SceneError::new(
                format!("{path}[{k}]"),
                format!("must be a finite number {unit}, got {x}"),
            ));
        }
    }
    finite
}

/// Check `brownian.flow` (`viscosity` \[Pa s\]: the liquid's, already checked): finite
/// values in range, and a resulting speed of at most [`MAX_FLOW_SPEED`].
pub fn validate_flow(flow: &BrownianFlow, viscosity: f64, errors: &mut Vec<SceneError>) {
    let before = errors.len();
    let key = match flow {
        BrownianFlow::Uniform { velocity, .. } => {
            finite_vector("brownian.flow.velocity", velocity, "[m/s]", errors);
            "velocity"
        }
        BrownianFlow::Darcy {
            pressure_gradient,
            packing_fraction,
            fibre_diameter,
            fibre_length,
            kozeny_carman,
            ..
        } => {
            let p = "brownian.flow";
            finite_vector(
                &format!("{p}.pressure_gradient"),
                pressure_gradient,
                "[Pa/m]",
                errors,
            );
            within(
                errors,
                &format!("{p}.packing_fraction"),
                *packing_fraction,
                0.01,
                0.9,
                "(volume fraction)",
            );
            let (lo, hi) = LENGTH_RANGE;
            within(
                errors,
                &format!("{p}.fibre_diameter"),
                *fibre_diameter,
                lo,
                hi,
                "[m]",
            );
            if let Some(l) = fibre_length {
                within(errors, &format!("{p}.fibre_length"), *l, 0.0, hi, "[m]");
            }
            if let Some(c) = kozeny_carman {
                within(
                    errors,
                    &format!("{p}.kozeny_carman"),
                    *c,
                    1e-3,
                    1e3,
                    "(C_KC)",
                );
            }
            "pressure_gradient"
        }
    };
    if errors.len() > before || !(viscosity.is_finite() && viscosity > 0.0) {
        return;
    }
    let speed = flow.velocity(viscosity).length();
    if speed.is_nan() || speed > MAX_FLOW_SPEED {
        errors.push(SceneError::new(
            format!("brownian.flow.{key}"),
            format!(
                "gives an interstitial speed of {speed:.3e} m/s; it must be at most \
                 {MAX_FLOW_SPEED} m/s (laminar flow through a filter)"
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The thesis's 4 mm x 0.4 mm fibres with C_KC = 5: ν = 0.0952 mm, and k = 1.0e-9 m² at
    /// φ = 0.49 (the random contact equation's packing for L/D = 10), 2.3e-8 m² at φ = 0.2 (the
    /// thesis's measured 2.2e-8 m²), computed by hand from eq. 7.4.
    #[test]
    fn kozeny_carman_matches_hand_values() {
        let k = |phi| kozeny_carman_permeability(phi, 400e-6, Some(4e-3), 5.0);
        assert!((k(0.49) / 1.0022e-9 - 1.0).abs() < 1e-3, "{}", k(0.49));
        assert!((k(0.2) / 2.3220e-8 - 1.0).abs() < 1e-3, "{}", k(0.2));
        // long fibres: ν → D/4
        let long = kozeny_carman_permeability(0.2, 400e-6, Some(1e3), 5.0);
        let limit = kozeny_carman_permeability(0.2, 400e-6, None, 5.0);
        assert!((long / limit - 1.0).abs() < 1e-6);
        assert!((limit - 0.8f64.powi(3) * 1e-8 / (5.0 * 0.04)).abs() < 1e-20);
    }

    /// Darcy's mass flow rate (eq. 7.3), U = k (ρ/η) A ΔP / L, is what the interstitial
    /// velocity carries through the pores: U = ρ A (1 − φ) |u|; u points down the gradient and
    /// scales as 1/η.
    #[test]
    fn darcy_velocity_gives_the_mass_flow_of_eq_7_3() {
        let (rho, eta, area, dp, len, phi) = (997.0, 0.89e-3, 3.1416e-4, 1e5, 0.28, 0.3);
        let flow = BrownianFlow::Darcy {
            pressure_gradient: [0.0, 0.0, dp / len],
            packing_fraction: phi,
            fibre_diameter: 400e-6,
            fibre_length: Some(7e-3),
            kozeny_carman: None,
            around_fibres: AroundFibres::None,
        };
        let u = flow.velocity(eta);
        let k = kozeny_carman_permeability(phi, 400e-6, Some(7e-3), 5.0);
        let mass_rate = k * rho / eta * area * dp / len;
        assert!((rho * area * (1.0 - phi) * u.length() / mass_rate - 1.0).abs() < 1e-12);
        assert!(u.z < 0.0 && u.x == 0.0 && u.y == 0.0, "{u}");
        assert!((flow.velocity(2.0 * eta) * 2.0 - u).length() < 1e-15 * u.length());
    }

    #[test]
    fn validation_names_the_key() {
        let check = |flow: BrownianFlow| {
            let mut errors = Vec::new();
            validate_flow(&flow, 1e-3, &mut errors);
            errors.iter().map(|e| e.path.clone()).collect::<Vec<_>>()
        };
        let darcy = |g: f64, phi: f64| BrownianFlow::Darcy {
            pressure_gradient: [g, 0.0, 0.0],
            packing_fraction: phi,
            fibre_diameter: 400e-6,
            fibre_length: None,
            kozeny_carman: None,
            around_fibres: AroundFibres::None,
        };
        assert!(check(darcy(1e4, 0.3)).is_empty());
        assert_eq!(check(darcy(1e4, 0.95)), ["brownian.flow.packing_fraction"]);
        assert_eq!(
            check(darcy(f64::NAN, 0.3)),
            ["brownian.flow.pressure_gradient[0]"]
        );
        assert_eq!(check(darcy(1e9, 0.3)), ["brownian.flow.pressure_gradient"]);
        let uniform = |v: f64| BrownianFlow::Uniform {
            velocity: [0.0, v, 0.0],
            around_fibres: AroundFibres::Potential,
        };
        assert!(check(uniform(1.0)).is_empty());
        assert_eq!(check(uniform(1.01)), ["brownian.flow.velocity"]);
        assert_eq!(check(uniform(f64::INFINITY)), ["brownian.flow.velocity[1]"]);
    }
}
