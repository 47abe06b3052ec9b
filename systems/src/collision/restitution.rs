//! Wet normal restitution (Izard et al., thesis 002 eq. 2.36) and the collision-law provider
//! [`CollisionModel`].
//!
//! **Binary normal Stokes number** ([T002 §2.2.4.2]): `St_n = (2/9)(ρ*/ρ_f) Re_rel`, with the reduced
//! density `ρ* = (1/ρ_1 + 1/ρ_2)⁻¹` and `Re_rel = d u_n/ν` (`u_n` the normal approach speed of the
//! contact points, `ν` the kinematic viscosity).
//!
//! **Izard et al. correlation** (2.36):
//! `e_eff/e_dry = (1 + ln(2η_e/d)/St) exp(−(π/2)/√(St + ln(2η_e/d)))`, `η_e` the effective roughness.
//! Since `ln(2η_e/d) < 0`, the formula is defined only for `St > −ln(2η_e/d)` (7.42 for
//! `η_e = 1.5 µm`, `d = 5 mm`); below that threshold `e_eff = 0` (D-002-6 in docs/references.md),
//! and it is clamped to `[0, e_dry]` (it never exceeds `e_dry` for `η_e < d/2` anyway).
//! Examples (`e_dry = 0.86`, `η_e = 1.5 µm`, `d = 5 mm`): `St = 10 → e ≈ 0.084`,
//! `St = 14 → e ≈ 0.22`.
//!
//! **Choices where the thesis is silent.**
//! * *Unequal spheres:* `d` is the harmonic-mean diameter `d* = 2 d_1 d_2/(d_1 + d_2)` (twice the
//!   reduced radius times 2, i.e. `4 r_1 r_2/(r_1 + r_2)`), which is `d_p` for equal spheres, the only
//!   case the thesis uses. The same `d*` enters `Re_rel` and the roughness ratio `2η_e/d*`.
//! * *Wall collisions* (the thesis gives only the particle–particle form, [T002 eq. 2.36]): `ρ_2 → ∞`, so
//!   `ρ* = ρ_p`, and `d = d_p` (the particle's own diameter, not the `d* → 2 d_p` limit, so that the
//!   roughness ratio stays the particle's). Note that this wall Stokes number
//!   `(2/9)(ρ_p/ρ_f) Re` is twice the usual wall definition `(1/9)(ρ_p/ρ_f) Re` of Joseph et al.
//!   (2001) — it is the literal `ρ_2 → ∞` limit of the thesis form.
//! * *Resting contacts:* approaches slower than `rest_speed` are fully inelastic (`e_n = e_t = 0`,
//!   friction unchanged). Within a step the motion is ballistic, so a particle resting on a wall
//!   under gravity approaches it at `≈ g h` every step; with `e_n > 0` it would bounce off by a tiny
//!   amount each step (jitter), and a stack would produce ever-shorter bounce sequences (a Zeno /
//!   inelastic-collapse cascade). Fully inelastic slow impacts end such sequences: choose
//!   `rest_speed` a few times `|g_eff| h`. With wet restitution the Izard clamp already makes slow
//!   impacts inelastic (below `St = −ln(2η_e/d)`), so `rest_speed` matters mainly for dry models.

use super::impulse::CollisionLaw;

/// Reduced density `ρ* = (1/ρ_1 + 1/ρ_2)⁻¹` [kg/m³]; `rho_2 = ∞` (a wall) gives `ρ_1`.
///
/// ```
/// use magsep_systems::collision::restitution::reduced_density;
/// assert_eq!(reduced_density(1400.0, 1400.0), 700.0);
/// assert_eq!(reduced_density(1400.0, f64::INFINITY), 1400.0);
/// ```
pub fn reduced_density(rho_1: f64, rho_2: f64) -> f64 {
    1.0 / (1.0 / rho_1 + 1.0 / rho_2)
}

