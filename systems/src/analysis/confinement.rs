//! Confinement measures: rescaled packing fraction and contact number, the bulk
//! extrapolation in 1/D_cyl, and Student-t confidence intervals ([T000 §2.3-2.5],
//! see docs/references.md).
//!
//! Rescalings ([T000 §2.4]) map the confined value onto [0, 1] between a reference low value
//! and the periodic (bulk) value:
//!
//! * cylinder: `phi* = phi / phi_periodic`;
//! * wedge: `phi* = (phi - phi_lw,min) / (phi_periodic - phi_lw,min)`, with `phi_lw,min` of
//!   eq. 2.13 ([`crate::packing::walls::wedge_min_packing_fraction`]);
//! * both: `<C>* = (<C> - 2) / (<C>_periodic - 2)` (the thesis's "\[2, `<C>_periodic`\] ->
//!   \[0, 1\]"; it can exceed 1).
//!
//! Bulk extrapolation (Scott & Kilgour \[ScottKilgour1969\], [T000 §2.5]): ordinary least squares phi = a + b / D_cyl;
//! the intercept a is the extrapolation to 1/D_cyl -> 0, with standard error
//! s sqrt(1/n + xbar^2 / Sxx), s^2 = RSS / (n - 2), Sxx = sum (x - xbar)^2, x = 1/D_cyl.
//!
//! Confidence intervals ([T000 §2.3]): xbar +- t_{0.975, n-1} s / sqrt(n) with the sample standard
//! deviation s. t is tabulated to 4 decimals for 1..=30 degrees of freedom; beyond, the
//! Cornish-Fisher expansion t = z + g1/nu + g2/nu^2 + g3/nu^3 (z = 1.959964) is used, within
//! 1e-4 of the exact quantile (the normal quantile 1.96 is its nu -> infinity limit; the expansion
//! removes the 4 % jump from 2.042 to 1.96 at nu = 31).

/// Rescaled packing fraction in a cylinder, phi / phi_periodic.
///
/// ```
/// use magsep_systems::analysis::confinement::rescaled_packing_fraction;
/// assert_eq!(rescaled_packing_fraction(0.5, 0.625), 0.8);
/// ```
pub fn rescaled_packing_fraction(phi: f64, phi_periodic: f64) -> f64 {
    phi / phi_periodic
}

/// Rescaled packing fraction in a wedge, (phi - phi_min) / (phi_periodic - phi_min), with
/// phi_min the packing fraction of the minimum wedge (eq. 2.13).
///
/// ```
/// use magsep_systems::analysis::confinement::rescaled_packing_fraction_wedge;
/// assert_eq!(rescaled_packing_fraction_wedge(0.5, 0.6, 0.4), 0.5);
/// ```
pub fn rescaled_packing_fraction_wedge(phi: f64, phi_periodic: f64, phi_min: f64) -> f64 {
    (phi - phi_min) / (phi_periodic - phi_min)
}

/// Rescaled contact number `(<C> - 2) / (<C>_periodic - 2)`.
///
/// ```
/// use magsep_systems::analysis::confinement::rescaled_contact_number;
/// assert_eq!(rescaled_contact_number(2.0, 6.0), 0.0);
/// assert_eq!(rescaled_contact_number(5.0, 6.0), 0.75);
/// ```
pub fn rescaled_contact_number(c: f64, c_periodic: f64) -> f64 {
    (c - 2.0) / (c_periodic - 2.0)
}

/// Why a least-squares line could not be fitted.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FitError {
    /// x and y differ in length.
    #[error("{x} abscissae but {y} ordinates")]
    LengthMismatch {
        /// Number of x values.
        x: usize,
        /// Number of y values.
        y: usize,
    },
    /// Fewer than three points (no residual degree of freedom for the standard errors).
    #[error("a line with standard errors needs at least 3 points, got {0}")]
    TooFewPoints(usize),
    /// All abscissae are equal.
    #[error("all abscissae are equal")]
    DegenerateAbscissa,
    /// A value is NaN or infinite.
    #[error("non-finite input")]
    NonFinite,
}

/// A least-squares straight line y = intercept + slope x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearFit {
    /// Slope b.
    pub slope: f64,
    /// Intercept a (value at x = 0).
    pub intercept: f64,
    /// Standard error of the slope.
    pub slope_stderr: f64,
    /// Standard error of the intercept.
    pub intercept_stderr: f64,
    /// Residual standard deviation s = sqrt(RSS / (n - 2)).
    pub residual_sd: f64,
    /// Number of points.
    pub n: usize,
}

impl LinearFit {
    /// Value of the line at `x`.
    ///
    /// ```
    /// use magsep_systems::analysis::confinement::fit_line;
    /// let f = fit_line(&[0.0, 1.0, 2.0], &[1.0, 3.0, 5.0]).unwrap();
    /// assert_eq!(f.at(3.0), 7.0);
    /// ```
    pub fn at(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }

