//! One sphere moving vertically in a quiescent magnetised liquid: the reduced system of
//! thesis 002, eq. 2.41-2.46 (corrected, erratum E-002-4), integrated with the same kernels and
//! the same step as the particle-fluid pipeline (`motion`, `drag`, `history`). It serves the
//! single-particle studies (levitation time against diameter, history effects, the critical
//! diameter by direct integration) and the validation against the exact unsteady-Stokes
//! solution; a pipeline test checks that the ECS path gives the same trajectory.
//!
//! The corrected coefficients of eq. 2.44 (β without its spurious 2π/g, ε positive, ζ with
//! 1/m_p) are implied: the forces are evaluated from their definitions, not from (2.44).

use glam::DVec3;

use super::config::{ForceTerms, Integrator};
use super::drag::{DragLaw, translational_drag};
use super::history::{HistoryError, HistoryKernel, HistoryPlan, HistoryState, basset_coefficient};
use super::magnet::{Liquid, MagnetModel};
use super::motion::{effective_mass, velocity_step};

/// A sphere in a liquid above/between magnets, moving along y (gravity along −y).
#[derive(Debug, Clone, PartialEq)]
pub struct SphereInLiquid {
    /// The liquid.
    pub liquid: Liquid,
    /// The magnets.
    pub magnet: MagnetModel,
    /// g [m/s²].
    pub gravity: f64,
    /// Sphere diameter d_p [m].
    pub diameter: f64,
    /// Sphere density ρ_p [kg/m³].
    pub density: f64,
    /// Terms of the equation of motion (rotation and collisions are ignored here).
    pub terms: ForceTerms,
    /// Steady drag law.
    pub drag_law: DragLaw,
    /// Velocity update.
    pub integrator: Integrator,
    /// History quadrature.
    pub history: HistoryKernel,
}

/// A sampled trajectory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    /// Sample times [s].
    pub times: Vec<f64>,
    /// Heights y [m].
    pub heights: Vec<f64>,
    /// Velocities v_y [m/s].
    pub velocities: Vec<f64>,
    /// History force F_H,y [N] at the sample times.
    pub history_force: Vec<f64>,
    /// Largest translational Reynolds number.
    pub max_reynolds: f64,
}

impl SphereInLiquid {
    /// The table 2.1 rig (bottom magnet, MnCl₂, PVC-U density) for a sphere of `diameter`.
    ///
    /// ```
    /// use magsep_systems::fluid::single::SphereInLiquid;
    /// let s = SphereInLiquid::table_2_1(5e-3);
    /// assert_eq!(s.density, 1434.0);
    /// ```
    pub fn table_2_1(diameter: f64) -> Self {
        Self {
            liquid: Liquid {
                density: 1403.0,
                viscosity: 5.54e-3,
                susceptibility: 7e-4,
            },
            magnet: MagnetModel::Bottom {
                surface_field: 422e3,
                pole_size: 0.1181,
                half_height: 0.075,
            },
            gravity: 9.81,
            diameter,
            density: 1434.0,
            terms: ForceTerms::default(),
            drag_law: DragLaw::SchillerNaumann,
            integrator: Integrator::Implicit,
            history: HistoryKernel::window(0.2, 1e-3, true),
        }
    }

    /// A sphere of `radius` [m] and `density` [kg/m³] released in quiescent MnCl₂(aq) without
    /// a magnet, with Stokes drag: the set-up of the exact unsteady-Stokes release
    /// (`stokes_reference::StokesRelease`) used to validate the history quadrature.
    ///
    /// ```
    /// use magsep_systems::fluid::history::HistoryKernel;
    /// use magsep_systems::fluid::single::SphereInLiquid;
    /// let s = SphereInLiquid::stokes_release(50e-6, 1434.0, HistoryKernel::Full);
    /// assert_eq!(s.diameter, 100e-6);
    /// ```
    pub fn stokes_release(radius: f64, density: f64, history: HistoryKernel) -> Self {
        Self {
            liquid: Liquid {
                density: 1403.0,
                viscosity: 5.54e-3,
                susceptibility: 0.0,
            },
            magnet: MagnetModel::None,
            gravity: 9.81,
            diameter: 2.0 * radius,
            density,
            terms: ForceTerms {
                magnetic_buoyancy: false,
                ..ForceTerms::default()
            },
            drag_law: DragLaw::Stokes,
            integrator: Integrator::Implicit,
            history,
        }
    }

