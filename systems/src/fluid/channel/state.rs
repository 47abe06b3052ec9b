//! Setting, diagnosing and serialising the state of a [`ChannelSolver`].

use super::cheb::clenshaw_curtis_weights;
use super::solver::{ChannelError, ChannelParams};
use super::stepper::ChannelSolver;
use glam::DVec3;
use num_complex::Complex64 as C;
use rayon::prelude::*;

const ZERO: C = C::new(0.0, 0.0);
/// First bytes of a serialised channel state.
pub const STATE_MAGIC: [u8; 8] = *b"MGSPCHAN";
/// Version of the serialised channel state.
pub const STATE_VERSION: u32 = 1;
/// Header size in bytes: magic, version, nx, ny, nz, modes, values per field, ν, Δt, t, steps.
const HEADER: usize = 8 + 4 + 6 * 8 + 3 * 8 + 8;

impl ChannelSolver {
    /// Sets the velocity from physical values at the nodes \[m/s\], keeping only the
    /// divergence-free part that satisfies the wall conditions: per Fourier mode the z-velocity
    /// and the z-vorticity of the input are kept, the z-velocity's wall values and wall slopes
    /// are removed by cubic Hermite polynomials in z, the vorticity's wall values are set to
    /// zero, and the horizontal velocities are rebuilt from continuity; the mean flows U, V
    /// keep their interior values with zero wall values, the mean z-velocity is zero.
    /// A divergence-free field that satisfies no slip is reproduced up to rounding.
    pub fn set_velocity(&mut self, u: [&[f64]; 3]) -> Result<(), ChannelError> {
        let n = self.grid().len();
        for (c, f) in u.iter().enumerate() {
            if f.len() != n {
                return Err(ChannelError::FieldSize {
                    component: c,
                    got: f.len(),
                    expected: n,
                });
            }
            if f.iter().any(|v| !v.is_finite()) {
                return Err(ChannelError::NonFinite(c));
            }
        }
        let modes = self.to_modes(&u);
        let g = *self.grid();
        let nz = g.nz;
        let z = g.z_levels();
        let h = g.height;
        let herm: Vec<[f64; 4]> = z
            .iter()
            .map(|z| {
                let s = z / h;
                let (s2, s3) = (s * s, s * s * s);
                [
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    -2.0 * s3 + 3.0 * s2,
                    (s3 - 2.0 * s2 + s) * h,
                    (s3 - s2) * h,
                ]
            })
            .collect();
        let ops = &self.ops;
        self.w
            .par_chunks_mut(nz)
            .zip(self.eta.par_chunks_mut(nz))
            .enumerate()
            .for_each(|(m, (wm, em))| {
                wm.fill(ZERO);
                em.fill(ZERO);
                if m == 0 {
                    return;
                }
                let Some((kx, ky)) = ops.k(m) else { return };
                let md = &modes[m * 3 * nz..(m + 1) * 3 * nz];
                let (ikx, iky) = (C::new(0.0, kx), C::new(0.0, ky));
                for k in 1..nz - 1 {
                    em[k] = ikx * md[nz + k] - iky * md[k];
                }
                wm.copy_from_slice(&md[2 * nz..3 * nz]);
                let (d0, dn) = ops.wall_dz(wm);
                let (w0, wn) = (wm[0], wm[nz - 1]);
                for k in 0..nz {
                    let hk = herm[k];
                    wm[k] -= w0 * hk[0] + wn * hk[1] + d0 * hk[2] + dn * hk[3];
                }
                wm[0] = ZERO;
                wm[nz - 1] = ZERO;
            });
        for c in 0..2 {
            for k in 0..nz {
                self.um[c][k] = if k == 0 || k == nz - 1 {
                    0.0
                } else {
                    modes[c * nz + k].re
                };
            }
        }
        self.update_physical();
        Ok(())
    }

    /// Maximum of `|∇·u|` over the nodes \[1/s\], from the physical velocity differentiated
    /// spectrally (Fourier in x, y; Chebyshev in z).
    pub fn divergence_max(&self) -> f64 {
        let vel = self.velocity();
        let modes = self.to_modes(&vel);
        let nz = self.grid().nz;
        let ops = &self.ops;
        let mut div = vec![ZERO; self.nmodes * nz];
        div.par_chunks_mut(nz).enumerate().for_each(|(m, o)| {
            let md = &modes[m * 3 * nz..(m + 1) * 3 * nz];
            ops.dz(&md[2 * nz..], o);
            if let Some((kx, ky)) = ops.k(m) {
                let (ikx, iky) = (C::new(0.0, kx), C::new(0.0, ky));
                for k in 0..nz {
                    o[k] += ikx * md[k] + iky * md[nz + k];
                }
            } else {
                o.fill(ZERO);
            }
        });
        let mut out = vec![Vec::new()];
        self.to_phys(&div, &mut out);
        out[0].iter().fold(0.0, |a, v| a.max(v.abs()))
    }

    /// Volume-averaged velocity \[m/s\] (uniform weights in x, y; Clenshaw-Curtis in z).
    pub fn mean_velocity(&self) -> DVec3 {
        let g = self.grid();
        let w = clenshaw_curtis_weights(g);
        let np = g.nx * g.ny;
        let mut out = DVec3::ZERO;
        for (k, wk) in w.iter().enumerate() {
            let mut s = DVec3::ZERO;
            for p in k * np..(k + 1) * np {
                s += DVec3::new(self.vel[0][p], self.vel[1][p], self.vel[2][p]);
            }
            out += s * (wk / (np as f64 * g.height));
        }
        out
    }

