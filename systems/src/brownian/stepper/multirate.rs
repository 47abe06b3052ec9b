//! Multirate step doubling on the Brownian tree: only the particles that need smaller steps
//! take them.
//!
//! The global adaptive scheme ([`super::advance`]) bisects every particle's step as soon as one
//! particle fails the error test, so one stiff pair among 10⁴ particles costs 10⁴ × its
//! sub-steps. Here an interval `[s, s + h]` is tried for a *set* R of particles, as one step and
//! as two half steps on the same Brownian path (bridge increments from each particle's own
//! stream, exactly as in the global scheme). The particles whose error or displacement fails
//! (F) and their interaction partners within R (one layer, so that every accepted particle is at
//! least one interaction range from a failing one) form R′; the rest of R is accepted over the
//! interval with its two-half-step result, and R′ recurses on the two halves. While R′ is
//! refined, every other particle enters the forces at its position interpolated along its own
//! accepted sub-steps (piecewise linear through its start, middle and end), and the drift is
//! evaluated for R′ only.
//!
//! Properties (tested): a particle that never meets a failing neighbour takes the same path as
//! in the global scheme when no particle fails; for independent particles each particle's path
//! is bitwise that of the global scheme run on it alone; and the result converges to the same
//! path solution as the global scheme as the tolerance shrinks. Multirate methods of this kind
//! (local time stepping with a buffer layer and interpolated neighbours) are first order in the
//! coupling between fast and slow particles, like the explicit update itself.
//!
//! The bridge draws come from each particle's own stream in the order of its own refinements,
//! so a multirate and a global run of one seed share the first step's increments only.
//!
//! Not for hydrodynamic interactions (the noise couples all particles) or hard cores (the
//! overlap projection is global): the caller falls back to [`super::advance`].

use glam::DVec3;
use rand_xoshiro::Xoshiro256PlusPlus;

use magsep_components::brownian::BrownianStats;

use super::{Dynamics, normal3, wiener_increments};

/// Dynamics whose drift can be evaluated for a subset of particles.
pub trait LocalDynamics: Dynamics {
    /// Drift `μ F(x)` [m/s] of the particles in `active` (ascending indices) at configuration
    /// `x`; other entries of `v` are left untouched.
    fn drift_of(&mut self, x: &[DVec3], active: &[usize], v: &mut [DVec3]);
    /// Call `f(j)` for every particle `j` whose position the force on `i` depends on at `x`
    /// (a superset is fine).
    fn partners(&mut self, x: &[DVec3], i: usize, f: &mut dyn FnMut(usize));
}

/// Where an accepted particle is during later sub-steps: piecewise linear through its start,
/// middle and end over `[t0, t0 + h]` (fractions of the step).
#[derive(Debug, Clone, Copy)]
struct Track {
    t0: f64,
    h: f64,
    start: DVec3,
    mid: DVec3,
    end: DVec3,
}

impl Track {
    fn at(&self, t: f64) -> DVec3 {
        if self.h <= 0.0 {
            return self.end;
        }
        let u = ((t - self.t0) / self.h).clamp(0.0, 1.0);
        if u <= 0.5 {
            self.start + (self.mid - self.start) * (2.0 * u)
        } else {
            self.mid + (self.end - self.mid) * (2.0 * u - 1.0)
        }
    }
}

/// One interval of the tree: start and length (fractions of the step), the set's increments
/// (indexed like `set`), the set, the depth, and whether the set's drift at the start is known.
struct Interval {
    s: f64,
    h: f64,
    w: Vec<DVec3>,
    set: Vec<usize>,
    depth: u32,
    drift_known: bool,
}

