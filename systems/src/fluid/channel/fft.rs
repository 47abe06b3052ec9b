//! Two-dimensional real transforms of one constant-z plane (`realfft` along y, `rustfft`
//! along x), with optional zero padding for the 3/2-rule dealiasing.
//!
//! Spectral plane layout: `nx · (ny/2 + 1)` complex amplitudes, mode `m = ix·(ny/2 + 1) + iy`,
//! `kx = 2π/lx · (ix or ix − nx)`, `ky = 2π/ly · iy`. The forward transform is normalised
//! (amplitudes, `f = Σ f̂ e^{i(kx x + ky y)}`); the Nyquist modes (`ix = nx/2`, `iy = ny/2`) are
//! always zero.

use num_complex::Complex64 as C;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Plans for transforming between the `nx × ny` spectral plane and an `mx × my` physical
/// plane (`mx = nx`, `my = ny` without padding).
#[derive(Clone)]
pub struct PlaneFft {
    nx: usize,
    ny: usize,
    mx: usize,
    my: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    xf: Arc<dyn Fft<f64>>,
    xi: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for PlaneFft {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PlaneFft({}x{} -> {}x{})",
            self.nx, self.ny, self.mx, self.my
        )
    }
}

/// Per-task work buffers of a [`PlaneFft`].
pub struct PlaneScratch {
    buf: Vec<C>,
    col: Vec<C>,
    fft: Vec<C>,
    row_r: Vec<f64>,
}

impl PlaneFft {
    /// Plans for an `nx × ny` spectral plane on an `mx × my` physical plane (`mx ≥ nx`,
    /// `my ≥ ny`, all even).
    pub fn new(nx: usize, ny: usize, mx: usize, my: usize) -> Self {
        let mut rp = RealFftPlanner::<f64>::new();
        let mut cp = FftPlanner::<f64>::new();
        Self {
            nx,
            ny,
            mx,
            my,
            r2c: rp.plan_fft_forward(my),
            c2r: rp.plan_fft_inverse(my),
            xf: cp.plan_fft_forward(mx),
            xi: cp.plan_fft_inverse(mx),
        }
    }

    /// Number of spectral modes of a plane, `nx · (ny/2 + 1)`.
    pub fn modes(&self) -> usize {
        self.nx * (self.ny / 2 + 1)
    }

    /// Physical points of a plane, `mx · my`.
    pub fn points(&self) -> usize {
        self.mx * self.my
    }

    /// Work buffers for one task.
    pub fn scratch(&self) -> PlaneScratch {
        let myh = self.my / 2 + 1;
        let s = self
            .r2c
            .get_scratch_len()
            .max(self.c2r.get_scratch_len())
            .max(self.xf.get_inplace_scratch_len())
            .max(self.xi.get_inplace_scratch_len());
        PlaneScratch {
            buf: vec![C::new(0.0, 0.0); self.mx * myh],
            col: vec![C::new(0.0, 0.0); self.mx],
            fft: vec![C::new(0.0, 0.0); s.max(1)],
            row_r: vec![0.0; self.my],
        }
    }

    /// Padded x index of spectral row `ix`, `None` for the Nyquist row.
    #[inline]
    fn xpad(&self, ix: usize) -> Option<usize> {
        let h = self.nx / 2;
        if ix < h {
            Some(ix)
        } else if ix == h {
            None
        } else {
            Some(self.mx + ix - self.nx)
        }
    }

