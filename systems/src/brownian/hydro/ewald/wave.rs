//! Wave-space (smooth, long-ranged) part of the spectral Ewald RPY product in free space.
//!
//! u_i^wave = h⁶ Σ_n g(y_n − x_i) Σ_m K(y_n − y_m) Σ_j g(y_m − x_j) q_j on a uniform grid y of
//! spacing h: Gaussian spreading g(x) = (2ξ²/πη)^{3/2} e^{−2ξ²|x|²/η} truncated to P³ points
//! (spectral Ewald, Lindbo & Tornberg 2010), the middle kernel K sampled in real space
//! (closed forms in [`super::kernels`], smooth because it carries the Gaussian e^{−(1−η)k²/4ξ²}),
//! an aperiodic discrete convolution by zero-padded FFTs ([`super::fft3`]), and gathering with
//! the same Gaussian (trapezoidal rule). Because the convolution is aperiodic there are no
//! periodic images: the result is the free-space sum.
//!
//! Two source densities handle polydispersity: q = f and q = a²f, with
//! u_i = (S̃∗f)_i + (a_i²/6)(L̃∗f)_i + (L̃∗(a²f))_i/6 (S̃, L̃ the wave parts of the Stokeslet and
//! of its Laplacian). For equal radii these fold into one kernel S̃ + (a²/3) L̃ (3 instead of 6
//! transforms each way).

use glam::DVec3;
use rayon::prelude::*;
use realfft::num_complex::Complex64;
use std::f64::consts::PI;

use std::sync::{Arc, Mutex};

use super::fft3::{ConvScratch, Fft3};
use super::kernels::{smoothed_laplacian, wave_stokeslet};
use super::params::Params;
use super::simd::Simd;

/// Symmetric 3×3 kernel at one wavenumber: xx, yy, zz, xy, xz, yz (real: the sampled
/// kernels are even).
type Sym = [f64; 6];

/// The prepared wave-space operator of one configuration.
#[derive(Debug)]
pub(crate) struct Wave {
    fft: Fft3,
    support: usize,
    /// per particle: first grid index per axis
    start: Vec<[usize; 3]>,
    /// per particle: P weights per axis (x block, y block, z block)
    weights: Vec<f64>,
    /// per x-plane: the particles whose support covers it, increasing index
    plane_members: Vec<Vec<u32>>,
    /// Stokeslet kernel (or the combined S̃ + a²/3 L̃ for equal radii), scaled
    kernel_s: Arc<Vec<Sym>>,
    /// Laplacian kernel for unequal radii, scaled
    kernel_l: Option<Arc<Vec<Sym>>>,
    radii_sq: Vec<f64>,
    /// buffers reused by every product of this configuration
    scratch: Mutex<WaveScratch>,
}

/// The grids and transform buffers of one product.
#[derive(Debug, Default)]
struct WaveScratch {
    grid: Vec<f64>,
    field: Vec<f64>,
    conv: ConvScratch,
}

/// The kernel spectra of one grid: Stokeslet (or combined) and, for unequal radii, Laplacian.
type Spectra = (Arc<Vec<Sym>>, Option<Arc<Vec<Sym>>>);

/// Cache key: FFT length and the bits of h, ξ, α, the prefactor and the common a² (NaN bits for
/// unequal radii).
type Key = (usize, [u64; 5]);

/// The most recent kernel spectra (a step rebuilds the mobility at a configuration whose grid
/// parameters rarely change). Recomputing gives bitwise the same values, so the cache cannot
/// change results.
static CACHE: Mutex<Vec<(Key, Spectra)>> = Mutex::new(Vec::new());

/// Entries kept in [`CACHE`].
const CACHE_ENTRIES: usize = 3;

