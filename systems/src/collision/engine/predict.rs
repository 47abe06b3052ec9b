//! Event predictions of the collision step: each particle's earliest pair or wall event within
//! the rest of the step (see the engine header for the approach filters).
//!
//! Predicting every particle at once ([`Sim::predict_all`]: the start of the step and every
//! rebuild) runs on fixed chunks of particles side by side; each prediction is a pure function
//! of the state, and the events are pushed in particle order, so the heap and the result are
//! bitwise those of the serial loop on any number of threads.

use std::cmp::Reverse;

use rayon::prelude::*;

use super::event::Event;
use super::{Sim, sphere_plane_toi, sphere_sphere_toi};

/// Particles per chunk of [`Sim::predict_all`]; fewer particles than two chunks predict serially.
const CHUNK: usize = 512;

impl Sim<'_, '_> {
    /// Pushes particle `i`'s earliest event in `[now, h]`, if any.
    pub(super) fn predict(&mut self, i: usize, now: f64) {
        if let Some(ev) = self.prediction(i, now) {
            self.eng.heap.push(Reverse(ev));
        }
    }

    /// [`Self::predict`] for every particle, in particle order (see the module header).
    pub(super) fn predict_all(&mut self, now: f64) {
        let n = self.n();
        if n < 2 * CHUNK {
            for i in 0..n {
                self.predict(i, now);
            }
            return;
        }
        let mut found = std::mem::take(&mut self.eng.predicted);
        found.clear();
        let this = &*self;
        found.par_extend(
            (0..n)
                .into_par_iter()
                .with_min_len(CHUNK)
                .filter_map(|i| this.prediction(i, now)),
        );
        self.eng.heap.extend(found.drain(..).map(Reverse));
        self.eng.predicted = found;
    }

    /// Particle `i`'s earliest event in `[now, h]`, if any (a pure function of the state).
    pub(super) fn prediction(&self, i: usize, now: f64) -> Option<Event> {
        if self.capped(i) {
            return None;
        }
        let n = self.n();
        let horizon = self.h - now;
        let tol = self.cfg.approach_tolerance / self.h;
        let (xi, vi, ri) = (
            self.position_at(i, now),
            self.p.velocities[i],
            self.eng.radius[i],
        );
        let rest = self.eng.resting_partners(i);
        // the floor applies to spheres; a spheroid's contacts keep the residual rule alone
        let rest_limit_shape = 2.0 * self.resting_residual;
        let rest_limit = rest_limit_shape.max(self.cfg.resting_floor);
        let defer = self.cfg.defer_slow_after;
        let busy_i = self.eng.count[i] >= defer;
        let slow = self.model.rest_speed;
        let mut r = 0;
        let mut is_resting = |code: usize| {
            while r < rest.len() && (rest[r] as usize) < code {
                r += 1;
            }
            r < rest.len() && rest[r] as usize == code
        };
        let mut best: Option<(f64, u32, u32)> = None;
        let mut offer = |t: f64, lo: usize, hi: usize| {
            let cand = (now + t, lo as u32, hi as u32);
            let better = match best {
                None => true,
                Some(b) => cand
                    .0
                    .total_cmp(&b.0)
                    .then((cand.1, cand.2).cmp(&(b.1, b.2)))
                    .is_lt(),
            };
            if better {
                best = Some(cand);
            }
        };
        for &j in self.eng.candidates.of(i) {
            let j = j as usize;
            if self.capped(j) {
                continue;
            }
            let dx = self.domain.minimum_image(self.position_at(j, now) - xi);
            let dv = self.p.velocities[j] - vi;
            let s = ri + self.eng.radius[j];
            let resting = is_resting(j);
            let busy = busy_i || self.eng.count[j] >= defer;
            if !(self.is_round(i) && self.is_round(j)) {
                let mut min_approach = tol * s;
                if resting {
                    min_approach = min_approach.max(rest_limit_shape);
                }
                if busy {
                    min_approach = min_approach.max(slow);
                }
                if let Some(hit) =
                    self.spheroid_pair_impact(i, j, xi, dx, now, horizon, min_approach)
                {
                    offer(hit.time, i.min(j), i.max(j));
                }
                continue;
            }
            if let Some(t) = sphere_sphere_toi(dx, dv, s, horizon) {
                let d = dx + dv * t;
                let approach = -dv.dot(d) / d.length();
                if approach > tol * s
                    && !(resting && approach <= rest_limit)
                    && !(busy && approach < slow)
                {
                    offer(t, i.min(j), i.max(j));
                }
            }
        }
        for (w, plane) in self.domain.planes.iter().enumerate() {
            let approach = -vi.dot(plane.normal);
            let resting = is_resting(n + w);
            if !self.is_round(i) {
                let mut min_approach = tol * 2.0 * ri;
                if resting {
                    min_approach = min_approach.max(rest_limit_shape);
                }
                if busy_i {
                    min_approach = min_approach.max(slow);
                }
                if let Some(hit) =
                    self.spheroid_wall_impact(i, xi, now, plane, horizon, min_approach)
                {
                    offer(hit.time, i, n + w);
                }
                continue;
            }
            if let Some(t) = sphere_plane_toi(xi, vi, ri, plane, horizon)
                && approach > tol * 2.0 * ri
                && !(resting && approach <= rest_limit)
                && !(busy_i && approach < slow)
            {
                offer(t, i, n + w);
            }
        }
        let (time, lo, hi) = best?;
        let v = &self.eng.version;
        Some(Event {
            time: time.min(self.h),
            lo,
            hi,
            owner: i as u32,
            ver_lo: v[lo as usize],
            ver_hi: v.get(hi as usize).copied().unwrap_or(0),
        })
    }
}
