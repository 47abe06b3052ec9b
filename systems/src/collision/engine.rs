//! The event-driven hard-sphere collision step (thesis 002: ch. 2, §2.2.4.2, with Hoomans et al.'s
//! sequence of binary collisions; ch. 4, §4.2.1.3).
//!
//! **Input.** Dense arrays in a stable particle order: start positions `x_n`, velocities `v` and
//! angular velocities `Ω` *already updated by the force integrator for this step*, radii, inverse
//! masses, inverse inertias, densities; a [`CollisionDomain`]; the step `h`; a [`CollisionModel`].
//! **Output:** end-of-step positions (unwrapped), post-collision velocities and angular
//! velocities, and a [`CollisionReport`] (events, each particle's last collision for the Basset
//! reset, counters).
//!
//! **Model.** Within the step the motion is ballistic, "the linear and angular velocities of the
//! particles are assumed to change only due to collisions" ([T002 §4.2.1.3]), and sustained contacts are
//! sequences of instantaneous binary collisions ([T002 §4.2.1.3]). Every collision uses the impulse law
//! of [`super::impulse`] with the coefficients from [`CollisionModel::law`] at the approach speed.
//!
//! **Algorithm.**
//! 1. Candidate pairs from a cell grid (private `cells` module) with reach `2 V h + 0.1 r_max`,
//!    `V` a bound on every speed during the step (the maximum after step 2; if a collision
//!    produces a faster particle, `V` is raised to 1.5× that speed and the grid and all
//!    predictions are rebuilt).
//! 2. Resting contacts (touching, or closer than `rest_speed · h`, and approaching slower than
//!    `rest_speed`) are resolved at `t = 0` by a warm-started projected Gauss–Seidel solve of
//!    fully inelastic contacts with Coulomb friction (private `resting` submodule). It is the
//!    converged limit of the infinite sequence of `e = 0` binary collisions (inelastic collapse)
//!    that a bed under gravity would otherwise exchange at `t = 0` every step, which the event
//!    loop would resolve only with `O(height²)` events per particle. Its impulses are reported as
//!    events at time 0 flagged `resting`.
//! 3. Each particle keeps a local time and is advanced lazily. Each particle's earliest predicted
//!    event (pair TOI from [`super::toi`] or wall TOI) sits in a binary heap ordered by
//!    `(time, lower index, higher index or N + wall, owner)`; per-particle version counters
//!    discard stale events (a stale event whose owner is unchanged re-predicts the owner).
//! 4. The earliest event advances its particles to the event time, applies the impulse and
//!    re-predicts both within the remaining step; until the heap is empty. All particles are then
//!    advanced to `h` with their final velocities.
//! 5. Position projection (a safety net, *not physics*): Gauss–Seidel sweeps over the candidate
//!    pairs, then the walls, push overlapping pairs apart along the centre line, split by inverse
//!    mass (walls and zero-inverse-mass particles immovable), until no overlap exceeds
//!    `projection_tolerance` (or `projection_sweeps`). Velocities are untouched. The largest
//!    overlap before and after is reported.
//!
//! **Choices where the thesis is silent.**
//! * Approaches slower than `approach_tolerance · (r_i + r_j)/h` (walls: `· 2 r_i/h`) are ignored:
//!   they open less than `approach_tolerance` d of overlap (the projection removes it). At the
//!   resting contacts of step 2, approaches up to `max(resting_floor, 2 × residual)` are left to
//!   the resting solve: below twice its residual the event loop would only go on with its Gauss–
//!   Seidel iteration; below [`EngineConfig::resting_floor`] (`|g| h`, spheres) they count as rest.
//! * Dense clusters: after `defer_slow_after` events of a particle in one step, its approaches
//!   slower than `rest_speed` are deferred (overlap `< rest_speed · h`, removed by the projection,
//!   the next step's resting solve settles the velocities). Hard cap: a particle that took part
//!   in `max_events_per_particle` events gets no further events this step (reported as
//!   `capped_particles`/`skipped_events`). The loop therefore always terminates.
//! * The rest-speed rule of [`CollisionModel`] makes slow impacts fully inelastic, so a particle
//!   resting on a wall (or a bed) under gravity loses its approach velocity each step instead of
//!   bouncing or sinking.
//! * Positions are returned **unwrapped** (periodic wrapping is the caller's; see
//!   [`CollisionDomain::wrap`]). Overlaps are reported relative to `r_i + r_j` (the mean
//!   diameter; `2 r_i` for walls).
//! * [`InverseInertia::Scalar`] and [`InverseInertia::Tensor`] are held fixed during the step
//!   (exact for spheres with isotropic inertia); [`InverseInertia::Principal`] is rotated to the
//!   lab frame with the orientation at the event time.
//! * The warm start keys contacts by particle index: call
//!   [`CollisionEngine::clear_warm_start`] when the particle order or set changes.
//! * Deterministic: fixed orders everywhere; the NNCG resting solve and the projection of many
//!   spheres run two blocks side by side, bitwise the same on any number of threads.
//!
//! **Spheroids** ([`SpheroidArrays`], thesis ch. 4): orientations rotate ballistically with the
//! particle's local time; a pair with a non-round member uses the common-normal contact and the
//! conservative-advancement TOI of [`super::spheroid`] (its approach filter is passed into the TOI
//! as the minimum approach speed, so a slower touch does not hide a later faster one), walls the
//! closed-form spheroid–plane gap; the resting solve and the projection use the contact normal and
//! lever arms (translation only for the projection). The cell grid uses the bounding radii.
//! Overlaps of spheroids are reported relative to the sum of the bounding radii (`d_major` for
//! equal discs). Without shapes the sphere path is unchanged (bitwise; checked against the
//! sphere-only engine on a 300-sphere settling bed). For dense beds of flat discs the defaults are
//! costly: a resting disc that rocks keeps approaching its neighbours at ~1e-4 m/s, above the
//! default approach tolerance, and the default projection tolerance (1e-5 of `d_major`, 2e-4 of a
//! 1:10 disc's half-thickness) is tighter than the TOI's penetration tolerance; `approach_tolerance
//! = 1e-3` and `projection_tolerance = 1e-4` (the bed tests) cut the cost ~10× with overlaps still
//! below 5e-4 `d_major` after the projection.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::DVec3;

