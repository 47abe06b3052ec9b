//! Position projection after the event loop (a safety net, not physics; see the engine header):
//! Gauss–Seidel sweeps over the candidate pairs, then the walls, that push overlapping pairs apart
//! along the centre line, split by inverse mass (walls and zero-inverse-mass particles immovable),
//! until no overlap exceeds `projection_tolerance` or `projection_sweeps` sweeps are done. The
//! sweep direction alternates (symmetric Gauss–Seidel); a forward sweep, which treats the walls
//! last, ends the projection when the budget allows, so that no particle is left in a wall.
//! Pairs with a spheroid are pushed apart along their contact normal by the penetration depth,
//! a spheroid out of a wall along the wall normal (translations only; orientations are kept).
//!
//! Fast path: a pair (or particle–wall pair) that was found apart, and neither of whose
//! particles has moved since, is apart again, so the sweeps skip it (every evaluation is a pure
//! function of the two positions). Per-particle stamps of the last move and per-pair stamps of
//! the last evaluation that found the pair apart decide it. The result is bitwise that of the
//! plain sweeps (`sweep_reference`, kept for the tests), which visit every pair every time.

use glam::DVec3;

use super::Sim;

pub(super) mod blocked;

/// The sweep budget of the projection: `sweep(fix, backward)` until no overlap exceeds `tol` or
/// `max` sweeps are done, ending with a forward sweep (walls last) even one past the budget, and
/// a last measuring sweep; returns the overlaps before, the sweeps and the overlaps after.
fn budget(max: usize, tol: f64, mut sweep: impl FnMut(bool, bool) -> f64) -> (f64, usize, f64) {
    let before = sweep(max > 0, false);
    let mut worst = before;
    let mut sweeps = usize::from(max > 0);
    while sweeps < max && worst > tol {
        worst = sweep(true, sweeps % 2 == 1);
        sweeps += 1;
    }
    // end with a forward sweep (walls last), even one past the budget
    if sweeps % 2 == 0 && worst > 0.0 {
        sweep(true, false);
        sweeps += 1;
    }
    let after = if max > 0 { sweep(false, false) } else { before };
    (before, sweeps, after)
}

impl Sim<'_, '_> {
    /// Overlap-projection sweeps (see the module header); records the largest overlaps.
    pub(super) fn project(&mut self) {
        let (before, sweeps, after) = if self.blocked_projection() {
            self.project_blocked()
        } else {
            self.reset_stamps();
            let (max, tol) = (
                self.cfg.projection_sweeps as usize,
                self.cfg.projection_tolerance,
            );
            budget(max, tol, |fix, backward| self.sweep(fix, backward))
        };
        let st = &mut self.report.stats;
        st.max_overlap_before_projection = before;
        st.projection_sweeps = sweeps;
        st.max_overlap_after_projection = after;
    }

    /// Clears the stamps of the fast sweeps (every pair is evaluated in the first sweep).
    fn reset_stamps(&mut self) {
        let e = &mut self.eng.fast;
        e.stamp = 0;
        e.moved.clear();
        e.moved.resize(self.p.positions.len(), 0);
        e.pair_apart.clear();
        e.pair_apart.resize(self.eng.candidates.total(), 0);
        e.wall_apart.clear();
        e.wall_apart
            .resize(self.p.positions.len() * self.domain.planes.len(), 0);
    }

    /// One pass over all candidate pairs and walls (forward: pairs in index order, then walls;
    /// backward: walls, then pairs in reverse order); returns the largest relative overlap seen
    /// (before each correction) and corrects if `fix`. Skips the pairs known to be apart (see
    /// the module header); bitwise equal to [`Self::sweep_reference`].
    fn sweep(&mut self, fix: bool, backward: bool) -> f64 {
        if self.eng.reference {
            return self.sweep_reference(fix, backward);
        }
        let n = self.n();
        let mut worst = 0.0f64;
        if backward {
            worst = worst.max(self.sweep_walls_fast(fix, true));
        }
        for k in 0..n {
            let i = if backward { n - 1 - k } else { k };
            let range = self.eng.candidates.range(i);
            let (a, b) = (range.start, range.end);
            for q in 0..b - a {
                let slot = if backward { b - 1 - q } else { a + q };
                let j = self.eng.candidates.at(slot) as usize;
                if j <= i {
                    continue;
                }
                let e = &self.eng.fast;
                let apart = e.pair_apart[slot];
                if apart > e.moved[i] && apart > e.moved[j] {
                    continue; // apart when last seen, and neither has moved since
                }
                self.eng.fast.stamp += 1;
                let before = (self.p.positions[i], self.p.positions[j]);
                let o = self.separate(i, j, fix);
                worst = worst.max(o);
                let e = &mut self.eng.fast;
                if o > 0.0 {
                    if (self.p.positions[i], self.p.positions[j]) != before {
                        e.moved[i] = e.stamp;
                        e.moved[j] = e.stamp;
                    }
                } else {
                    e.pair_apart[slot] = e.stamp;
                }
            }
        }
        if !backward {
            worst = worst.max(self.sweep_walls_fast(fix, false));
        }
        worst
    }

