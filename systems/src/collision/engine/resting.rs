//! The resting-contact solve at the start of the step (see the engine header): a warm-started,
//! projected Gauss–Seidel solve of fully inelastic contacts with Coulomb friction, the converged
//! limit of the sequence of `e = 0` binary collisions that touching particles would otherwise
//! exchange at `t = 0`.
//!
//! Contacts: candidate pairs and particle–wall pairs with gap `≤ rest_speed · h` whose normal
//! approach speed is below `rest_speed`. Per contact, with `K` the collision matrix, the
//! accumulated normal impulse obeys `λ_n ≥ 0` and the speculative target `v_n ≥ −max(gap, 0)/h`
//! (a pair a little apart may close the gap within the step, not more); the accumulated
//! tangential impulse is driven towards zero tangential contact velocity along the current slip
//! direction `t̂` with the scalar mass `1/(t̂·K t̂)` and clamped to `|λ_t| ≤ μ λ_n` (static =
//! dynamic friction, no tangential restitution: the rest-speed law).
//!
//! Order and convergence: the contacts are sorted by the distance of the contact point from the
//! nearest wall (then by index), so that a forward sweep carries the support of a bed up from its
//! floor; sweeps alternate direction (symmetric Gauss–Seidel) until no contact velocity changes by
//! more than `resting_tolerance · (r_i + r_j)/h`, or `resting_sweeps`. The final impulses are
//! cached (keyed by particle indices, so the caller must keep the particle order) and applied
//! first in the next step (warm start), which makes a resting stack converge in a few sweeps
//! instead of `O(height²)`.

use glam::DVec3;

use super::resting_fast::{self, Body, blocked};
use super::{CollisionEvent, FrictionRegime, InverseInertia, LastCollision, Partner, Sim};
use crate::collision::impulse::RigidBody;
use crate::collision::toi::ContactGeometry;

/// A cached resting-contact impulse (on the partner `j`; `j ≥ N` is wall `j − N`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Cached {
    i: u32,
    j: u32,
    normal: f64,
    tangent: DVec3,
}

/// One resting contact during the solve (compact: the sweeps are memory bound).
#[derive(Debug, Clone, Copy)]
pub(super) struct Contact {
    pub(super) i: u32,
    pub(super) j: u32,
    pub(super) normal: DVec3,
    pub(super) r_a: DVec3,
    pub(super) r_b: DVec3,
    pub(super) m_n: f64,
    pub(super) bias: f64,
    pub(super) approach: f64,
    /// Distance of the contact point from the nearest wall (sweep order) [m].
    pub(super) depth: f64,
    pub(super) lambda_n: f64,
    pub(super) lambda_t: DVec3,
}

impl Contact {
    fn ij(&self) -> (usize, usize) {
        (self.i as usize, self.j as usize)
    }

    /// The residual scale of this contact [m/s per unit of `tol`]: `tol` times the summed
    /// radii (twice the particle's radius against a wall, `j ≥ n`).
    fn scale(&self, radius: &[f64], n: usize, tol: f64) -> f64 {
        let (i, j) = self.ij();
        tol * if j < n {
            radius[i] + radius[j]
        } else {
            2.0 * radius[i]
        }
    }
}

impl Sim<'_, '_> {
    /// `I_i⁻¹ x` [1/(kg m²) · x].
    #[inline]
    fn inv_inertia_times(&self, i: usize, x: DVec3) -> DVec3 {
        match self.p.inv_inertias {
            InverseInertia::Scalar(s) => x * s[i],
            InverseInertia::Tensor(t) => t[i] * x,
            InverseInertia::Principal(_) => self.inv_inertia(i) * x,
        }
    }

    /// `t·K t` of contact `c` (see [`crate::collision::impulse::collision_matrix`]) [1/kg].
    #[inline]
    fn k_quad(&self, c: &Contact, t: DVec3) -> f64 {
        let (i, j) = c.ij();
        let ra = c.r_a.cross(t);
        let mut k = self.p.inv_masses[i] + ra.dot(self.inv_inertia_times(i, ra));
        if j < self.n() {
            let rb = c.r_b.cross(t);
            k += self.p.inv_masses[j] + rb.dot(self.inv_inertia_times(j, rb));
        }
        k
    }

    #[inline]
    fn contact_velocity(&self, c: &Contact) -> DVec3 {
        let (i, j) = c.ij();
        let a = self.p.velocities[i] + self.p.angular_velocities[i].cross(c.r_a);
        let b = if j < self.n() {
            self.p.velocities[j] + self.p.angular_velocities[j].cross(c.r_b)
        } else {
            DVec3::ZERO
        };
        b - a
    }

