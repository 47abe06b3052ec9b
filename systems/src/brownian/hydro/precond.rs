//! Cluster preconditioner for the Lanczos noise of the matrix-free mobility (Ando, Chow, Saad
//! & Skolnick, J. Chem. Phys. 137, 064106 (2012), §III.C: sample μ^{1/2}w as
//! L (L⁻¹ μ L⁻ᵀ)^{1/2} w with a cheap factor L).
//!
//! # Equations
//! L is block diagonal: for a cluster of close particles (pairs with r < [`REACH`]·(a_i + a_j),
//! joined closest pair first, at most [`MAX_CLUSTER`] particles) it is the lower Cholesky
//! factor of the cluster's dense RPY block μ_c = L_c L_cᵀ; for a particle in no cluster it
//! is √(μ_ii) I. With G = L⁻¹ μ L⁻ᵀ (symmetric positive definite) the noise
//! y = L G^{1/2} w has covariance L G Lᵀ = μ exactly, whatever L is; L only changes how
//! fast Lanczos converges. Close and overlapping pairs give μ its smallest eigenvalues
//! (a strongly overlapping pair moves almost as one sphere), which G no longer has: at
//! φ = 0.01 with uniformly random (overlapping) positions, N = 10⁴, the smallest Ritz value
//! of μ/μ₀ is 0.11 and the largest 121.
//!
//! # Properties
//! Preparation O(N) (cell grid) plus O(s³) per cluster of s particles; each product adds two
//! triangular solves, O(Σ s²). A cluster whose Cholesky factorisation fails in floating point
//! falls back to √(μ_ii) per particle (still a valid preconditioner). Sequential and in a
//! fixed order: results are bitwise the same for every thread count.
//!
//! # Units
//! L in √(m/(N s)) (μ in m/(N s)); G is dimensionless.

use glam::DVec3;
use std::collections::HashMap;

use super::rpy::{rpy_block, self_mobility};

/// Pairs closer than `REACH`·(a_i + a_j) are joined into clusters.
pub(crate) const REACH: f64 = 1.5;

/// Largest cluster (particles); joining stops at this size (dense Cholesky is O(s³)).
pub(crate) const MAX_CLUSTER: usize = 32;

/// One cluster: its particles (increasing) and the row-major lower factor (3s × 3s).
#[derive(Debug, Clone)]
struct Cluster {
    members: Vec<u32>,
    l: Vec<f64>,
}

/// The block-diagonal factor L of one configuration.
#[derive(Debug, Clone)]
pub(crate) struct ClusterFactor {
    clusters: Vec<Cluster>,
    /// √(μ_ii) per particle (used for particles in no cluster)
    sqrt_self: Vec<f64>,
    /// per particle: in a cluster
    clustered: Vec<bool>,
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[i as usize];
        parent[i as usize] = parent[p as usize];
        i = p;
    }
    i
}

