//! Hydrodynamic mobilities and correlated Brownian displacements for the Ermak–McCammon
//! update (thesis: R. J. Baars 2016, ch. 6, eqs. 6.5–6.16; D-000-9 in docs/references.md).
//!
//! # Equations
//! x(t+h) = x + h μ(x) F + √(2 k_B T) B ΔW, ΔW ~ N(0, h I_{3N}), B Bᵀ = μ = D/k_BT.
//! No divergence term: ∇·μ = 0 for RPY ([T000 §6.2.2]; erratum E-000-19).
//!
//! * [`MobilityMethod::FreeDraining`]: μ_ii = I/(6πηa_i), μ_ij = 0, B = μ^{1/2} (O(N)).
//! * [`MobilityMethod::Cholesky`]: dense RPY μ ([`rpy`], Zuk et al. 2014 polydisperse blocks
//!   with overlap branches), B = lower Cholesky factor L (faer, O(N³) once per configuration,
//!   then O(N²) per draw). The factorisation runs with `faer::Par::Seq` unless
//!   [`MobilityOptions::parallel_cholesky`] is set. faer's parallel Cholesky gave bitwise the
//!   same factor as the sequential one in the one case checked (N = 400, 2 threads), but
//!   this is not guaranteed by faer, so the default stays sequential.
//!
//! Measured at N = 3000 (test profile: opt-level 1, dependencies opt-level 2, 2 cores):
//! Cholesky prepare 7.1 s + 0.09 s per draw; TEA prepare 0.6 s + 0.18 s per draw; Krylov
//! (tol 1e-6, φ ≈ 1e-2) 44 iterations, 8.7 s per draw (matvec-bound).
//! * [`MobilityMethod::Tea`]: TEA-HI of Geyer & Winter (2009), see [`tea`] (O(N²)).
//! * [`MobilityMethod::Krylov`]: Lanczos approximation of μ^{1/2} w (Ando et al. 2012), see
//!   [`krylov`] (O(m N²), m iterations).
//! * [`MobilityMethod::SpectralEwald`]: no matrix at all: the product μF by free-space
//!   spectral Ewald summation to a relative tolerance [`MobilityOptions::ewald_tolerance`]
//!   (see [`ewald`], O(N log N) per product for a fixed tolerance), and the noise by Lanczos
//!   over that product (O(m N log N)), preconditioned: y = L (L⁻¹ μ L⁻ᵀ)^{1/2} w with L the
//!   Cholesky factors of close-pair clusters (see `precond`; covariance μ exactly, fewer
//!   iterations; y is then not the symmetric square root μ^{1/2} w).
//!
//! All dense products are row-chunk parallel (rayon) with a fixed per-element summation
//! order, so every output is bitwise identical whatever the rayon thread count.
//!
//! # Units
//! SI: positions and radii \[m\], viscosity [Pa s], forces \[N\], μ [m/(N s)], velocities [m/s].
//! `noise` returns B w in units of √μ; the caller multiplies by √(2 k_B T) and uses w = ΔW.
//!
//! # Assumptions
//! Unbounded fluid (no fibre/wall hydrodynamics), pairwise RPY, translations only.

pub mod ewald;
pub mod krylov;
mod precond;
pub mod rpy;
mod select;
pub mod tea;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_ewald;
#[cfg(test)]
mod tests_krylov;
#[cfg(test)]
mod tests_noise;
#[cfg(test)]
mod tests_pse;

pub use ewald::EwaldSummary;
pub use rpy::{rpy_block, rpy_matrix};
pub use select::{auto_method, covariance_error};
pub use tea::TeaStats;

