//! The collocation grid of the channel-flow solver and the layout of its physical fields.
//!
//! magsep's vertical is z, so the channel is periodic in x and y and bounded by no-slip walls
//! at z = 0 and z = `height` (the magnet surfaces of the separation channel). The periodic
//! directions are sampled uniformly (`nx`, `ny` points, Fourier), the wall-normal direction at
//! the `nz` Chebyshev-Gauss-Lobatto points, ascending from the bottom wall:
//!
//! `z_k = height/2 · (1 − cos(π k/(nz − 1)))`, so `ξ_k = 2 z_k/height − 1 = −cos(π k/(nz − 1))`.
//!
//! A physical field is a flat `[f64]` of `nx·ny·nz` values, planes of constant z contiguous,
//! y fastest: `index(i, j, k) = (k·nx + i)·ny + j`. Units: metres.

use glam::DVec3;
use std::f64::consts::PI;

/// Why a grid is rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// A periodic point count is odd or below 4.
    #[error("periodic point counts must be even and at least 4 (got nx = {nx}, ny = {ny})")]
    Periodic {
        /// Points along x.
        nx: usize,
        /// Points along y.
        ny: usize,
    },
    /// Too few wall-normal points.
    #[error("the wall-normal point count must be at least 5 (got nz = {0})")]
    WallNormal(usize),
    /// A length is not finite and positive.
    #[error("the channel lengths must be finite and > 0 (got {0:?})")]
    Length([f64; 3]),
    /// The grid is too large to address.
    #[error("the grid has too many points ({0:?})")]
    TooLarge([usize; 3]),
}

/// Channel grid: `nx × ny` periodic points over `lx × ly` \[m\], `nz` Chebyshev-Gauss-Lobatto
/// points over `0 ≤ z ≤ height` \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelGrid {
    /// Points along x (periodic, even).
    pub nx: usize,
    /// Points along y (periodic, even).
    pub ny: usize,
    /// Chebyshev-Gauss-Lobatto points along z (walls included).
    pub nz: usize,
    /// Period along x \[m\].
    pub lx: f64,
    /// Period along y \[m\].
    pub ly: f64,
    /// Distance between the walls \[m\].
    pub height: f64,
}

impl ChannelGrid {
    /// A checked grid.
    ///
    /// ```
    /// use magsep_systems::fluid::channel::grid::ChannelGrid;
    /// let g = ChannelGrid::new([8, 8, 9], [1.0, 1.0, 2.0]).unwrap();
    /// assert_eq!(g.z(0), 0.0);
    /// assert!((g.z(8) - 2.0).abs() < 1e-15);
    /// assert!((g.z(4) - 1.0).abs() < 1e-15);
    /// assert_eq!(g.index(1, 2, 3), (3 * 8 + 1) * 8 + 2);
    /// ```
    pub fn new(points: [usize; 3], lengths: [f64; 3]) -> Result<Self, GridError> {
        let [nx, ny, nz] = points;
        if nx < 4 || ny < 4 || nx % 2 == 1 || ny % 2 == 1 {
            return Err(GridError::Periodic { nx, ny });
        }
        if nz < 5 {
            return Err(GridError::WallNormal(nz));
        }
        if lengths.iter().any(|l| !(l.is_finite() && *l > 0.0)) {
            return Err(GridError::Length(lengths));
        }
        if nx
            .checked_mul(ny)
            .and_then(|p| p.checked_mul(nz))
            .is_none_or(|n| n > (1 << 31))
        {
            return Err(GridError::TooLarge(points));
        }
        Ok(Self {
            nx,
            ny,
            nz,
            lx: lengths[0],
            ly: lengths[1],
            height: lengths[2],
        })
    }

    /// Number of grid points.
    pub fn len(&self) -> usize {
        self.nx * self.ny * self.nz
    }