use super::cells::Candidates;
use super::domain::CollisionDomain;
use super::impulse::{CollisionLaw, FrictionRegime, RigidBody, collision_impulse};
use super::restitution::{CollisionModel, Counterpart};
use super::toi::{sphere_plane_toi, sphere_sphere_toi};
use event::Event;
mod event;
mod predict;
mod projection;
mod resting;
mod resting_fast;
mod shapes;
mod types;

pub use types::{
    CollisionError, CollisionEvent, CollisionReport, CollisionStats, EngineConfig, InverseInertia,
    LastCollision, ParticleArrays, Partner, SpheroidArrays,
};

/// Reusable event-driven collision stepper (holds its scratch buffers between steps).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::domain::CollisionDomain;
/// use magsep_systems::collision::engine::{CollisionEngine, EngineConfig, InverseInertia, ParticleArrays};
/// use magsep_systems::collision::restitution::CollisionModel;
/// // two 1 mm spheres closing at 2 m/s, gap 2 mm: elastic, frictionless head-on impact at 1 ms
/// let mut x = [DVec3::new(-0.002, 0.0, 0.0), DVec3::new(0.002, 0.0, 0.0)];
/// let mut v = [DVec3::X, -DVec3::X];
/// let mut w = [DVec3::ZERO; 2];
/// let arrays = ParticleArrays {
///     positions: &mut x,
///     velocities: &mut v,
///     angular_velocities: &mut w,
///     radii: &[1e-3; 2],
///     inv_masses: &[1.0; 2],
///     inv_inertias: InverseInertia::Scalar(&[1.0; 2]),
///     densities: &[1000.0; 2],
///     spheroids: None,
/// };
/// let model = CollisionModel::dry(1.0, 0.0, 0.0);
/// let mut engine = CollisionEngine::new(EngineConfig::default());
/// let report = engine.step(arrays, &CollisionDomain::unbounded(), &model, 2e-3).unwrap();
/// assert_eq!(report.stats.events, 1);
/// assert!((report.events[0].time - 1e-3).abs() < 1e-15);
/// assert_eq!((v[0], v[1]), (-DVec3::X, DVec3::X));
/// assert!((x[0].x + 0.002).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Default)]
pub struct CollisionEngine {
    config: EngineConfig,
    candidates: Candidates,
    heap: BinaryHeap<Reverse<Event>>,
    start: Vec<DVec3>,
    local_time: Vec<f64>,
    version: Vec<u32>,
    count: Vec<u32>,
    v_start: Vec<DVec3>,
    contacts: Vec<resting::Contact>,
    warm: Vec<resting::Cached>,
    rest_rows: Vec<usize>,
    rest_partners: Vec<u32>,
    /// Bounding radii of this step (the radii for spheres).
    radius: Vec<f64>,
    /// Scratch of the fast kernels.
    fast: resting_fast::Scratch,
    /// Scratch of the blocked projection.
    proj: projection::blocked::Scratch,
    /// Use the plain reference kernels instead of the fast ones (tests compare the two).
    reference: bool,
    /// Scratch of the parallel predictions.
    predicted: Vec<Event>,
}

