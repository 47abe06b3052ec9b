//! The resting solve for spheres as used by default: nonsmooth nonlinear conjugate gradients
//! (NNCG; Silcowitz, Niebe & Erleben 2010, `Silcowitz2010` in docs/references.md) on projected
//! Gauss–Seidel sweeps over two blocks of the contact graph that share no particle, solved
//! side by side.
//!
//! Blocks: with at least [`SPLIT_MIN_CONTACTS`] contacts, the particles are split at the median
//! of their (wrapped) coordinate along a horizontal axis into two halves; the contacts within
//! each half form blocks 0 and 1, the contacts across the cut (and across a periodic seam) form
//! block 2. A forward sweep relaxes blocks 0 and 1 (each in the usual depth order, on two
//! threads when there are two) and then block 2; a backward sweep runs the reverse. Blocks 0
//! and 1 touch disjoint particles, so the result does not depend on the number of threads: it
//! is that of a serial sweep in block order.
//!
//! Momentum: after sweep `k` the change of the contact impulses `s_k` (normal and tangential,
//! stacked) gives `β = |s_k|²/|s_{k−1}|²`; with `β ≤ 1` the impulses move on by `β p_{k−1}` and
//! `p_k = s_k + β p_{k−1}`, otherwise the direction restarts (`p_k = s_k`). The next sweep
//! projects the impulses back onto their cones; the last sweep is never followed by a momentum
//! step, so the returned impulses are always projected. The plain sweeps
//! ([`super::sweeps`]) stay the reference; a test compares the two on a settling bed.

use std::ops::Range;

use glam::DVec3;

use super::{Body, relax_pair, relax_wall};
use crate::collision::domain::CollisionDomain;
use crate::collision::engine::resting::Contact;

/// Fewest resting contacts for which the solve splits the contact graph into blocks.
pub(in crate::collision::engine) const SPLIT_MIN_CONTACTS: usize = 2048;

/// The block layout of the contacts: `contacts[..g0]` block 0 (particles `0..n0`, indices
/// local to it), `contacts[g0..g0 + g1]` block 1 (particles `n0..n`, indices minus `n0`), the
/// rest block 2 (indices `0..n`). Wall partners keep their code `j ≥ n`.
#[derive(Debug, Clone, Copy)]
pub(in crate::collision::engine) struct Blocks {
    pub(in crate::collision::engine) n: usize,
    pub(in crate::collision::engine) n0: usize,
    pub(in crate::collision::engine) g0: usize,
    pub(in crate::collision::engine) g1: usize,
}

/// Per-contact impulse change of the last sweep and the search direction (normal, tangent).
pub(in crate::collision::engine) type Delta = [f64; 4];

/// Per contact: the impulse change of the last sweep and the search direction.
pub(in crate::collision::engine) type Aux = [Delta; 2];

/// One sweep over a block; returns the largest velocity change, its largest ratio to the
/// contact's threshold and `|s|²` of the impulse changes (written to `aux[k][0]`).
fn pass(
    contacts: &mut [Contact],
    aux: &mut [Aux],
    bodies: &mut [Body],
    scale: &[f64],
    mu: f64,
    backward: bool,
) -> (f64, f64, f64) {
    let n = bodies.len();
    let m = contacts.len();
    let (mut worst, mut ratio, mut norm) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..m {
        let k = if backward { m - 1 - k } else { k };
        let c = &mut contacts[k];
        let (ln, lt) = (c.lambda_n, c.lambda_t);
        let dv = if (c.j as usize) < n {
            relax_pair(c, bodies, mu)
        } else {
            relax_wall(c, bodies, mu)
        };
        let d = c.lambda_t - lt;
        let s = [c.lambda_n - ln, d.x, d.y, d.z];
        norm += s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + s[3] * s[3];
        aux[k][0] = s;
        worst = worst.max(dv);
        ratio = ratio.max(dv / scale[k]);
    }
    (worst, ratio, norm)
}

/// The momentum step over a block: impulses `+= β p`, bodies updated, `p = s + β p` (or `p = s`
/// when `restart`).
fn momentum(
    contacts: &mut [Contact],
    aux: &mut [Aux],
    bodies: &mut [Body],
    beta: f64,
    restart: bool,
) {
    let n = bodies.len();
    for (c, [s, p]) in contacts.iter_mut().zip(aux.iter_mut()) {
        if restart {
            *p = *s;
            continue;
        }
        let dn = beta * p[0];
        let dt = DVec3::new(p[1], p[2], p[3]) * beta;
        c.lambda_n += dn;
        c.lambda_t += dt;
        let imp = c.normal * dn + dt;
        let a = &mut bodies[c.i as usize];
        a.v -= imp * a.inv_mass;
        a.w -= c.r_a.cross(imp) * a.inv_inertia;
        if (c.j as usize) < n {
            let b = &mut bodies[c.j as usize];
            b.v += imp * b.inv_mass;
            b.w += c.r_b.cross(imp) * b.inv_inertia;
        }
        *p = [
            s[0] + beta * p[0],
            s[1] + beta * p[1],
            s[2] + beta * p[2],
            s[3] + beta * p[3],
        ];
    }
}