/// Pairs (r/(a_i + a_j), i, j), i < j, with r < reach·(a_i + a_j), closest first.
fn close_pairs(positions: &[DVec3], radii: &[f64], reach: f64) -> Vec<(f64, u32, u32)> {
    let a_max = radii.iter().fold(0.0_f64, |m, a| m.max(*a));
    let cell = 2.0 * reach * a_max;
    let key = |p: DVec3| -> [i64; 3] {
        let c = (p / cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, p) in positions.iter().enumerate() {
        cells.entry(key(*p)).or_default().push(i as u32);
    }
    let mut pairs = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        let k = key(*p);
        for d in 0..27 {
            let nk = [k[0] + d / 9 - 1, k[1] + (d / 3) % 3 - 1, k[2] + d % 3 - 1];
            let Some(list) = cells.get(&nk) else { continue };
            for &j in list {
                let j = j as usize;
                if j <= i {
                    continue;
                }
                let s = radii[i] + radii[j];
                let ratio = (positions[j] - *p).length() / s;
                if ratio < reach {
                    pairs.push((ratio, i as u32, j as u32));
                }
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    pairs
}

/// In-place lower Cholesky factor of the row-major k×k matrix `a` (None if not positive).
fn cholesky(a: &mut [f64], k: usize) -> Option<()> {
    for j in 0..k {
        let mut d = a[j * k + j];
        for p in 0..j {
            d -= a[j * k + p] * a[j * k + p];
        }
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let d = d.sqrt();
        a[j * k + j] = d;
        for i in j + 1..k {
            let mut s = a[i * k + j];
            for p in 0..j {
                s -= a[i * k + p] * a[j * k + p];
            }
            a[i * k + j] = s / d;
        }
        for p in j + 1..k {
            a[j * k + p] = 0.0;
        }
    }
    Some(())
}

impl ClusterFactor {
    /// The factor at one configuration (inputs already validated: finite, positive radii and
    /// viscosity).
    pub fn new(positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        Self::with_reach(positions, radii, viscosity, REACH)
    }

    /// As [`ClusterFactor::new`] joining pairs closer than `reach`·(a_i + a_j).
    pub fn with_reach(positions: &[DVec3], radii: &[f64], viscosity: f64, reach: f64) -> Self {
        let n = positions.len();
        let sqrt_self: Vec<f64> = radii
            .iter()
            .map(|&a| self_mobility(a, viscosity).sqrt())
            .collect();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        let mut size = vec![1usize; n];
        for (_, i, j) in close_pairs(positions, radii, reach) {
            let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
            if ri != rj && size[ri as usize] + size[rj as usize] <= MAX_CLUSTER {
                let (lo, hi) = (ri.min(rj), ri.max(rj));
                parent[hi as usize] = lo;
                size[lo as usize] += size[hi as usize];
            }
        }
        let mut groups: Vec<Vec<u32>> = vec![Vec::new(); n];
        for i in 0..n as u32 {
            let r = find(&mut parent, i);
            groups[r as usize].push(i);
        }
        let mut clustered = vec![false; n];
        let mut clusters = Vec::new();
        for members in groups.into_iter().filter(|g| g.len() > 1) {
            let k = 3 * members.len();
            let mut l = vec![0.0; k * k];
            for (a, &i) in members.iter().enumerate() {
                for (b, &j) in members.iter().enumerate() {
                    let (i, j) = (i as usize, j as usize);
                    let blk = if i == j {
                        glam::DMat3::from_diagonal(DVec3::splat(sqrt_self[i] * sqrt_self[i]))
                    } else {
                        rpy_block(positions[i] - positions[j], radii[i], radii[j], viscosity)
                    };
                    for r in 0..3 {
                        for c in 0..3 {
                            l[(3 * a + r) * k + 3 * b + c] = blk.col(c)[r];
                        }
                    }
                }
            }
            if cholesky(&mut l, k).is_some() {
                for &i in &members {
                    clustered[i as usize] = true;
                }
                clusters.push(Cluster { members, l });
            }
        }
        Self {
            clusters,
            sqrt_self,
            clustered,
        }
    }

    /// Particles in clusters (for the tests and probes).
    #[cfg(test)]
    pub fn clustered(&self) -> usize {
        self.clustered.iter().filter(|c| **c).count()
    }

    fn singletons(&self, x: &mut [f64], op: impl Fn(f64, f64) -> f64) {
        for ((v, s), c) in x
            .chunks_exact_mut(3)
            .zip(&self.sqrt_self)
            .zip(&self.clustered)
        {
            if !c {
                v.iter_mut().for_each(|e| *e = op(*e, *s));
            }
        }
    }

    /// x ← L x (flat 3N).
    pub fn mul_l(&self, x: &mut [f64]) {
        self.singletons(x, |e, s| e * s);
        for c in &self.clusters {
            let k = 3 * c.members.len();
            let v = gather(&c.members, x);
            let u: Vec<f64> = (0..k)
                .map(|r| (0..=r).map(|p| c.l[r * k + p] * v[p]).sum())
                .collect();
            scatter(&c.members, &u, x);
        }
    }

    /// x ← L⁻¹ x (forward substitution).
    pub fn solve_l(&self, x: &mut [f64]) {
        self.singletons(x, |e, s| e / s);
        for c in &self.clusters {
            let k = 3 * c.members.len();
            let mut v = gather(&c.members, x);
            for r in 0..k {
                let s: f64 = (0..r).map(|p| c.l[r * k + p] * v[p]).sum();
                v[r] = (v[r] - s) / c.l[r * k + r];
            }
            scatter(&c.members, &v, x);
        }
    }

    /// x ← L⁻ᵀ x (back substitution).
    pub fn solve_lt(&self, x: &mut [f64]) {
        self.singletons(x, |e, s| e / s);
        for c in &self.clusters {
            let k = 3 * c.members.len();
            let mut v = gather(&c.members, x);
            for r in (0..k).rev() {
                let s: f64 = (r + 1..k).map(|p| c.l[p * k + r] * v[p]).sum();
                v[r] = (v[r] - s) / c.l[r * k + r];
            }
            scatter(&c.members, &v, x);
        }
    }
}

fn gather(members: &[u32], x: &[f64]) -> Vec<f64> {
    members
        .iter()
        .flat_map(|&i| x[3 * i as usize..3 * i as usize + 3].iter().copied())
        .collect()
}

fn scatter(members: &[u32], v: &[f64], x: &mut [f64]) {
    for (&i, c) in members.iter().zip(v.chunks_exact(3)) {
        x[3 * i as usize..3 * i as usize + 3].copy_from_slice(c);
    }
}