    /// Applies the impulse `p` on `j` and `−p` on `i`.
    #[inline]
    fn push(&mut self, c: &Contact, p: DVec3) {
        let (i, j) = c.ij();
        let dw = self.inv_inertia_times(i, c.r_a.cross(p));
        self.p.velocities[i] -= p * self.p.inv_masses[i];
        self.p.angular_velocities[i] -= dw;
        if j < self.n() {
            let dw = self.inv_inertia_times(j, c.r_b.cross(p));
            self.p.velocities[j] += p * self.p.inv_masses[j];
            self.p.angular_velocities[j] += dw;
        }
    }

    fn make_contact(&self, i: usize, j: usize, geo: ContactGeometry) -> Option<Contact> {
        let n = self.n();
        let margin = self.model.rest_speed * self.h;
        if geo.gap > margin || geo.gap.is_nan() {
            return None;
        }
        let a = self.body(i);
        let b = if j < n {
            self.body(j)
        } else {
            RigidBody::fixed()
        };
        let approach = -(b.point_velocity(geo.r_b) - a.point_velocity(geo.r_a)).dot(geo.normal);
        if !self.model.is_resting(approach) {
            return None;
        }
        let point = self.p.positions[i] + geo.r_a;
        let planes = self.domain.planes.iter();
        let depth = planes
            .map(|p| p.signed_distance(point))
            .fold(f64::INFINITY, f64::min);
        let mut c = Contact {
            i: i as u32,
            j: j as u32,
            normal: geo.normal,
            r_a: geo.r_a,
            r_b: geo.r_b,
            m_n: 0.0,
            bias: geo.gap.max(0.0) / self.h,
            approach,
            depth: if depth.is_finite() { depth } else { 0.0 },
            lambda_n: 0.0,
            lambda_t: DVec3::ZERO,
        };
        let knn = self.k_quad(&c, geo.normal);
        c.m_n = 1.0 / knn;
        (knn > 0.0 && knn.is_finite()).then_some(c)
    }

    /// Runs the resting-contact solve at `t = 0` (see the module header).
    pub(super) fn solve_resting(&mut self) {
        let mut contacts = std::mem::take(&mut self.eng.contacts);
        contacts.clear();
        self.eng.rest_rows.clear();
        self.eng.rest_partners.clear();
        self.resting_residual = 0.0;
        let enabled = self.cfg.resting_sweeps > 0 && self.h > 0.0 && self.model.rest_speed > 0.0;
        if !enabled {
            self.eng.warm.clear();
            self.eng.contacts = contacts;
            return;
        }
        let n = self.n();
        let margin = self.model.rest_speed * self.h;
        for i in 0..n {
            for &j in self.eng.candidates.of(i) {
                let j = j as usize;
                if j > i {
                    let xi = self.p.positions[i];
                    let dx = self.domain.minimum_image(self.p.positions[j] - xi);
                    let bound = self.eng.radius[i] + self.eng.radius[j] + margin;
                    if !(self.is_round(i) && self.is_round(j)) && dx.length() > bound {
                        continue; // bounding spheres apart: skip the contact solve
                    }
                    if let Some(geo) = self.pair_contact(i, j, xi, dx, 0.0) {
                        contacts.extend(self.make_contact(i, j, geo));
                    }
                }
            }
            for (w, plane) in self.domain.planes.iter().enumerate() {
                let geo = self.wall_contact(i, self.p.positions[i], 0.0, plane);
                contacts.extend(self.make_contact(i, n + w, geo));
            }
        }
        if contacts.is_empty() {
            self.eng.warm.clear();
            self.eng.contacts = contacts;
            return;
        }
        self.eng.v_start.clear();
        self.eng.v_start.extend_from_slice(self.p.velocities);
        let mu = self.model.friction;
        if self.cfg.warm_start {
            let warm = std::mem::take(&mut self.eng.warm);
            let mut k = 0;
            for c in contacts.iter_mut() {
                let key = (c.i, c.j);
                while k < warm.len() && (warm[k].i, warm[k].j) < key {
                    k += 1;
                }
                if k < warm.len() && (warm[k].i, warm[k].j) == key {
                    let nrm = c.normal;
                    c.lambda_n = warm[k].normal.max(0.0);
                    let t = warm[k].tangent - nrm * warm[k].tangent.dot(nrm);
                    c.lambda_t = t.clamp_length_max(mu * c.lambda_n);
                }
            }
            for c in &contacts {
                self.push(c, c.normal * c.lambda_n + c.lambda_t);
            }
            self.eng.warm = warm;
        }
        // sweep outwards from the walls: support propagates through a bed in one forward sweep
        contacts.sort_unstable_by(|a, b| {
            a.depth
                .total_cmp(&b.depth)
                .then((a.i, a.j).cmp(&(b.i, b.j)))
        });
        let tol = self.cfg.resting_tolerance / self.h;
        let (sweeps, residual) = match self.p.inv_inertias {
            InverseInertia::Scalar(s) if !self.eng.reference => {
                self.resting_sweeps_fast(&mut contacts, s, tol, mu)
            }
            _ => self.resting_sweeps_reference(&mut contacts, tol, mu),
        };
        self.finish_resting(&contacts, sweeps, residual);
        self.index_resting(&contacts);
        self.eng.contacts = contacts;
    }