impl CollisionEngine {
    /// An engine with the given settings.
    pub fn new(config: EngineConfig) -> Self {
        Self {
            config,
            ..Self::default()
        }
    }

    /// The settings.
    pub fn config(&self) -> &EngineConfig {
        &self.config
    }

    /// Replaces the settings (the warm start is kept).
    pub fn set_config(&mut self, config: EngineConfig) {
        self.config = config;
    }

    /// Partner codes (particle index, or `N + wall`) of particle `i`'s resting contacts this step.
    fn resting_partners(&self, i: usize) -> &[u32] {
        match (self.rest_rows.get(i), self.rest_rows.get(i + 1)) {
            (Some(&a), Some(&b)) => &self.rest_partners[a..b],
            _ => &[],
        }
    }

    /// Forgets the resting-contact impulses kept for the warm start (call it when the particle
    /// order or set changes between steps).
    pub fn clear_warm_start(&mut self) {
        self.warm.clear();
    }

    /// Resolves all collisions of one step of length `h` \[s\] and advances the positions to its end
    /// (see the module header). The arrays are updated in place.
    pub fn step(
        &mut self,
        p: ParticleArrays<'_>,
        domain: &CollisionDomain,
        model: &CollisionModel,
        h: f64,
    ) -> Result<CollisionReport, CollisionError> {
        let n = p.positions.len();
        let inertia_len = p.inv_inertias.len();
        let (shapes_len, orientations_len) = match &p.spheroids {
            Some(s) => (s.shapes.len(), s.orientations.len()),
            None => (n, n),
        };
        for (name, found) in [
            ("shapes", shapes_len),
            ("orientations", orientations_len),
            ("velocities", p.velocities.len()),
            ("angular_velocities", p.angular_velocities.len()),
            ("radii", p.radii.len()),
            ("inv_masses", p.inv_masses.len()),
            ("inv_inertias", inertia_len),
            ("densities", p.densities.len()),
        ] {
            if found != n {
                return Err(CollisionError::LengthMismatch {
                    name,
                    expected: n,
                    found,
                });
            }
        }
        if !(h >= 0.0 && h.is_finite()) {
            return Err(CollisionError::InvalidStep(h));
        }
        if n > (u32::MAX as usize / 2).saturating_sub(domain.planes.len()) {
            return Err(CollisionError::LengthMismatch {
                name: "positions",
                expected: u32::MAX as usize / 2,
                found: n,
            });
        }
        if let Some((axis, length)) = domain.invalid_axis() {
            return Err(CollisionError::InvalidDomain { axis, length });
        }
        let mut sim = Sim {
            p,
            domain,
            model,
            h,
            cfg: self.config,
            eng: self,
            report: CollisionReport {
                last_collision: vec![None; n],
                ..CollisionReport::default()
            },
            speed_bound: 0.0,
            resting_residual: 0.0,
        };
        sim.run();
        Ok(sim.report)
    }
}