/// Binary normal Stokes number `St_n = (2/9)(ρ*/ρ_f)(d u_n/ν)` [-] from the reduced density `ρ*`
/// [kg/m³], fluid density `ρ_f` [kg/m³], diameter `d` \[m\], normal approach speed `u_n` [m/s] and
/// kinematic viscosity `ν` [m²/s].
///
/// ```
/// use magsep_systems::collision::restitution::binary_stokes_number;
/// let st = binary_stokes_number(700.0, 1400.0, 4e-3, 0.1, 4e-6);
/// assert!((st - 2.0 / 9.0 * 0.5 * 100.0).abs() < 1e-12);
/// ```
pub fn binary_stokes_number(
    reduced_density: f64,
    fluid_density: f64,
    diameter: f64,
    normal_speed: f64,
    kinematic_viscosity: f64,
) -> f64 {
    2.0 / 9.0 * reduced_density / fluid_density * diameter * normal_speed / kinematic_viscosity
}

/// Stokes number below which the Izard correlation gives no rebound, `−ln(2η_e/d)` [-], for the
/// roughness `η_e` \[m\] and diameter `d` \[m\].
///
/// ```
/// use magsep_systems::collision::restitution::izard_threshold;
/// assert!((izard_threshold(1.5e-6, 5e-3) - 7.418).abs() < 1e-3);
/// ```
pub fn izard_threshold(roughness: f64, diameter: f64) -> f64 {
    -(2.0 * roughness / diameter).ln()
}

/// Izard et al. ratio `e_eff/e_dry` (2.36) for the binary Stokes number `stokes`, roughness `η_e`
/// \[m\] and diameter `d` \[m\]; 0 at or below [`izard_threshold`], clamped to `[0, 1]`, 0 for NaN.
///
/// ```
/// use magsep_systems::collision::restitution::izard_ratio;
/// assert!((0.86 * izard_ratio(10.0, 1.5e-6, 5e-3) - 0.0836).abs() < 1e-4);
/// assert_eq!(izard_ratio(7.0, 1.5e-6, 5e-3), 0.0);
/// ```
pub fn izard_ratio(stokes: f64, roughness: f64, diameter: f64) -> f64 {
    let l = (2.0 * roughness / diameter).ln();
    let s = stokes + l;
    if s <= 0.0 || s.is_nan() {
        return 0.0;
    }
    let ratio = (1.0 + l / stokes) * (-(std::f64::consts::FRAC_PI_2) / s.sqrt()).exp();
    if ratio.is_nan() {
        0.0
    } else {
        ratio.clamp(0.0, 1.0)
    }
}

/// Normal restitution model.
///
/// ```
/// use magsep_systems::collision::restitution::Restitution;
/// let wet: Restitution = serde_json::from_str(
///     r#"{"kind": "wet", "dry_normal": 0.85, "roughness": 1.5e-6}"#).unwrap();
/// assert_eq!(wet, Restitution::Wet { dry_normal: 0.85, roughness: 1.5e-6 });
/// assert_eq!(Restitution::Dry { normal: 0.1 }.normal(1.0, 4e-3), 0.1);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Restitution {
    /// Constant normal restitution (the ch. 4 model, `e = 0.1`).
    Dry {
        /// Normal restitution `e_n` [-]. Range: [0, 1].
        normal: f64,
    },
    /// Izard et al. wet restitution (2.36) (the ch. 2 model).
    Wet {
        /// Dry normal restitution `e_n,dry` [-]. Range: [0, 1]. Thesis: 0.85 (runs), 0.86 (fit).
        dry_normal: f64,
        /// Effective surface roughness `η_e` \[m\]. Range: > 0. Thesis: 1.5e-6.
        roughness: f64,
    },
}

impl Restitution {
    /// Normal restitution at the binary Stokes number `stokes` for the diameter `d` \[m\].
    pub fn normal(&self, stokes: f64, diameter: f64) -> f64 {
        match *self {
            Self::Dry { normal } => normal,
            Self::Wet {
                dry_normal,
                roughness,
            } => dry_normal * izard_ratio(stokes, roughness, diameter),
        }
    }
}

