//! Public contact entry point: bounding spheres, GJK/EPA seeding (parry3d-f64 on the analytic
//! support maps), the common-normal Newton polish and the acceptance tests ([T000 §4.4.1],
//! with the changes listed in the module header).

use glam::{DMat3, DQuat, DVec3};

use super::mass::bounding_radius_cheap;
use super::newton::{self, Newton, NewtonSettings, PairFrame};
use super::prepared::Prepared;
use super::seed::{SeedKind, gjk_epa, seed_from};
use super::shape::Superquadric;

/// Options of [`contact`].
///
/// ```
/// use magsep_systems::geometry::superquadric::ContactOptions;
/// let o = ContactOptions { polish: false, ..ContactOptions::default() };
/// assert_eq!(o.max_iterations, 50);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactOptions {
    /// Gap below which Newton computes the contact, in units of the smallest semi-axis L of
    /// the pair. Default: 0.05. Range: >= 0 (infinite: always polish).
    pub newton_band: f64,
    /// Newton tolerance: normal misalignment \[rad\] and residual lengths (tangential part of
    /// k, distance of the points from their surfaces) in units of the smallest semi-axis.
    /// Default: 1e-12. Range: > 0.
    pub tolerance: f64,
    /// Newton iterations before non-convergence is declared. Default: 50.
    pub max_iterations: u32,
    /// Polish with Newton; `false` returns the GJK/EPA answer alone (GJK then always runs
    /// to its full precision). Default: true.
    pub polish: bool,
    /// Gap \[m\] beyond which gaps are not computed. GJK stops as soon as it knows that the
    /// gap exceeds c = max(`gap_cutoff`, `newton_band` L) (status
    /// [`ContactStatus::SeparatedGjk`], overlap only an upper bound, below -c); pairs known
    /// to be closer leave GJK early and Newton computes their gap exactly. Infinity: GJK
    /// computes every gap to its own precision (about 5e-8 relative, several times slower on
    /// curved shapes) and Newton polishes those within the band. Default: 0 (c = band).
    pub gap_cutoff: f64,
}

impl Default for ContactOptions {
    fn default() -> Self {
        Self {
            newton_band: 0.05,
            tolerance: 1e-12,
            max_iterations: 50,
            polish: true,
            gap_cutoff: 0.0,
        }
    }
}

/// How a [`ContactResult`] was obtained.
///
/// ```
/// use magsep_systems::geometry::superquadric::ContactStatus;
/// assert_ne!(ContactStatus::Converged, ContactStatus::Fallback);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ContactStatus {
    /// Newton converged and passed the acceptance tests: overlap exact to the tolerance.
    Converged,
    /// The bounding spheres are apart; `overlap = r_a + r_b - |d| < 0` is only an upper bound
    /// (the true gap is at least `-overlap`) and the normal is the centre line.
    FarApart,
    /// GJK, or the separating-axis test along the centre line that runs first, found a gap
    /// wider than the cutoff (see [`ContactOptions::gap_cutoff`]); the overlap is the
    /// support-function value in that direction, an upper bound of the true overlap (to GJK
    /// precision for an infinite cutoff, otherwise only known to be below minus the cutoff).
    SeparatedGjk,
    /// `polish = false`: the GJK/EPA answer, projected onto both surfaces.
    GjkEpa,
    /// Newton did not converge or its solution was rejected: the GJK/EPA answer is returned
    /// (never "no contact"); callers should count these.
    Fallback,
    /// Invalid shape or non-finite pose: overlap NaN.
    InvalidInput,
}

/// Body-frame surface points of a solved pair, to seed the next call for the same pair.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::superquadric::WarmStart;
/// let w = WarmStart { s_a: DVec3::X, s_b: -DVec3::X };
/// assert_eq!(w.s_a.x, 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WarmStart {
    /// Point on a, body frame of a \[m\].
    pub s_a: DVec3,
    /// Point on b, body frame of b \[m\].
    pub s_b: DVec3,
}