    /// [`Self::sweep_walls`] with the stamps of [`Self::sweep`].
    fn sweep_walls_fast(&mut self, fix: bool, backward: bool) -> f64 {
        let mut worst = 0.0f64;
        let n = self.p.positions.len();
        let h = self.h;
        let planes = self.domain.planes.len();
        for k in 0..n {
            let i = if backward { n - 1 - k } else { k };
            for p in 0..planes {
                let slot = i * planes + p;
                let e = &self.eng.fast;
                if e.wall_apart[slot] > e.moved[i] {
                    continue;
                }
                self.eng.fast.stamp += 1;
                let plane = self.domain.planes[p];
                let x = self.p.positions[i];
                let overlap = if self.p.spheroids.is_none() {
                    self.eng.radius[i] - plane.signed_distance(x)
                } else {
                    -self.wall_contact(i, x, h, &plane).gap
                };
                if overlap <= 0.0 || overlap.is_nan() {
                    self.eng.fast.wall_apart[slot] = self.eng.fast.stamp;
                    continue;
                }
                worst = worst.max(overlap / (2.0 * self.eng.radius[i]));
                if fix && self.p.inv_masses[i] > 0.0 {
                    self.p.positions[i] += plane.normal * overlap;
                    if self.p.positions[i] != x {
                        self.eng.fast.moved[i] = self.eng.fast.stamp;
                    }
                }
            }
        }
        worst
    }

    /// The plain sweep: every candidate pair and wall, every time (the reference of
    /// [`Self::sweep`]).
    fn sweep_reference(&mut self, fix: bool, backward: bool) -> f64 {
        let n = self.n();
        let mut worst = 0.0f64;
        if backward {
            worst = worst.max(self.sweep_walls(fix, true));
        }
        for k in 0..n {
            let i = if backward { n - 1 - k } else { k };
            let m = self.eng.candidates.of(i).len();
            for q in 0..m {
                let j = self.eng.candidates.of(i)[if backward { m - 1 - q } else { q }] as usize;
                if j > i {
                    worst = worst.max(self.separate(i, j, fix));
                }
            }
        }
        if !backward {
            worst = worst.max(self.sweep_walls(fix, false));
        }
        worst
    }

    /// Corrects (if `fix`) and returns the relative overlap of the pair `(i, j)`.
    fn separate(&mut self, i: usize, j: usize, fix: bool) -> f64 {
        if !(self.is_round(i) && self.is_round(j)) {
            return self.separate_spheroids(i, j, fix);
        }
        let (x, r, w) = (&mut *self.p.positions, &self.eng.radius, self.p.inv_masses);
        let dx = self.domain.minimum_image(x[j] - x[i]);
        let dist = dx.length();
        let s = r[i] + r[j];
        let overlap = s - dist;
        if overlap <= 0.0 || overlap.is_nan() {
            return 0.0;
        }
        let wsum = w[i] + w[j];
        if fix && wsum > 0.0 {
            let normal = if dist > 0.0 { dx / dist } else { DVec3::Z };
            x[i] -= normal * (overlap * w[i] / wsum);
            x[j] += normal * (overlap * w[j] / wsum);
        }
        overlap / s
    }

    /// [`Self::separate`] for a pair with a spheroid: along the contact normal.
    fn separate_spheroids(&mut self, i: usize, j: usize, fix: bool) -> f64 {
        let h = self.h;
        let xi = self.p.positions[i];
        let dx = self.domain.minimum_image(self.p.positions[j] - xi);
        let s = self.eng.radius[i] + self.eng.radius[j];
        if dx.length().partial_cmp(&s) != Some(std::cmp::Ordering::Less) {
            return 0.0;
        }
        let Some(c) = self.pair_contact(i, j, xi, dx, h) else {
            return 0.0;
        };
        let overlap = -c.gap;
        if overlap <= 0.0 || overlap.is_nan() {
            return 0.0;
        }
        let w = self.p.inv_masses;
        let wsum = w[i] + w[j];
        if fix && wsum > 0.0 {
            self.p.positions[i] -= c.normal * (overlap * w[i] / wsum);
            self.p.positions[j] += c.normal * (overlap * w[j] / wsum);
        }
        overlap / s
    }

    /// Particle–wall pass; returns the largest relative overlap seen.
    fn sweep_walls(&mut self, fix: bool, backward: bool) -> f64 {
        let mut worst = 0.0f64;
        let n = self.p.positions.len();
        let h = self.h;
        for k in 0..n {
            let i = if backward { n - 1 - k } else { k };
            for p in 0..self.domain.planes.len() {
                let plane = self.domain.planes[p];
                let x = self.p.positions[i];
                let overlap = if self.p.spheroids.is_none() {
                    self.eng.radius[i] - plane.signed_distance(x)
                } else {
                    -self.wall_contact(i, x, h, &plane).gap
                };
                let (x, r, w) = (&mut *self.p.positions, &self.eng.radius, self.p.inv_masses);
                if overlap <= 0.0 || overlap.is_nan() {
                    continue;
                }
                worst = worst.max(overlap / (2.0 * r[i]));
                if fix && w[i] > 0.0 {
                    x[i] += plane.normal * overlap;
                }
            }
        }
        worst
    }
}
