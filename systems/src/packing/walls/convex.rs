//! Wall contacts of any convex particle through its deepest point (support-map rule; the
//! cylinder's fixed-point iteration and its convergence are argued in the parent module).

use std::f64::consts::TAU;

use glam::DVec3;

use super::{WallId, WallKind, cylinder_offset, planes};

/// A particle-wall contact at the particle's deepest point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallContact {
    /// Penetration depth / D (> 0: the particle is inside the wall; < 0: gap).
    pub overlap: f64,
    /// The particle's outward unit normal at its deepest point = the wall's outward normal
    /// there (pointing out of the container).
    pub normal: DVec3,
    /// Deepest point relative to the particle's centre / D (lab frame).
    pub rc: DVec3,
    /// The wall.
    pub wall: WallId,
}

/// Azimuths sampled before the cylinder iteration.
const SAMPLES: usize = 16;
/// Iteration cap per start.
const MAX_STEPS: usize = 60;

/// One deepest-point candidate against the cylinder wall.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    rc: DVec3,
    rho: f64,
}

/// Support point in the horizontal direction of azimuth `theta` and its distance from the
/// axis.
#[inline]
fn at_azimuth(
    r_cyl: f64,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
    theta: f64,
) -> Candidate {
    let rc = support(DVec3::new(theta.cos(), theta.sin(), 0.0));
    Candidate {
        rc,
        rho: cylinder_offset(r_cyl, centre + rc).length(),
    }
}