/// Advance `x` by one step `dt` \[s\] with multirate step doubling (see the module header).
/// `v0` is the drift at `x` if the caller has it. `stats.substeps` counts accepted intervals
/// (two sub-steps each, like the global scheme), `stats.particle_substeps` the sub-steps taken
/// per particle.
#[allow(clippy::too_many_arguments)]
pub fn advance_multirate<D: LocalDynamics>(
    dynamics: &mut D,
    x: &mut [DVec3],
    v0: Option<Vec<DVec3>>,
    dt: f64,
    (tolerance, max_displacement, max_depth): (f64, f64, u32),
    rngs: &mut [Xoshiro256PlusPlus],
    stats: &mut BrownianStats,
) {
    let n = x.len();
    let mobile0 = dynamics.mobile().to_vec();
    let mut v = v0.unwrap_or_else(|| {
        let mut v = vec![DVec3::ZERO; n];
        dynamics.at_time(0.0);
        dynamics.drift(x, &mut v);
        stats.force_evaluations += 1;
        v
    });
    let w = wiener_increments(&mobile0, dt, rngs);
    let set: Vec<usize> = (0..n).filter(|&i| mobile0[i]).collect();
    let mut tracks: Vec<Track> = x
        .iter()
        .map(|&p| Track {
            t0: 0.0,
            h: 0.0,
            start: p,
            mid: p,
            end: p,
        })
        .collect();
    let mut in_set = vec![false; n];
    let mut stack = vec![Interval {
        w: set.iter().map(|&i| w[i]).collect(),
        set,
        s: 0.0,
        h: 1.0,
        depth: 0,
        drift_known: true,
    }];
    // scratch, full length: positions of everyone at a time, increments, displacements
    let mut env = x.to_vec();
    let mut wfull = vec![DVec3::ZERO; n];
    let mut bl = vec![DVec3::ZERO; n];
    let mut br = vec![DVec3::ZERO; n];
    let mut vm = vec![DVec3::ZERO; n];
    while let Some(iv) = stack.pop() {
        // the set may have lost particles captured meanwhile
        let keep: Vec<bool> = iv.set.iter().map(|&i| dynamics.mobile()[i]).collect();
        let (set, w): (Vec<usize>, Vec<DVec3>) = iv
            .set
            .iter()
            .zip(&iv.w)
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|((&i, &wi), _)| (i, wi))
            .unzip();
        if set.is_empty() {
            continue;
        }
        for &i in &set {
            in_set[i] = true;
        }
        let place = |env: &mut [DVec3], t: f64, in_set: &[bool], tracks: &[Track], x: &[DVec3]| {
            for i in 0..env.len() {
                env[i] = if in_set[i] { x[i] } else { tracks[i].at(t) };
            }
        };
        let (s, h) = (iv.s, iv.h);
        place(&mut env, s, &in_set, &tracks, x);
        if !iv.drift_known {
            dynamics.at_time(s);
            dynamics.drift_of(&env, &set, &mut v);
            stats.force_evaluations += 1;
        }
        // bridge increments of the set's particles
        let sq = 0.5 * (h * dt).sqrt();
        let wl: Vec<DVec3> = set
            .iter()
            .zip(&w)
            .map(|(&i, &wi)| wi * 0.5 + normal3(&mut rngs[i]) * sq)
            .collect();
        let wr: Vec<DVec3> = w.iter().zip(&wl).map(|(a, l)| *a - *l).collect();
        for (&i, &wi) in set.iter().zip(&wl) {
            wfull[i] = wi;
        }
        dynamics.noise(&wfull, &mut bl);
        for (&i, &wi) in set.iter().zip(&wr) {
            wfull[i] = wi;
        }
        dynamics.noise(&wfull, &mut br);
        for &i in &set {
            wfull[i] = DVec3::ZERO;
        }
        let hs = h * dt;
        // half steps: the set moves, everyone else follows its track
        let start: Vec<DVec3> = set.iter().map(|&i| x[i]).collect();
        place(&mut env, s + 0.5 * h, &in_set, &tracks, x);
        for (k, &i) in set.iter().enumerate() {
            env[i] = start[k] + v[i] * (0.5 * hs) + bl[i];
        }
        let xm: Vec<DVec3> = set.iter().map(|&i| env[i]).collect();
        dynamics.at_time(s + 0.5 * h);
        dynamics.drift_of(&env, &set, &mut vm);
        stats.force_evaluations += 1;
        let mut fail = Vec::new();
        let mut x2 = Vec::with_capacity(set.len());
        for (k, &i) in set.iter().enumerate() {
            let end = xm[k] + vm[i] * (0.5 * hs) + br[i];
            let one = start[k] + v[i] * hs + bl[i] + br[i];
            let inv = 1.0 / dynamics.radii()[i];
            let err = (one - end).length() * inv;
            let disp = ((xm[k] - start[k]).length() * inv).max((end - xm[k]).length() * inv);
            let ok = err <= tolerance && disp <= max_displacement && err.is_finite();
            if !ok {
                fail.push(i);
            }
            x2.push(end);
        }
        // refine the failing particles and their partners, unless at the depth limit
        let refine = if fail.is_empty() || iv.depth + 1 >= max_depth {
            if !fail.is_empty() {
                stats.depth_limit_hits += 1;
            }
            vec![false; set.len()]
        } else {
            let mut mark = vec![false; n];
            for &i in &fail {
                mark[i] = true;
                dynamics.partners(&env, i, &mut |j| mark[j] = true);
            }
            set.iter().map(|&i| mark[i]).collect()
        };
        // accept the others over [s, s + h]: two half steps, with capture on each
        let accepted: Vec<usize> = (0..set.len()).filter(|&k| !refine[k]).collect();
        if !accepted.is_empty() {
            stats.max_depth_reached = stats.max_depth_reached.max(iv.depth + 1);
            stats.substeps += 2;
            stats.particle_substeps += 2 * accepted.len() as u64;
            accept_interval(
                dynamics,
                x,
                &set,
                &accepted,
                &start,
                &xm,
                &x2,
                (s, h),
                &mut tracks,
            );
        }
        for &i in &set {
            in_set[i] = false;
        }
        if accepted.len() < set.len() {
            stats.rejections += 1;
            let sub = |ws: &[DVec3]| -> (Vec<usize>, Vec<DVec3>) {
                (0..set.len())
                    .filter(|&k| refine[k])
                    .map(|k| (set[k], ws[k]))
                    .unzip()
            };
            let (rs, rw) = sub(&wr);
            let (ls, lw) = sub(&wl);
            stack.push(Interval {
                s: s + 0.5 * h,
                h: 0.5 * h,
                w: rw,
                set: rs,
                depth: iv.depth + 1,
                drift_known: false,
            });
            stack.push(Interval {
                s,
                h: 0.5 * h,
                w: lw,
                set: ls,
                depth: iv.depth + 1,
                drift_known: true,
            });
        }
    }
}