/// Result of [`contact`].
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{contact, ContactOptions, Superquadric};
/// let s = Superquadric::superball(1.0, 2.0);
/// let r = contact(&s, DVec3::ZERO, DQuat::IDENTITY, &s, DVec3::X * 1.5, DQuat::IDENTITY,
///                 &ContactOptions::default(), None);
/// assert!((r.overlap - 0.5).abs() < 1e-12 && !r.is_fallback());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactResult {
    /// Overlap depth along the common normal \[m\]: > 0 overlap, < 0 gap.
    pub overlap: f64,
    /// Lab-frame unit outward normal of a at its contact point (towards b).
    pub normal: DVec3,
    /// Contact point on a relative to a's centre, lab frame \[m\].
    pub rc_a: DVec3,
    /// Contact point on b relative to b's centre, lab frame \[m\].
    pub rc_b: DVec3,
    /// How the answer was obtained.
    pub status: ContactStatus,
    /// Newton iterations spent (warm attempt and cold solves together).
    pub iterations: u32,
    /// Points to pass as `warm` next time (None when no surface points were computed, GJK
    /// stopped early beyond the band, or Newton failed).
    pub warm: Option<WarmStart>,
}

impl ContactResult {
    /// Whether this is not a trusted answer: a Newton failure (fallback estimate) or invalid
    /// input.
    ///
    /// ```
    /// use glam::{DQuat, DVec3};
    /// use magsep_systems::geometry::superquadric::{contact, ContactOptions, Superquadric};
    /// let s = Superquadric::superball(1.0, 0.5); // invalid exponent
    /// let r = contact(&s, DVec3::ZERO, DQuat::IDENTITY, &s, DVec3::X, DQuat::IDENTITY,
    ///                 &ContactOptions::default(), None);
    /// assert!(r.is_fallback() && r.overlap.is_nan());
    /// ```
    pub fn is_fallback(&self) -> bool {
        matches!(
            self.status,
            ContactStatus::Fallback | ContactStatus::InvalidInput
        )
    }
}

/// Raw GJK/EPA answer of parry3d-f64 (no projection, no polish), see [`gjk_epa_contact`].
///
/// ```
/// use magsep_systems::geometry::superquadric::GjkEpaContact;
/// fn depth(c: &GjkEpaContact) -> f64 { c.overlap }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GjkEpaContact {
    /// Overlap \[m\] (> 0 penetration, < 0 gap) as parry reports it.
    pub overlap: f64,
    /// Lab-frame unit normal of a towards b.
    pub normal: DVec3,
    /// Witness point on a relative to a's centre, lab frame \[m\].
    pub rc_a: DVec3,
    /// Witness point on b relative to b's centre, lab frame \[m\].
    pub rc_b: DVec3,
}

/// Everything [`contact`] derives from its arguments once.
pub(super) struct Setup {
    pub(super) pa: Prepared,
    pub(super) pb: Prepared,
    pub(super) pair: PairFrame,
    pub(super) qa: DQuat,
    pub(super) qb: DQuat,
    pub(super) qab: DQuat,
    pub(super) d: DVec3,
    /// Smallest semi-axis of the pair.
    pub(super) scale: f64,
}

fn setup(
    a: &Superquadric,
    xa: DVec3,
    qa: DQuat,
    b: &Superquadric,
    xb: DVec3,
    qb: DQuat,
) -> Option<Setup> {
    let finite = xa.is_finite() && xb.is_finite() && qa.is_finite() && qb.is_finite();
    if !(finite && a.is_valid() && b.is_valid() && qa.length() > 0.0 && qb.length() > 0.0) {
        return None;
    }
    let scale = a.semi_axes.min_element().min(b.semi_axes.min_element());
    Some(pose_setup(
        a.prepared(),
        b.prepared(),
        scale,
        xa,
        qa,
        xb,
        qb,
    ))
}

/// The [`Setup`] of valid shapes (`pa`, `pb`, smallest semi-axis `scale`) at finite poses
/// with nonzero quaternions.
#[inline]
pub(super) fn pose_setup(
    pa: Prepared,
    pb: Prepared,
    scale: f64,
    xa: DVec3,
    qa: DQuat,
    xb: DVec3,
    qb: DQuat,
) -> Setup {
    let (qa, qb) = (qa.normalize(), qb.normalize());
    let qbi = qb.conjugate();
    Setup {
        pa,
        pb,
        pair: PairFrame {
            r: DMat3::from_quat(qbi * qa),
            c: qbi * (xa - xb),
        },
        qa,
        qb,
        qab: qa.conjugate() * qb,
        d: xb - xa,
        scale,
    }
}

