//! [`ChannelSolver`]: state, time stepping and the physical fields (method in [`super::solver`]).

use super::fft::PlaneFft;
use super::grid::ChannelGrid;
use super::solver::{ChannelError, ChannelParams, GAMMA, Ops, ZETA};
use num_complex::Complex64 as C;
use rayon::prelude::*;

const ZERO: C = C::new(0.0, 0.0);

/// The channel-flow solver (see [`super::solver`] for the method). Starts with the fluid at
/// rest; [`ChannelSolver::step`] advances one time step.
#[derive(Debug)]
pub struct ChannelSolver {
    pub(crate) params: ChannelParams,
    pub(crate) ops: Ops,
    /// Transforms on the collocation grid.
    pub(crate) fft: PlaneFft,
    /// Transforms on the (possibly) padded grid of the nonlinear term.
    pub(crate) fft_pad: PlaneFft,
    pub(crate) nmodes: usize,
    /// z-velocity per mode (mode-major, `nz` levels each) \[m/s\].
    pub(crate) w: Vec<C>,
    /// z-vorticity per mode \[1/s\].
    pub(crate) eta: Vec<C>,
    /// Mean velocities U(z), V(z) \[m/s\].
    pub(crate) um: [Vec<f64>; 2],
    hw_prev: Vec<C>,
    heta_prev: Vec<C>,
    hm_prev: [Vec<f64>; 2],
    /// Homogeneous clamped solutions `[stage][m][2][nz]` (influence matrix).
    hom: Vec<f64>,
    /// Inverse wall-slope matrices `[stage][m]`.
    hom_inv: Vec<[f64; 4]>,
    pub(crate) force: [Vec<f64>; 3],
    pub(crate) vel: [Vec<f64>; 3],
    pub(crate) vort: [Vec<f64>; 3],
    pub(crate) time: f64,
    pub(crate) steps: u64,
}

/// Per-task work space of the mode loop.
struct ModeWork {
    h: [Vec<C>; 3],
    a: Vec<C>,
    b: Vec<C>,
    c: Vec<C>,
    r: Vec<C>,
    out: Vec<C>,
    work: Vec<C>,
}

impl ModeWork {
    fn new(nz: usize) -> Self {
        let v = || vec![ZERO; nz];
        Self {
            h: [v(), v(), v()],
            a: v(),
            b: v(),
            c: v(),
            r: v(),
            out: v(),
            work: vec![ZERO; 6 * nz],
        }
    }
}

