//! The overlap projection of spheres on two blocks side by side (used with the NNCG resting
//! solve, [`EngineConfig::nncg_sweeps`](super::super::EngineConfig::nncg_sweeps) > 0, from
//! [`SPLIT_MIN_PARTICLES`] particles).
//!
//! The particles are split into two halves as for the resting solve
//! ([`Halves`]: across a horizontal axis at the median). Block 0 (1) holds the candidate pairs
//! within half 0 (1), block 2 the pairs across the cut and the periodic seam. A forward sweep
//! separates the pairs of blocks 0 and 1 (each in particle order, side by side), then those of
//! block 2, then pushes particles out of the walls (each half side by side); a backward sweep
//! runs the reverse. Blocks 0 and 1 share no particle, so the result does not depend on the
//! number of threads. The skipping of pairs found apart whose particles did not move is that of
//! the serial sweeps ([`super`]), with stamps `phase << 32 | count`: the phases run one after
//! the other, and within a phase each block counts for itself and only compares its own
//! particles' stamps.
//!
//! Pairs provably apart are skipped too: each particle sums the lengths of its moves in the step
//! (`travel`), and a pair found apart by a gap `g` keeps `slack = g + travel_i + travel_j` (less
//! 1e-9 of the summed radii for rounding); while `travel_i + travel_j < slack` the two moved less
//! than the gap in all, so the pair is still apart (the minimum-image distance changes no faster
//! than the positions) and its evaluation, which would only find it apart, is skipped. Evaluating
//! an apart pair changes no position and no overlap, so the result is bitwise that of the
//! stamps alone (`Scratch::plain`, a test compares the two).
//!
//! Momentum (as in the NNCG resting solve, [`super::super::resting_fast::blocked`]): after a
//! correcting sweep the particles' displacements `s_k` give `β = |s_k|²/|s_{k−1}|²`; before the
//! next correcting sweep the particles move on by `β p_{k−1}` (`β ≤ 1`; otherwise the direction
//! restarts) and `p_k = s_k + β p_{k−1}`. The sweep that follows projects the pairs again, so
//! the projection still ends with a plain forward sweep. Each particle's momentum move counts as
//! a move (stamp and travel). `Scratch::no_momentum` gives the plain sweeps (tests).

use glam::DVec3;

use super::super::Sim;
use super::super::resting_fast::blocked::Halves;
use crate::collision::domain::CollisionDomain;
use crate::collision::toi::Plane;

/// Fewest particles for which the projection splits into blocks.
pub(in crate::collision::engine) const SPLIT_MIN_PARTICLES: usize = 512;

/// Scratch of the blocked projection (kept between steps).
#[derive(Debug, Clone, Default)]
pub(in crate::collision::engine) struct Scratch {
    halves: Halves,
    /// Local positions, radii, inverse masses.
    x: Vec<DVec3>,
    r: Vec<f64>,
    w: Vec<f64>,
    /// Per local particle, the stamp of its last move.
    moved: Vec<u64>,
    /// Per block, its pairs (indices local to the block) and the stamps of their last
    /// evaluation that found them apart.
    pairs: [Vec<[u32; 2]>; 3],
    apart: [Vec<u64>; 3],
    /// Per local particle and wall, the stamp of the last evaluation that found them apart.
    wall_apart: Vec<u64>,
    /// Per local particle, the summed lengths of its moves this step [m].
    travel: Vec<f64>,
    /// Per block and pair, its gap plus its particles' travel when last found apart [m].
    slack: [Vec<f64>; 3],
    /// Skip pairs by the stamps alone (the reference of the slack skip; tests).
    pub(in crate::collision::engine) plain: bool,
    /// Plain Gauss–Seidel sweeps without the momentum step (the reference of the momentum;
    /// tests).
    pub(in crate::collision::engine) no_momentum: bool,
    /// Per local particle, its position at the start of the current sweep's passes [m].
    start: Vec<DVec3>,
    /// Per local particle, the displacement of the last sweep's passes (`s`, x) and the
    /// search direction (`p`, y) [m].
    step: Vec<[DVec3; 2]>,
    /// `|s|²` of the last sweep, of the one before [m²], and whether a sweep recorded `s`.
    norm: [f64; 2],
    pending: bool,
}

