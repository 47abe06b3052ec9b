//! The collision domain: periodic axes (minimum image) and static planar walls.
//!
//! A periodic axis `k` with `[min, min + length)` identifies `x_k` and `x_k + length`; pair offsets
//! use the minimum image `Δ_k − L round(Δ_k/L)`. The minimum image is unambiguous for a pair over a
//! whole step only if `L/2` exceeds the contact distance plus the relative displacement in the step,
//! i.e. `L > 2 (d_max + 2 v_max h)`; the engine assumes this (no check, no panic otherwise).

use glam::DVec3;

use super::toi::Plane;

/// One periodic axis `[min, min + length)`.
///
/// ```
/// use magsep_systems::collision::domain::PeriodicAxis;
/// let p = PeriodicAxis { min: -1.0, length: 2.0 };
/// assert_eq!(p.wrap(1.5), -0.5);
/// assert_eq!(p.image(1.5), -0.5);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicAxis {
    /// Lower bound of the primary cell \[m\].
    pub min: f64,
    /// Period \[m\]. Range: > 0.
    pub length: f64,
}

impl PeriodicAxis {
    /// Minimum image of the offset `d` \[m\].
    #[inline]
    pub fn image(&self, d: f64) -> f64 {
        d - self.length * round_half_away(d / self.length)
    }

    /// `x` \[m\] wrapped into `[min, min + length)`.
    pub fn wrap(&self, x: f64) -> f64 {
        let y = self.min + (x - self.min).rem_euclid(self.length);
        // rem_euclid can round up to exactly `length`
        if y >= self.min + self.length {
            self.min
        } else {
            y
        }
    }
}

/// `x.round()` (halves away from zero) without the call into libm that `f64::round` makes on
/// targets without SSE4.1, bitwise equal for every input but NaN (sign of zero and infinities
/// included; NaN gives NaN): the minimum image is the inner loop of the collision engine.
#[inline]
fn round_half_away(x: f64) -> f64 {
    // 2^52: from here on every f64 is an integer
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    // exact: |x| < 2^52 fits an i64, and x − trunc(x) is exact
    let t = ((x as i64) as f64).copysign(x);
    let f = x - t;
    if f >= 0.5 {
        t + 1.0
    } else if f <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

/// Periodic axes (x, y, z; any subset) and static walls.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::domain::CollisionDomain;
/// use magsep_systems::collision::toi::Plane;
/// let box_ = CollisionDomain::unbounded()
///     .with_periodic(0, 0.0, 1.0)
///     .with_periodic(2, 0.0, 1.0)
///     .with_plane(Plane::new(DVec3::ZERO, DVec3::Y));
/// assert_eq!(box_.minimum_image(DVec3::new(0.75, 0.9, -0.75)), DVec3::new(-0.25, 0.9, 0.25));
/// assert_eq!(box_.wrap(DVec3::new(1.25, 3.0, -0.25)), DVec3::new(0.25, 3.0, 0.75));
/// ```
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollisionDomain {
    /// Periodicity of the x, y and z axes (`None`: unbounded along that axis).
    pub periodic: [Option<PeriodicAxis>; 3],
    /// Static walls; each keeps particles on the side its normal points to.
    pub planes: Vec<Plane>,
}

impl CollisionDomain {
    /// No periodic axes and no walls.
    pub fn unbounded() -> Self {
        Self::default()
    }

    /// Makes axis `axis` (0 = x, 1 = y, 2 = z; larger values are ignored) periodic on
    /// `[min, min + length)` \[m\].
    pub fn with_periodic(mut self, axis: usize, min: f64, length: f64) -> Self {
        if let Some(slot) = self.periodic.get_mut(axis) {
            *slot = Some(PeriodicAxis { min, length });
        }
        self
    }

    /// Adds a wall.
    pub fn with_plane(mut self, plane: Plane) -> Self {
        self.planes.push(plane);
        self
    }

    /// Minimum image of the offset `d` \[m\] along the periodic axes.
    #[inline]
    pub fn minimum_image(&self, d: DVec3) -> DVec3 {
        let mut out = d;
        for (k, p) in self.periodic.iter().enumerate() {
            if let Some(p) = p {
                out[k] = p.image(d[k]);
            }
        }
        out
    }

    /// `x` \[m\] wrapped into the primary cell along the periodic axes.
    pub fn wrap(&self, x: DVec3) -> DVec3 {
        let mut out = x;
        for (k, p) in self.periodic.iter().enumerate() {
            if let Some(p) = p {
                out[k] = p.wrap(x[k]);
            }
        }
        out
    }

    /// The first periodic axis whose length is not positive and finite, if any.
    pub fn invalid_axis(&self) -> Option<(usize, f64)> {
        self.periodic.iter().enumerate().find_map(|(k, p)| {
            p.filter(|p| !(p.length > 0.0 && p.length.is_finite() && p.min.is_finite()))
                .map(|p| (k, p.length))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::round_half_away;

    #[test]
    fn round_half_away_is_bitwise_f64_round() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.3,
            -0.3,
            0.5,
            -0.5,
            1.5,
            -2.5,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
            1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        // a deterministic spread over many magnitudes
        let mut u: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..100_000 {
            u ^= u << 13;
            u ^= u >> 7;
            u ^= u << 17;
            xs.push(f64::from_bits(u));
            xs.push((u >> 11) as f64 / (1u64 << 40) as f64 - 4096.0);
        }
        for x in xs {
            if x.is_nan() {
                assert!(round_half_away(x).is_nan());
            } else {
                assert_eq!(round_half_away(x).to_bits(), x.round().to_bits(), "{x:e}");
            }
        }
    }
}