/// The body a particle collides with.
///
/// ```
/// use magsep_systems::collision::restitution::Counterpart;
/// let other = Counterpart::Particle { diameter: 4e-3, density: 1200.0 };
/// # let _ = (other, Counterpart::Wall);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Counterpart {
    /// Another particle.
    Particle {
        /// Its diameter \[m\].
        diameter: f64,
        /// Its density [kg/m³].
        density: f64,
    },
    /// A static wall (infinite density and mass).
    Wall,
}

/// An invalid [`CollisionModel`] parameter.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CollisionModelError {
    /// A parameter lies outside its range.
    #[error("collision model parameter `{name}` = {value} is outside {range}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Allowed range.
        range: &'static str,
    },
}

/// Collision-law provider: restitution model, tangential restitution, friction, rest speed and the
/// fluid properties entering the Stokes number.
///
/// ```
/// use magsep_systems::collision::restitution::{CollisionModel, Counterpart};
/// let model = CollisionModel::default(); // thesis ch. 2 many-particle runs
/// model.validate().unwrap();
/// let other = Counterpart::Particle { diameter: 4e-3, density: 1400.0 };
/// let slow = model.law(4e-3, 1400.0, other, 0.01);
/// assert_eq!(slow.normal_restitution, 0.0); // St below the Izard threshold
/// let fast = model.law(4e-3, 1400.0, other, 1.0);
/// assert!(fast.normal_restitution > 0.5 && fast.normal_restitution < 0.85);
/// assert_eq!(fast.friction, 0.005);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollisionModel {
    /// Normal restitution model. Default: `Wet { dry_normal: 0.85, roughness: 1.5e-6 }` ([T002 §2.5.3]).
    pub restitution: Restitution,
    /// Tangential restitution `e_t` (stick regime) [-]. Default: 0 (ch. 4; ch. 2 runs all slide).
    /// Range: [−1, 1].
    pub tangential_restitution: f64,
    /// Coulomb friction coefficient μ [-]. Default: 0.005 ([T002 §2.5.3]; ch. 4 uses 0.05). Range: ≥ 0.
    pub friction: f64,
    /// Approaches slower than this are fully inelastic, `e_n = e_t = 0`; it is also the speed
    /// scale of the engine's resting contacts [m/s]. Default: 0.01 (below the Izard threshold of
    /// the default wet model for 2–5 mm spheres, so it changes no restitution there). Range: ≥ 0;
    /// choose at least a few `|g_eff| h`.
    pub rest_speed: f64,
    /// Fluid density ρ_f [kg/m³]. Default: 1400 (Table 2.3). Range: > 0.
    pub fluid_density: f64,
    /// Fluid kinematic viscosity ν [m²/s]. Default: 5.54e-3/1400 (Table 2.3). Range: > 0.
    pub kinematic_viscosity: f64,
}

impl Default for CollisionModel {
    fn default() -> Self {
        Self {
            restitution: Restitution::Wet {
                dry_normal: 0.85,
                roughness: 1.5e-6,
            },
            tangential_restitution: 0.0,
            friction: 0.005,
            rest_speed: 0.01,
            fluid_density: 1400.0,
            kinematic_viscosity: 5.54e-3 / 1400.0,
        }
    }
}

fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    range: &'static str,
) -> Result<(), CollisionModelError> {
    if ok {
        Ok(())
    } else {
        Err(CollisionModelError::OutOfRange { name, value, range })
    }
}

impl CollisionModel {
    /// A dry model with constant `e_n`, no tangential restitution, friction `μ` and rest speed
    /// [m/s] (fluid properties of the default model, unused).
    pub fn dry(normal_restitution: f64, friction: f64, rest_speed: f64) -> Self {
        Self {
            restitution: Restitution::Dry {
                normal: normal_restitution,
            },
            friction,
            rest_speed,
            ..Self::default()
        }
    }

    /// Checks every parameter against its documented range (the first violation; see
    /// [`violations`](Self::violations) for all of them).
    pub fn validate(&self) -> Result<(), CollisionModelError> {
        match self.violations().first() {
            Some(e) => Err(*e),
            None => Ok(()),
        }
    }

