//! Zero-padded 3D real FFT for the aperiodic (free-space) grid convolution.
//!
//! A field lives on an m³ "compact" grid (the particles' region); the FFT grid has n ≥ 2m
//! points per dimension, the rest zero, so that the circular convolution of length n equals
//! the aperiodic convolution on the m³ region (Hockney & Eastwood). Transforms are pruned:
//! the forward z transforms run only on the m² nonzero lines, the y transforms on the m
//! nonzero x-planes; the inverse computes only what the m³ region needs.
//!
//! Spectrum layout ("T layout"): `[kz][iy][ix]` with kz < n/2 + 1 (real-to-complex along z),
//! element `(kz * n + ky) * n + kx`. Every stage is a set of independent line transforms
//! (rustfft / realfft), distributed over rayon tasks by whole lines, so results are bitwise
//! independent of the thread count.

use std::sync::Arc;

use rayon::prelude::*;
use realfft::num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::Fft;

/// Plans for one grid size.
pub(crate) struct Fft3 {
    pub n: usize,
    pub m: usize,
    pub nzc: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    fwd: Arc<dyn Fft<f64>>,
    inv: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for Fft3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Fft3 {{ n: {}, m: {} }}", self.n, self.m)
    }
}

impl Fft3 {
    /// Plans for FFT length `n` (even) and compact size `m` ≤ n.
    pub fn new(n: usize, m: usize) -> Self {
        let mut rp = RealFftPlanner::<f64>::new();
        let mut cp = rustfft::FftPlanner::<f64>::new();
        Self {
            n,
            m: m.min(n),
            nzc: n / 2 + 1,
            r2c: rp.plan_fft_forward(n),
            c2r: rp.plan_fft_inverse(n),
            fwd: cp.plan_fft_forward(n),
            inv: cp.plan_fft_inverse(n),
        }
    }

    /// Length of a spectrum in T layout.
    pub fn spectrum_len(&self) -> usize {
        self.nzc * self.n * self.n
    }

    /// Forward transform of the field `src[((ix * m + iy) * m + iz) * stride + offset]` on
    /// the compact grid into `out` (T layout, length [`Fft3::spectrum_len`]).
    pub fn forward(&self, src: &[f64], stride: usize, offset: usize, out: &mut [Complex64]) {
        let (n, m, nzc) = (self.n, self.m, self.nzc);
        let zero = Complex64::new(0.0, 0.0);
        // stage 1+2: per x-plane ix < m: z r2c on iy < m, then y FFTs; slab layout [kz][iy]
        let mut slabs = vec![zero; m * nzc * n];
        slabs
            .par_chunks_mut(nzc * n)
            .enumerate()
            .for_each(|(ix, slab)| {
                let mut line = vec![0.0; n];
                let mut spec = vec![zero; nzc];
                let mut scratch = vec![
                    zero;
                    self.r2c
                        .get_scratch_len()
                        .max(self.fwd.get_inplace_scratch_len())
                ];
                for iy in 0..m {
                    for iz in 0..m {
                        line[iz] = src[((ix * m + iy) * m + iz) * stride + offset];
                    }
                    line[m..].fill(0.0);
                    // lengths are right by construction: the only error realfft reports
                    let _ = self
                        .r2c
                        .process_with_scratch(&mut line, &mut spec, &mut scratch);
                    for (kz, v) in spec.iter().enumerate() {
                        slab[kz * n + iy] = *v;
                    }
                }
                self.fwd.process_with_scratch(slab, &mut scratch);
            });
        // stage 3: transpose to [kz][iy][ix] (contiguous reads of each slab row, writes
        // within the n² chunk, which stays in cache) and x FFTs
        out.par_chunks_mut(n * n)
            .enumerate()
            .for_each(|(kz, chunk)| {
                chunk.fill(zero);
                for ix in 0..m {
                    let row = &slabs[(ix * nzc + kz) * n..(ix * nzc + kz + 1) * n];
                    for (iy, v) in row.iter().enumerate() {
                        chunk[iy * n + ix] = *v;
                    }
                }
                let mut scratch = vec![zero; self.fwd.get_inplace_scratch_len()];
                self.fwd.process_with_scratch(chunk, &mut scratch);
            });
    }