    /// The sweeps on a compact copy of the bodies ([`super::resting_fast`]); bitwise equal to
    /// [`Self::resting_sweeps_reference`] for isotropic inertias `inv_inertia`.
    fn resting_sweeps_fast(
        &mut self,
        contacts: &mut [Contact],
        inv_inertia: &[f64],
        tol: f64,
        mu: f64,
    ) -> (usize, f64) {
        if self.cfg.nncg_sweeps > 0 {
            return self.resting_nncg(contacts, inv_inertia, tol, mu);
        }
        let n = self.n();
        let mut bodies = std::mem::take(&mut self.eng.fast.bodies);
        bodies.clear();
        bodies.extend((0..n).map(|i| self.fast_body(i, inv_inertia)));
        let mut scale = std::mem::take(&mut self.eng.fast.scale);
        scale.clear();
        let r = &self.eng.radius;
        scale.extend(contacts.iter().map(|c| c.scale(r, n, tol)));
        let max = self.cfg.resting_sweeps as usize;
        let out = resting_fast::sweeps(contacts, &mut bodies, &scale, n, mu, max);
        for (i, b) in bodies.iter().enumerate() {
            self.store_fast_body(i, b);
        }
        self.eng.fast.bodies = bodies;
        self.eng.fast.scale = scale;
        out
    }

    /// Particle `i` as the fast sweeps see it (isotropic inverse inertia `inv_inertia[i]`).
    fn fast_body(&self, i: usize, inv_inertia: &[f64]) -> Body {
        Body {
            v: self.p.velocities[i],
            w: self.p.angular_velocities[i],
            inv_mass: self.p.inv_masses[i],
            inv_inertia: inv_inertia[i],
        }
    }

    /// Write a fast sweep's velocities back to particle `i`.
    fn store_fast_body(&mut self, i: usize, b: &Body) {
        self.p.velocities[i] = b.v;
        self.p.angular_velocities[i] = b.w;
    }

    /// The NNCG solve on blocks of the contact graph ([`blocked`]) for isotropic inertias.
    fn resting_nncg(
        &mut self,
        contacts: &mut [Contact],
        inv_inertia: &[f64],
        tol: f64,
        mu: f64,
    ) -> (usize, f64) {
        let n = self.n();
        let mut lay = std::mem::take(&mut self.eng.fast.blocked);
        let blocks = blocked::layout(contacts, self.p.positions, self.domain, &mut lay);
        let mut bodies = std::mem::take(&mut self.eng.fast.bodies);
        bodies.clear();
        bodies.extend(
            lay.perm
                .iter()
                .map(|&i| self.fast_body(i as usize, inv_inertia)),
        );
        let mut scale = std::mem::take(&mut self.eng.fast.scale);
        scale.clear();
        let r = &self.eng.radius;
        scale.extend(
            lay.src
                .iter()
                .map(|&k| contacts[k as usize].scale(r, n, tol)),
        );
        let max = self.cfg.nncg_sweeps as usize;
        let (grouped, aux) = (&mut lay.grouped, &mut lay.aux);
        let out = blocked::sweeps(grouped, &mut bodies, blocks, &scale, aux, mu, max);
        for (g, &k) in lay.grouped.iter().zip(&lay.src) {
            let c = &mut contacts[k as usize];
            (c.lambda_n, c.lambda_t) = (g.lambda_n, g.lambda_t);
        }
        for (b, &i) in bodies.iter().zip(&lay.perm) {
            self.store_fast_body(i as usize, b);
        }
        self.eng.fast.bodies = bodies;
        self.eng.fast.scale = scale;
        self.eng.fast.blocked = lay;
        out
    }