/// Sampled kernel DFT (real part) in T layout, scaled by `scale`.
fn kernel_spectrum(
    fft: &Fft3,
    h: f64,
    scale: f64,
    eval: &(dyn Fn(f64) -> (f64, f64) + Sync),
) -> Vec<Sym> {
    let n = fft.n;
    // displacement index i ↦ i for i ≤ n/2, i − n above. Only |d| < m is ever used by the
    // convolution (n ≥ 2m), so the kernel does not depend on m and can be cached by n.
    let disp = |i: usize| -> Option<f64> {
        if i <= n / 2 {
            Some(i as f64)
        } else {
            Some(i as f64 - n as f64)
        }
    };
    let mut samples = vec![0.0; n * n * n * 6];
    samples
        .par_chunks_mut(n * n * 6)
        .enumerate()
        .for_each(|(ix, plane)| {
            let Some(dx) = disp(ix) else { return };
            for iy in 0..n {
                let Some(dy) = disp(iy) else { continue };
                for iz in 0..n {
                    let Some(dz) = disp(iz) else { continue };
                    let d = DVec3::new(dx, dy, dz) * h;
                    let r = d.length();
                    let (a, b) = eval(r);
                    let f = if r > 0.0 { b / (r * r) } else { 0.0 };
                    let o = &mut plane[(iy * n + iz) * 6..(iy * n + iz) * 6 + 6];
                    o[0] = a + f * d.x * d.x;
                    o[1] = a + f * d.y * d.y;
                    o[2] = a + f * d.z * d.z;
                    o[3] = f * d.x * d.y;
                    o[4] = f * d.x * d.z;
                    o[5] = f * d.y * d.z;
                }
            }
        });
    let full = Fft3::new(n, n);
    let mut spec = vec![Complex64::new(0.0, 0.0); fft.spectrum_len()];
    let mut out = vec![[0.0; 6]; fft.spectrum_len()];
    for c in 0..6 {
        full.forward(&samples, 6, c, &mut spec);
        for (o, s) in out.iter_mut().zip(&spec) {
            o[c] = s.re * scale;
        }
    }
    out
}

#[inline]
fn sym_mul(k: &Sym, v: [Complex64; 3]) -> [Complex64; 3] {
    [
        v[0] * k[0] + v[1] * k[3] + v[2] * k[4],
        v[0] * k[3] + v[1] * k[1] + v[2] * k[5],
        v[0] * k[4] + v[1] * k[5] + v[2] * k[2],
    ]
}

impl Wave {
    /// Prepare the grid, the spreading weights and the kernel spectra. `params` must not be
    /// the direct sum. Units: output velocities in 1/(8πη) units times `prefactor`.
    pub fn new(params: &Params, positions: &[DVec3], radii: &[f64], prefactor: f64) -> Self {
        let (m, n, p, h) = (params.m, params.fft_n, params.support, params.h);
        let xi = params.xi;
        let fft = Fft3::new(n, m);
        // spreading Gaussian per axis: (2ξ²/πη)^{1/2} e^{−2ξ²d²/η}
        let c_exp = 2.0 * xi * xi / params.split;
        let c_norm = (c_exp / PI).sqrt();
        let mut weights = vec![0.0; positions.len() * 3 * p];
        let start: Vec<[usize; 3]> = positions
            .par_iter()
            .zip(weights.par_chunks_mut(3 * p))
            .map(|(x, w)| {
                let t = (*x - params.origin) / h;
                let mut s = [0usize; 3];
                for (k, wk) in w.chunks_exact_mut(p).enumerate() {
                    // support centred on the particle: reaches ≥ (P − 2)h/2 on both sides
                    let m0 = ((t[k] - (p as f64 - 1.0) / 2.0 + 0.5).floor() as i64)
                        .clamp(0, (m - p) as i64);
                    s[k] = m0 as usize;
                    for (q, wq) in wk.iter_mut().enumerate() {
                        let d = (t[k] - (m0 as usize + q) as f64) * h;
                        *wq = c_norm * (-c_exp * d * d).exp();
                    }
                }
                s
            })
            .collect();
        let mut plane_members = vec![Vec::new(); m];
        for (i, s) in start.iter().enumerate() {
            for plane in plane_members.iter_mut().skip(s[0]).take(p) {
                plane.push(i as u32);
            }
        }
        let mono = radii.windows(2).all(|w| w[0] == w[1]);
        let h3 = h * h * h;
        let scale = prefactor * h3 * h3 / (n as f64).powi(3);
        let alpha = params.alpha;
        let a2 = if mono {
            radii.first().map_or(0.0, |a| a * a)
        } else {
            f64::NAN
        };
        let key = (
            n,
            [
                h.to_bits(),
                xi.to_bits(),
                alpha.to_bits(),
                prefactor.to_bits(),
                a2.to_bits(),
            ],
        );
        let cached = CACHE
            .lock()
            .ok()
            .and_then(|c| c.iter().find(|(k, _)| *k == key).map(|(_, v)| v.clone()));
        let (kernel_s, kernel_l) = cached.unwrap_or_else(|| {
            let spectra: Spectra = if mono {
                let k = kernel_spectrum(&fft, h, scale, &|r| {
                    let (sa, sb) = wave_stokeslet(r, alpha, xi);
                    let (la, lb) = smoothed_laplacian(r, alpha);
                    (sa + a2 / 3.0 * la, sb + a2 / 3.0 * lb)
                });
                (Arc::new(k), None)
            } else {
                let ks = kernel_spectrum(&fft, h, scale, &|r| wave_stokeslet(r, alpha, xi));
                let kl = kernel_spectrum(&fft, h, scale / 6.0, &|r| smoothed_laplacian(r, alpha));
                (Arc::new(ks), Some(Arc::new(kl)))
            };
            if let Ok(mut c) = CACHE.lock() {
                if c.len() >= CACHE_ENTRIES {
                    c.remove(0);
                }
                c.push((key, spectra.clone()));
            }
            spectra
        });
        Self {
            fft,
            support: p,
            start,
            weights,
            plane_members,
            kernel_s,
            kernel_l,
            radii_sq: radii.iter().map(|a| a * a).collect(),
            scratch: Mutex::new(WaveScratch::default()),
        }
    }