pub(super) fn invalid() -> ContactResult {
    ContactResult {
        overlap: f64::NAN,
        normal: DVec3::ZERO,
        rc_a: DVec3::ZERO,
        rc_b: DVec3::ZERO,
        status: ContactStatus::InvalidInput,
        iterations: 0,
        warm: None,
    }
}

/// Accept a Newton solution if it converged to an anti-parallel common normal lying between
/// the inscribed- and circumscribed-sphere bounds, on the centre-line side of a (true of the
/// global solution of centrally symmetric bodies) and not above `seed_overlap` (the
/// support-function value of the seed direction, an upper bound of the true overlap).
fn accept(
    s: &Setup,
    nw: &Newton,
    bounds: (f64, f64),
    seed_overlap: Option<f64>,
    slack: f64,
    tol: f64,
) -> Option<(f64, DVec3)> {
    if !nw.converged {
        return None;
    }
    let u = (s.pair.r * nw.grad_a).try_normalize()?;
    let m = nw.grad_b.try_normalize()?;
    if u.dot(m) >= -0.5 || u.dot(m).is_nan() {
        return None; // parallel normals: a far-side solution of eq. 4.9
    }
    let k = nw.s_b - (s.pair.r * nw.s_a + s.pair.c);
    let kn = k.dot(u);
    let overlap = -kn;
    let cross = (k - kn * u).length(); // |k x n_a|
    let d_b = -s.pair.c;
    let ok = cross <= (1e3 * tol).max(1e-6) * s.scale
        && overlap <= bounds.1 + slack
        && overlap >= bounds.0 - slack
        && seed_overlap.is_none_or(|so| overlap <= so + slack)
        && u.dot(d_b) >= -1e-9 * d_b.length() - slack
        && overlap.is_finite();
    ok.then_some((overlap, u))
}

/// Contact of superquadric `a` (centre `xa`, orientation `qa`) with `b` (lab frame).
///
/// Algorithm: bounding spheres (reject); a warm start, if given, goes straight to Newton;
/// otherwise GJK (separated: closest points) or EPA (penetrating) on the analytic support
/// maps gives a normal, whose support points on both surfaces seed the common-normal Newton
/// solve of eqs. 4.7-4.14. Pairs separated by more than the Newton band (or `gap_cutoff`)
/// keep the GJK answer ([`ContactStatus::SeparatedGjk`]).
/// A Newton failure is retried once from the centre line, then reported as
/// [`ContactStatus::Fallback`] with the GJK/EPA answer: non-convergence never becomes "no
/// contact". Warm starts assume the pair moved little since the cached call (a large move can
/// converge to another local solution; the acceptance tests catch far-side ones).
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{contact, ContactOptions, ContactStatus, Superquadric};
/// let a = Superquadric::superball(1.0, 4.0);
/// let opts = ContactOptions::default();
/// // face to face along x, 0.02 apart (inside the default Newton band of 0.05 a)
/// let r = contact(&a, DVec3::ZERO, DQuat::IDENTITY, &a, DVec3::new(2.02, 0.0, 0.0),
///                 DQuat::IDENTITY, &opts, None);
/// assert_eq!(r.status, ContactStatus::Converged);
/// assert!((r.overlap + 0.02).abs() < 1e-12 && (r.normal - DVec3::X).length() < 1e-12);
/// // the next call for this pair starts from the cached points
/// let r2 = contact(&a, DVec3::ZERO, DQuat::IDENTITY, &a, DVec3::new(1.99, 0.0, 0.0),
///                  DQuat::IDENTITY, &opts, r.warm.as_ref());
/// assert!((r2.overlap - 0.01).abs() < 1e-12 && r2.iterations <= 3);
/// ```
#[allow(clippy::too_many_arguments)]
pub fn contact(
    a: &Superquadric,
    xa: DVec3,
    qa: DQuat,
    b: &Superquadric,
    xb: DVec3,
    qb: DQuat,
    opts: &ContactOptions,
    warm: Option<&WarmStart>,
) -> ContactResult {
    let Some(s) = setup(a, xa, qa, b, xb, qb) else {
        return invalid();
    };
    let dist = s.d.length();
    let box_bound = a.semi_axes.length() + b.semi_axes.length();
    if dist > box_bound {
        return far_apart(s.d, dist, box_bound);
    }
    let outer = bounding_radius_cheap(a.semi_axes, a.exponents)
        + bounding_radius_cheap(b.semi_axes, b.exponents);
    if dist > outer {
        return far_apart(s.d, dist, outer);
    }
    let inner = a.semi_axes.min_element() + b.semi_axes.min_element();
    solve_pair(&s, dist, (inner - dist, outer - dist), opts, warm, true)
}