    /// Volume [m³].
    pub fn volume(&self) -> f64 {
        std::f64::consts::PI * self.diameter.powi(3) / 6.0
    }

    /// Net force without drag and history at height y [N] (gravity, buoyancy, magnetic
    /// buoyancy, as switched on).
    pub fn static_force(&self, y: f64) -> f64 {
        let v = self.volume();
        let mut f = 0.0;
        if self.terms.gravity {
            f -= self.density * v * self.gravity;
        }
        if self.terms.buoyancy {
            f += self.liquid.density * v * self.gravity;
        }
        if self.terms.magnetic_buoyancy {
            f += self
                .magnet
                .magnetic_buoyancy(self.liquid.susceptibility, v, y);
        }
        f
    }

    /// Integrate from (y0 [m], v0 [m/s]) at t = 0 to `t_end` [s] with step `dt` [s], keeping
    /// every `sample_every`-th state (and the first and last).
    ///
    /// # Errors
    /// An invalid `dt` or history window.
    ///
    /// ```
    /// use magsep_systems::fluid::single::SphereInLiquid;
    /// let s = SphereInLiquid::table_2_1(2e-3);
    /// let t = s.simulate(-0.9 * 0.075, 0.0, 1e-3, 20.0, 100).unwrap();
    /// let y_e = s.magnet.equilibrium_height(&s.liquid, s.gravity, s.density).unwrap();
    /// assert!((t.heights.last().unwrap() - y_e).abs() < 5e-4);
    /// ```
    pub fn simulate(
        &self,
        y0: f64,
        v0: f64,
        dt: f64,
        t_end: f64,
        sample_every: usize,
    ) -> Result<Trajectory, HistoryError> {
        let plan = HistoryPlan::new(dt, self.history)?;
        let mut state = HistoryState::new(DVec3::new(0.0, -v0, 0.0), 0.0);
        let c_h = basset_coefficient(self.diameter, self.liquid.density, self.liquid.viscosity);
        let mass = effective_mass(
            self.density * self.volume(),
            self.volume(),
            self.liquid.density,
            self.terms.added_mass,
        );
        let implicit = self.integrator == Integrator::Implicit;
        let steps = (t_end / dt).round().max(0.0) as u64;
        let every = sample_every.max(1) as u64;
        let mut out = Trajectory::default();
        let (mut y, mut v) = (y0, v0);
        let mut f_h = 0.0;
        let record = |n: u64, y: f64, v: f64, f_h: f64, out: &mut Trajectory| {
            out.times.push(n as f64 * dt);
            out.heights.push(y);
            out.velocities.push(v);
            out.history_force.push(f_h);
        };
        record(0, y, v, 0.0, &mut out);
        for n in 0..steps {
            let t_next = (n + 1) as f64 * dt;
            let mut force = self.static_force(y);
            let mut stiffness = 0.0;
            if self.terms.drag {
                let (fd, k, re) = translational_drag(
                    self.drag_law,
                    self.liquid.density,
                    self.liquid.viscosity,
                    self.diameter,
                    DVec3::new(0.0, -v, 0.0),
                );
                force += fd.y;
                out.max_reynolds = out.max_reynolds.max(re);
                if implicit {
                    stiffness += k;
                }
            }
            let mut history_part = 0.0;
            if self.terms.history {
                history_part = if implicit {
                    stiffness += c_h * plan.newest_weight();
                    c_h * state.past_integral(&plan, t_next).y
                } else {
                    c_h * state.current_integral(&plan, n as f64 * dt).y
                };
                force += history_part;
            }
            let v_new = velocity_step(DVec3::Y * v, DVec3::Y * force, mass, stiffness, dt).y;
            if self.terms.history {
                f_h = if implicit {
                    history_part + c_h * plan.newest_weight() * (v - v_new)
                } else {
                    history_part
                };
                state.push(&plan, DVec3::new(0.0, -v_new, 0.0));
            }
            v = v_new;
            y += dt * v;
            if (n + 1) % every == 0 || n + 1 == steps {
                record(n + 1, y, v, f_h, &mut out);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
#[path = "single_tests.rs"]
mod tests;