    /// Inverse transform (unnormalised) of `spec` (T layout; overwritten) into the compact
    /// grid `dst[((ix * m + iy) * m + iz) * stride + offset]`: the separate pass, reference
    /// of [`Fft3::convolve`] in the tests.
    #[cfg(test)]
    pub fn inverse(&self, spec: &mut [Complex64], dst: &mut [f64], stride: usize, offset: usize) {
        let (n, m, nzc) = (self.n, self.m, self.nzc);
        let zero = Complex64::new(0.0, 0.0);
        spec.par_chunks_mut(n * n).for_each(|chunk| {
            let mut scratch = vec![zero; self.inv.get_inplace_scratch_len()];
            self.inv.process_with_scratch(chunk, &mut scratch);
        });
        let spec = &*spec;
        // blocks of PLANES x-planes per task: each spectrum row is read PLANES values (one
        // cache line) at a time instead of one
        const PLANES: usize = 4;
        dst.par_chunks_mut(PLANES * m * m * stride)
            .enumerate()
            .for_each(|(block, planes)| {
                let ix0 = block * PLANES;
                let count = planes.len() / (m * m * stride);
                // slabs [kz][iy] of these x-planes, then y inverse FFTs
                let mut slabs = vec![zero; count * nzc * n];
                for kz in 0..nzc {
                    for iy in 0..n {
                        let row = &spec[(kz * n + iy) * n + ix0..(kz * n + iy) * n + ix0 + count];
                        for (t, v) in row.iter().enumerate() {
                            slabs[t * nzc * n + kz * n + iy] = *v;
                        }
                    }
                }
                let len = self
                    .inv
                    .get_inplace_scratch_len()
                    .max(self.c2r.get_scratch_len());
                let mut scratch = vec![zero; len];
                let mut line = vec![zero; nzc];
                let mut out = vec![0.0; n];
                for (slab, plane) in slabs
                    .chunks_exact_mut(nzc * n)
                    .zip(planes.chunks_exact_mut(m * m * stride))
                {
                    self.inv.process_with_scratch(slab, &mut scratch);
                    for iy in 0..m {
                        for (kz, v) in line.iter_mut().enumerate() {
                            *v = slab[kz * n + iy];
                        }
                        // a real field's spectrum: these are real up to rounding
                        line[0].im = 0.0;
                        if n % 2 == 0 {
                            line[nzc - 1].im = 0.0;
                        }
                        let _ = self
                            .c2r
                            .process_with_scratch(&mut line, &mut out, &mut scratch);
                        for iz in 0..m {
                            plane[(iy * m + iz) * stride + offset] = out[iz];
                        }
                    }
                }
            });
    }
}

/// Buffers of [`Fft3::convolve`], reused across products (no page faults per product).
#[derive(Debug, Default)]
pub(crate) struct ConvScratch {
    slabs: Vec<Complex64>,
    spec: Vec<Complex64>,
}