/// Runs `f` on blocks 0 and 1 side by side, then on block 2 (`rev`: block 2 first); each call
/// gets the block's contacts, their [`Aux`], the block's bodies and its range of contacts.
fn each_block<R: Send>(
    contacts: &mut [Contact],
    aux: &mut [Aux],
    bodies: &mut [Body],
    b: Blocks,
    rev: bool,
    f: &(impl Fn(&mut [Contact], &mut [Aux], &mut [Body], Range<usize>) -> R + Sync),
) -> [R; 3] {
    let g01 = b.g0 + b.g1;
    let m = contacts.len();
    let (c01, c2) = contacts.split_at_mut(g01);
    let (a01, a2) = aux.split_at_mut(g01);
    let bodies = &mut bodies[..b.n];
    let r2 = if rev {
        Some(f(c2, a2, bodies, g01..m))
    } else {
        None
    };
    let (c0, c1) = c01.split_at_mut(b.g0);
    let (a0, a1) = a01.split_at_mut(b.g0);
    let (b0, b1) = bodies.split_at_mut(b.n0);
    let (r0, r1) = if b.g0 > 0 && b.g1 > 0 {
        rayon::join(|| f(c0, a0, b0, 0..b.g0), || f(c1, a1, b1, b.g0..g01))
    } else {
        (f(c0, a0, b0, 0..b.g0), f(c1, a1, b1, b.g0..g01))
    };
    let r2 = match r2 {
        Some(r) => r,
        None => f(c2, a2, bodies, g01..m),
    };
    [r0, r1, r2]
}

/// The NNCG solve (see the module header) over `contacts` laid out as `blocks`, at most
/// `max_sweeps` sweeps; `scale[k]` is contact `k`'s convergence threshold [m/s]; `aux` is
/// scratch. Returns the sweeps done and the residual (the largest velocity change of the last
/// sweep) [m/s].
#[allow(clippy::too_many_arguments)]
pub(in crate::collision::engine) fn sweeps(
    contacts: &mut [Contact],
    bodies: &mut [Body],
    blocks: Blocks,
    scale: &[f64],
    aux: &mut Vec<Aux>,
    mu: f64,
    max_sweeps: usize,
) -> (usize, f64) {
    let m = contacts.len();
    aux.clear();
    aux.resize(m, [[0.0; 4]; 2]);
    let (mut sweeps, mut residual, mut last_norm) = (0, 0.0, f64::INFINITY);
    while sweeps < max_sweeps {
        let backward = sweeps % 2 == 1;
        sweeps += 1;
        let r = each_block(
            contacts,
            aux,
            bodies,
            blocks,
            backward,
            &|c, a, b, range| pass(c, a, b, &scale[range], mu, backward),
        );
        residual = r[0].0.max(r[1].0).max(r[2].0);
        let ratio = r[0].1.max(r[1].1).max(r[2].1);
        let norm = r[0].2 + r[1].2 + r[2].2;
        if ratio < 1.0 || ratio.is_nan() || sweeps == max_sweeps {
            break;
        }
        let beta = norm / last_norm;
        let restart = beta.partial_cmp(&1.0).is_none_or(|o| o.is_gt()) || sweeps == 1;
        last_norm = norm;
        each_block(contacts, aux, bodies, blocks, false, &|c, a, b, _| {
            momentum(c, a, b, beta, restart)
        });
    }
    (sweeps, residual)
}

/// Two halves of the particles (see the module header), kept between steps.
#[derive(Debug, Clone, Default)]
pub(in crate::collision::engine) struct Halves {
    /// Per particle, its coordinate along the cut axis (wrapped) [m].
    key: Vec<f64>,
    /// Scratch for the median.
    sample: Vec<f64>,
    /// Per particle, its half (0 or 1).
    pub(in crate::collision::engine) side: Vec<u8>,
    /// Local particle index (half 0 first, each half in particle order) → particle index.
    pub(in crate::collision::engine) perm: Vec<u32>,
    /// Particle index → local index.
    pub(in crate::collision::engine) local: Vec<u32>,
    /// Particles in half 0.
    pub(in crate::collision::engine) n0: usize,
}