    /// Spread `NF` interleaved source fields (`src(i, c)` gives particle i's value c) onto
    /// the compact grid, layout `((ix * m + iy) * m + iz) * NF + c`. Per particle and x-plane
    /// the P·NF products (source × z weight) are formed once, then every (x, y) row of the
    /// support is one contiguous axpy of length P·NF (vectorised). Equal to the plain loop
    /// [`Wave::spread_reference`] up to rounding (tested).
    fn spread<const NF: usize>(
        &self,
        src: &(dyn Fn(usize, usize) -> f64 + Sync),
        grid: &mut Vec<f64>,
        simd: Simd,
    ) {
        let (m, p) = (self.fft.m, self.support);
        grid.clear();
        grid.resize(m * m * m * NF, 0.0);
        grid.par_chunks_mut(m * m * NF)
            .enumerate()
            .for_each(|(ix, plane)| {
                let mut t = vec![0.0; p * NF];
                #[cfg(target_arch = "x86_64")]
                match simd {
                    // SAFETY: `detect` reports AVX-512 F/DQ/VL (and AVX2, FMA) only when
                    // the processor has them
                    Simd::Avx512 => unsafe {
                        self.spread_plane_avx512::<NF>(ix, plane, &mut t, src)
                    },
                    // SAFETY: as above, AVX2 and FMA
                    Simd::Avx2 => unsafe { self.spread_plane_avx2::<NF>(ix, plane, &mut t, src) },
                    Simd::Plain => self.spread_plane::<NF>(ix, plane, &mut t, src),
                }
                #[cfg(not(target_arch = "x86_64"))]
                self.spread_plane::<NF>(ix, plane, &mut t, src);
            });
    }

    /// [`Wave::spread_plane`] compiled for AVX-512 (bitwise the same result).
    ///
    /// # Safety
    /// The processor must support AVX-512 F, DQ and VL, AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512dq,avx512vl")]
    unsafe fn spread_plane_avx512<const NF: usize>(
        &self,
        ix: usize,
        plane: &mut [f64],
        t: &mut [f64],
        src: &(dyn Fn(usize, usize) -> f64 + Sync),
    ) {
        self.spread_plane::<NF>(ix, plane, t, src);
    }