/// One step in progress.
struct Sim<'s, 'a> {
    p: ParticleArrays<'a>,
    domain: &'s CollisionDomain,
    model: &'s CollisionModel,
    h: f64,
    cfg: EngineConfig,
    eng: &'s mut CollisionEngine,
    report: CollisionReport,
    speed_bound: f64,
    /// Largest approach speed left at a resting contact by the resting solve [m/s].
    resting_residual: f64,
}

impl Sim<'_, '_> {
    fn n(&self) -> usize {
        self.p.positions.len()
    }

    fn run(&mut self) {
        let n = self.n();
        self.eng.start.clear();
        self.eng.start.extend_from_slice(self.p.positions);
        self.eng.local_time.clear();
        self.eng.local_time.resize(n, 0.0);
        self.eng.version.clear();
        self.eng.version.resize(n, 0);
        self.eng.count.clear();
        self.eng.count.resize(n, 0);
        self.eng.heap.clear();
        self.fill_radii();
        self.speed_bound = self.max_speed();
        self.build_candidates();
        self.solve_resting();
        let fastest = self.max_speed();
        if fastest > self.speed_bound {
            self.speed_bound = fastest;
            self.build_candidates();
        }
        self.predict_all(0.0);
        while let Some(Reverse(ev)) = self.eng.heap.pop() {
            self.handle(ev);
        }
        let h = self.h;
        for i in 0..n {
            self.advance(i, h);
        }
        let cap = self.cfg.max_events_per_particle;
        self.report.stats.capped_particles = self.eng.count.iter().filter(|&&c| c >= cap).count();
        self.project();
    }

    fn max_speed(&self) -> f64 {
        let speeds = self.p.velocities.iter().map(|v| v.length());
        speeds.filter(|s| s.is_finite()).fold(0.0, f64::max)
    }

    /// Candidate lists from the start positions for the current speed bound.
    fn build_candidates(&mut self) {
        let r_max = self
            .eng
            .radius
            .iter()
            .copied()
            .filter(|r| r.is_finite())
            .fold(0.0, f64::max);
        let reach = 2.0 * self.speed_bound * self.h + 0.1 * r_max;
        self.eng
            .candidates
            .build(&self.eng.start, &self.eng.radius, self.domain, reach);
    }

    /// Rebuilds the candidate lists for the current speed bound and re-predicts everyone at `now`.
    fn rebuild(&mut self, now: f64) {
        self.build_candidates();
        self.eng.heap.clear();
        for i in 0..self.n() {
            self.eng.version[i] = self.eng.version[i].wrapping_add(1);
        }
        self.predict_all(now);
    }

    #[inline]
    fn position_at(&self, i: usize, t: f64) -> DVec3 {
        self.p.positions[i] + self.p.velocities[i] * (t - self.eng.local_time[i])
    }

    #[inline]
    fn advance(&mut self, i: usize, t: f64) {
        self.p.positions[i] = self.position_at(i, t);
        self.advance_orientation(i, t);
        self.eng.local_time[i] = t;
    }

    #[inline]
    fn capped(&self, i: usize) -> bool {
        self.eng.count[i] >= self.cfg.max_events_per_particle
    }

    fn body(&self, i: usize) -> RigidBody {
        RigidBody {
            inv_mass: self.p.inv_masses[i],
            inv_inertia: self.inv_inertia(i),
            velocity: self.p.velocities[i],
            angular_velocity: self.p.angular_velocities[i],
        }
    }