/// Monotone ascent of rho from azimuth `theta`: p <- x + s(rho_hat(p)), with Aitken
/// extrapolation of the azimuth every third step (kept only if rho increases).
fn ascend(
    r_cyl: f64,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
    mut theta: f64,
    mut cur: Candidate,
) -> Candidate {
    let mut hist = [theta; 3];
    let mut nh = 1;
    for _ in 0..MAX_STEPS {
        let off = cylinder_offset(r_cyl, centre + cur.rc);
        if off.length_squared() == 0.0 {
            break;
        }
        let raw = off.y.atan2(off.x);
        let g = theta + (raw - theta + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
        if (g - theta).abs() <= 1e-13 {
            break;
        }
        let next = at_azimuth(r_cyl, centre, support, g);
        if next.rho <= cur.rho {
            break; // no ascent left (round-off level): cur is a fixed point
        }
        (theta, cur) = (g, next);
        if nh < 3 {
            hist[nh] = theta;
            nh += 1;
        } else {
            hist = [hist[1], hist[2], theta];
        }
        if nh == 3 {
            let (d1, d2) = (hist[1] - hist[0], hist[2] - hist[1]);
            let den = d2 - d1;
            if den.abs() > 1e-300 {
                let t = hist[2] - d2 * d2 / den;
                if t.is_finite() && (t - theta).abs() < 1.0 {
                    let ext = at_azimuth(r_cyl, centre, support, t);
                    if ext.rho > cur.rho {
                        (theta, cur) = (t, ext);
                    }
                }
            }
            hist[0] = theta;
            nh = 1;
        }
    }
    cur
}

/// The particle's horizontal support points at `SAMPLES` azimuths and, per sector between
/// neighbouring azimuths, an upper bound of rho: the points of the particle whose horizontal
/// outward normal lies in the sector project into the triangle of the two support points and
/// the corner of their support lines, and the convex rho is largest at a triangle vertex.
struct Sampled {
    at: [Candidate; SAMPLES],
    /// `bound[k]`: upper bound of rho over sector [theta_k, theta_k+1].
    bound: [f64; SAMPLES],
}

impl Sampled {
    fn new(r_cyl: f64, centre: DVec3, support: &impl Fn(DVec3) -> DVec3) -> Self {
        let theta = |k: usize| TAU * k as f64 / SAMPLES as f64;
        let at: [Candidate; SAMPLES] =
            std::array::from_fn(|k| at_azimuth(r_cyl, centre, support, theta(k)));
        let bound = std::array::from_fn(|k| {
            let k1 = (k + 1) % SAMPLES;
            let (d0, d1) = (
                glam::DVec2::from_angle(theta(k)),
                glam::DVec2::from_angle(theta(k1)),
            );
            // support lines d.q = sigma in the axis frame; their corner
            let s0 = d0.dot(cylinder_offset(r_cyl, centre + at[k].rc));
            let s1 = d1.dot(cylinder_offset(r_cyl, centre + at[k1].rc));
            let det = d0.perp_dot(d1);
            let corner = glam::DVec2::new(s0 * d1.y - s1 * d0.y, d0.x * s1 - d1.x * s0) / det;
            corner.length().max(at[k].rho).max(at[k1].rho)
        });
        Self { at, bound }
    }

    /// Upper bound of rho near sample `k` (its two sectors).
    fn near(&self, k: usize) -> f64 {
        self.bound[k].max(self.bound[(k + SAMPLES - 1) % SAMPLES])
    }

    fn upper(&self) -> f64 {
        self.bound.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Ascents from the centre's radial direction and from every sample whose sectors may hold
/// rho > `threshold` (so every sector that can hold a contact has a start of its own).
fn ascents(
    r_cyl: f64,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
    sampled: &Sampled,
    threshold: f64,
    found: &mut [Candidate; SAMPLES + 1],
) -> usize {
    let mut n = 0;
    let off = cylinder_offset(r_cyl, centre);
    if off.length_squared() > 0.0 {
        let theta = off.y.atan2(off.x);
        let start = at_azimuth(r_cyl, centre, support, theta);
        found[n] = ascend(r_cyl, centre, support, theta, start);
        n += 1;
    }
    for k in 0..SAMPLES {
        if sampled.near(k) > threshold {
            let theta = TAU * k as f64 / SAMPLES as f64;
            found[n] = ascend(r_cyl, centre, support, theta, sampled.at[k]);
            n += 1;
        }
    }
    n
}

/// Distinct local maxima of rho above R_cyl - `margin`, deepest first, through `emit`.
fn cylinder_contacts(
    r_cyl: f64,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
    margin: f64,
    mut emit: impl FnMut(Candidate),
) {
    let zone = r_cyl - margin;
    let sampled = Sampled::new(r_cyl, centre, support);
    if sampled.upper() <= zone {
        return;
    }
    let mut found = [Candidate {
        rc: DVec3::ZERO,
        rho: f64::NEG_INFINITY,
    }; SAMPLES + 1];
    let n = ascents(r_cyl, centre, support, &sampled, zone, &mut found);
    let found = &mut found[..n];
    found.sort_by(|a, b| b.rho.total_cmp(&a.rho));
    let mut kept = [DVec3::ZERO; SAMPLES + 1];
    let mut nk = 0;
    for c in found.iter() {
        if c.rho <= zone {
            break;
        }
        let p = centre + c.rc;
        // the same contact if close, or if the chord to a kept point (inside the convex
        // particle) stays in the contact zone rho > R_cyl - margin
        let same = kept[..nk].iter().any(|&q| {
            let (a, b) = (cylinder_offset(r_cyl, q), cylinder_offset(r_cyl, p));
            let ab = b - a;
            let l2 = ab.length_squared();
            let t = if l2 > 0.0 {
                (-a.dot(ab) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p - q).length() < 1e-9 || (a + t * ab).length() >= zone - 1e-12
        });
        if !same {
            kept[nk] = p;
            nk += 1;
            emit(*c);
        }
    }
}

/// Largest rho over the particle (branch and bound over the sampled sectors).
fn cylinder_max_rho(r_cyl: f64, centre: DVec3, support: &impl Fn(DVec3) -> DVec3) -> f64 {
    let sampled = Sampled::new(r_cyl, centre, support);
    let mut best = sampled
        .at
        .iter()
        .map(|c| c.rho)
        .fold(f64::NEG_INFINITY, f64::max);
    let off = cylinder_offset(r_cyl, centre);
    if off.length_squared() > 0.0 {
        let theta = off.y.atan2(off.x);
        let start = at_azimuth(r_cyl, centre, support, theta);
        best = best.max(ascend(r_cyl, centre, support, theta, start).rho);
    }
    let mut order: [usize; SAMPLES] = std::array::from_fn(|k| k);
    order.sort_by(|&a, &b| sampled.near(b).total_cmp(&sampled.near(a)));
    for k in order {
        if sampled.near(k) <= best {
            break;
        }
        let theta = TAU * k as f64 / SAMPLES as f64;
        best = best.max(ascend(r_cyl, centre, support, theta, sampled.at[k]).rho);
    }
    best
}

/// Append to `out` the contacts with overlap > -`margin` of a convex particle at `centre`
/// with the walls, at the particle's deepest point per wall. `support(d)` returns the
/// particle's farthest point in the unit lab direction `d`, relative to its centre. The
/// cylinder can yield several contacts (a particle touching opposite sides of a narrow
/// cylinder: distinct local maxima of rho, see the module header).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallId, WallKind, convex_wall_contacts};
/// // a sphere of radius 0.5 at height 0.4 above the floor of a box
/// let support = |d: DVec3| 0.5 * d;
/// let mut c = Vec::new();
/// let x = DVec3::new(2.0, 2.0, 0.4);
/// convex_wall_contacts(WallKind::Box, DVec3::splat(4.0), x, &support, 0.0, &mut c);
/// assert_eq!(c.len(), 1);
/// assert_eq!((c[0].wall, c[0].normal), (WallId::Low { axis: 2 }, DVec3::NEG_Z));
/// assert!((c[0].overlap - 0.1).abs() < 1e-15 && c[0].rc == DVec3::new(0.0, 0.0, -0.5));
/// ```
pub fn convex_wall_contacts(
    kind: WallKind,
    edges: DVec3,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
    margin: f64,
    out: &mut Vec<WallContact>,
) {
    match kind {
        WallKind::Periodic => {}
        WallKind::Cylinder { radius: r_cyl } => {
            cylinder_contacts(r_cyl, centre, support, margin, |c| {
                let off = cylinder_offset(r_cyl, centre + c.rc);
                let normal = if c.rho > 0.0 {
                    (off / c.rho).extend(0.0)
                } else {
                    DVec3::X
                };
                out.push(WallContact {
                    overlap: c.rho - r_cyl,
                    normal,
                    rc: c.rc,
                    wall: WallId::Cylinder,
                });
            });
        }
        _ => {
            for plane in planes(kind, edges).iter() {
                let rc = support(plane.normal);
                let overlap = -plane.distance(centre + rc);
                if overlap > -margin {
                    out.push(WallContact {
                        overlap,
                        normal: plane.normal,
                        rc,
                        wall: plane.wall,
                    });
                }
            }
        }
    }
}

/// Largest penetration depth of a convex particle into any wall / D (<= 0: inside;
/// `f64::NEG_INFINITY` without walls). `support` as in [`convex_wall_contacts`].
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallKind, penetration_depth};
/// // a rod (R = 0.5, half length 1) lying along x, 2.8 from the cylinder axis
/// let u = DVec3::X;
/// let support = |d: DVec3| u * u.dot(d).signum() + 0.5 * d;
/// let k = WallKind::Cylinder { radius: 3.0 };
/// let x = DVec3::new(3.0, 0.2, 1.0);
/// let depth = penetration_depth(k, DVec3::new(6.0, 6.0, 5.0), x, &support);
/// assert!((depth - (2.8f64.hypot(1.0) + 0.5 - 3.0)).abs() < 1e-12);
/// ```
pub fn penetration_depth(
    kind: WallKind,
    edges: DVec3,
    centre: DVec3,
    support: &impl Fn(DVec3) -> DVec3,
) -> f64 {
    match kind {
        WallKind::Periodic => f64::NEG_INFINITY,
        WallKind::Cylinder { radius: r_cyl } => cylinder_max_rho(r_cyl, centre, support) - r_cyl,
        _ => planes(kind, edges)
            .iter()
            .map(|p| -p.distance(centre + support(p.normal)))
            .fold(f64::NEG_INFINITY, f64::max),
    }
}