    /// Half width of the 95 % confidence interval of the intercept, t_{n-2} x stderr.
    ///
    /// ```
    /// use magsep_systems::analysis::confinement::fit_line;
    /// let f = fit_line(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 3.0, 2.0, 5.0, 4.0]).unwrap();
    /// // t_{0.975, 3} = 3.182446305284263 (exact Student-t quantile)
    /// assert!((f.intercept_half_width_95() - 3.182446305284263 * 1.32f64.sqrt()).abs() < 1e-9);
    /// ```
    pub fn intercept_half_width_95(&self) -> f64 {
        student_t_95(self.n - 2) * self.intercept_stderr
    }
}

/// Ordinary least-squares line through (x_k, y_k) with standard errors.
///
/// # Errors
/// [`FitError`] if the lengths differ, n < 3, all x are equal, or a value is not finite.
///
/// ```
/// use magsep_systems::analysis::confinement::fit_line;
/// let f = fit_line(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 3.0, 2.0, 5.0, 4.0]).unwrap();
/// assert!((f.slope - 0.8).abs() < 1e-14 && (f.intercept - 0.6).abs() < 1e-14);
/// ```
pub fn fit_line(x: &[f64], y: &[f64]) -> Result<LinearFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch {
            x: x.len(),
            y: y.len(),
        });
    }
    let n = x.len();
    if n < 3 {
        return Err(FitError::TooFewPoints(n));
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(FitError::NonFinite);
    }
    let nf = n as f64;
    let (xm, ym) = (x.iter().sum::<f64>() / nf, y.iter().sum::<f64>() / nf);
    let sxx: f64 = x.iter().map(|xi| (xi - xm).powi(2)).sum();
    if sxx <= 0.0 {
        return Err(FitError::DegenerateAbscissa);
    }
    let sxy: f64 = x.iter().zip(y).map(|(xi, yi)| (xi - xm) * (yi - ym)).sum();
    let slope = sxy / sxx;
    let intercept = ym - slope * xm;
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(xi, yi)| (yi - intercept - slope * xi).powi(2))
        .sum();
    let s2 = rss / (nf - 2.0);
    Ok(LinearFit {
        slope,
        intercept,
        slope_stderr: (s2 / sxx).sqrt(),
        intercept_stderr: (s2 * (1.0 / nf + xm * xm / sxx)).sqrt(),
        residual_sd: s2.sqrt(),
        n,
    })
}

/// Linear fit of phi against 1/D_cyl (`cylinder_diameters` in D); its `intercept` is the
/// bulk packing fraction extrapolated to 1/D_cyl -> 0 ([T000 §2.5]).
///
/// # Errors
/// As [`fit_line`].
///
/// ```
/// use magsep_systems::analysis::confinement::bulk_extrapolation;
/// let d = [2.0, 4.0, 8.0];
/// let phi: Vec<f64> = d.iter().map(|d| 0.63 - 0.3 / d).collect();
/// let f = bulk_extrapolation(&d, &phi).unwrap();
/// assert!((f.intercept - 0.63).abs() < 1e-14 && f.intercept_stderr < 1e-14);
/// ```
pub fn bulk_extrapolation(cylinder_diameters: &[f64], phi: &[f64]) -> Result<LinearFit, FitError> {
    let x: Vec<f64> = cylinder_diameters.iter().map(|d| 1.0 / d).collect();
    fit_line(&x, phi)
}

/// Two-sided 95 % Student-t quantile t_{0.975, dof} (infinite for 0 degrees of freedom),
/// exact to double precision through `statrs`' inverse CDF.
///
/// ```
/// use magsep_systems::analysis::confinement::student_t_95;
/// assert!((student_t_95(4) - 2.776_445_105_197_799).abs() < 1e-9);
/// assert!((student_t_95(100_000) - 1.96).abs() < 1e-3);
/// ```
pub fn student_t_95(dof: usize) -> f64 {
    if dof == 0 {
        return f64::INFINITY;
    }
    match statrs::distribution::StudentsT::new(0.0, 1.0, dof as f64) {
        Ok(t) => statrs::distribution::ContinuousCDF::inverse_cdf(&t, 0.975),
        Err(_) => f64::NAN,
    }
}

/// A sample mean with its 95 % confidence interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeanInterval {
    /// Sample mean.
    pub mean: f64,
    /// Half width t_{0.975, n-1} sd / sqrt(n).
    pub half_width: f64,
    /// Sample standard deviation (n - 1 in the denominator).
    pub sd: f64,
    /// Number of samples.
    pub n: usize,
}

