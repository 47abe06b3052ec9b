//! The force model of the Brownian pipeline: field force on superparamagnetic moments,
//! dipole-dipole forces within a cut-off, and Mie(30, 15) pseudo-hard-sphere contacts
//! (thesis 000, eqs. 6.12, 6.19-6.23).
//!
//! * Moments are parallel to the local flux density B = B_ext + Σ fibres (ch. 5 fields), with
//!   magnitude from [`MomentModel`] (saturated, or Langevin eq. 6.22). Mutual induction
//!   between particles is neglected, as in the thesis ([T000 §6.2.4]: it matters only at ~mT fields).
//! * Field force `F = |m| ∇|B|` ([`crate::field::dipole_force`]), computed with the moments
//!   from one field evaluation per particle; with no fibres the applied
//!   field is uniform and exerts no force.
//! * Pair forces are summed per particle over a [`CellList`] in a fixed order, in parallel over
//!   particles: bitwise identical for any thread count.
//!
//! Which particles feel forces (`mobile`) and which exert pair forces (`exerts`) are separate
//! masks, so captured particles can keep or stop interacting (a scene option).

use glam::DVec3;
use magsep_components::brownian::MomentModel;
use rayon::prelude::*;

use super::cells::CellList;
use super::pair::{Mie, dipole_force};
use crate::field::{CylinderSource, FieldGradient, total_field, total_field_gradient};

/// Per-particle data the force model reads (all slices of length N, in `ParticleId` order).
#[derive(Debug, Clone, Copy)]
pub struct ParticleView<'a> {
    /// Radii a_i [m].
    pub radii: &'a [f64],
    /// Moment laws.
    pub moments: &'a [MomentModel],
    /// Particles that move and feel forces (not captured).
    pub mobile: &'a [bool],
    /// Particles that exert pair forces on others.
    pub exerts: &'a [bool],
}

/// The three force contributions and the moments at one configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ForceParts {
    /// Field force [N].
    pub field: Vec<DVec3>,
    /// Dipole-dipole force [N].
    pub dipole: Vec<DVec3>,
    /// Contact force [N].
    pub contact: Vec<DVec3>,
    /// Moments [A m²].
    pub moments: Vec<DVec3>,
}

impl ForceParts {
    /// Zeroed parts for `n` particles.
    pub fn zeros(n: usize) -> Self {
        Self {
            field: vec![DVec3::ZERO; n],
            dipole: vec![DVec3::ZERO; n],
            contact: vec![DVec3::ZERO; n],
            moments: vec![DVec3::ZERO; n],
        }
    }

    /// Sum of the three forces on particle `i` [N].
    #[inline]
    pub fn total(&self, i: usize) -> DVec3 {
        self.field[i] + self.dipole[i] + self.contact[i]
    }
}

/// The cell lists of one configuration.
#[derive(Debug, Clone, Default)]
pub struct PairCells {
    /// Cells of the dipole cut-off (None: no dipole forces).
    pub dipole: Option<CellList>,
    /// Cells of the Mie range (None: no soft core).
    pub contact: Option<CellList>,
}

/// Fibres, applied field and interaction parameters.
#[derive(Debug, Clone)]
pub struct ForceModel {
    /// Magnetised fibres.
    pub sources: Vec<CylinderSource>,
    /// Applied flux density [T].
    pub b_ext: glam::DVec3,
    /// Field tolerance (relative).
    pub tolerance: f64,
    /// Thermal energy k_B T [J].
    pub kt: f64,
    /// Mie contact (None: no soft core).
    pub mie: Option<Mie>,
    /// Dipole cut-off in units of the pair's mean radius (None: no dipole forces).
    pub dipole_cutoff: Option<f64>,
}

/// Parallel map over particles in chunks (sequential below 512 particles).
fn par_fill<T: Send>(out: &mut [T], f: impl Fn(usize, &mut T) + Sync + Send) {
    if out.len() < 512 {
        out.iter_mut().enumerate().for_each(|(i, o)| f(i, o));
    } else {
        out.par_iter_mut()
            .with_min_len(128)
            .enumerate()
            .for_each(|(i, o)| f(i, o));
    }
}

impl ForceModel {
    /// The moment of a particle with law `law` in flux density `b` [A m²].
    #[inline]
    pub fn moment(&self, law: &MomentModel, b: DVec3) -> DVec3 {
        let bm = b.length();
        if bm == 0.0 || !law.is_magnetic() {
            return DVec3::ZERO;
        }
        b * (law.magnitude(bm, self.kt) / bm)
    }