use glam::DVec3;
use rpy::{DenseSym, matvec_cols, self_mobility};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Which mobility (scene key `mobility`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MobilityMethod {
    /// no hydrodynamic interactions (Stokes drag only)
    FreeDraining,
    /// dense RPY + exact Cholesky factor
    Cholesky,
    /// dense RPY + TEA-HI approximate factor
    Tea,
    /// dense RPY + Krylov/Lanczos square root
    Krylov,
    /// matrix-free RPY product by free-space spectral Ewald + Krylov/Lanczos square root
    SpectralEwald,
}

/// Errors preparing or using a [`Mobility`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HydroError {
    /// the Cholesky factorisation met a non-positive pivot (μ not positive definite)
    #[error("mobility matrix not positive definite (pivot {index})")]
    NotPositiveDefinite {
        /// index of the failing pivot
        index: usize,
    },
    /// TEA-HI has no real β' (a > 1)
    #[error("TEA-HI breakdown: a = {a} > 1")]
    TeaBreakdown {
        /// a = (N'−1)ε² − (N'−2)ε
        a: f64,
    },
    /// Lanczos did not reach the tolerance within the iteration limit
    #[error(
        "Krylov square root not converged after {iterations} iterations (relative change {residual})"
    )]
    KrylovNotConverged {
        /// iterations performed
        iterations: usize,
        /// last relative change of y
        residual: f64,
    },
    /// the small tridiagonal eigen-solver did not converge
    #[error("tridiagonal eigen-solver did not converge (size {size})")]
    EigenNotConverged {
        /// matrix size
        size: usize,
    },
    /// bad arguments (lengths, non-positive radius or viscosity, non-finite values)
    #[error("invalid input: {0}")]
    InvalidInput(&'static str),
}

/// Tuning knobs of [`Mobility::new_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MobilityOptions {
    /// Krylov stopping tolerance on the relative change of y (default 1e-6)
    pub krylov_tolerance: f64,
    /// Krylov iteration limit (default 200; never more than 3N)
    pub krylov_max_iterations: usize,
    /// run faer's Cholesky with rayon parallelism (default false: `Par::Seq`)
    pub parallel_cholesky: bool,
    /// relative accuracy of the spectral Ewald product (default 1e-6; 1e-12 … 0.1)
    pub ewald_tolerance: f64,
}

impl Default for MobilityOptions {
    fn default() -> Self {
        Self {
            krylov_tolerance: 1e-6,
            krylov_max_iterations: 200,
            parallel_cholesky: false,
            ewald_tolerance: 1e-6,
        }
    }
}

#[derive(Debug)]
enum Inner {
    FreeDraining {
        mob: Vec<f64>,
    },
    Cholesky {
        m: DenseSym,
        l: faer::Mat<f64>,
    },
    Tea {
        m: DenseSym,
        tea: tea::Tea,
    },
    Krylov {
        m: DenseSym,
    },
    SpectralEwald {
        op: Box<ewald::SpectralEwald>,
        pc: precond::ClusterFactor,
    },
}

/// The mobility prepared at one configuration.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::brownian::hydro::{Mobility, MobilityMethod};
/// let pos = [DVec3::ZERO, DVec3::new(3e-7, 0.0, 0.0)];
/// let mob = Mobility::new(MobilityMethod::Cholesky, &pos, &[1e-7; 2], 1e-3, 1e-6).unwrap();
/// let mut v = [DVec3::ZERO; 2];
/// mob.apply(&[DVec3::new(1e-15, 0.0, 0.0); 2], &mut v);
/// assert!(v[0].x > 1e-15 / (6.0 * std::f64::consts::PI * 1e-3 * 1e-7)); // HI speeds it up
/// let mut y = [DVec3::ZERO; 2];
/// mob.noise(&[DVec3::X, DVec3::Y], &mut y).unwrap();
/// ```
#[derive(Debug)]
pub struct Mobility {
    method: MobilityMethod,
    n: usize,
    options: MobilityOptions,
    inner: Inner,
    last_iterations: AtomicUsize,
}