impl ChannelSolver {
    /// A solver with the fluid at rest.
    pub fn new(params: ChannelParams) -> Result<Self, ChannelError> {
        let g = params.grid;
        let g = ChannelGrid::new([g.nx, g.ny, g.nz], [g.lx, g.ly, g.height])?;
        if !(params.viscosity.is_finite() && params.viscosity > 0.0) {
            return Err(ChannelError::Viscosity(params.viscosity));
        }
        if !(params.dt.is_finite() && params.dt > 0.0) {
            return Err(ChannelError::TimeStep(params.dt));
        }
        if params.mean_pressure_gradient.iter().any(|v| !v.is_finite()) {
            return Err(ChannelError::PressureGradient(
                params.mean_pressure_gradient,
            ));
        }
        let ops = Ops::new(&g)?;
        let fft = PlaneFft::new(g.nx, g.ny, g.nx, g.ny);
        let fft_pad = if params.dealias {
            let even = |n: usize| (3 * n).div_ceil(2).next_multiple_of(2);
            PlaneFft::new(g.nx, g.ny, even(g.nx), even(g.ny))
        } else {
            fft.clone()
        };
        let nmodes = fft.modes();
        let ns = nmodes * g.nz;
        let n = g.len();
        let zf = || vec![0.0; n];
        // influence-matrix homogeneous solutions per stage and mode: 2 nz reals each
        let nz = g.nz;
        let mut hom = vec![0.0; 3 * nmodes * 2 * nz];
        let mut hom_inv = vec![[0.0; 4]; 3 * nmodes];
        for s in 0..3 {
            let b = 0.5 * (GAMMA[s] + ZETA[s]) * params.dt * params.viscosity;
            let ops = &ops;
            hom[s * nmodes * 2 * nz..(s + 1) * nmodes * 2 * nz]
                .par_chunks_mut(2 * nz)
                .zip(hom_inv[s * nmodes..(s + 1) * nmodes].par_iter_mut())
                .enumerate()
                .for_each_init(
                    || vec![ZERO; 4 * nz],
                    |work, (m, (h, inv))| {
                        if m == 0 {
                            return;
                        }
                        if let Some((kx, ky)) = ops.k(m) {
                            let (h1, h2) = h.split_at_mut(nz);
                            *inv = ops.homogeneous(b, kx * kx + ky * ky, h1, h2, work);
                        }
                    },
                );
        }
        if hom_inv.iter().flatten().any(|v| !v.is_finite()) {
            return Err(ChannelError::Operators(super::cheb::ChebError::Eigen(
                "singular influence matrix".into(),
            )));
        }
        Ok(Self {
            params,
            ops,
            fft,
            fft_pad,
            nmodes,
            w: vec![ZERO; ns],
            eta: vec![ZERO; ns],
            um: [vec![0.0; g.nz], vec![0.0; g.nz]],
            hw_prev: vec![ZERO; ns],
            heta_prev: vec![ZERO; ns],
            hm_prev: [vec![0.0; g.nz], vec![0.0; g.nz]],
            hom,
            hom_inv,
            force: [zf(), zf(), zf()],
            vel: [zf(), zf(), zf()],
            vort: [zf(), zf(), zf()],
            time: 0.0,
            steps: 0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ChannelParams {
        &self.params
    }

    /// The grid.
    pub fn grid(&self) -> &ChannelGrid {
        &self.params.grid
    }

    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Body force per unit mass \[m/s²\] at the nodes (x, y, z components), held constant over
    /// the next step; the caller overwrites it before each step (it is kept, not cleared,
    /// between steps). Zero initially, and after [`ChannelSolver::from_state_bytes`].
    pub fn body_force_mut(&mut self) -> [&mut [f64]; 3] {
        let [a, b, c] = &mut self.force;
        [a, b, c]
    }

    /// Velocity \[m/s\] at the nodes after the last step (x, y, z components).
    pub fn velocity(&self) -> [&[f64]; 3] {
        [&self.vel[0], &self.vel[1], &self.vel[2]]
    }

    /// Vorticity `∇ × u` \[1/s\] at the nodes after the last step.
    pub fn vorticity(&self) -> [&[f64]; 3] {
        [&self.vort[0], &self.vort[1], &self.vort[2]]
    }

    /// Mode-major spectral amplitudes `[m][f][k]` of `nf` physical fields.
    pub(crate) fn to_modes(&self, fields: &[&[f64]]) -> Vec<C> {
        let nf = fields.len();
        let (nz, nm) = (self.ops.nz, self.nmodes);
        let np = self.fft.points();
        let mut planes = vec![ZERO; nz * nf * nm];
        planes.par_chunks_mut(nf * nm).enumerate().for_each_init(
            || self.fft.scratch(),
            |s, (k, out)| {
                for (f, field) in fields.iter().enumerate() {
                    let o = &mut out[f * nm..(f + 1) * nm];
                    self.fft
                        .forward(&field[k * np..(k + 1) * np], |m, v| o[m] = v, s);
                }
            },
        );
        let mut modes = vec![ZERO; nz * nf * nm];
        modes
            .par_chunks_mut(nf * nz)
            .enumerate()
            .for_each(|(m, o)| {
                for f in 0..nf {
                    for k in 0..nz {
                        o[f * nz + k] = planes[(k * nf + f) * nm + m];
                    }
                }
            });
        modes
    }

    /// Physical fields from mode-major amplitudes `[m][f][k]` of `out.len()` fields.
    pub(crate) fn to_phys(&self, modes: &[C], out: &mut [Vec<f64>]) {
        let nf = out.len();
        let nz = self.ops.nz;
        let np = self.fft.points();
        let mut planes = vec![0.0; nz * nf * np];
        planes.par_chunks_mut(nf * np).enumerate().for_each_init(
            || self.fft.scratch(),
            |s, (k, o)| {
                for f in 0..nf {
                    self.fft.inverse(
                        |m| modes[(m * nf + f) * nz + k],
                        &mut o[f * np..(f + 1) * np],
                        s,
                    );
                }
            },
        );
        for (f, field) in out.iter_mut().enumerate() {
            field.resize(nz * np, 0.0);
            for k in 0..nz {
                field[k * np..(k + 1) * np]
                    .copy_from_slice(&planes[(k * nf + f) * np..(k * nf + f + 1) * np]);
            }
        }
    }

    /// Spectral velocity and vorticity `[m][u, v, w, ωx, ωy, ωz][k]` of the current state.
    pub(crate) fn fields(&self) -> Vec<C> {
        let nz = self.ops.nz;
        let ops = &self.ops;
        let mut out = vec![ZERO; self.nmodes * 6 * nz];
        out.par_chunks_mut(6 * nz).enumerate().for_each_init(
            || (vec![ZERO; nz], vec![ZERO; nz]),
            |(t1, t2), (m, o)| {
                let (u, rest) = o.split_at_mut(nz);
                let (v, rest) = rest.split_at_mut(nz);
                let (w, rest) = rest.split_at_mut(nz);
                let (ox, rest) = rest.split_at_mut(nz);
                let (oy, oz) = rest.split_at_mut(nz);
                if m == 0 {
                    for k in 0..nz {
                        u[k] = C::new(self.um[0][k], 0.0);
                        v[k] = C::new(self.um[1][k], 0.0);
                    }
                    ops.dz(v, t1);
                    ops.dz(u, t2);
                    for k in 0..nz {
                        ox[k] = -t1[k];
                        oy[k] = t2[k];
                    }
                    return;
                }
                let Some((kx, ky)) = ops.k(m) else { return };
                let k2 = kx * kx + ky * ky;
                let wm = &self.w[m * nz..(m + 1) * nz];
                let em = &self.eta[m * nz..(m + 1) * nz];
                ops.dz(wm, t1);
                let (ikx, iky) = (C::new(0.0, kx / k2), C::new(0.0, ky / k2));
                for k in 0..nz {
                    u[k] = ikx * t1[k] + iky * em[k];
                    v[k] = iky * t1[k] - ikx * em[k];
                    w[k] = wm[k];
                    oz[k] = em[k];
                }
                ops.dz(u, t1);
                ops.dz(v, t2);
                let (ikx, iky) = (C::new(0.0, kx), C::new(0.0, ky));
                for k in 0..nz {
                    ox[k] = iky * wm[k] - t2[k];
                    oy[k] = t1[k] - ikx * wm[k];
                }
            },
        );
        out
    }

    /// Plane-major spectral `H = u × ω` `[k][x, y, z][m]` of the current state.
    fn nonlinear(&self) -> Vec<C> {
        let (nz, nm) = (self.ops.nz, self.nmodes);
        let fields = self.fields();
        let fp = &self.fft_pad;
        let np = fp.points();
        let mut h = vec![ZERO; nz * 3 * nm];
        h.par_chunks_mut(3 * nm).enumerate().for_each_init(
            || (fp.scratch(), vec![0.0; 6 * np]),
            |(s, phys), (k, o)| {
                for f in 0..6 {
                    fp.inverse(
                        |m| fields[(m * 6 + f) * nz + k],
                        &mut phys[f * np..(f + 1) * np],
                        s,
                    );
                }
                for p in 0..np {
                    let (u, v, w) = (phys[p], phys[np + p], phys[2 * np + p]);
                    let (ox, oy, oz) = (phys[3 * np + p], phys[4 * np + p], phys[5 * np + p]);
                    phys[p] = v * oz - w * oy;
                    phys[np + p] = w * ox - u * oz;
                    phys[2 * np + p] = u * oy - v * ox;
                }
                for f in 0..3 {
                    let of = &mut o[f * nm..(f + 1) * nm];
                    fp.forward(&phys[f * np..(f + 1) * np], |m, v| of[m] = v, s);
                }
            },
        );
        h
    }

    /// Advances one time step (three Runge-Kutta stages) and updates the physical fields.
    pub fn step(&mut self) {
        let force: Vec<&[f64]> = self.force.iter().map(|f| f.as_slice()).collect();
        let fhat = self.to_modes(&force);
        for s in 0..3 {
            self.stage(s, &fhat);
        }
        self.time += self.params.dt;
        self.steps += 1;
        self.update_physical();
    }

    /// One Runge-Kutta stage.
    fn stage(&mut self, s: usize, fhat: &[C]) {
        let (nz, nm) = (self.ops.nz, self.nmodes);
        let h = self.nonlinear();
        let dt = self.params.dt;
        let nu = self.params.viscosity;
        let (g, z) = (GAMMA[s], ZETA[s]);
        let a = 0.5 * (g + z) * dt * nu;
        let b = a;
        let ops = &self.ops;
        self.w
            .par_chunks_mut(nz)
            .zip(self.eta.par_chunks_mut(nz))
            .zip(self.hw_prev.par_chunks_mut(nz))
            .zip(self.heta_prev.par_chunks_mut(nz))
            .enumerate()
            .for_each_init(
                || ModeWork::new(nz),
                |wk, (m, (((wm, em), hwp), hep))| {
                    if m == 0 {
                        return;
                    }
                    let Some((kx, ky)) = ops.k(m) else { return };
                    let k2 = kx * kx + ky * ky;
                    for f in 0..3 {
                        for k in 0..nz {
                            wk.h[f][k] = h[(k * 3 + f) * nm + m] + fhat[(m * 3 + f) * nz + k];
                        }
                    }
                    let (ikx, iky) = (C::new(0.0, kx), C::new(0.0, ky));
                    // h_w = −∂z(i kx Hx + i ky Hy) − k² Hz
                    for k in 0..nz {
                        wk.a[k] = ikx * wk.h[0][k] + iky * wk.h[1][k];
                    }
                    ops.dz(&wk.a, &mut wk.b);
                    for k in 0..nz {
                        let hw = -wk.b[k] - wk.h[2][k] * k2;
                        let n = hw * g + hwp[k] * z;
                        hwp[k] = hw;
                        wk.b[k] = n; // explicit part
                    }
                    // φ = ∇²w, r = φ + a ∇²φ + dt N
                    ops.dzz(wm, &mut wk.a);
                    for k in 0..nz {
                        wk.a[k] -= wm[k] * k2;
                    }
                    ops.dzz(&wk.a, &mut wk.c);
                    for k in 0..nz {
                        wk.r[k] = wk.a[k] + (wk.c[k] - wk.a[k] * k2) * a + wk.b[k] * dt;
                    }
                    let hs = &self.hom[(s * nm + m) * 2 * nz..(s * nm + m + 1) * 2 * nz];
                    let (h1, h2) = hs.split_at(nz);
                    let inv = self.hom_inv[s * nm + m];
                    ops.clamped_solve(b, k2, &wk.r, &mut wk.out, &mut wk.work, h1, h2, inv);
                    wm.copy_from_slice(&wk.out);
                    // η
                    ops.dzz(em, &mut wk.a);
                    for k in 0..nz {
                        let he = ikx * wk.h[1][k] - iky * wk.h[0][k];
                        let n = he * g + hep[k] * z;
                        hep[k] = he;
                        wk.r[k] = em[k] + (wk.a[k] - em[k] * k2) * a + n * dt;
                    }
                    let (out, tmp) = (&mut wk.out, &mut wk.work);
                    ops.helm.solve(1.0, b, k2, &wk.r, ZERO, ZERO, out, tmp);
                    em.copy_from_slice(out);
                },
            );
        // mean flow
        let mut wk = ModeWork::new(nz);
        for c in 0..2 {
            let um = &mut self.um[c];
            let gp = self.params.mean_pressure_gradient[c];
            for k in 0..nz {
                wk.a[k] = C::new(um[k], 0.0);
            }
            ops.dzz(&wk.a, &mut wk.b);
            for k in 0..nz {
                let hm = h[(k * 3 + c) * nm].re + fhat[c * nz + k].re + gp;
                let n = hm * g + self.hm_prev[c][k] * z;
                self.hm_prev[c][k] = hm;
                wk.r[k] = C::new(um[k] + wk.b[k].re * a + n * dt, 0.0);
            }
            ops.helm
                .solve(1.0, b, 0.0, &wk.r, ZERO, ZERO, &mut wk.out, &mut wk.work);
            for k in 0..nz {
                um[k] = wk.out[k].re;
            }
        }
    }

    /// Recomputes the physical velocity and vorticity from the spectral state.
    pub(crate) fn update_physical(&mut self) {
        let f = self.fields();
        let mut out: Vec<Vec<f64>> = (0..6).map(|_| Vec::new()).collect();
        self.to_phys(&f, &mut out);
        let mut it = out.into_iter();
        for v in self.vel.iter_mut().chain(self.vort.iter_mut()) {
            if let Some(x) = it.next() {
                *v = x;
            }
        }
    }
}