    /// The field and its gradient at `p` (uniform applied field when there are no fibres).
    pub fn field_gradient(&self, p: DVec3) -> FieldGradient {
        if self.sources.is_empty() {
            return FieldGradient {
                b: self.b_ext,
                grad_b: glam::DMat3::ZERO,
            };
        }
        total_field_gradient(&self.sources, self.b_ext, p, self.tolerance)
    }

    /// Moments of every particle and field forces on the mobile ones, from one field
    /// evaluation per particle (with the gradient only where a force is needed).
    pub fn moments_and_field(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        moments: &mut [DVec3],
        field: &mut [DVec3],
    ) {
        let mut pairs = vec![(DVec3::ZERO, DVec3::ZERO); x.len()];
        par_fill(&mut pairs, |i, o| {
            let law = &view.moments[i];
            if !law.is_magnetic() {
                *o = (DVec3::ZERO, DVec3::ZERO);
            } else if view.mobile[i] && !self.sources.is_empty() {
                let g = self.field_gradient(x[i]);
                *o = (
                    self.moment(law, g.b),
                    crate::field::dipole_force(&g, law, self.kt),
                );
            } else {
                let b = if self.sources.is_empty() {
                    self.b_ext
                } else {
                    total_field(&self.sources, self.b_ext, x[i], self.tolerance).b
                };
                *o = (self.moment(law, b), DVec3::ZERO);
            }
        });
        for (i, (m, f)) in pairs.into_iter().enumerate() {
            moments[i] = m;
            field[i] = f;
        }
    }

    /// Cell lists of the particles that exert pair forces: one with the dipole cut-off of the
    /// largest pair, one with the Mie range (so contacts do not scan the dipole neighbourhood).
    pub fn cells(&self, x: &[DVec3], view: &ParticleView) -> PairCells {
        let amax = view.radii.iter().copied().fold(0.0, f64::max);
        let build = |range: f64, reach: i64| {
            (range > 0.0 && range.is_finite())
                .then(|| CellList::build_with_reach(x, range, reach, |j| view.exerts[j]))
        };
        PairCells {
            dipole: self.dipole_cutoff.and_then(|c| build(c * amax, 2)),
            contact: self.mie.and_then(|m| build(2.0 * amax * m.min_ratio, 1)),
        }
    }

    /// Dipole-dipole forces on the mobile particles from the exerting ones [N].
    pub fn dipole_forces(
        &self,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        cells: &PairCells,
        out: &mut [DVec3],
    ) {
        let (Some(cut), Some(cells)) = (self.dipole_cutoff, cells.dipole.as_ref()) else {
            out.fill(DVec3::ZERO);
            return;
        };
        par_fill(out, |i, f| {
            *f = DVec3::ZERO;
            if !view.mobile[i] || moments[i] == DVec3::ZERO {
                return;
            }
            let (ai, mi) = (view.radii[i], moments[i]);
            let mut sum = DVec3::ZERO;
            cells.for_each_neighbour(x, i, cells.edge(), |j, d| {
                let rc = cut * 0.5 * (ai + view.radii[j]);
                if d.length_squared() < rc * rc {
                    sum += dipole_force(d, mi, moments[j]);
                }
            });
            *f = sum;
        });
    }

    /// Mie contact forces on the mobile particles from the exerting ones [N].
    pub fn contact_forces(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        cells: &PairCells,
        out: &mut [DVec3],
    ) {
        let (Some(mie), Some(cells)) = (self.mie, cells.contact.as_ref()) else {
            out.fill(DVec3::ZERO);
            return;
        };
        par_fill(out, |i, f| {
            *f = DVec3::ZERO;
            if !view.mobile[i] {
                return;
            }
            let ai = view.radii[i];
            let mut sum = DVec3::ZERO;
            cells.for_each_neighbour(x, i, cells.edge(), |j, d| {
                sum += mie.force(d, ai + view.radii[j]);
            });
            *f = sum;
        });
    }

    /// All parts at configuration `x` (the sub-step evaluation of the integrator).
    pub fn evaluate(&self, x: &[DVec3], view: &ParticleView, parts: &mut ForceParts) {
        let n = x.len();
        if parts.field.len() != n {
            *parts = ForceParts::zeros(n);
        }
        self.moments_and_field(x, view, &mut parts.moments, &mut parts.field);
        let cells = self.cells(x, view);
        let moments = std::mem::take(&mut parts.moments);
        self.dipole_forces(x, &moments, view, &cells, &mut parts.dipole);
        parts.moments = moments;
        self.contact_forces(x, view, &cells, &mut parts.contact);
    }
}