    /// Wall shear stress per unit density of the mean flow \[m²/s²\]: `ν ∂(U, V)/∂z` at the
    /// bottom wall (index 0) and the top wall (index 1).
    pub fn wall_shear(&self) -> [[f64; 2]; 2] {
        let nz = self.grid().nz;
        let nu = self.params.viscosity;
        let d = &self.ops.d;
        let dot = |row: usize, f: &[f64]| -> f64 {
            d[row * nz..(row + 1) * nz]
                .iter()
                .zip(f)
                .map(|(a, b)| a * b)
                .sum::<f64>()
                * nu
        };
        [
            [dot(0, &self.um[0]), dot(0, &self.um[1])],
            [dot(nz - 1, &self.um[0]), dot(nz - 1, &self.um[1])],
        ]
    }

    /// The mean velocity profiles U(z), V(z) \[m/s\] at the levels.
    pub fn mean_profiles(&self) -> [&[f64]; 2] {
        [&self.um[0], &self.um[1]]
    }

    /// Convective Courant number `Δt · max(|u|/Δx + |v|/Δy + |w|/Δz_k)` over the nodes, with
    /// `Δz_k` the smaller gap to the neighbouring levels.
    pub fn cfl(&self) -> f64 {
        let g = self.grid();
        let z = g.z_levels();
        let np = g.nx * g.ny;
        let (dx, dy) = (g.dx(), g.dy());
        let mut c = 0.0f64;
        for k in 0..g.nz {
            let lo = if k > 0 {
                z[k] - z[k - 1]
            } else {
                f64::INFINITY
            };
            let hi = if k + 1 < g.nz {
                z[k + 1] - z[k]
            } else {
                f64::INFINITY
            };
            let dz = lo.min(hi);
            for p in k * np..(k + 1) * np {
                let v = self.vel[0][p].abs() / dx
                    + self.vel[1][p].abs() / dy
                    + self.vel[2][p].abs() / dz;
                c = c.max(v);
            }
        }
        c * self.params.dt
    }

    /// Lossless serialisation: a header (magic, version, nx, ny, nz, modes, values per field,
    /// ν, Δt, time, steps) and the spectral state (w, η per mode, then U, V) as little-endian
    /// f64. [`ChannelSolver::from_state_bytes`] restores it bit for bit.
    pub fn state_bytes(&self) -> Vec<u8> {
        let g = self.grid();
        let ns = self.w.len();
        let mut b = Vec::with_capacity(HEADER + (4 * ns + 2 * g.nz) * 8);
        b.extend_from_slice(&STATE_MAGIC);
        b.extend_from_slice(&STATE_VERSION.to_le_bytes());
        for v in [g.nx, g.ny, g.nz, self.nmodes, ns] {
            b.extend_from_slice(&(v as u64).to_le_bytes());
        }
        b.extend_from_slice(&((2 * ns + g.nz) as u64).to_le_bytes());
        for v in [self.params.viscosity, self.params.dt, self.time] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&self.steps.to_le_bytes());
        for c in self.w.iter().chain(&self.eta) {
            b.extend_from_slice(&c.re.to_le_bytes());
            b.extend_from_slice(&c.im.to_le_bytes());
        }
        for v in self.um[0].iter().chain(&self.um[1]) {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// Restores a solver from [`ChannelSolver::state_bytes`]. `params` must have the same grid
    /// dimensions; its viscosity and time step are used (they may differ from the state's).
    /// Never panics: wrong magic, version, grid, length or non-finite values are errors.
    pub fn from_state_bytes(params: ChannelParams, bytes: &[u8]) -> Result<Self, ChannelError> {
        let mut s = Self::new(params)?;
        if bytes.len() < 8 || bytes[..8] != STATE_MAGIC {
            return Err(ChannelError::Magic);
        }
        if bytes.len() < HEADER {
            return Err(ChannelError::Length {
                got: bytes.len(),
                expected: HEADER,
            });
        }
        let u32_at =
            |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        let u64_at = |o: usize| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&bytes[o..o + 8]);
            u64::from_le_bytes(a)
        };
        let version = u32_at(8);
        if version != STATE_VERSION {
            return Err(ChannelError::Version(version));
        }
        let g = *s.grid();
        let dims = [u64_at(12), u64_at(20), u64_at(28)];
        let want = [g.nx as u64, g.ny as u64, g.nz as u64];
        if dims != want {
            return Err(ChannelError::GridMismatch {
                state: dims,
                params: want,
            });
        }
        let ns = s.w.len();
        if u64_at(36) != s.nmodes as u64
            || u64_at(44) != ns as u64
            || u64_at(52) != (2 * ns + g.nz) as u64
        {
            return Err(ChannelError::Corrupt("field lengths do not match the grid"));
        }
        let expected = HEADER + (4 * ns + 2 * g.nz) * 8;
        if bytes.len() != expected {
            return Err(ChannelError::Length {
                got: bytes.len(),
                expected,
            });
        }
        let f64_at = |o: usize| f64::from_bits(u64_at(o));
        let time = f64_at(76);
        if !time.is_finite() {
            return Err(ChannelError::Corrupt("non-finite time"));
        }
        s.time = time;
        s.steps = u64_at(84);
        let mut o = HEADER;
        for c in s.w.iter_mut().chain(s.eta.iter_mut()) {
            *c = C::new(f64_at(o), f64_at(o + 8));
            o += 16;
        }
        for v in s.um.iter_mut().flatten() {
            *v = f64_at(o);
            o += 8;
        }
        let bad =
            s.w.iter()
                .chain(&s.eta)
                .any(|c| !(c.re.is_finite() && c.im.is_finite()))
                || s.um.iter().flatten().any(|v| !v.is_finite());
        if bad {
            return Err(ChannelError::Corrupt("non-finite state value"));
        }
        s.update_physical();
        Ok(s)
    }
}