    /// The plain projected Gauss–Seidel sweeps (the reference of [`Self::resting_sweeps_fast`]); returns
    /// the sweeps done and the residual.
    fn resting_sweeps_reference(
        &mut self,
        contacts: &mut [Contact],
        tol: f64,
        mu: f64,
    ) -> (usize, f64) {
        let n = self.n();
        let mut sweeps = 0;
        let mut residual = 0.0;
        while sweeps < self.cfg.resting_sweeps as usize {
            // symmetric Gauss–Seidel: alternate the sweep direction
            let backward = sweeps % 2 == 1;
            sweeps += 1;
            let (mut worst, mut worst_ratio) = (0.0f64, 0.0f64);
            let m = contacts.len();
            for k in 0..m {
                let c = &mut contacts[if backward { m - 1 - k } else { k }];
                let scale = c.scale(&self.eng.radius, n, tol);
                let dv = self.relax(c, mu);
                worst = worst.max(dv);
                worst_ratio = worst_ratio.max(dv / scale);
            }
            residual = worst;
            if worst_ratio < 1.0 || worst_ratio.is_nan() {
                break;
            }
        }
        (sweeps, residual)
    }

    /// One projected Gauss–Seidel update of contact `c` (normal, then friction); returns the
    /// largest contact-velocity change it caused [m/s].
    #[inline]
    fn relax(&mut self, c: &mut Contact, mu: f64) -> f64 {
        let nrm = c.normal;
        let vn = self.contact_velocity(c).dot(nrm);
        let target = (c.lambda_n - c.m_n * (vn + c.bias)).max(0.0);
        let dn = target - c.lambda_n;
        c.lambda_n = target;
        self.push(c, nrm * dn);
        let mut dv = (dn / c.m_n).abs();
        let v = self.contact_velocity(c);
        let vt = v - nrm * v.dot(nrm);
        let slip = vt.length();
        if slip > 0.0 {
            let t = vt / slip;
            let kt = self.k_quad(c, t);
            if kt > 0.0 {
                let lt = (c.lambda_t - vt / kt).clamp_length_max(mu * c.lambda_n);
                let dp = lt - c.lambda_t;
                c.lambda_t = lt;
                self.push(c, dp);
                dv = dv.max(dp.length() * kt);
            }
        }
        dv
    }

    /// Symmetric per-particle lists of the resting contacts (the event loop ignores their approaches
    /// up to twice the solve's residual, see the engine header) and that residual.
    fn index_resting(&mut self, contacts: &[Contact]) {
        let n = self.n();
        let mut residual = 0.0f64;
        let rows = &mut self.eng.rest_rows;
        rows.clear();
        rows.resize(n + 1, 0);
        for c in contacts {
            let (i, j) = c.ij();
            rows[i + 1] += 1;
            if j < n {
                rows[j + 1] += 1;
            }
        }
        for i in 0..n {
            rows[i + 1] += rows[i];
        }
        let mut fill = rows.clone();
        let partners = &mut self.eng.rest_partners;
        partners.clear();
        partners.resize(rows[n], 0);
        for c in contacts {
            let (i, j) = c.ij();
            partners[fill[i]] = c.j;
            fill[i] += 1;
            if j < n {
                partners[fill[j]] = c.i;
                fill[j] += 1;
            }
        }
        for i in 0..n {
            partners[rows[i]..rows[i + 1]].sort_unstable();
        }
        for c in contacts {
            let vn = self.contact_velocity(c).dot(c.normal);
            residual = residual.max(-(vn + c.bias));
        }
        self.resting_residual = residual;
    }

    /// Records the resting impulses (events, last collisions, stats) and refreshes the cache.
    fn finish_resting(&mut self, contacts: &[Contact], sweeps: usize, residual: f64) {
        let n = self.n();
        let mu = self.model.friction;
        self.eng.warm.clear();
        let stats = &mut self.report.stats;
        stats.resting_sweeps = sweeps;
        stats.resting_residual = residual;
        for c in contacts {
            let total = c.normal * c.lambda_n + c.lambda_t;
            if total == DVec3::ZERO {
                continue;
            }
            stats.resting_contacts += 1;
            self.eng.warm.push(Cached {
                i: c.i,
                j: c.j,
                normal: c.lambda_n,
                tangent: c.lambda_t,
            });
            let (i, j) = c.ij();
            for k in [i, j] {
                if k < n {
                    self.report.last_collision[k] = Some(LastCollision {
                        time: 0.0,
                        velocity_before: self.eng.v_start[k],
                        velocity_after: self.p.velocities[k],
                        resting: true,
                    });
                }
            }
            if self.cfg.record_events {
                let saturated = c.lambda_t.length() >= mu * c.lambda_n * (1.0 - 1e-12);
                self.report.events.push(CollisionEvent {
                    particle: i,
                    partner: if j < n {
                        Partner::Particle(j)
                    } else {
                        Partner::Wall(j - n)
                    },
                    time: 0.0,
                    approach_speed: c.approach,
                    regime: if saturated {
                        FrictionRegime::Slide
                    } else {
                        FrictionRegime::Stick
                    },
                    resting: true,
                    impulse: -total,
                });
            }
        }
        self.eng.warm.sort_unstable_by_key(|c| (c.i, c.j));
    }
}