fn flatten(v: &[DVec3]) -> Vec<f64> {
    v.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn unflatten(src: &[f64], out: &mut [DVec3]) {
    for (o, c) in out.iter_mut().zip(src.chunks_exact(3)) {
        *o = DVec3::new(c[0], c[1], c[2]);
    }
}

impl Mobility {
    /// Prepares `method` at the given configuration with default options except the Krylov
    /// tolerance. Errors: invalid input, non-positive-definite matrix (Cholesky), TEA breakdown.
    pub fn new(
        method: MobilityMethod,
        positions: &[DVec3],
        radii: &[f64],
        viscosity: f64,
        krylov_tolerance: f64,
    ) -> Result<Self, HydroError> {
        let options = MobilityOptions {
            krylov_tolerance,
            ..MobilityOptions::default()
        };
        Self::new_with(method, positions, radii, viscosity, options)
    }

    /// As [`Mobility::new`] with all options.
    pub fn new_with(
        method: MobilityMethod,
        positions: &[DVec3],
        radii: &[f64],
        viscosity: f64,
        options: MobilityOptions,
    ) -> Result<Self, HydroError> {
        if positions.len() != radii.len() {
            return Err(HydroError::InvalidInput(
                "positions and radii differ in length",
            ));
        }
        if !(viscosity.is_finite() && viscosity > 0.0) {
            return Err(HydroError::InvalidInput("viscosity must be finite and > 0"));
        }
        if radii.iter().any(|a| !(a.is_finite() && *a > 0.0)) {
            return Err(HydroError::InvalidInput("radii must be finite and > 0"));
        }
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(HydroError::InvalidInput("positions must be finite"));
        }
        if !options.krylov_tolerance.is_finite() || options.krylov_tolerance <= 0.0 {
            return Err(HydroError::InvalidInput("krylov_tolerance must be > 0"));
        }
        let inner = match method {
            MobilityMethod::FreeDraining => Inner::FreeDraining {
                mob: radii.iter().map(|&a| self_mobility(a, viscosity)).collect(),
            },
            MobilityMethod::Cholesky => {
                let m = DenseSym::rpy(positions, radii, viscosity);
                let l = cholesky(&m, options.parallel_cholesky)?;
                Inner::Cholesky { m, l }
            }
            MobilityMethod::Tea => {
                let m = DenseSym::rpy(positions, radii, viscosity);
                let tea = tea::Tea::new(&m)?;
                Inner::Tea { m, tea }
            }
            MobilityMethod::Krylov => Inner::Krylov {
                m: DenseSym::rpy(positions, radii, viscosity),
            },
            MobilityMethod::SpectralEwald => {
                // the (sequential) cluster factor is built beside the operator
                let (op, pc) = rayon::join(
                    || {
                        ewald::SpectralEwald::new(
                            positions,
                            radii,
                            viscosity,
                            options.ewald_tolerance,
                        )
                    },
                    || precond::ClusterFactor::new(positions, radii, viscosity),
                );
                Inner::SpectralEwald {
                    op: Box::new(op?),
                    pc,
                }
            }
        };
        Ok(Self {
            method,
            n: positions.len(),
            options,
            inner,
            last_iterations: AtomicUsize::new(0),
        })
    }

    /// The method this mobility was prepared with.
    #[must_use]
    pub fn method(&self) -> MobilityMethod {
        self.method
    }

    /// Number of particles N.
    #[must_use]
    pub fn len(&self) -> usize {
        self.n
    }

    /// True if there are no particles.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// TEA parameters (ε, a, β') when the method is TEA.
    #[must_use]
    pub fn tea_stats(&self) -> Option<TeaStats> {
        match &self.inner {
            Inner::Tea { tea, .. } => Some(tea.stats),
            _ => None,
        }
    }

    /// Parameters of the spectral Ewald operator (None for the other methods).
    #[must_use]
    pub fn ewald_summary(&self) -> Option<EwaldSummary> {
        match &self.inner {
            Inner::SpectralEwald { op, .. } => Some(op.summary()),
            _ => None,
        }
    }

    /// Krylov iterations (matrix-vector products) used by the most recent successful
    /// [`Mobility::noise`] call on this value (0 for other methods or before any call).
    /// Stored in an atomic, so `Mobility` stays `Sync`; with concurrent calls it reports one
    /// of them.
    #[must_use]
    pub fn krylov_iterations(&self) -> usize {
        self.last_iterations.load(Ordering::Relaxed)
    }

    /// Velocities v = μ F [m/s]; `forces` and `out` have length N. O(N) free draining,
    /// O(N log N) spectral Ewald (to its tolerance), O(N²) otherwise.
    pub fn apply(&self, forces: &[DVec3], out: &mut [DVec3]) {
        assert_eq!(forces.len(), self.n, "forces length");
        assert_eq!(out.len(), self.n, "out length");
        let m = match &self.inner {
            Inner::FreeDraining { mob } => {
                for ((o, f), mu) in out.iter_mut().zip(forces).zip(mob) {
                    *o = *f * *mu;
                }
                return;
            }
            Inner::SpectralEwald { op, .. } => {
                let f = flatten(forces);
                let mut v = vec![0.0; f.len()];
                op.apply(&f, &mut v);
                unflatten(&v, out);
                return;
            }
            Inner::Cholesky { m, .. } | Inner::Tea { m, .. } | Inner::Krylov { m } => m,
        };
        let f = flatten(forces);
        let mut v = vec![0.0; f.len()];
        m.matvec(&f, &mut v);
        unflatten(&v, out);
    }

    /// y = B w with B Bᵀ ≈ μ (exact for free draining and Cholesky). Linear in w except for
    /// Krylov (y ≈ μ^{1/2} w) and spectral Ewald (y ≈ L (L⁻¹ μ L⁻ᵀ)^{1/2} w, the Krylov
    /// tolerance applying to the preconditioned root). The Brownian displacement is √(2 k_B T)·B·ΔW.
    /// Errors only for Krylov when the tolerance is not reached.
    pub fn noise(&self, w: &[DVec3], out: &mut [DVec3]) -> Result<(), HydroError> {
        assert_eq!(w.len(), self.n, "w length");
        assert_eq!(out.len(), self.n, "out length");
        let wf = flatten(w);
        let mut y = vec![0.0; wf.len()];
        match &self.inner {
            Inner::FreeDraining { mob } => {
                for ((o, wi), mu) in out.iter_mut().zip(w).zip(mob) {
                    *o = *wi * mu.sqrt();
                }
                return Ok(());
            }
            Inner::Cholesky { l, .. } => {
                matvec_cols(l.nrows(), |c| l.col_as_slice(c), &wf, &mut y, true);
            }
            Inner::Tea { m, tea } => tea.apply(m, &wf, &mut y),
            Inner::Krylov { m } => y = self.lanczos(|x, o| m.matvec(x, o), &wf)?,
            Inner::SpectralEwald { op, pc } => {
                // y = L (L⁻¹ μ L⁻ᵀ)^{1/2} w: covariance L G Lᵀ = μ (see `precond`)
                let g = |x: &[f64], o: &mut [f64]| {
                    let mut t = x.to_vec();
                    pc.solve_lt(&mut t);
                    op.apply(&t, o);
                    pc.solve_l(o);
                };
                y = self.lanczos(g, &wf)?;
                pc.mul_l(&mut y);
            }
        }
        unflatten(&y, out);
        Ok(())
    }

    /// μ^{1/2} w by Lanczos over the product `matvec`, recording the iterations.
    fn lanczos(
        &self,
        matvec: impl Fn(&[f64], &mut [f64]),
        w: &[f64],
    ) -> Result<Vec<f64>, HydroError> {
        let res = krylov::lanczos_sqrt(
            matvec,
            w,
            self.options.krylov_tolerance,
            self.options.krylov_max_iterations,
        )?;
        self.last_iterations
            .store(res.iterations, Ordering::Relaxed);
        Ok(res.y)
    }

    /// The dense 3N×3N factor B actually used by [`Mobility::noise`] (column k = B e_k;
    /// for Krylov the columns of the approximate μ^{1/2}). O(N²) for TEA, O(N³) for Krylov.
    pub fn dense_factor(&self) -> Result<faer::Mat<f64>, HydroError> {
        let n3 = 3 * self.n;
        match &self.inner {
            Inner::Tea { m, tea } => Ok(tea.dense_b(m)),
            Inner::Cholesky { l, .. } => Ok(faer::Mat::from_fn(n3, n3, |r, c| {
                if r >= c { l[(r, c)] } else { 0.0 }
            })),
            _ => {
                let mut b = faer::Mat::<f64>::zeros(n3, n3);
                let mut w = vec![DVec3::ZERO; self.n];
                let mut y = vec![DVec3::ZERO; self.n];
                for k in 0..n3 {
                    w.fill(DVec3::ZERO);
                    w[k / 3][k % 3] = 1.0;
                    self.noise(&w, &mut y)?;
                    for (r, v) in y.iter().enumerate() {
                        for c in 0..3 {
                            b[(3 * r + c, k)] = v[c];
                        }
                    }
                }
                Ok(b)
            }
        }
    }
}

/// Lower Cholesky factor of the dense mobility with faer (`Par::Seq` unless `parallel`).
fn cholesky(m: &DenseSym, parallel: bool) -> Result<faer::Mat<f64>, HydroError> {
    use faer::linalg::cholesky::llt::factor;
    let mut l = m.to_faer();
    let par = if parallel {
        faer::Par::rayon(0)
    } else {
        faer::Par::Seq
    };
    let mut mem = faer::dyn_stack::MemBuffer::new(factor::cholesky_in_place_scratch::<f64>(
        m.n,
        par,
        Default::default(),
    ));
    let stack = faer::dyn_stack::MemStack::new(&mut mem);
    factor::cholesky_in_place(
        l.as_mut(),
        Default::default(),
        par,
        stack,
        Default::default(),
    )
    .map_err(|e| match e {
        factor::LltError::NonPositivePivot { index } => HydroError::NotPositiveDefinite { index },
    })?;
    Ok(l)
}