/// The momentum step over particles `x` (see the module header): `x += β p` (unless
/// `restart`), `p = s + β p`; stamps and travel of moved particles updated.
fn momentum(
    x: &mut [DVec3],
    step: &mut [[DVec3; 2]],
    moved: &mut [u64],
    travel: &mut [f64],
    beta: f64,
    restart: bool,
    stamp: u64,
) {
    for (i, [s, p]) in step.iter_mut().enumerate() {
        if restart {
            *p = *s;
            continue;
        }
        let d = *p * beta;
        let before = x[i];
        x[i] += d;
        if x[i] != before {
            moved[i] = stamp;
            travel[i] += d.length();
        }
        *p = *s + d;
    }
}

/// `s = x − start` over a half; returns `|s|²`.
fn displacement(x: &[DVec3], start: &[DVec3], step: &mut [[DVec3; 2]]) -> f64 {
    let mut norm = 0.0;
    for ((x, a), [s, _]) in x.iter().zip(start).zip(step.iter_mut()) {
        *s = *x - *a;
        norm += s.length_squared();
    }
    norm
}

/// The shared read-only inputs of a pass.
#[derive(Clone, Copy)]
struct Ctx<'a> {
    domain: &'a CollisionDomain,
    planes: &'a [Plane],
    fix: bool,
    backward: bool,
    phase: u64,
    plain: bool,
}

/// One pass over `pairs` of particles `x` (local indices); returns the largest relative overlap.
#[allow(clippy::too_many_arguments)]
fn pairs_pass(
    ctx: Ctx<'_>,
    pairs: &[[u32; 2]],
    apart: &mut [u64],
    slack: &mut [f64],
    x: &mut [DVec3],
    r: &[f64],
    w: &[f64],
    moved: &mut [u64],
    travel: &mut [f64],
) -> f64 {
    let mut stamp = ctx.phase << 32;
    let mut worst = 0.0f64;
    let m = pairs.len();
    for k in 0..m {
        let k = if ctx.backward { m - 1 - k } else { k };
        let [i, j] = pairs[k];
        let (i, j) = (i as usize, j as usize);
        if apart[k] > moved[i] && apart[k] > moved[j] {
            continue;
        }
        if !ctx.plain && travel[i] + travel[j] < slack[k] {
            continue; // moved less than the gap since found apart
        }
        stamp += 1;
        let dx = ctx.domain.minimum_image(x[j] - x[i]);
        let dist = dx.length();
        let s = r[i] + r[j];
        let overlap = s - dist;
        if overlap <= 0.0 || overlap.is_nan() {
            apart[k] = stamp;
            // NaN: no skip (the comparison fails)
            slack[k] = travel[i] + travel[j] - overlap - 1e-9 * s;
            continue;
        }
        worst = worst.max(overlap / s);
        let wsum = w[i] + w[j];
        if ctx.fix && wsum > 0.0 {
            let before = (x[i], x[j]);
            let normal = if dist > 0.0 { dx / dist } else { DVec3::Z };
            let (si, sj) = (overlap * w[i] / wsum, overlap * w[j] / wsum);
            x[i] -= normal * si;
            x[j] += normal * sj;
            if (x[i], x[j]) != before {
                moved[i] = stamp;
                moved[j] = stamp;
                travel[i] += si;
                travel[j] += sj;
            }
        }
    }
    worst
}