/// Accept the two half steps `start → xm → x2` of the set's entries `accepted` over `[s, s+h]`:
/// capture hooks on each half (with everyone else held still, so only these particles are
/// swept), then record their tracks.
#[allow(clippy::too_many_arguments)]
fn accept_interval<D: Dynamics>(
    dynamics: &mut D,
    x: &mut [DVec3],
    set: &[usize],
    accepted: &[usize],
    start: &[DVec3],
    xm: &[DVec3],
    x2: &[DVec3],
    (s, h): (f64, f64),
    tracks: &mut [Track],
) {
    let from = x.to_vec();
    let mut mid = from.clone();
    let moved: Vec<usize> = accepted.iter().map(|&k| set[k]).collect();
    for &k in accepted {
        mid[set[k]] = xm[k];
    }
    dynamics.accept_moved(&from, &mut mid, &moved, s + 0.5 * h);
    let mut end = mid.clone();
    for &k in accepted {
        let i = set[k];
        // captured at mid-step: stays there
        if dynamics.mobile()[i] {
            end[i] = x2[k];
        }
    }
    dynamics.accept_moved(&mid, &mut end, &moved, s + h);
    for &k in accepted {
        let i = set[k];
        tracks[i] = Track {
            t0: s,
            h,
            start: start[k],
            mid: mid[i],
            end: end[i],
        };
        x[i] = end[i];
    }
}

#[cfg(test)]
mod tests;