    /// Physical plane (`mx · my`, y fastest) from the spectral amplitudes `spec(m)`.
    pub fn inverse(&self, spec: impl Fn(usize) -> C, out: &mut [f64], s: &mut PlaneScratch) {
        let nyh = self.ny / 2 + 1;
        let myh = self.my / 2 + 1;
        s.buf.fill(C::new(0.0, 0.0));
        for ix in 0..self.nx {
            if let Some(xp) = self.xpad(ix) {
                for iy in 0..nyh - 1 {
                    s.buf[xp * myh + iy] = spec(ix * nyh + iy);
                }
            }
        }
        for iy in 0..nyh - 1 {
            for xp in 0..self.mx {
                s.col[xp] = s.buf[xp * myh + iy];
            }
            self.xi.process_with_scratch(&mut s.col, &mut s.fft);
            for xp in 0..self.mx {
                s.buf[xp * myh + iy] = s.col[xp];
            }
        }
        for xp in 0..self.mx {
            let row = &mut s.buf[xp * myh..(xp + 1) * myh];
            row[0].im = 0.0;
            row[myh - 1] = C::new(0.0, 0.0);
            let o = &mut out[xp * self.my..(xp + 1) * self.my];
            // the only error realfft reports is a non-real first/last entry, excluded above
            let _ = self.c2r.process_with_scratch(row, o, &mut s.fft);
        }
    }

    /// Spectral amplitudes (`modes()`, Nyquist zero) of the physical plane `phys` (`mx · my`),
    /// written through `put(m, value)`.
    pub fn forward(&self, phys: &[f64], mut put: impl FnMut(usize, C), s: &mut PlaneScratch) {
        let nyh = self.ny / 2 + 1;
        let myh = self.my / 2 + 1;
        for xp in 0..self.mx {
            s.row_r
                .copy_from_slice(&phys[xp * self.my..(xp + 1) * self.my]);
            let row = &mut s.buf[xp * myh..(xp + 1) * myh];
            let _ = self.r2c.process_with_scratch(&mut s.row_r, row, &mut s.fft);
        }
        let norm = 1.0 / (self.mx * self.my) as f64;
        for iy in 0..nyh {
            if iy == nyh - 1 {
                for ix in 0..self.nx {
                    put(ix * nyh + iy, C::new(0.0, 0.0));
                }
                continue;
            }
            for xp in 0..self.mx {
                s.col[xp] = s.buf[xp * myh + iy];
            }
            self.xf.process_with_scratch(&mut s.col, &mut s.fft);
            for ix in 0..self.nx {
                let v = match self.xpad(ix) {
                    Some(xp) => s.col[xp] * norm,
                    None => C::new(0.0, 0.0),
                };
                put(ix * nyh + iy, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_padding() {
        let (nx, ny) = (8, 6);
        for (mx, my) in [(8, 6), (12, 10)] {
            let f = PlaneFft::new(nx, ny, mx, my);
            let mut s = f.scratch();
            let nyh = ny / 2 + 1;
            let mut spec = vec![C::new(0.0, 0.0); f.modes()];
            spec[nyh + 1] = C::new(0.5, -0.25); // kx = 1, ky = 1
            spec[0] = C::new(2.0, 0.0);
            spec[(nx - 2) * nyh] = C::new(0.1, 0.3); // kx = -2, ky = 0
            spec[2 * nyh] = C::new(0.1, -0.3); // its conjugate partner
            let mut phys = vec![0.0; f.points()];
            f.inverse(|m| spec[m], &mut phys, &mut s);
            for i in 0..mx {
                for j in 0..my {
                    let (x, y) = (i as f64 / mx as f64, j as f64 / my as f64);
                    let tp = 2.0 * std::f64::consts::PI;
                    let e = 2.0
                        + 2.0 * (C::new(0.5, -0.25) * C::from_polar(1.0, tp * (x + y))).re
                        + 2.0 * (C::new(0.1, -0.3) * C::from_polar(1.0, tp * 2.0 * x)).re;
                    assert!((phys[i * my + j] - e).abs() < 1e-13);
                }
            }
            let mut back = vec![C::new(0.0, 0.0); f.modes()];
            f.forward(&phys, |m, v| back[m] = v, &mut s);
            for m in 0..f.modes() {
                assert!((back[m] - spec[m]).norm() < 1e-14, "{m}");
            }
        }
    }
}