    /// Every parameter outside its documented range, in declaration order.
    pub fn violations(&self) -> Vec<CollisionModelError> {
        let unit = |x: f64| (0.0..=1.0).contains(&x);
        let positive = |x: f64| x > 0.0 && x.is_finite();
        let non_negative = |x: f64| x >= 0.0 && x.is_finite();
        let mut checks: Vec<(&'static str, f64, bool, &'static str)> = match self.restitution {
            Restitution::Dry { normal } => {
                vec![("restitution.normal", normal, unit(normal), "[0, 1]")]
            }
            Restitution::Wet {
                dry_normal,
                roughness,
            } => vec![
                (
                    "restitution.dry_normal",
                    dry_normal,
                    unit(dry_normal),
                    "[0, 1]",
                ),
                (
                    "restitution.roughness",
                    roughness,
                    positive(roughness),
                    "(0, ∞)",
                ),
            ],
        };
        let (et, mu, v) = (self.tangential_restitution, self.friction, self.rest_speed);
        let (rho, nu) = (self.fluid_density, self.kinematic_viscosity);
        checks.extend([
            (
                "tangential_restitution",
                et,
                (-1.0..=1.0).contains(&et),
                "[-1, 1]",
            ),
            ("friction", mu, non_negative(mu), "[0, ∞)"),
            ("rest_speed", v, non_negative(v), "[0, ∞)"),
            ("fluid_density", rho, positive(rho), "(0, ∞)"),
            ("kinematic_viscosity", nu, positive(nu), "(0, ∞)"),
        ]);
        checks
            .into_iter()
            .filter_map(|(name, value, ok, range)| check(name, value, ok, range).err())
            .collect()
    }

    /// Whether an approach at `approach_speed` [m/s] counts as a resting contact (fully inelastic).
    pub fn is_resting(&self, approach_speed: f64) -> bool {
        approach_speed < self.rest_speed
    }

    /// Normal restitution of a particle (diameter \[m\], density [kg/m³]) hitting `other` at the
    /// normal approach speed `approach_speed` [m/s], before the rest-speed rule.
    pub fn normal_restitution(
        &self,
        diameter: f64,
        density: f64,
        other: Counterpart,
        approach_speed: f64,
    ) -> f64 {
        match self.restitution {
            Restitution::Dry { normal } => normal,
            Restitution::Wet { .. } => {
                let (rho_star, d) = match other {
                    Counterpart::Particle {
                        diameter: d2,
                        density: rho2,
                    } => (
                        reduced_density(density, rho2),
                        2.0 * diameter * d2 / (diameter + d2),
                    ),
                    Counterpart::Wall => (density, diameter),
                };
                let st = binary_stokes_number(
                    rho_star,
                    self.fluid_density,
                    d,
                    approach_speed,
                    self.kinematic_viscosity,
                );
                self.restitution.normal(st, d)
            }
        }
    }