/// The [`ContactStatus::FarApart`] answer for centres `d` = x_b - x_a at distance `dist`
/// beyond the bound `bound` of r_a + r_b.
pub(super) fn far_apart(d: DVec3, dist: f64, bound: f64) -> ContactResult {
    ContactResult {
        overlap: bound - dist,
        normal: d.try_normalize().unwrap_or(DVec3::X),
        rc_a: DVec3::ZERO,
        rc_b: DVec3::ZERO,
        status: ContactStatus::FarApart,
        iterations: 0,
        warm: None,
    }
}

/// [`contact`] after the bounding-sphere rejects: `bounds` = (inscribed, circumscribed)
/// sphere bounds of the overlap. `centre_line`: try the separating-axis reject along the
/// centre line first (skipped by callers that know the pair lies within the cut-off, where
/// it cannot end the call).
pub(super) fn solve_pair(
    s: &Setup,
    dist: f64,
    bounds: (f64, f64),
    opts: &ContactOptions,
    warm: Option<&WarmStart>,
    centre_line: bool,
) -> ContactResult {
    let tol = if opts.tolerance > 0.0 {
        opts.tolerance
    } else {
        1e-12
    };
    let slack = tol.max(1e-10) * 10.0 * s.scale;
    let set = NewtonSettings {
        tol,
        max_iter: opts.max_iterations,
        scale: s.scale,
        chord: true,
    };
    let done = |overlap: f64, u_b: DVec3, s_a: DVec3, s_b: DVec3, status, iterations, warm| {
        ContactResult {
            overlap,
            normal: s.qb * u_b,
            rc_a: s.qa * s_a,
            rc_b: s.qb * s_b,
            status,
            iterations,
            warm,
        }
    };
    // a converged, accepted Newton solution (also the pair's next warm start)
    let converged = |nw: &newton::Newton, overlap: f64, u: DVec3, iterations| {
        let ws = WarmStart {
            s_a: nw.s_a,
            s_b: nw.s_b,
        };
        done(
            overlap,
            u,
            nw.s_a,
            nw.s_b,
            ContactStatus::Converged,
            iterations,
            Some(ws),
        )
    };
    // separating-axis test along the centre line: a gap beyond the cutoff ends here, before
    // any warm start, GJK or Newton (the same answer class as GJK's early exit)
    let cutoff = opts.gap_cutoff.max(opts.newton_band * s.scale);
    if centre_line && opts.polish && cutoff.is_finite() && dist > 0.0 {
        let u = s.d / dist;
        let (ua, ub) = (s.qa.conjugate() * u, s.qb.conjugate() * -u);
        let (sa, sb) = (s.pa.support(ua), s.pb.support(ub));
        let bound = ua.dot(sa) + ub.dot(sb) - dist;
        if bound < -cutoff {
            return ContactResult {
                overlap: bound,
                normal: u,
                rc_a: s.qa * sa,
                rc_b: s.qb * sb,
                status: ContactStatus::SeparatedGjk,
                iterations: 0,
                warm: None,
            };
        }
    }
    let mut iterations = 0;
    if opts.polish
        && let Some(w) = warm.filter(|w| w.s_a.is_finite() && w.s_b.is_finite())
    {
        let nw = newton::solve(&s.pa, &s.pb, &s.pair, w.s_a, w.s_b, &set);
        iterations += nw.iterations;
        if let Some((overlap, u)) = accept(s, &nw, bounds, None, slack, tol) {
            return converged(&nw, overlap, u, iterations);
        }
    }
    let d_a = s.qa.conjugate() * s.d;
    let band = opts.newton_band * s.scale;
    let cutoff = opts.gap_cutoff.max(band);
    let (cutoff, exact) = if !opts.polish || cutoff.is_nan() || cutoff == f64::INFINITY {
        (f64::INFINITY, true)
    } else {
        (cutoff, false)
    };
    let seed = gjk_epa(&s.pa, &s.pb, &s.pair, s.qab, d_a, cutoff, exact);
    let seed_result = |status, iterations| {
        let ws = WarmStart {
            s_a: seed.s_a,
            s_b: seed.s_b,
        };
        // rough seeds (GJK stopped early, or Newton failed) make poor warm starts
        let rough =
            status == ContactStatus::Fallback || (status == ContactStatus::SeparatedGjk && !exact);
        let warm = (!rough).then_some(ws);
        done(
            seed.overlap,
            s.pair.r * seed.n_a,
            seed.s_a,
            seed.s_b,
            status,
            iterations,
            warm,
        )
    };
    // exact GJK: keep its answer beyond the band; early-exit GJK: only beyond the cutoff
    if seed.kind == SeedKind::Beyond
        || (exact && opts.polish && seed.kind == SeedKind::Gjk && seed.overlap < -band)
    {
        return seed_result(ContactStatus::SeparatedGjk, iterations);
    }
    if !opts.polish {
        let status = if seed.kind == SeedKind::Failed {
            ContactStatus::Fallback
        } else {
            ContactStatus::GjkEpa
        };
        return seed_result(status, iterations);
    }
    let upper = (seed.kind != SeedKind::Failed).then_some(seed.overlap);
    let nw = newton::solve(&s.pa, &s.pb, &s.pair, seed.s_a, seed.s_b, &set);
    iterations += nw.iterations;
    if let Some((overlap, u)) = accept(s, &nw, bounds, upper, slack, tol) {
        return converged(&nw, overlap, u, iterations);
    }
    // retry once from the centre line
    let centre = d_a.try_normalize().unwrap_or(DVec3::X);
    let (s_a, s_b, _) = seed_from(&s.pa, &s.pb, &s.pair, centre);
    let nw = newton::solve(&s.pa, &s.pb, &s.pair, s_a, s_b, &set);
    iterations += nw.iterations;
    if let Some((overlap, u)) = accept(s, &nw, bounds, upper, slack, tol) {
        return converged(&nw, overlap, u, iterations);
    }
    seed_result(ContactStatus::Fallback, iterations)
}