/// Mean and Student-t 95 % half width of `samples` (`None` for fewer than two samples).
///
/// ```
/// use magsep_systems::analysis::confinement::mean_interval_95;
/// let m = mean_interval_95(&[0.60, 0.62, 0.64]).unwrap();
/// assert!((m.mean - 0.62).abs() < 1e-15);
/// assert!((m.half_width - 4.302_652_729_749_46 * 0.02 / 3f64.sqrt()).abs() < 1e-9);
/// ```
pub fn mean_interval_95(samples: &[f64]) -> Option<MeanInterval> {
    let n = samples.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let mean = samples.iter().sum::<f64>() / nf;
    let sd = (samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (nf - 1.0)).sqrt();
    Some(MeanInterval {
        mean,
        half_width: student_t_95(n - 1) * sd / nf.sqrt(),
        sd,
        n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P(|T| <= t) for nu degrees of freedom, by Simpson quadrature after x = sqrt(nu) tan(a):
    /// the density becomes proportional to cos^(nu - 1)(a) on [0, pi/2).
    fn two_sided_cdf(t: f64, nu: f64) -> f64 {
        let simpson = |b: f64| {
            let m = 20_000;
            let h = b / m as f64;
            let f = |a: f64| a.cos().powf(nu - 1.0);
            let mut s = f(0.0) + f(b);
            for k in 1..m {
                s += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
            }
            s * h / 3.0
        };
        simpson((t / nu.sqrt()).atan()) / simpson(std::f64::consts::FRAC_PI_2)
    }

    #[test]
    fn t_quantiles_cover_95_percent() {
        let mut max_err: f64 = 0.0;
        for dof in (1..=40).chain([50, 75, 100, 200, 1000]) {
            let p = two_sided_cdf(student_t_95(dof), dof as f64);
            max_err = max_err.max((p - 0.95).abs());
        }
        eprintln!("t quantiles: max |P - 0.95| = {max_err:.1e}");
        assert!(max_err < 1e-5, "{max_err}");
        assert!(student_t_95(0).is_infinite());
        // Reference values t_{0.975, nu} (R: qt(0.975, nu)).
        for (nu, t) in [
            (1, 12.706_204_736_174_7),
            (2, 4.302_652_729_749_46),
            (10, 2.228_138_851_986_27),
            (30, 2.042_272_456_301_24),
            (120, 1.979_930_405_052_72),
        ] {
            assert!((student_t_95(nu) - t).abs() < 1e-8 * t, "nu = {nu}");
        }
    }

    #[test]
    fn fit_matches_hand_computation() {
        // x = 1..5, y = (1, 3, 2, 5, 4): Sxx = 10, Sxy = 8, RSS = 3.6, s^2 = 1.2
        let f = fit_line(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 3.0, 2.0, 5.0, 4.0]).unwrap();
        assert!((f.slope - 0.8).abs() < 1e-14);
        assert!((f.intercept - 0.6).abs() < 1e-14);
        assert!((f.slope_stderr - 0.12f64.sqrt()).abs() < 1e-14);
        assert!((f.intercept_stderr - 1.32f64.sqrt()).abs() < 1e-14);
        assert!((f.residual_sd - 1.2f64.sqrt()).abs() < 1e-14);
        assert_eq!(
            fit_line(&[1.0, 2.0], &[1.0, 2.0]),
            Err(FitError::TooFewPoints(2))
        );
        assert_eq!(
            fit_line(&[1.0; 4], &[1.0, 2.0, 3.0, 4.0]),
            Err(FitError::DegenerateAbscissa)
        );
        assert_eq!(
            fit_line(&[1.0, 2.0, 3.0], &[1.0, 2.0]),
            Err(FitError::LengthMismatch { x: 3, y: 2 })
        );
        assert_eq!(
            fit_line(&[1.0, 2.0, f64::NAN], &[1.0, 2.0, 3.0]),
            Err(FitError::NonFinite)
        );
    }

    #[test]
    fn extrapolation_interval_covers_the_bulk_value() {
        // phi = 0.64 - 0.25 / D plus noise: the 95 % interval must cover 0.64 in about 95 %
        // of repetitions (checked over 400 deterministic pseudo-random data sets)
        use crate::rng::particle_stream;
        use rand::RngExt;
        let d = [1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0];
        let mut rng = particle_stream(41, 0);
        let mut covered = 0;
        let reps = 400;
        for _ in 0..reps {
            let phi: Vec<f64> = d
                .iter()
                .map(|d| {
                    // sum of 12 uniforms - 6: a near-normal deviate with unit variance
                    let g: f64 = (0..12).map(|_| rng.random::<f64>()).sum::<f64>() - 6.0;
                    0.64 - 0.25 / d + 0.005 * g
                })
                .collect();
            let f = bulk_extrapolation(&d, &phi).unwrap();
            covered += usize::from((f.intercept - 0.64).abs() <= f.intercept_half_width_95());
        }
        let rate = covered as f64 / reps as f64;
        assert!((rate - 0.95).abs() < 0.035, "{rate}");
    }

    #[test]
    fn rescalings_hit_their_anchor_points() {
        assert_eq!(rescaled_packing_fraction(0.6, 0.6), 1.0);
        assert_eq!(rescaled_packing_fraction_wedge(0.3, 0.6, 0.3), 0.0);
        assert_eq!(rescaled_packing_fraction_wedge(0.6, 0.6, 0.3), 1.0);
        assert_eq!(rescaled_contact_number(6.0, 6.0), 1.0);
        assert!(rescaled_contact_number(7.0, 6.0) > 1.0); // may exceed 1 ([T000 §2.4])
        let m = mean_interval_95(&[1.0, 1.0, 1.0, 1.0]).unwrap();
        assert_eq!((m.mean, m.half_width, m.n), (1.0, 0.0, 4));
        assert!(mean_interval_95(&[1.0]).is_none());
    }
}