/// One pass of particles `x` against the walls; returns the largest relative overlap.
fn walls_pass(
    ctx: Ctx<'_>,
    x: &mut [DVec3],
    r: &[f64],
    w: &[f64],
    moved: &mut [u64],
    wall_apart: &mut [u64],
    travel: &mut [f64],
) -> f64 {
    let mut stamp = ctx.phase << 32;
    let mut worst = 0.0f64;
    let n = x.len();
    let planes = ctx.planes.len();
    for k in 0..n {
        let i = if ctx.backward { n - 1 - k } else { k };
        for (p, plane) in ctx.planes.iter().enumerate() {
            let slot = i * planes + p;
            if wall_apart[slot] > moved[i] {
                continue;
            }
            stamp += 1;
            let overlap = r[i] - plane.signed_distance(x[i]);
            if overlap <= 0.0 || overlap.is_nan() {
                wall_apart[slot] = stamp;
                continue;
            }
            worst = worst.max(overlap / (2.0 * r[i]));
            if ctx.fix && w[i] > 0.0 {
                let before = x[i];
                x[i] += plane.normal * overlap;
                if x[i] != before {
                    moved[i] = stamp;
                    travel[i] += overlap;
                }
            }
        }
    }
    worst
}

impl Scratch {
    /// Before a correcting sweep: the momentum step from the last sweep's displacement (if
    /// any), and the positions the sweep starts from.
    fn before_sweep(&mut self, phase: &mut u64) {
        let n0 = self.halves.n0;
        if self.pending {
            let [last, prev] = self.norm;
            let beta = last / prev;
            let restart = beta.partial_cmp(&1.0).is_none_or(|o| o.is_gt());
            *phase += 1;
            let stamp = (*phase << 32) | 1;
            let (x0, x1) = self.x.split_at_mut(n0);
            let (q0, q1) = self.step.split_at_mut(n0);
            let (m0, m1) = self.moved.split_at_mut(n0);
            let (t0, t1) = self.travel.split_at_mut(n0);
            rayon::join(
                || momentum(x0, q0, m0, t0, beta, restart, stamp),
                || momentum(x1, q1, m1, t1, beta, restart, stamp),
            );
        }
        self.start.clear();
        self.start.extend_from_slice(&self.x);
    }

    /// After a correcting sweep: its displacement and `|s|²`.
    fn after_sweep(&mut self) {
        let n0 = self.halves.n0;
        let (x0, x1) = self.x.split_at(n0);
        let (a0, a1) = self.start.split_at(n0);
        let (q0, q1) = self.step.split_at_mut(n0);
        let (s0, s1) = rayon::join(|| displacement(x0, a0, q0), || displacement(x1, a1, q1));
        let prev = if self.pending {
            self.norm[0]
        } else {
            f64::INFINITY
        };
        self.norm = [s0 + s1, prev];
        self.pending = true;
    }

    /// One sweep (see the module header); `phase` counts the phases run so far.
    fn sweep(
        &mut self,
        domain: &CollisionDomain,
        fix: bool,
        backward: bool,
        phase: &mut u64,
    ) -> f64 {
        let momentum = fix && !self.no_momentum;
        if momentum {
            self.before_sweep(phase);
        }
        let worst = self.passes(domain, fix, backward, phase);
        if momentum {
            self.after_sweep();
        }
        worst
    }

