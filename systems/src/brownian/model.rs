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
//! * Pair forces are summed per particle over cached Verlet lists ([`VerletList`], one per
//!   range, rebuilt only when a particle has moved half the skin) in a fixed order, in
//!   parallel over particles: bitwise identical for any thread count.
//!
//! Which particles feel forces (`mobile`) and which exert pair forces (`exerts`) are separate
//! masks, so captured particles can keep or stop interacting (a scene option).

use glam::DVec3;
use magsep_components::brownian::MomentModel;
use rayon::prelude::*;

use super::pair::{Mie, dipole_force};
use super::patch::{FieldPatches, Patch, patched_field};
use super::verlet::VerletList;
use crate::field::{CylinderSource, FieldGradient, total_field, total_field_gradient};

/// Per-particle data the force model reads (all slices of length N, in `ParticleId` order).
#[derive(Debug, Clone, Copy)]
pub struct ParticleView<'a> {
    /// Radii a_i \[m\].
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
    /// Field force \[N\].
    pub field: Vec<DVec3>,
    /// Dipole-dipole force \[N\].
    pub dipole: Vec<DVec3>,
    /// Contact force \[N\].
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

    /// Sum of the three forces on particle `i` \[N\].
    #[inline]
    pub fn total(&self, i: usize) -> DVec3 {
        self.field[i] + self.dipole[i] + self.contact[i]
    }
}

/// The state the force model caches across evaluations: the neighbour lists of the pair
/// forces and the particles' field patches.
#[derive(Debug, Clone, Default)]
pub struct PairLists {
    /// Pairs within the dipole cut-off (used when the model has one).
    pub dipole: VerletList,
    /// Pairs within the Mie range (used when the model has a soft core).
    pub contact: VerletList,
    /// Field-patch memos (used when the model has a patch size).
    pub patches: FieldPatches,
    /// Per particle, a lower bound of its gap to the fibres where it last moved (the capture
    /// search's memo, see [`swept_capture_cached`](super::contact::swept_capture_cached)).
    pub capture_gaps: Vec<Option<super::contact::GapBound>>,
    /// The per-pair buffer of the dipole sum, kept across evaluations.
    pub pair_scratch: super::verlet::PairScratch,
    /// The learnt shifts of the parts' bounds ([`super::balance`]).
    pub balance: super::balance::PartBalance,
}

impl PairLists {
    /// Rebuilds of both lists so far.
    pub fn builds(&self) -> u64 {
        self.dipole.builds() + self.contact.builds()
    }

    /// Rebuild both lists at every evaluation (the uncached reference of the tests).
    pub fn set_rebuild_always(&mut self, on: bool) {
        self.dipole.rebuild_always = on;
        self.contact.rebuild_always = on;
    }
}

/// Skin of a list of pair range `range` for largest radius `amax` \[m\]: 15 % of the range,
/// at least 0.6 radii (0.3 diameters, LAMMPS's default skin in reduced units).
pub fn list_skin(range: f64, amax: f64) -> f64 {
    (0.15 * range).max(0.6 * amax)
}

/// Fibres, applied field and interaction parameters.
#[derive(Debug, Clone)]
pub struct ForceModel {
    /// Magnetised fibres.
    pub sources: Vec<CylinderSource>,
    /// Applied flux density \[T\].
    pub b_ext: glam::DVec3,
    /// Field tolerance (relative).
    pub tolerance: f64,
    /// Thermal energy k_B T \[J\].
    pub kt: f64,
    /// Mie contact (None: no soft core).
    pub mie: Option<Mie>,
    /// Dipole cut-off in units of the pair's mean radius (None: no dipole forces).
    pub dipole_cutoff: Option<f64>,
    /// Relative field-patch size ε ([`super::patch`]); None: the exact field everywhere.
    pub field_patch: Option<f64>,
}

/// Dipole force on `i` \[N\] from `j` at `d = x_i − x_j` within the pair's cut-off `cut` × mean
/// radius (zero beyond): the one pair rule of every dipole kernel.
#[inline]
pub(super) fn dipole_pair(cut: f64, d: DVec3, (ai, aj): (f64, f64), mi: DVec3, mj: DVec3) -> DVec3 {
    let rc = cut * 0.5 * (ai + aj);
    if d.length_squared() < rc * rc {
        dipole_force(d, mi, mj)
    } else {
        DVec3::ZERO
    }
}