    fn handle(&mut self, ev: Event) {
        let n = self.n();
        let (lo, hi, owner) = (ev.lo as usize, ev.hi as usize, ev.owner as usize);
        let wall = hi >= n;
        let v = &self.eng.version;
        let current = v[lo] == ev.ver_lo && (wall || v[hi] == ev.ver_hi);
        if !current {
            let owner_ver = if owner == lo { ev.ver_lo } else { ev.ver_hi };
            if v[owner] == owner_ver {
                self.predict(owner, ev.time);
            }
            return;
        }
        if self.capped(lo) || (!wall && self.capped(hi)) {
            self.report.stats.skipped_events += 1;
            self.predict(owner, ev.time);
            return;
        }
        let now = ev.time;
        self.advance(lo, now);
        let (a, b, contact, other) = if wall {
            let plane = &self.domain.planes[hi - n];
            let c = self.wall_contact(lo, self.p.positions[lo], now, plane);
            (self.body(lo), RigidBody::fixed(), c, Counterpart::Wall)
        } else {
            self.advance(hi, now);
            let dx = self
                .domain
                .minimum_image(self.p.positions[hi] - self.p.positions[lo]);
            let Some(c) = self.pair_contact(lo, hi, self.p.positions[lo], dx, now) else {
                // invalid shape or pose: nothing to resolve
                self.report.stats.skipped_events += 1;
                self.predict(lo, now);
                self.predict(hi, now);
                return;
            };
            let other = Counterpart::Particle {
                diameter: self.diameter(hi),
                density: self.p.densities[hi],
            };
            (self.body(lo), self.body(hi), c, other)
        };
        self.eng.count[lo] += 1;
        self.eng.version[lo] = self.eng.version[lo].wrapping_add(1);
        if !wall {
            self.eng.count[hi] += 1;
            self.eng.version[hi] = self.eng.version[hi].wrapping_add(1);
        }
        let approach =
            -(b.point_velocity(contact.r_b) - a.point_velocity(contact.r_a)).dot(contact.normal);
        let law: CollisionLaw =
            self.model
                .law(self.diameter(lo), self.p.densities[lo], other, approach);
        if let Some(hit) = collision_impulse(&a, &b, &contact, &law) {
            let resting = self.model.is_resting(hit.approach_speed);
            let before = a.velocity;
            self.p.velocities[lo] += hit.delta_velocity_a;
            self.p.angular_velocities[lo] += hit.delta_angular_velocity_a;
            self.record(lo, now, before, resting);
            if !wall {
                self.p.velocities[hi] += hit.delta_velocity_b;
                self.p.angular_velocities[hi] += hit.delta_angular_velocity_b;
                self.record(hi, now, b.velocity, resting);
            }
            let st = &mut self.report.stats;
            st.events += 1;
            st.wall_events += usize::from(wall);
            st.resting += usize::from(resting);
            match hit.regime {
                FrictionRegime::Stick => st.stick += 1,
                FrictionRegime::Slide | FrictionRegime::Frictionless => st.slide += 1,
            }
            if self.cfg.record_events {
                self.report.events.push(CollisionEvent {
                    particle: lo,
                    partner: if wall {
                        Partner::Wall(hi - n)
                    } else {
                        Partner::Particle(hi)
                    },
                    time: now,
                    approach_speed: hit.approach_speed,
                    regime: hit.regime,
                    resting,
                    impulse: -hit.impulse,
                });
            }
            let fastest = self.p.velocities[lo].length().max(if wall {
                0.0
            } else {
                self.p.velocities[hi].length()
            });
            if fastest > self.speed_bound && fastest.is_finite() {
                self.speed_bound = 1.5 * fastest;
                self.report.stats.rebuilds += 1;
                self.rebuild(now);
                return;
            }
        }
        self.predict(lo, now);
        if !wall {
            self.predict(hi, now);
        }
    }

    fn record(&mut self, i: usize, time: f64, before: DVec3, resting: bool) {
        self.report.last_collision[i] = Some(LastCollision {
            time,
            velocity_before: before,
            velocity_after: self.p.velocities[i],
            resting,
        });
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_spheroid;