    /// The passes of one sweep (see the module header).
    fn passes(
        &mut self,
        domain: &CollisionDomain,
        fix: bool,
        backward: bool,
        phase: &mut u64,
    ) -> f64 {
        let n0 = self.halves.n0;
        let planes = &domain.planes;
        let mut ctx = Ctx {
            domain,
            planes,
            fix,
            backward,
            phase: 0,
            plain: self.plain,
        };
        let mut worst = 0.0f64;
        let order: [u8; 3] = if backward { [2, 1, 0] } else { [0, 1, 2] };
        for stage in order {
            *phase += 1;
            ctx.phase = *phase;
            let (x0, x1) = self.x.split_at_mut(n0);
            let (r0, r1) = self.r.split_at(n0);
            let (w0, w1) = self.w.split_at(n0);
            let (m0, m1) = self.moved.split_at_mut(n0);
            let (t0, t1) = self.travel.split_at_mut(n0);
            let o = match stage {
                0 => {
                    let [p0, p1, _] = &self.pairs;
                    let [a0, a1, _] = &mut self.apart;
                    let [k0, k1, _] = &mut self.slack;
                    let (o0, o1) = rayon::join(
                        || pairs_pass(ctx, p0, a0, k0, x0, r0, w0, m0, t0),
                        || pairs_pass(ctx, p1, a1, k1, x1, r1, w1, m1, t1),
                    );
                    o0.max(o1)
                }
                1 => pairs_pass(
                    ctx,
                    &self.pairs[2],
                    &mut self.apart[2],
                    &mut self.slack[2],
                    &mut self.x,
                    &self.r,
                    &self.w,
                    &mut self.moved,
                    &mut self.travel,
                ),
                _ => {
                    let (s0, s1) = self.wall_apart.split_at_mut(n0 * planes.len());
                    let (o0, o1) = rayon::join(
                        || walls_pass(ctx, x0, r0, w0, m0, s0, t0),
                        || walls_pass(ctx, x1, r1, w1, m1, s1, t1),
                    );
                    o0.max(o1)
                }
            };
            worst = worst.max(o);
        }
        worst
    }
}

impl Sim<'_, '_> {
    /// Whether the projection runs on blocks: spheres, the NNCG solve, enough particles.
    pub(super) fn blocked_projection(&self) -> bool {
        self.cfg.nncg_sweeps > 0
            && !self.eng.reference
            && self.p.spheroids.is_none()
            && self.n() >= SPLIT_MIN_PARTICLES
    }

    /// [`Self::project`] on blocks (see the module header); returns the overlaps before, the
    /// sweeps and the overlaps after.
    pub(super) fn project_blocked(&mut self) -> (f64, usize, f64) {
        let n = self.n();
        let mut s = std::mem::take(&mut self.eng.proj);
        s.halves.split(self.p.positions, self.domain, None);
        let h = &s.halves;
        let n0 = h.n0;
        s.x.clear();
        s.r.clear();
        s.w.clear();
        for &i in &h.perm {
            let i = i as usize;
            s.x.push(self.p.positions[i]);
            s.r.push(self.eng.radius[i]);
            s.w.push(self.p.inv_masses[i]);
        }
        for p in &mut s.pairs {
            p.clear();
        }
        for i in 0..n {
            for &j in self.eng.candidates.of(i) {
                let j = j as usize;
                if j <= i {
                    continue;
                }
                let b = h.block(i, j) as usize;
                let shift = if b == 1 { n0 as u32 } else { 0 };
                s.pairs[b].push([h.local[i] - shift, h.local[j] - shift]);
            }
        }
        for b in 0..3 {
            s.apart[b].clear();
            s.apart[b].resize(s.pairs[b].len(), 0);
            s.slack[b].clear();
            s.slack[b].resize(s.pairs[b].len(), 0.0);
        }
        s.moved.clear();
        s.moved.resize(n, 0);
        s.travel.clear();
        s.travel.resize(n, 0.0);
        s.wall_apart.clear();
        s.wall_apart.resize(n * self.domain.planes.len(), 0);
        s.step.clear();
        s.step.resize(n, [DVec3::ZERO; 2]);
        s.pending = false;
        let mut phase = 0;
        let max = self
            .cfg
            .projection_sweeps
            .min(self.cfg.nncg_projection_sweeps);
        let (max, tol) = (max as usize, self.cfg.projection_tolerance);
        let out = super::budget(max, tol, |fix, backward| {
            s.sweep(self.domain, fix, backward, &mut phase)
        });
        for (l, &i) in s.halves.perm.iter().enumerate() {
            self.p.positions[i as usize] = s.x[l];
        }
        self.eng.proj = s;
        out
    }
}