impl Fft3 {
    /// The aperiodic convolution of `nf` interleaved fields in one pass: forward transforms
    /// of `src` (compact grid, layout `((ix * m + iy) * m + iz) * nf + c`), `mult(kz, chunks)`
    /// applied to the `nf` spectra of one kz plane (each chunk `[ky][kx]`, element
    /// `ky * n + kx`, i.e. T-layout index `kz * n² + ky * n + kx`), inverse transforms
    /// (unnormalised) into `dst` (same layout as `src`). The kernel product runs right after
    /// the x transforms of its plane, and only the x < m part of the spectrum is kept for the
    /// inverse: the same operations as [`Fft3::forward`], the product and [`Fft3::inverse`]
    /// (bitwise the same result, tested) with less memory traffic.
    pub fn convolve(
        &self,
        src: &[f64],
        nf: usize,
        mult: &(dyn Fn(usize, &mut [Vec<Complex64>]) + Sync),
        dst: &mut [f64],
        scratch: &mut ConvScratch,
    ) {
        let (n, m, nzc) = (self.n, self.m, self.nzc);
        let zero = Complex64::new(0.0, 0.0);
        let scratch_len = self
            .r2c
            .get_scratch_len()
            .max(self.c2r.get_scratch_len())
            .max(self.fwd.get_inplace_scratch_len())
            .max(self.inv.get_inplace_scratch_len());
        // stage 1+2: per x-plane and field: z r2c on iy < m, y FFTs; layout [ix][c][kz][iy]
        scratch.slabs.resize(m * nf * nzc * n, zero);
        scratch
            .slabs
            .par_chunks_mut(nf * nzc * n)
            .enumerate()
            .for_each(|(ix, slabs)| {
                let mut line = vec![0.0; n];
                let mut spec = vec![zero; nzc];
                let mut work = vec![zero; scratch_len];
                for (c, slab) in slabs.chunks_exact_mut(nzc * n).enumerate() {
                    // rows iy ≥ m are zero padding (the reused buffer holds the last FFT)
                    for row in slab.chunks_exact_mut(n) {
                        row[m..].fill(zero);
                    }
                    for iy in 0..m {
                        let row = &src[(ix * m + iy) * m * nf..(ix * m + iy + 1) * m * nf];
                        for (l, v) in line.iter_mut().zip(row.iter().skip(c).step_by(nf)) {
                            *l = *v;
                        }
                        line[m..].fill(0.0);
                        let _ = self
                            .r2c
                            .process_with_scratch(&mut line, &mut spec, &mut work);
                        for (kz, v) in spec.iter().enumerate() {
                            slab[kz * n + iy] = *v;
                        }
                    }
                    self.fwd.process_with_scratch(slab, &mut work);
                }
            });
        // stage 3: per kz plane: transpose, x FFTs, kernel product, inverse x FFTs; keep
        // x < m in layout [c][kz][iy][ix]
        scratch.spec.resize(nf * nzc * n * m, zero);
        let slabs = &scratch.slabs;
        let mut per_plane: Vec<&mut [Complex64]> = Vec::with_capacity(nzc);
        {
            // nf disjoint [kz][iy][ix] blocks, regrouped by kz
            let mut fields: Vec<std::slice::ChunksExactMut<'_, Complex64>> = scratch
                .spec
                .chunks_exact_mut(nzc * n * m)
                .map(|f| f.chunks_exact_mut(n * m))
                .collect();
            for _ in 0..nzc {
                for f in fields.iter_mut() {
                    per_plane.extend(f.next());
                }
            }
        }
        let mut grouped: Vec<Vec<&mut [Complex64]>> = Vec::with_capacity(nzc);
        let mut it = per_plane.into_iter();
        for _ in 0..nzc {
            grouped.push(it.by_ref().take(nf).collect());
        }
        grouped.into_par_iter().enumerate().for_each_init(
            || (vec![vec![zero; n * n]; nf], vec![zero; scratch_len]),
            |(chunks, work), (kz, outs)| {
                for (c, chunk) in chunks.iter_mut().enumerate() {
                    chunk.fill(zero);
                    for ix in 0..m {
                        let base = ((ix * nf + c) * nzc + kz) * n;
                        for (iy, v) in slabs[base..base + n].iter().enumerate() {
                            chunk[iy * n + ix] = *v;
                        }
                    }
                    self.fwd.process_with_scratch(chunk, work);
                }
                mult(kz, chunks);
                for (chunk, out) in chunks.iter_mut().zip(outs) {
                    self.inv.process_with_scratch(chunk, work);
                    for (o, row) in out.chunks_exact_mut(m).zip(chunk.chunks_exact(n)) {
                        o.copy_from_slice(&row[..m]);
                    }
                }
            },
        );
        // stage 4: per block of x-planes and field: y inverse FFTs, z c2r on iy < m
        const PLANES: usize = 4;
        let spec = &scratch.spec;
        dst.par_chunks_mut(PLANES * m * m * nf)
            .enumerate()
            .for_each_init(
                || (vec![zero; PLANES * nzc * n], vec![zero; scratch_len]),
                |(slabs, work), (block, planes)| {
                    let ix0 = block * PLANES;
                    let count = planes.len() / (m * m * nf);
                    let mut line = vec![zero; nzc];
                    let mut out = vec![0.0; n];
                    for c in 0..nf {
                        for kz in 0..nzc {
                            for iy in 0..n {
                                let at = ((c * nzc + kz) * n + iy) * m + ix0;
                                for (t, v) in spec[at..at + count].iter().enumerate() {
                                    slabs[t * nzc * n + kz * n + iy] = *v;
                                }
                            }
                        }
                        for (t, plane) in planes.chunks_exact_mut(m * m * nf).enumerate() {
                            let slab = &mut slabs[t * nzc * n..(t + 1) * nzc * n];
                            self.inv.process_with_scratch(slab, work);
                            for iy in 0..m {
                                for (kz, v) in line.iter_mut().enumerate() {
                                    *v = slab[kz * n + iy];
                                }
                                line[0].im = 0.0;
                                if n % 2 == 0 {
                                    line[nzc - 1].im = 0.0;
                                }
                                let _ = self.c2r.process_with_scratch(&mut line, &mut out, work);
                                let row = &mut plane[iy * m * nf..(iy + 1) * m * nf];
                                for (o, v) in row.iter_mut().skip(c).step_by(nf).zip(&out[..m]) {
                                    *o = *v;
                                }
                            }
                        }
                    }
                },
            );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Naive DFT of the zero-padded compact field against [`Fft3::forward`], and the
    /// inverse of the forward transform against n³ times the field (odd m, m < n/2 and
    /// m = n/2, so the transposition blocks end both full and partial).
    #[test]
    fn forward_matches_naive_dft_and_inverse_inverts() {
        for (n, m) in [(8, 3), (10, 5), (12, 6)] {
            let fft = Fft3::new(n, m);
            let field: Vec<f64> = (0..m * m * m)
                .map(|k| ((k * 7919) % 101) as f64 / 50.0 - 1.0)
                .collect();
            let mut spec = vec![Complex64::new(0.0, 0.0); fft.spectrum_len()];
            fft.forward(&field, 1, 0, &mut spec);
            let tau = 2.0 * std::f64::consts::PI / n as f64;
            for kz in 0..fft.nzc {
                for ky in 0..n {
                    for kx in 0..n {
                        let mut acc = Complex64::new(0.0, 0.0);
                        for ix in 0..m {
                            for iy in 0..m {
                                for iz in 0..m {
                                    let ph = -tau * (kx * ix + ky * iy + kz * iz) as f64;
                                    acc += Complex64::from_polar(field[(ix * m + iy) * m + iz], ph);
                                }
                            }
                        }
                        let got = spec[(kz * n + ky) * n + kx];
                        assert!((got - acc).norm() < 1e-12, "n {n} k ({kx},{ky},{kz})");
                    }
                }
            }
            let mut back = vec![0.0; 2 * m * m * m];
            fft.inverse(&mut spec, &mut back, 2, 1);
            let n3 = (n * n * n) as f64;
            for (k, v) in field.iter().enumerate() {
                assert!((back[2 * k + 1] / n3 - v).abs() < 1e-13, "n {n} at {k}");
                assert_eq!(back[2 * k], 0.0);
            }
        }
    }

    /// The fused convolution equals the forward transforms, a product per wavenumber mixing
    /// the fields, and the inverse transforms done separately, bitwise, also when the
    /// scratch is reused.
    #[test]
    fn fused_convolution_equals_the_separate_passes() {
        let zero = Complex64::new(0.0, 0.0);
        for (n, m, nf) in [(8, 3, 3), (10, 5, 6), (12, 6, 3), (12, 5, 1)] {
            let fft = Fft3::new(n, m);
            let src: Vec<f64> = (0..m * m * m * nf)
                .map(|k| ((k * 7919) % 101) as f64 / 50.0 - 1.0)
                .collect();
            let coef = |idx: usize, c: usize, d: usize| {
                ((idx * 31 + c * 7 + d * 3) % 17) as f64 / 17.0 - 0.5
            };
            let len = fft.spectrum_len();
            let mut specs: Vec<Vec<Complex64>> = (0..nf)
                .map(|c| {
                    let mut s = vec![zero; len];
                    fft.forward(&src, nf, c, &mut s);
                    s
                })
                .collect();
            for idx in 0..len {
                let v: Vec<Complex64> = specs.iter().map(|s| s[idx]).collect();
                for (c, s) in specs.iter_mut().enumerate() {
                    s[idx] = (0..nf).map(|d| v[d] * coef(idx, c, d)).sum();
                }
            }
            let mut expect = vec![0.0; m * m * m * nf];
            for (c, s) in specs.iter_mut().enumerate() {
                fft.inverse(s, &mut expect, nf, c);
            }
            let mult = |kz: usize, chunks: &mut [Vec<Complex64>]| {
                for j in 0..n * n {
                    let idx = kz * n * n + j;
                    let v: Vec<Complex64> = chunks.iter().map(|ch| ch[j]).collect();
                    for (c, ch) in chunks.iter_mut().enumerate() {
                        ch[j] = (0..nf).map(|d| v[d] * coef(idx, c, d)).sum();
                    }
                }
            };
            let mut scratch = ConvScratch::default();
            for round in 0..2 {
                let mut got = vec![f64::NAN; m * m * m * nf];
                fft.convolve(&src, nf, &mult, &mut got, &mut scratch);
                assert_eq!(got, expect, "n {n} m {m} nf {nf} round {round}");
            }
        }
    }
}