    /// Whether the grid has no points (never, for a checked grid).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Flat index of node (i, j, k).
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.nx + i) * self.ny + j
    }

    /// Spacing along x \[m\].
    pub fn dx(&self) -> f64 {
        self.lx / self.nx as f64
    }

    /// Spacing along y \[m\].
    pub fn dy(&self) -> f64 {
        self.ly / self.ny as f64
    }

    /// x of column i \[m\].
    pub fn x(&self, i: usize) -> f64 {
        i as f64 * self.dx()
    }

    /// y of row j \[m\].
    pub fn y(&self, j: usize) -> f64 {
        j as f64 * self.dy()
    }

    /// z of level k \[m\] (Chebyshev-Gauss-Lobatto, ascending; exact 0 and `height` at the walls).
    pub fn z(&self, k: usize) -> f64 {
        let n = self.nz - 1;
        if k == 0 {
            return 0.0;
        }
        if k == n {
            return self.height;
        }
        0.5 * self.height * (1.0 - (PI * k as f64 / n as f64).cos())
    }

    /// All z levels \[m\].
    pub fn z_levels(&self) -> Vec<f64> {
        (0..self.nz).map(|k| self.z(k)).collect()
    }

    /// Node position \[m\].
    pub fn node(&self, i: usize, j: usize, k: usize) -> DVec3 {
        DVec3::new(self.x(i), self.y(j), self.z(k))
    }

    /// Wall-normal control-volume widths \[m\]: each level owns the half-gaps to its neighbours
    /// (half a gap at the walls); they sum to `height` exactly up to rounding.
    pub fn z_widths(&self) -> Vec<f64> {
        let z = self.z_levels();
        let n = self.nz;
        (0..n)
            .map(|k| {
                let lo = if k == 0 {
                    z[0]
                } else {
                    0.5 * (z[k - 1] + z[k])
                };
                let hi = if k + 1 == n {
                    z[n - 1]
                } else {
                    0.5 * (z[k] + z[k + 1])
                };
                hi - lo
            })
            .collect()
    }

    /// Clenshaw-Curtis quadrature weights \[m\] of the z levels: `Σ_k w_k f(z_k)` is exact for
    /// polynomials of degree ≤ nz − 1 on `[0, height]` (all weights are positive). Multiplied
    /// by `dx·dy` they are the node volumes of the discrete integrals (momentum budgets,
    /// filter normalisation).
    ///
    /// ```
    /// use magsep_systems::fluid::channel::grid::ChannelGrid;
    /// let g = ChannelGrid::new([4, 4, 9], [1.0, 1.0, 2.0]).unwrap();
    /// let w = g.z_quadrature_weights();
    /// let int_z4: f64 = w.iter().enumerate().map(|(k, w)| w * g.z(k).powi(4)).sum();
    /// assert!((int_z4 - 32.0 / 5.0).abs() < 1e-13);
    /// ```
    pub fn z_quadrature_weights(&self) -> Vec<f64> {
        let n = self.nz - 1;
        let nf = n as f64;
        let scale = 0.5 * self.height;
        let end = if n.is_multiple_of(2) {
            1.0 / (nf * nf - 1.0)
        } else {
            1.0 / (nf * nf)
        };
        let mut w = vec![end * scale; self.nz];
        for (k, wk) in w.iter_mut().enumerate().take(n).skip(1) {
            let theta = PI * k as f64 / nf;
            let mut v = 1.0;
            for m in 1..=(n - 1) / 2 {
                let mf = m as f64;
                v -= 2.0 * (2.0 * mf * theta).cos() / (4.0 * mf * mf - 1.0);
            }
            if n.is_multiple_of(2) {
                v -= (nf * theta).cos() / (nf * nf - 1.0);
            }
            *wk = 2.0 * v / nf * scale;
        }
        w
    }

    /// The level k with `z_k ≤ z < z_{k+1}` (clamped to the channel), for the host cell of a
    /// point; `None` for a non-finite z.
    pub fn level_below(&self, z: f64) -> Option<usize> {
        if !z.is_finite() {
            return None;
        }
        // invert the Chebyshev map, then correct for rounding against the stored levels
        let xi = (2.0 * z / self.height - 1.0).clamp(-1.0, 1.0);
        let n = self.nz - 1;
        let mut k = (((-xi).acos() / PI) * n as f64).floor().max(0.0) as usize;
        k = k.min(n - 1);
        while k > 0 && self.z(k) > z {
            k -= 1;
        }
        while k + 1 < n && self.z(k + 1) <= z {
            k += 1;
        }
        Some(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_sum_to_height_and_levels_are_found() {
        let g = ChannelGrid::new([4, 6, 33], [1.0, 2.0, 0.15]).unwrap();
        let w: f64 = g.z_widths().iter().sum();
        assert!((w - 0.15).abs() < 1e-15);
        for k in 0..g.nz - 1 {
            let zm = 0.5 * (g.z(k) + g.z(k + 1));
            assert_eq!(g.level_below(zm), Some(k));
            assert_eq!(g.level_below(g.z(k)), Some(k));
        }
        assert_eq!(g.level_below(-1.0), Some(0));
        assert_eq!(g.level_below(1.0), Some(g.nz - 2));
        assert_eq!(g.level_below(f64::NAN), None);
        for nz in [5, 6, 33, 64] {
            let g = ChannelGrid::new([4, 4, nz], [1.0, 1.0, 0.3]).unwrap();
            let w = g.z_quadrature_weights();
            assert!(w.iter().all(|w| *w > 0.0));
            for p in 0..nz as i32 {
                let exact = 0.3f64.powi(p + 1) / f64::from(p + 1);
                let num: f64 = w.iter().enumerate().map(|(k, w)| w * g.z(k).powi(p)).sum();
                assert!(
                    (num - exact).abs() < 1e-13 * exact.max(1e-3),
                    "nz {nz} p {p}"
                );
            }
        }
        assert!(ChannelGrid::new([3, 4, 9], [1.0; 3]).is_err());
        assert!(ChannelGrid::new([4, 4, 4], [1.0; 3]).is_err());
        assert!(ChannelGrid::new([4, 4, 9], [1.0, 0.0, 1.0]).is_err());
    }
}