    /// [`Wave::spread_plane`] compiled for AVX2 (the same operations on wider vectors,
    /// bitwise the same result: no contraction to FMA without an explicit `mul_add`).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn spread_plane_avx2<const NF: usize>(
        &self,
        ix: usize,
        plane: &mut [f64],
        t: &mut [f64],
        src: &(dyn Fn(usize, usize) -> f64 + Sync),
    ) {
        self.spread_plane::<NF>(ix, plane, t, src);
    }

    /// Adds every member particle's contribution to x-plane `ix`; `t` is scratch of P·NF.
    #[inline(always)]
    fn spread_plane<const NF: usize>(
        &self,
        ix: usize,
        plane: &mut [f64],
        t: &mut [f64],
        src: &(dyn Fn(usize, usize) -> f64 + Sync),
    ) {
        let (m, p) = (self.fft.m, self.support);
        for &i in &self.plane_members[ix] {
            let i = i as usize;
            let s = self.start[i];
            let w = &self.weights[3 * p * i..3 * p * (i + 1)];
            let wx = w[ix - s[0]];
            let mut q = [0.0; NF];
            for (c, qc) in q.iter_mut().enumerate() {
                *qc = src(i, c) * wx;
            }
            for (tb, wz) in t.chunks_exact_mut(NF).zip(&w[2 * p..3 * p]) {
                for (tc, qc) in tb.iter_mut().zip(&q) {
                    *tc = qc * wz;
                }
            }
            for (a, wy) in w[p..2 * p].iter().enumerate() {
                let row0 = ((s[1] + a) * m + s[2]) * NF;
                for (o, tv) in plane[row0..row0 + p * NF].iter_mut().zip(&*t) {
                    *o += wy * tv;
                }
            }
        }
    }

    /// Gather the `NF` interleaved fields at particle `i`; `acc` is scratch of length P·NF.
    /// Every (x, y) row of the support is one contiguous axpy of length P·NF into `acc`,
    /// reduced with the z weights at the end. Equal to [`Wave::gather_reference`] up to
    /// rounding (tested).
    fn gather<const NF: usize>(
        &self,
        grid: &[f64],
        i: usize,
        acc: &mut [f64],
        simd: Simd,
    ) -> [f64; NF] {
        #[cfg(target_arch = "x86_64")]
        match simd {
            // SAFETY: `simd` comes from `Simd::detect`: the processor has these features
            Simd::Avx512 => unsafe { self.gather_avx512::<NF>(grid, i, acc) },
            // SAFETY: as above
            Simd::Avx2 => unsafe { self.gather_avx2::<NF>(grid, i, acc) },
            Simd::Plain => self.gather_plain::<NF>(grid, i, acc),
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = simd;
            self.gather_plain::<NF>(grid, i, acc)
        }
    }

    /// [`Wave::gather_plain`] compiled for AVX-512 (bitwise the same result).
    ///
    /// # Safety
    /// The processor must support AVX-512 F, DQ and VL, AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512dq,avx512vl")]
    unsafe fn gather_avx512<const NF: usize>(
        &self,
        grid: &[f64],
        i: usize,
        acc: &mut [f64],
    ) -> [f64; NF] {
        self.gather_plain::<NF>(grid, i, acc)
    }

    /// [`Wave::gather_plain`] compiled for AVX2 (bitwise the same result).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn gather_avx2<const NF: usize>(
        &self,
        grid: &[f64],
        i: usize,
        acc: &mut [f64],
    ) -> [f64; NF] {
        self.gather_plain::<NF>(grid, i, acc)
    }

    /// The body of [`Wave::gather`].
    #[inline(always)]
    fn gather_plain<const NF: usize>(&self, grid: &[f64], i: usize, acc: &mut [f64]) -> [f64; NF] {
        let (m, p) = (self.fft.m, self.support);
        let s = self.start[i];
        let w = &self.weights[3 * p * i..3 * p * (i + 1)];
        acc.fill(0.0);
        for (a, wx) in w[..p].iter().enumerate() {
            for (b, wy) in w[p..2 * p].iter().enumerate() {
                let c = wx * wy;
                let base = (((s[0] + a) * m + s[1] + b) * m + s[2]) * NF;
                for (ac, g) in acc.iter_mut().zip(&grid[base..base + p * NF]) {
                    *ac += c * g;
                }
            }
        }
        let mut out = [0.0; NF];
        for (ab, wz) in acc.chunks_exact(NF).zip(&w[2 * p..3 * p]) {
            for (o, v) in out.iter_mut().zip(ab) {
                *o += wz * v;
            }
        }
        out
    }

    /// The wave-space velocities of `f` (flat 3N) in the reference form (the plain
    /// spreading and gathering loops) for the tests of the fast path.
    #[cfg(test)]
    pub fn apply_reference(&self, f: &[f64]) -> Vec<f64> {
        let nf = if self.kernel_l.is_some() { 6 } else { 3 };
        let grid = self.spread_reference(nf, &|i, c| self.source(f, i, c));
        let field = self.convolve(&grid, nf);
        (0..self.start.len())
            .flat_map(|i| self.combine(&self.gather_reference(&field, nf, i), i))
            .collect()
    }

    /// Source field c of particle i: f (c < 3), a²f (c ≥ 3).
    #[inline]
    fn source(&self, f: &[f64], i: usize, c: usize) -> f64 {
        if c < 3 {
            f[3 * i + c]
        } else {
            self.radii_sq[i] * f[3 * i + c - 3]
        }
    }

    /// Velocity of particle i from its gathered fields: the second field group is
    /// (L̃∗f)/6, weighted by the target's a².
    #[inline]
    fn combine(&self, g: &[f64], i: usize) -> [f64; 3] {
        let a2 = self.radii_sq[i];
        std::array::from_fn(|k| g[k] + g.get(3 + k).map_or(0.0, |e| a2 * e))
    }

    /// Reference spreading (plain loops, any `nf`) for the tests.
    #[cfg(test)]
    fn spread_reference(&self, nf: usize, src: &(dyn Fn(usize, usize) -> f64 + Sync)) -> Vec<f64> {
        let (m, p) = (self.fft.m, self.support);
        let mut grid = vec![0.0; m * m * m * nf];
        grid.par_chunks_mut(m * m * nf)
            .enumerate()
            .for_each(|(ix, plane)| {
                let mut q = [0.0; 6];
                for &i in &self.plane_members[ix] {
                    let i = i as usize;
                    let s = self.start[i];
                    let w = &self.weights[3 * p * i..3 * p * (i + 1)];
                    let wx = w[ix - s[0]];
                    for (c, qc) in q.iter_mut().enumerate().take(nf) {
                        *qc = src(i, c) * wx;
                    }
                    for a in 0..p {
                        let wy = w[p + a];
                        let row = (s[1] + a) * m + s[2];
                        for b in 0..p {
                            let wyz = wy * w[2 * p + b];
                            let o = &mut plane[(row + b) * nf..(row + b + 1) * nf];
                            for (oc, qc) in o.iter_mut().zip(&q) {
                                *oc += qc * wyz;
                            }
                        }
                    }
                }
            });
        grid
    }

    /// Reference gathering (plain loops) for the tests.
    #[cfg(test)]
    fn gather_reference(&self, grid: &[f64], nf: usize, i: usize) -> [f64; 6] {
        let (m, p) = (self.fft.m, self.support);
        let s = self.start[i];
        let w = &self.weights[3 * p * i..3 * p * (i + 1)];
        let mut acc = [0.0; 6];
        for a in 0..p {
            let mut acc_y = [0.0; 6];
            for b in 0..p {
                let wy = w[p + b];
                let mut acc_z = [0.0; 6];
                let base = (((s[0] + a) * m + s[1] + b) * m + s[2]) * nf;
                for c in 0..p {
                    let wz = w[2 * p + c];
                    for (f, az) in acc_z.iter_mut().enumerate().take(nf) {
                        *az += grid[base + c * nf + f] * wz;
                    }
                }
                for f in 0..nf {
                    acc_y[f] += acc_z[f] * wy;
                }
            }
            for f in 0..nf {
                acc[f] += acc_y[f] * w[a];
            }
        }
        acc
    }

    /// Adds the wave-space velocities of the forces `f` (flat, 3N) to `out` (flat, 3N).
    pub fn apply_add(&self, f: &[f64], out: &mut [f64]) {
        self.apply_add_with(f, out, Simd::detect());
    }

    /// [`Wave::apply_add`] with spreading and gathering compiled for `simd` (which the
    /// processor must support: a level from [`Simd::detect`] or below).
    pub fn apply_add_with(&self, f: &[f64], out: &mut [f64], simd: Simd) {
        let p = self.support;
        // the buffers of the previous product (a fresh set if another product holds them)
        let mut guard = self.scratch.try_lock().ok();
        let mut fresh = WaveScratch::default();
        let WaveScratch { grid, field, conv } = match guard.as_deref_mut() {
            Some(s) => s,
            None => &mut fresh,
        };
        if self.kernel_l.is_some() {
            self.spread::<6>(&|i, c| self.source(f, i, c), grid, simd);
            self.convolve_into(grid, 6, field, conv);
            out.par_chunks_mut(3).enumerate().for_each_init(
                || vec![0.0; 6 * p],
                |acc, (i, o)| {
                    let v = self.combine(&self.gather::<6>(field, i, acc, simd), i);
                    o.iter_mut().zip(v).for_each(|(o, v)| *o += v);
                },
            );
        } else {
            self.spread::<3>(&|i, c| f[3 * i + c], grid, simd);
            self.convolve_into(grid, 3, field, conv);
            out.par_chunks_mut(3).enumerate().for_each_init(
                || vec![0.0; 3 * p],
                |acc, (i, o)| {
                    let v = self.gather::<3>(field, i, acc, simd);
                    o.iter_mut().zip(v).for_each(|(o, v)| *o += v);
                },
            );
        }
    }

    /// The grid convolution of the `nf` spread fields with the kernel(s) (allocating), for
    /// the tests.
    #[cfg(test)]
    fn convolve(&self, grid: &[f64], nf: usize) -> Vec<f64> {
        let mut field = Vec::new();
        self.convolve_into(grid, nf, &mut field, &mut ConvScratch::default());
        field
    }

    /// The grid convolution of the `nf` spread fields with the kernel(s) into `field`:
    /// forward FFTs, the 3×3 kernel products per wavenumber, inverse FFTs to the compact
    /// grid ([`Fft3::convolve`], the product fused with the x transforms of each kz plane).
    fn convolve_into(&self, grid: &[f64], nf: usize, field: &mut Vec<f64>, conv: &mut ConvScratch) {
        let (n, m) = (self.fft.n, self.fft.m);
        let plane = n * n;
        let ks = &self.kernel_s[..];
        let mult = |kz: usize, chunks: &mut [Vec<Complex64>]| {
            let ks = &ks[kz * plane..(kz + 1) * plane];
            // nf is 3 without and 6 with the Laplacian kernel (by construction)
            match (&self.kernel_l, chunks) {
                (None, [a, b, c]) => {
                    for (j, k) in ks.iter().enumerate() {
                        let v = sym_mul(k, [a[j], b[j], c[j]]);
                        (a[j], b[j], c[j]) = (v[0], v[1], v[2]);
                    }
                }
                (Some(kl), [a, b, c, d, e, g]) => {
                    let kl = &kl[kz * plane..(kz + 1) * plane];
                    for (j, (ks, kl)) in ks.iter().zip(kl).enumerate() {
                        let fv = [a[j], b[j], c[j]];
                        let u1 = sym_mul(ks, fv);
                        let u2 = sym_mul(kl, [d[j], e[j], g[j]]);
                        let u3 = sym_mul(kl, fv);
                        (a[j], b[j], c[j]) = (u1[0] + u2[0], u1[1] + u2[1], u1[2] + u2[2]);
                        (d[j], e[j], g[j]) = (u3[0], u3[1], u3[2]);
                    }
                }
                _ => {}
            }
        };
        field.clear();
        field.resize(m * m * m * nf, 0.0);
        self.fft.convolve(grid, nf, &mult, field, conv);
    }
}