/// The dipole force on `i` \[N\] gathered from the pair slots `pf` in its list order (a
/// pair without a slot, from a particle that does not exert, computed here); zero unless `i`
/// is mobile and magnetic.
#[inline]
fn dipole_gather(
    cut: f64,
    x: &[DVec3],
    moments: &[DVec3],
    view: &ParticleView,
    list: &VerletList,
    pf: &[DVec3],
    i: usize,
) -> DVec3 {
    if !view.mobile[i] || moments[i] == DVec3::ZERO {
        return DVec3::ZERO;
    }
    let mut sum = DVec3::ZERO;
    for (j, s) in list.entries(i) {
        sum += match pf.get(s as usize) {
            Some(&p) if j > i => p,
            Some(&p) => -p,
            None => dipole_pair(
                cut,
                x[i] - x[j],
                (view.radii[i], view.radii[j]),
                moments[i],
                moments[j],
            ),
        };
    }
    sum
}

/// Particles per chunk of the pair-force pass.
const PAIR_CHUNK: usize = 256;

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

    /// The field and its gradient at `p` (uniform applied field when there are no fibres),
    /// exact or from the patch memo `slot` of a particle of radius `a` \[m\].
    pub fn field_gradient(&self, p: DVec3, a: f64, slot: &mut Option<Patch>) -> FieldGradient {
        if self.sources.is_empty() {
            return FieldGradient {
                b: self.b_ext,
                grad_b: glam::DMat3::ZERO,
            };
        }
        match self.field_patch {
            Some(eps) => patched_field(&self.sources, self.b_ext, self.tolerance, eps, a, p, slot),
            None => total_field_gradient(&self.sources, self.b_ext, p, self.tolerance),
        }
    }

    /// Moment [A m²] and field force \[N\] of particle `i` (the force only when it is mobile);
    /// `slot` is its field-patch memo.
    pub fn moment_and_field_force(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        i: usize,
        slot: &mut Option<Patch>,
    ) -> (DVec3, DVec3) {
        let law = &view.moments[i];
        if !law.is_magnetic() {
            (DVec3::ZERO, DVec3::ZERO)
        } else if view.mobile[i] && !self.sources.is_empty() {
            let g = self.field_gradient(x[i], view.radii[i], slot);
            (
                self.moment(law, g.b),
                crate::field::dipole_force(&g, law, self.kt),
            )
        } else {
            let b = if self.sources.is_empty() {
                self.b_ext
            } else if self.field_patch.is_some() {
                self.field_gradient(x[i], view.radii[i], slot).b
            } else {
                total_field(&self.sources, self.b_ext, x[i], self.tolerance).b
            };
            (self.moment(law, b), DVec3::ZERO)
        }
    }

    /// Moments of every particle and field forces on the mobile ones, from one field
    /// evaluation per particle (with the gradient only where a force is needed).
    pub fn moments_and_field(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        patches: &mut FieldPatches,
        moments: &mut [DVec3],
        field: &mut [DVec3],
    ) {
        patches.ensure(x.len());
        if self.sources.is_empty() {
            self.uniform_moments(x, view, 0, moments, field);
            return;
        }
        let go = |(i, ((m, f), slot)): (usize, ((&mut DVec3, &mut DVec3), &mut Option<Patch>))| {
            (*m, *f) = self.moment_and_field_force(x, view, i, slot);
        };
        if x.len() < 512 {
            moments
                .iter_mut()
                .zip(field.iter_mut())
                .zip(patches.slots.iter_mut())
                .enumerate()
                .for_each(go);
        } else {
            moments
                .par_iter_mut()
                .zip(field.par_iter_mut())
                .zip(patches.slots.par_iter_mut())
                .with_min_len(128)
                .enumerate()
                .for_each(go);
        }
    }

    /// The moments of the particles `a..a + moments.len()` in a uniform field (no fibres)
    /// and their (zero) field forces. A moment depends on the particle's law alone, so
    /// consecutive particles of one law share one evaluation. Values already in place (the
    /// usual case: the last step's) are not written again: the other threads' pair passes
    /// read these arrays, and a write would take each cache line back from their caches.
    fn uniform_moments(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        a: usize,
        moments: &mut [DVec3],
        field: &mut [DVec3],
    ) {
        let bits = |v: &DVec3| v.to_array().map(f64::to_bits);
        let mut last: Option<(MomentModel, DVec3)> = None;
        for (k, (m, f)) in moments.iter_mut().zip(field.iter_mut()).enumerate() {
            let i = a + k;
            let law = view.moments[i];
            let v = match last {
                Some((l, v)) if l == law => v,
                _ => {
                    let v = self.moment_and_field_force(x, view, i, &mut None).0;
                    last = Some((law, v));
                    v
                }
            };
            if bits(m) != bits(&v) {
                *m = v;
            }
            if bits(f) != bits(&DVec3::ZERO) {
                *f = DVec3::ZERO;
            }
        }
    }

    /// The step's start: [`ForceModel::moments_and_field`] and [`ForceModel::update_lists`],
    /// the moments of a uniform field computed in the parts of the lists' displacement tests
    /// ([`super::parts::lists_within_skin_and`]: one parallel region for both, instead of a
    /// serial pass before it). The same values either way.
    pub fn prepare_step(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        lists: &mut PairLists,
        moments: &mut [DVec3],
        field: &mut [DVec3],
    ) -> u64 {
        let n = x.len();
        if !self.sources.is_empty() || moments.len() != n || field.len() != n {
            self.moments_and_field(x, view, &mut lists.patches, moments, field);
            return self.update_lists(x, view, lists);
        }
        lists.patches.ensure(n);
        let (dw, cw) =
            super::parts::lists_within_skin_and(x, lists, (moments, field), |a, m, f| {
                self.uniform_moments(x, view, a, m, f)
            });
        self.ensure_lists(x, view, lists, (dw, cw))
    }

    /// Make the neighbour lists of the particles that exert pair forces serve `x`: one with
    /// the dipole cut-off of the largest pair, one with the Mie range (so contacts do not scan
    /// the dipole neighbourhood). Returns the number of lists rebuilt.
    pub fn update_lists(&self, x: &[DVec3], view: &ParticleView, lists: &mut PairLists) -> u64 {
        // both lists' displacement tests in the parts of the step (each thread reads the
        // positions it wrote)
        let within = super::parts::lists_within_skin(x, lists);
        self.ensure_lists(x, view, lists, within)
    }

    /// [`ForceModel::update_lists`] after the displacement tests (`within` of the dipole and
    /// the contact list, see [`super::verlet::VerletList::ensure_checked`]).
    fn ensure_lists(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        lists: &mut PairLists,
        (dw, cw): (Option<bool>, Option<bool>),
    ) -> u64 {
        let amax = view.radii.iter().copied().fold(0.0, f64::max);
        let (dipole, contact) = (self.dipole_range(view), self.contact_range(view));
        let mut rebuilt = 0;
        let mut ensure = |list: &mut VerletList, range: f64, within: Option<bool>| {
            if range > 0.0 && range.is_finite() {
                let skin = list_skin(range, amax);
                rebuilt += list.ensure_checked(x, view.exerts, range, skin, within) as u64;
            }
        };
        if self.dipole_cutoff.is_some() {
            ensure(&mut lists.dipole, dipole, dw);
        }
        if self.mie.is_some() {
            ensure(&mut lists.contact, contact, cw);
        }
        rebuilt
    }

    /// Dipole-dipole forces on the mobile particles from the exerting ones \[N\].
    pub fn dipole_forces(
        &self,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        out: &mut [DVec3],
    ) {
        let Some(cut) = self.dipole_cutoff else {
            out.fill(DVec3::ZERO);
            return;
        };
        let pf = self.dipole_pair_pass(cut, x, moments, view, lists);
        par_fill(out, |i, f| {
            *f = dipole_gather(cut, x, moments, view, &lists.dipole, &pf, i)
        });
        lists.pair_scratch.put(pf);
    }

    /// Dipole-dipole \[N\] and contact forces \[N\] on the mobile particles: the same values as
    /// [`ForceModel::dipole_forces`] and [`ForceModel::contact_forces`], with both sums of a
    /// particle and the pairs it owns in one parallel region over fixed parts
    /// ([`super::parts::pair_forces_in_parts`]).
    pub fn pair_forces(
        &self,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        out: (&mut [DVec3], &mut [DVec3]),
    ) {
        super::parts::pair_forces_in_parts(self, x, moments, view, lists, out);
    }

    /// The dipole force of each listed pair on its lower index, in its slot (the buffer
    /// comes from `lists.pair_scratch`; give it back there).
    fn dipole_pair_pass(
        &self,
        cut: f64,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
    ) -> Vec<DVec3> {
        let list = &lists.dipole;
        // each pair once (the force on its lower index), into its slot; chunks of particles
        // own consecutive slot ranges
        let n = x.len();
        // every slot is written below before it is read
        let mut pf = lists.pair_scratch.take(list.pair_count());
        let mut parts: Vec<(usize, &mut [DVec3])> = Vec::with_capacity(n.div_ceil(PAIR_CHUNK));
        let mut rest = pf.as_mut_slice();
        for c in 0..n.div_ceil(PAIR_CHUNK) {
            let (a, b) = (c * PAIR_CHUNK, ((c + 1) * PAIR_CHUNK).min(n));
            let len = list.owned_range(a, b).len().min(rest.len());
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            parts.push((a, head));
            rest = tail;
        }
        parts.into_par_iter().for_each(|(a, out)| {
            let mut k = 0;
            for i in a..(a + PAIR_CHUNK).min(n) {
                let (js, _) = list.owned(i);
                let (xi, ai, mi) = (x[i], view.radii[i], moments[i]);
                for &j in js {
                    let j = j as usize;
                    out[k] = dipole_pair(cut, xi - x[j], (ai, view.radii[j]), mi, moments[j]);
                    k += 1;
                }
            }
        });
        debug_assert_eq!(pf.len(), list.pair_count());
        pf
    }

    /// [`ForceModel::dipole_forces`] computed per particle over every neighbour, each pair
    /// twice: the simple reference the pair kernel is tested against.
    pub fn dipole_forces_direct(
        &self,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        out: &mut [DVec3],
    ) {
        if self.dipole_cutoff.is_none() {
            out.fill(DVec3::ZERO);
            return;
        }
        let range = self.dipole_range(view);
        par_fill(out, |i, f| {
            *f = self.dipole_force_on(x, moments, view, lists, range, i)
        });
    }

    /// Dipole cut-off of the largest pair \[m\] (0 without dipole forces).
    pub fn dipole_range(&self, view: &ParticleView) -> f64 {
        self.dipole_cutoff
            .map_or(0.0, |c| c * view.radii.iter().copied().fold(0.0, f64::max))
    }

    /// Dipole-dipole force on particle `i` \[N\] from its listed neighbours within `range`
    /// ([`ForceModel::dipole_range`]; zero unless `i` is mobile and magnetic).
    pub fn dipole_force_on(
        &self,
        x: &[DVec3],
        moments: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        range: f64,
        i: usize,
    ) -> DVec3 {
        let Some(cut) = self.dipole_cutoff else {
            return DVec3::ZERO;
        };
        if !view.mobile[i] || moments[i] == DVec3::ZERO {
            return DVec3::ZERO;
        }
        let (ai, mi) = (view.radii[i], moments[i]);
        let mut sum = DVec3::ZERO;
        lists.dipole.for_each_neighbour(x, i, range, |j, d| {
            sum += dipole_pair(cut, d, (ai, view.radii[j]), mi, moments[j]);
        });
        sum
    }

    /// Mie contact forces on the mobile particles from the exerting ones \[N\].
    pub fn contact_forces(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        out: &mut [DVec3],
    ) {
        if self.mie.is_none() {
            out.fill(DVec3::ZERO);
            return;
        }
        let range = self.contact_range(view);
        par_fill(out, |i, f| {
            *f = self.contact_force_on(x, view, lists, range, i)
        });
    }

    /// Mie contact force on particle `i` \[N\] from its listed neighbours within `range` \[m\]
    /// (zero unless it is mobile).
    pub fn contact_force_on(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        lists: &PairLists,
        range: f64,
        i: usize,
    ) -> DVec3 {
        let Some(mie) = self.mie else {
            return DVec3::ZERO;
        };
        if !view.mobile[i] {
            return DVec3::ZERO;
        }
        let ai = view.radii[i];
        let mut sum = DVec3::ZERO;
        lists.contact.for_each_neighbour(x, i, range, |j, d| {
            sum += mie.force(d, ai + view.radii[j]);
        });
        sum
    }

    /// Mie range of the largest pair \[m\] (0 without a soft core).
    pub fn contact_range(&self, view: &ParticleView) -> f64 {
        self.mie.map_or(0.0, |m| {
            2.0 * view.radii.iter().copied().fold(0.0, f64::max) * m.min_ratio
        })
    }

    /// All parts at configuration `x` (the sub-step evaluation of the integrator), with the
    /// lists brought up to date.
    pub fn evaluate(
        &self,
        x: &[DVec3],
        view: &ParticleView,
        lists: &mut PairLists,
        parts: &mut ForceParts,
    ) {
        let n = x.len();
        if parts.field.len() != n {
            *parts = ForceParts::zeros(n);
        }
        self.moments_and_field(
            x,
            view,
            &mut lists.patches,
            &mut parts.moments,
            &mut parts.field,
        );
        self.update_lists(x, view, lists);
        let moments = std::mem::take(&mut parts.moments);
        let out = (parts.dipole.as_mut_slice(), parts.contact.as_mut_slice());
        self.pair_forces(x, &moments, view, lists, out);
        parts.moments = moments;
    }
}

#[cfg(test)]
#[path = "model_tests.rs"]
mod tests;
