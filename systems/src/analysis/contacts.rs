//! Mean contact number <C> ([T000 §2.2.5, §3.3]).
//!
//! Two particles touch when their surface gap is below delta. The mean per-particle count is
//! 2 (#touching pairs) / N (erratum E-000-5: the text omits the factor 2). Because overlaps up to
//! the tolerance survive and round-off blurs exact touching, <C>(delta) is evaluated at 16
//! log-spaced delta in [1e-8, 1e-5] D and a least-squares straight line in delta is
//! extrapolated to delta = 0 (Wouterse et al. 2007, as in the thesis). Gaps may be negative
//! (tolerated overlaps) and count as contacts.

use super::super::packing::neighbour::NeighbourList;
use super::super::packing::state::PackingState;

/// Contact numbers of a packing.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactNumbers {
    /// <C> extrapolated to delta = 0.
    pub extrapolated: f64,
    /// <C> at delta = 1e-4 D (the thesis's simple estimate).
    pub at_1e_4: f64,
    /// Sample points (delta / D, <C>(delta)) of the fit.
    pub samples: Vec<(f64, f64)>,
    /// Number of particles with each contact count (index = count) at delta -> 0 counted at
    /// the smallest delta.
    pub histogram: Vec<u64>,
    /// Largest overlap in the packing / D.
    pub max_overlap: f64,
}

/// Contact numbers of `state` (reduced units).
pub fn contact_numbers(state: &PackingState) -> ContactNumbers {
    let n = state.len().max(1);
    let mut list = NeighbourList::new(2e-4);
    let mut state = state.clone();
    list.build(&mut state);
    let state = &state;
    let mut gaps = Vec::new();
    let mut per_particle_small = vec![0u64; state.len()];
    let mut max_overlap: f64 = 0.0;
    let d_min = 1e-8;
    for (i, j, shift) in list.unique_pairs(state.edges) {
        let c = state.contact(i, j, shift);
        let gap = -c.overlap;
        max_overlap = max_overlap.max(c.overlap);
        gaps.push(gap);
        if gap < d_min {
            per_particle_small[i] += 1;
            per_particle_small[j] += 1;
        }
    }
    let count = |delta: f64| 2.0 * gaps.iter().filter(|g| **g < delta).count() as f64 / n as f64;
    let samples: Vec<(f64, f64)> = (0..16)
        .map(|k| {
            let delta = 1e-8 * 10f64.powf(3.0 * k as f64 / 15.0);
            (delta, count(delta))
        })
        .collect();
    let m = samples.len() as f64;
    let sx: f64 = samples.iter().map(|p| p.0).sum();
    let sy: f64 = samples.iter().map(|p| p.1).sum();
    let sxx: f64 = samples.iter().map(|p| p.0 * p.0).sum();
    let sxy: f64 = samples.iter().map(|p| p.0 * p.1).sum();
    let den = m * sxx - sx * sx;
    let slope = if den.abs() > 0.0 {
        (m * sxy - sx * sy) / den
    } else {
        0.0
    };
    let extrapolated = (sy - slope * sx) / m;
    let maxc = per_particle_small.iter().copied().max().unwrap_or(0) as usize;
    let mut histogram = vec![0u64; maxc + 1];
    for c in per_particle_small {
        histogram[c as usize] += 1;
    }
    ContactNumbers {
        extrapolated,
        at_1e_4: count(1e-4),
        samples,
        histogram,
        max_overlap,
    }
}