impl Halves {
    /// Splits the particles at `positions` across the axis of largest spread among those no
    /// wall faces (all three if every axis is faced) at the median coordinate of the particles
    /// `sample` (all particles if `None`).
    pub(in crate::collision::engine) fn split(
        &mut self,
        positions: &[DVec3],
        domain: &CollisionDomain,
        sample: Option<&mut dyn Iterator<Item = usize>>,
    ) {
        let n = positions.len();
        let faced = |a: usize| domain.planes.iter().any(|p| p.normal[a].abs() > 0.5);
        let spread = |a: usize| {
            let (lo, hi) =
                positions
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        let v = domain.wrap(*x)[a];
                        (lo.min(v), hi.max(v))
                    });
            hi - lo
        };
        let free: Vec<usize> = (0..3).filter(|&a| !faced(a)).collect();
        let axes = if free.is_empty() { vec![0, 1, 2] } else { free };
        let axis = axes
            .into_iter()
            .map(|a| (a, spread(a)))
            .fold((0, f64::NEG_INFINITY), |b, c| if c.1 > b.1 { c } else { b })
            .0;
        self.key.clear();
        self.key
            .extend(positions.iter().map(|x| domain.wrap(*x)[axis]));
        self.sample.clear();
        match sample {
            Some(it) => self.sample.extend(it.map(|i| self.key[i])),
            None => self.sample.extend_from_slice(&self.key),
        }
        let mid = self.sample.len() / 2;
        let cut = if self.sample.is_empty() {
            0.0
        } else {
            *self.sample.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        self.side.clear();
        self.side.extend(
            self.key
                .iter()
                .map(|&k| u8::from(k.total_cmp(&cut).is_ge())),
        );
        self.perm.clear();
        self.local.clear();
        self.local.resize(n, 0);
        for half in 0..2 {
            for i in 0..n {
                if self.side[i] == half {
                    self.local[i] = self.perm.len() as u32;
                    self.perm.push(i as u32);
                }
            }
            if half == 0 {
                self.n0 = self.perm.len();
            }
        }
    }

    /// The block of the pair `(i, j)` (`j ≥ n`: a wall): the common half, or 2.
    pub(in crate::collision::engine) fn block(&self, i: usize, j: usize) -> u8 {
        if j >= self.side.len() || self.side[i] == self.side[j] {
            self.side[i]
        } else {
            2
        }
    }
}

/// Scratch of [`layout`] and [`sweeps`] (kept between steps).
#[derive(Debug, Clone, Default)]
pub(in crate::collision::engine) struct Layout {
    /// The halves of the particles.
    pub(in crate::collision::engine) halves: Halves,
    /// Local particle index → particle index.
    pub(in crate::collision::engine) perm: Vec<u32>,
    /// Particle index → local index.
    local: Vec<u32>,
    /// The contacts in block order, with local indices.
    pub(in crate::collision::engine) grouped: Vec<Contact>,
    /// Per grouped contact, its index in the caller's contacts.
    pub(in crate::collision::engine) src: Vec<u32>,
    /// Per grouped contact, the NNCG vectors.
    pub(in crate::collision::engine) aux: Vec<Aux>,
}

/// Splits `contacts` (in sweep order; `n` particles at `positions`, walls `j ≥ n`) into blocks
/// (see the module header; the cut at the median of the contacts' first particles): fills
/// `s.grouped`, `s.src` and `s.perm` and returns the layout.
///
/// Local indices: within each half, the particles in the order a forward sweep of the half's
/// block first touches them, then the half's other particles in particle order. A sweep then
/// walks its bodies nearly in memory order; the arithmetic does not depend on where a body is
/// stored, so the solve is bitwise that of any other numbering.
pub(in crate::collision::engine) fn layout(
    contacts: &[Contact],
    positions: &[DVec3],
    domain: &CollisionDomain,
    s: &mut Layout,
) -> Blocks {
    let n = positions.len();
    let m = contacts.len();
    s.grouped.clear();
    s.src.clear();
    let split = m >= SPLIT_MIN_CONTACTS;
    let h = &mut s.halves;
    if split {
        h.split(
            positions,
            domain,
            Some(&mut contacts.iter().map(|c| c.i as usize)),
        );
    }
    let block = |i: usize, j: usize| if split { h.block(i, j) } else { 0 };
    let n0 = if split { h.n0 } else { n };
    let mut counts = [0usize; 3];
    for b in 0..3u8 {
        for (k, c) in contacts.iter().enumerate() {
            if block(c.i as usize, c.j as usize) == b {
                s.grouped.push(*c);
                s.src.push(k as u32);
                counts[b as usize] += 1;
            }
        }
    }
    // local indices: first touch in blocks 0 and 1, then the rest of each half
    s.local.clear();
    s.local.resize(n, u32::MAX);
    let mut next = [0u32, n0 as u32];
    let side = |i: usize| if split { h.side[i] as usize } else { 0 };
    let mut assign = |i: usize, local: &mut [u32]| {
        if local[i] == u32::MAX {
            local[i] = next[side(i)];
            next[side(i)] += 1;
        }
    };
    for c in &s.grouped[..counts[0] + counts[1]] {
        assign(c.i as usize, &mut s.local);
        if (c.j as usize) < n {
            assign(c.j as usize, &mut s.local);
        }
    }
    for i in 0..n {
        assign(i, &mut s.local);
    }
    s.perm.clear();
    s.perm.resize(n, 0);
    for (i, &l) in s.local.iter().enumerate() {
        s.perm[l as usize] = i as u32;
    }
    for (k, g) in s.grouped.iter_mut().enumerate() {
        let shift = if k >= counts[0] && k < counts[0] + counts[1] {
            n0 as u32
        } else {
            0
        };
        g.i = s.local[g.i as usize] - shift;
        if (g.j as usize) < n {
            g.j = s.local[g.j as usize] - shift;
        }
    }
    Blocks {
        n,
        n0,
        g0: counts[0],
        g1: counts[1],
    }
}