/// The raw GJK/EPA answer of parry3d-f64 on the analytic support maps (witness points and
/// normal as parry returns them, no projection or polish): the baseline of the accuracy
/// study. `None` for invalid input or when EPA fails.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{gjk_epa_contact, Superquadric};
/// let s = Superquadric::superball(1.0, 2.0);
/// let c = gjk_epa_contact(&s, DVec3::ZERO, DQuat::IDENTITY, &s, DVec3::X * 2.5, DQuat::IDENTITY)
///     .unwrap();
/// assert!((c.overlap + 0.5).abs() < 1e-6);
/// ```
pub fn gjk_epa_contact(
    a: &Superquadric,
    xa: DVec3,
    qa: DQuat,
    b: &Superquadric,
    xb: DVec3,
    qb: DQuat,
) -> Option<GjkEpaContact> {
    let s = setup(a, xa, qa, b, xb, qb)?;
    let d_a = s.qa.conjugate() * s.d;
    let seed = gjk_epa(&s.pa, &s.pb, &s.pair, s.qab, d_a, f64::INFINITY, true);
    let (p1, p2, n) = seed.raw?;
    Some(GjkEpaContact {
        overlap: -(p2 - p1).dot(n),
        normal: s.qa * n.try_normalize()?,
        rc_a: s.qa * p1,
        rc_b: s.qa * p2 - s.d,
    })
}