    /// Collision law of a particle (diameter \[m\], density [kg/m³]) hitting `other` at the normal
    /// approach speed `approach_speed` [m/s], including the rest-speed rule.
    pub fn law(
        &self,
        diameter: f64,
        density: f64,
        other: Counterpart,
        approach_speed: f64,
    ) -> CollisionLaw {
        if self.is_resting(approach_speed) {
            return CollisionLaw {
                normal_restitution: 0.0,
                tangential_restitution: 0.0,
                friction: self.friction,
            };
        }
        CollisionLaw {
            normal_restitution: self.normal_restitution(diameter, density, other, approach_speed),
            tangential_restitution: self.tangential_restitution,
            friction: self.friction,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn izard_spec_values_threshold_and_clamp() {
        let (eta, d, e_dry) = (1.5e-6, 5e-3, 0.86);
        let thr = izard_threshold(eta, d);
        assert!((thr - 7.4186).abs() < 1e-4, "{thr}");
        let e10 = e_dry * izard_ratio(10.0, eta, d);
        let e14 = e_dry * izard_ratio(14.0, eta, d);
        assert!((e10 - 0.084).abs() < 1e-3, "{e10}");
        assert!((e14 - 0.22).abs() < 1e-2, "{e14}");
        // at and below the threshold: no rebound; just above: continuous from 0
        assert_eq!(izard_ratio(thr, eta, d), 0.0);
        assert_eq!(izard_ratio(1.0, eta, d), 0.0);
        assert_eq!(izard_ratio(0.0, eta, d), 0.0);
        assert_eq!(izard_ratio(f64::NAN, eta, d), 0.0);
        assert!(izard_ratio(thr + 1e-6, eta, d) < 1e-6);
        // monotone and below e_dry up to huge Stokes numbers
        let mut last = 0.0;
        for k in 0..200 {
            let st = thr * (1.0 + 1e-3) * 1.1f64.powi(k);
            let r = izard_ratio(st, eta, d);
            assert!(r >= last && r <= 1.0, "{st} {r}");
            last = r;
        }
        assert!(last > 0.99);
        // absurd roughness (η > d/2): still clamped to e_dry
        assert_eq!(izard_ratio(0.5, 1e-2, 5e-3), 1.0);
    }

    #[test]
    fn stokes_number_pair_and_wall_conventions() {
        let m = CollisionModel {
            restitution: Restitution::Wet {
                dry_normal: 0.86,
                roughness: 1.5e-6,
            },
            rest_speed: 0.0,
            fluid_density: 1000.0,
            kinematic_viscosity: 1e-6,
            ..CollisionModel::default()
        };
        // equal spheres: ρ* = ρ/2, d = d_p; St = 10 at u such that (2/9)(1)(5e-3 u/1e-6) = 10
        let u = 10.0 / (2.0 / 9.0 * 5e3);
        let other = Counterpart::Particle {
            diameter: 5e-3,
            density: 2000.0,
        };
        let e = m.normal_restitution(5e-3, 2000.0, other, u);
        assert!((e - 0.86 * izard_ratio(10.0, 1.5e-6, 5e-3)).abs() < 1e-14);
        // wall: ρ* = ρ_p, so half the speed gives the same St
        let e_wall = m.normal_restitution(5e-3, 2000.0, Counterpart::Wall, u / 2.0);
        assert!((e_wall - e).abs() < 1e-12);
        // unequal spheres: harmonic-mean diameter
        let other = Counterpart::Particle {
            diameter: 1e-2,
            density: 2000.0,
        };
        let d_star = 2.0 * 5e-3 * 1e-2 / 1.5e-2;
        let st = binary_stokes_number(1000.0, 1000.0, d_star, 0.2, 1e-6);
        let e = m.normal_restitution(5e-3, 2000.0, other, 0.2);
        assert!((e - 0.86 * izard_ratio(st, 1.5e-6, d_star)).abs() < 1e-14);
    }

    #[test]
    fn rest_speed_makes_slow_impacts_fully_inelastic() {
        let m = CollisionModel {
            tangential_restitution: 0.3,
            ..CollisionModel::dry(0.9, 0.2, 0.05)
        };
        m.validate().unwrap();
        let slow = m.law(1e-3, 1000.0, Counterpart::Wall, 0.049);
        assert_eq!(
            (
                slow.normal_restitution,
                slow.tangential_restitution,
                slow.friction
            ),
            (0.0, 0.0, 0.2)
        );
        assert!(m.is_resting(0.049) && !m.is_resting(0.05));
        let fast = m.law(1e-3, 1000.0, Counterpart::Wall, 0.05);
        assert_eq!(
            (fast.normal_restitution, fast.tangential_restitution),
            (0.9, 0.3)
        );
    }

    #[test]
    fn validation_and_serde() {
        let bad = CollisionModel {
            friction: -1.0,
            ..CollisionModel::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(CollisionModelError::OutOfRange {
                name: "friction",
                ..
            })
        ));
        assert!(CollisionModel::dry(1.5, 0.0, 0.0).validate().is_err());
        let m = CollisionModel::default();
        let json = serde_json::to_string(&m).unwrap();
        let back: CollisionModel = serde_json::from_str(&json).unwrap();
        assert_eq!(back, m);
        let typo = json.replace("friction", "fricton");
        assert!(serde_json::from_str::<CollisionModel>(&typo).is_err());
    }
}
