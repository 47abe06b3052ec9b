//! The smallest wedge ([T000 §2.4, eqs. 2.12, 2.13]; D-000-17 in docs/references.md).
//!
//! The smallest wedge holds one row of particles along the slope: the first cap inscribed in
//! the vertex angle (its centre R / tan(alpha/2) from the vertex along the slope), the rod
//! along the slope, and the back wall touching the last cap:
//!
//! l_w,min = R / tan(alpha/2) + R + L cos(alpha)                          (2.12)
//!
//! (erratum E-000-9: the thesis prints "R/tan alpha/2", which is R / tan(alpha/2)). Its packing
//! fraction is that of one particle in a wedge of width 2R:
//!
//! phi_lw,min = pi R^2 (4/3 R + L) / (1/2 2R l_w,min^2 tan(alpha))        (2.13)
//!
//! L is the length of the cylindrical part (twice the half length).

/// Minimum wedge length l_w,min / D (eq. 2.12) for particles of radius `radius`, cylinder
/// length `cyl_length` (= 2 x half length), and wedge angle `alpha` (radians).
///
/// ```
/// use magsep_systems::packing::walls::wedge_min_length;
/// // spheres (D = 1) in a 45-degree wedge: 1/2 / tan(22.5 deg) + 1/2 = 1.707
/// let l = wedge_min_length(0.5, 0.0, std::f64::consts::FRAC_PI_4);
/// assert!((l - 1.7071).abs() < 1e-4);
/// ```
pub fn wedge_min_length(radius: f64, cyl_length: f64, alpha: f64) -> f64 {
    radius / (0.5 * alpha).tan() + radius + cyl_length * alpha.cos()
}

/// Packing fraction of the minimum wedge (eq. 2.13): one particle in a wedge of length
/// [`wedge_min_length`] and width 2R.
///
/// ```
/// use magsep_systems::packing::walls::wedge_min_packing_fraction;
/// let phi = wedge_min_packing_fraction(0.5, 0.0, std::f64::consts::FRAC_PI_4);
/// assert!((phi - 0.359).abs() < 5e-4);
/// ```
pub fn wedge_min_packing_fraction(radius: f64, cyl_length: f64, alpha: f64) -> f64 {
    let l = wedge_min_length(radius, cyl_length, alpha);
    let v = std::f64::consts::PI * radius * radius * (4.0 / 3.0 * radius + cyl_length);
    v / (0.5 * 2.0 * radius * l * l * alpha.tan())
}
