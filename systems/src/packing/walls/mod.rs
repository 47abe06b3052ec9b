//! Hard walls for the mechanical contraction method: container geometry, virtual particles
//! and the deepest-point rule ([T000 §2.2.4, Figs. 2.3-2.5]; E-000-11, D-000-19 in docs/references.md).
//!
//! # Container
//!
//! Reduced units (lengths / D). The container is the box `[0, edges.x] x [0, edges.y] x
//! [0, edges.z]` with the walls of a [`WallKind`]:
//!
//! | kind | walls (outward normal n, wall n.x = c) | periodic | compressed | volume |
//! |---|---|---|---|---|
//! | `Periodic` | none | x y z | x y z | l_x l_y l_z |
//! | `Cylinder { radius }` | rho(x) = R_cyl, rho = distance from the axis (R_cyl, R_cyl, z) | z | z | pi R_cyl^2 l_z |
//! | `Wedge { alpha }` | bottom (0,-1,0).x = 0, back (1,0,0).x = l_x, slope (-sin a, cos a, 0).x = 0 | z | z | 1/2 l_x l_y l_z |
//! | `Slab` | z = 0, z = l_z | x y | z | l_x l_y l_z |
//! | `Box` | the six faces | none | x y z | l_x l_y l_z |
//!
//! Conventions: cylinder `edges.x = edges.y = 2 R_cyl` (the radius is taken from the kind);
//! wedge `edges.y = edges.x tan(alpha)` (the slope plane is taken from the kind, the volume
//! from the edges, [T000 §2.2.4]: 1/2 l_w h_w w_w). The signed distance of a point to a wall is
//! positive inside: `c - n.x` for a plane, `R_cyl - rho(x)` for the cylinder.
//!
//! # Virtual particles ([`virtual_rods`], [T000 §2.2.4])
//!
//! A spherocylinder (radius R, half length h, axis u; a sphere has h = 0) with end points
//! p^+- = x +- h u (erratum E-000-8) penetrates a wall where an end cap does: distance(p) < R.
//! For each penetrating end point a *virtual rod* identical to the particle is placed outside
//! the wall, tangent to it at the foot of p ([T000 §2.2.4], reconstructions E-000-11 of
//! Figs. 2.4/2.5):
//!
//! * cylinder: centre (a + rho_hat (R_cyl + R), p_z), rho_hat = (p - a)_xy / |(p - a)_xy|,
//!   axis z ([T000 Fig. 2.4]);
//! * plane (n, c): centre p + (c - n.p + R) n (the foot point plus R n), axis in the plane:
//!   wedge bottom x, back y, slope (cos a, sin a, 0) as in the thesis ([T000 §2.2.4]); slab and box
//!   faces (not in the thesis): the projection of u onto the plane, normalised, or when u is
//!   (numerically) normal to the face the next coordinate axis (x face: y, y face: z,
//!   z face: x).
//!
//! The caller computes the contact of the particle with each virtual rod by the ordinary
//! pair contact with `r = virtual.centre - x` (no periodic image: the walls are not periodic
//! along their normals) and adds it to the particle's sums like any other contact ([T000 §2.2.4]).
//!
//! *Exactness* (target V-PK-6). Let p be the particle's deepest axis point with respect to the
//! wall (for a plane the end point with the smallest distance; for the cylinder the end point
//! with the largest rho: rho is convex along a segment, so its maximum is at an end). The
//! virtual rod's axis lies on the plane offset by R outside the wall (cylinder: on the
//! coaxial cylinder of radius R_cyl + R) and contains the foot point of p, so the axis
//! distance is exactly R + distance(p) (cylinder: |x_xy - a'| >= |a'| - rho(x) >=
//! R_cyl + R - rho(p) for every axis point x and virtual axis point a'), and the overlap
//! 2R - |k| equals the cap's penetration depth R - distance(p) (cylinder:
//! rho(p) + R - R_cyl) to round-off, as long as that depth is at most 2R (the end point not
//! beyond the virtual axis: no two rods overlap by more than 2R; MCM overlaps are << R).
//! When both end points penetrate the same wall region, the
//! shallower end point's virtual rod sees the deeper part of the axis: its overlap lies
//! between its own depth and the deeper end's depth (both bounds are attained: a rod parallel
//! to a plane gives both ends their own depth). This is inherent to any tangent virtual
//! particle (moving along the axis towards the deeper end always gets closer); we keep the
//! thesis's "one virtual particle per penetrating end point" ([T000 §2.2.4]), which pushes a rod
//! lying on a wall out without a spurious torque, and document the bound.
//!
//! # Deepest-point rule for any convex particle ([`convex_wall_contacts`])
//!
//! The particle is given by its support map s(d) (farthest point in lab direction d,
//! relative to the centre x). For a plane the deepest point is x + s(n), depth
//! n.(x + s(n)) - c. For the cylinder the deepest point maximises rho over the particle;
//! rho^2 is convex with horizontal gradient 2 (p - a)_xy, so the iteration
//! p_{k+1} = x + s(rho_hat(p_k)) (the conditional-gradient step of the convex function
//! rho^2) is a monotone ascent:
//!
//! ```text
//! rho^2(p_{k+1}) >= rho^2(p_k) + 2 (p_k - a)_xy . (p_{k+1} - p_k) >= rho^2(p_k),
//! ```
//!
//! the first by convexity, the second because p_{k+1} maximises rho_hat(p_k) . q over the
//! particle, which contains p_k. The bounded increasing sequence converges, and its fixed
//! points are the KKT points (local maxima) of rho; the angle error contracts per step by
//! about (local particle curvature radius) / (curvature radius + rho), slow only for
//! particles near the axis, so every third step is Aitken-extrapolated (accepted only if rho
//! increases).
//!
//! Starts: the particle's horizontal support points s(d(theta_k)) at 16 azimuths bound rho
//! from below, and the circumscribed 16-gon of their support lines bounds it from above per
//! sector (the points whose horizontal normal lies between theta_k and theta_k+1 project into
//! the triangle of the two support points and the corner of their support lines; rho is
//! convex, so its maximum there is at a vertex). Particles whose bound stays below
//! R_cyl - margin are rejected after these 16 support calls. Otherwise the iteration (at most
//! 60 steps) runs from the centre's radial direction (exact for spheres at once) and from
//! every sample whose sectors may hold a contact ([`penetration_depth`]: in the order of the
//! bounds, until the bound falls below the best rho found). Starting inside each candidate
//! sector matters: a capsule's support point jumps between its caps, which hides a cap's
//! local maximum from the samples. Distinct local maxima are distinct contacts when the chord
//! between them (inside the convex particle) leaves the contact zone rho > R_cyl - margin (a
//! rod across a narrow cylinder touches both sides; the virtual-rod method gives the same two
//! contacts); otherwise they are merged. A capped iteration falls back to its best point, a
//! lower bound of the depth that is still a point of the particle. The start heuristic is not
//! a proof of global optimality; the tests compare with dense surface sampling.

mod convex;
mod virtual_rods;
mod wedge;

#[cfg(test)]
mod tests;

pub use convex::{WallContact, convex_wall_contacts, penetration_depth};
pub use virtual_rods::{VirtualRod, virtual_rods};
pub use wedge::{wedge_min_length, wedge_min_packing_fraction};

use glam::{DVec2, DVec3};
use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

/// Wall geometry of the container `[0, edges]` (reduced units, see the module header).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WallKind {
    /// No walls: periodic along x, y and z, compressed isotropically.
    Periodic,
    /// Lateral wall rho = `radius` about the axis through (radius, radius, z); edges.x =
    /// edges.y = 2 radius; periodic in z, compressed along z only.
    Cylinder {
        /// Cylinder radius R_cyl / D.
        radius: f64,
    },
    /// Right prism: bottom y = 0, back x = edges.x, slope y = x tan(alpha); edges.y =
    /// edges.x tan(alpha); periodic in z, compressed along z only.
    Wedge {
        /// Acute angle between bottom and slope (radians). Range: (0, pi/2).
        alpha: f64,
    },
    /// Walls z = 0 and z = edges.z; periodic in x and y; compressed along z.
    Slab,
    /// Six walls; compressed isotropically.
    Box,
}

/// One wall of a container: the boundary entities' [`WallFace`](magsep_components::container::WallFace).
pub use magsep_components::container::WallFace as WallId;

/// A flat wall: points with `normal . x = offset`; the container is `normal . x < offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallPlane {
    /// Which wall.
    pub wall: WallId,
    /// Unit normal pointing out of the container.
    pub normal: DVec3,
    /// Offset c of the plane `normal . x = c` / D.
    pub offset: f64,
}

impl WallPlane {
    /// Signed distance of `point` to the plane / D (positive inside the container).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::packing::walls::{WallId, WallPlane};
    /// let top = WallPlane { wall: WallId::High { axis: 2 }, normal: DVec3::Z, offset: 5.0 };
    /// assert_eq!(top.distance(DVec3::new(1.0, 1.0, 4.0)), 1.0);
    /// ```
    #[inline]
    pub fn distance(&self, point: DVec3) -> f64 {
        self.offset - self.normal.dot(point)
    }
}

/// The flat walls of a container (at most six; derefs to a slice).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallPlanes {
    planes: [WallPlane; 6],
    len: usize,
}

impl std::ops::Deref for WallPlanes {
    type Target = [WallPlane];
    fn deref(&self) -> &[WallPlane] {
        &self.planes[..self.len]
    }
}

/// The walls of `kind`, in a fixed order (cylinder; wedge bottom, back, slope; faces low/high
/// per axis x, y, z).
///
/// ```
/// use magsep_systems::packing::walls::{WallId, WallKind, wall_ids};
/// assert_eq!(wall_ids(WallKind::Slab), [WallId::Low { axis: 2 }, WallId::High { axis: 2 }]);
/// assert!(wall_ids(WallKind::Periodic).is_empty());
/// ```
pub fn wall_ids(kind: WallKind) -> &'static [WallId] {
    const BOX: [WallId; 6] = [
        WallId::Low { axis: 0 },
        WallId::High { axis: 0 },
        WallId::Low { axis: 1 },
        WallId::High { axis: 1 },
        WallId::Low { axis: 2 },
        WallId::High { axis: 2 },
    ];
    match kind {
        WallKind::Periodic => &[],
        WallKind::Cylinder { .. } => &[WallId::Cylinder],
        WallKind::Wedge { .. } => &[WallId::WedgeBottom, WallId::WedgeBack, WallId::WedgeSlope],
        WallKind::Slab => &BOX[4..],
        WallKind::Box => &BOX,
    }
}

/// Which axes are periodic.
///
/// ```
/// use magsep_systems::packing::walls::{WallKind, periodic_axes};
/// assert_eq!(periodic_axes(WallKind::Cylinder { radius: 2.0 }), [false, false, true]);
/// assert_eq!(periodic_axes(WallKind::Slab), [true, true, false]);
/// ```
pub fn periodic_axes(kind: WallKind) -> [bool; 3] {
    match kind {
        WallKind::Periodic => [true; 3],
        WallKind::Cylinder { .. } | WallKind::Wedge { .. } => [false, false, true],
        WallKind::Slab => [true, true, false],
        WallKind::Box => [false; 3],
    }
}

/// Which axes shrink during compression (the others stay fixed).
///
/// ```
/// use magsep_systems::packing::walls::{WallKind, compressed_axes};
/// assert_eq!(compressed_axes(WallKind::Wedge { alpha: 0.3 }), [false, false, true]);
/// assert_eq!(compressed_axes(WallKind::Box), [true; 3]);
/// ```
pub fn compressed_axes(kind: WallKind) -> [bool; 3] {
    match kind {
        WallKind::Periodic | WallKind::Box => [true; 3],
        WallKind::Cylinder { .. } | WallKind::Wedge { .. } | WallKind::Slab => [false, false, true],
    }
}

/// Container volume / D^3: pi R_cyl^2 l_z (cylinder), 1/2 l_x l_y l_z (wedge), else the box.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallKind, container_volume};
/// let v = container_volume(WallKind::Cylinder { radius: 1.0 }, DVec3::new(2.0, 2.0, 3.0));
/// assert!((v - 3.0 * std::f64::consts::PI).abs() < 1e-14);
/// ```
pub fn container_volume(kind: WallKind, edges: DVec3) -> f64 {
    match kind {
        WallKind::Cylinder { radius } => std::f64::consts::PI * radius * radius * edges.z,
        WallKind::Wedge { .. } => 0.5 * edges.x * edges.y * edges.z,
        WallKind::Periodic | WallKind::Slab | WallKind::Box => edges.x * edges.y * edges.z,
    }
}

/// Edges of a cylinder container of `radius` and `length` (z): (2R, 2R, L).
///
/// ```
/// use magsep_systems::packing::walls::cylinder_edges;
/// assert_eq!(cylinder_edges(1.5, 10.0), glam::DVec3::new(3.0, 3.0, 10.0));
/// ```
pub fn cylinder_edges(radius: f64, length: f64) -> DVec3 {
    DVec3::new(2.0 * radius, 2.0 * radius, length)
}

/// Edges of a wedge of angle `alpha` (radians), length l_w (x) and width w_w (z):
/// (l_w, l_w tan(alpha), w_w).
///
/// ```
/// use magsep_systems::packing::walls::wedge_edges;
/// let e = wedge_edges(std::f64::consts::FRAC_PI_4, 2.0, 5.0);
/// assert!((e.y - 2.0).abs() < 1e-15 && e.z == 5.0);
/// ```
pub fn wedge_edges(alpha: f64, length: f64, width: f64) -> DVec3 {
    DVec3::new(length, length * alpha.tan(), width)
}

/// The flat walls of `kind` with outward normals (the cylinder has none).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallId, WallKind, planes};
/// let p = planes(WallKind::Wedge { alpha: 0.5 }, DVec3::new(4.0, 4.0 * 0.5f64.tan(), 3.0));
/// assert_eq!(p.len(), 3);
/// assert_eq!((p[1].wall, p[1].normal, p[1].offset), (WallId::WedgeBack, DVec3::X, 4.0));
/// ```
pub fn planes(kind: WallKind, edges: DVec3) -> WallPlanes {
    let dummy = WallPlane {
        wall: WallId::Cylinder,
        normal: DVec3::ZERO,
        offset: 0.0,
    };
    let mut out = WallPlanes {
        planes: [dummy; 6],
        len: 0,
    };
    let face = |id: WallId| -> WallPlane {
        match id {
            WallId::Low { axis } => WallPlane {
                wall: id,
                normal: -DVec3::AXES[axis as usize],
                offset: 0.0,
            },
            WallId::High { axis } => WallPlane {
                wall: id,
                normal: DVec3::AXES[axis as usize],
                offset: edges[axis as usize],
            },
            WallId::WedgeBottom => WallPlane {
                wall: id,
                normal: DVec3::NEG_Y,
                offset: 0.0,
            },
            WallId::WedgeBack => WallPlane {
                wall: id,
                normal: DVec3::X,
                offset: edges.x,
            },
            WallId::WedgeSlope => {
                let alpha = match kind {
                    WallKind::Wedge { alpha } => alpha,
                    _ => 0.0,
                };
                WallPlane {
                    wall: id,
                    normal: DVec3::new(-alpha.sin(), alpha.cos(), 0.0),
                    offset: 0.0,
                }
            }
            // the cylinder wall is not flat (never listed for a flat container)
            WallId::Cylinder => dummy,
        }
    };
    if !matches!(kind, WallKind::Cylinder { .. }) {
        for &id in wall_ids(kind) {
            out.planes[out.len] = face(id);
            out.len += 1;
        }
    }
    out
}

/// Horizontal offset of `point` from the cylinder axis through (radius, radius).
#[inline]
pub(crate) fn cylinder_offset(radius: f64, point: DVec3) -> DVec2 {
    DVec2::new(point.x - radius, point.y - radius)
}

/// Signed distance of `point` to wall `wall` of the container / D (positive inside).
/// `wall` must be one of [`wall_ids`]`(kind)`.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallId, WallKind, wall_distance};
/// let k = WallKind::Cylinder { radius: 2.0 };
/// let d = wall_distance(k, DVec3::new(4.0, 4.0, 1.0), WallId::Cylinder, DVec3::new(3.0, 2.0, 7.0));
/// assert!((d - 1.0).abs() < 1e-15);
/// ```
pub fn wall_distance(kind: WallKind, edges: DVec3, wall: WallId, point: DVec3) -> f64 {
    match (kind, wall) {
        (WallKind::Cylinder { radius }, _) => radius - cylinder_offset(radius, point).length(),
        _ => planes(kind, edges)
            .iter()
            .find(|p| p.wall == wall)
            .map_or(f64::INFINITY, |p| p.distance(point)),
    }
}

/// Outward unit normal of wall `wall` at the wall point nearest to `point` (cylinder: the
/// horizontal radial direction at `point`, x on the axis).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallId, WallKind, wall_normal};
/// let k = WallKind::Cylinder { radius: 2.0 };
/// let n = wall_normal(k, DVec3::new(4.0, 4.0, 1.0), WallId::Cylinder, DVec3::new(2.0, 3.0, 7.0));
/// assert_eq!(n, DVec3::Y);
/// ```
pub fn wall_normal(kind: WallKind, edges: DVec3, wall: WallId, point: DVec3) -> DVec3 {
    match (kind, wall) {
        (WallKind::Cylinder { radius }, _) => {
            let r = cylinder_offset(radius, point);
            let l = r.length();
            if l > 0.0 {
                (r / l).extend(0.0)
            } else {
                DVec3::X
            }
        }
        _ => planes(kind, edges)
            .iter()
            .find(|p| p.wall == wall)
            .map_or(DVec3::ZERO, |p| p.normal),
    }
}

/// Smallest signed distance of `point` to any wall / D (`f64::INFINITY` without walls).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallKind, min_wall_distance};
/// let d = min_wall_distance(WallKind::Box, DVec3::splat(4.0), DVec3::new(1.0, 2.0, 3.5));
/// assert_eq!(d, 0.5);
/// ```
pub fn min_wall_distance(kind: WallKind, edges: DVec3, point: DVec3) -> f64 {
    match kind {
        WallKind::Cylinder { radius } => radius - cylinder_offset(radius, point).length(),
        _ => planes(kind, edges)
            .iter()
            .map(|p| p.distance(point))
            .fold(f64::INFINITY, f64::min),
    }
}

/// Whether `point` lies inside the container at distance >= `clearance` from every wall.
/// Insert spheres by their centre and spherocylinders by both end points p^+- with
/// `clearance` = R (the set of admissible points is convex, so the whole rod is inside).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallKind, admissible};
/// let (k, e) = (WallKind::Slab, DVec3::new(5.0, 5.0, 2.0));
/// assert!(admissible(k, e, DVec3::new(-7.0, 9.0, 0.5), 0.5)); // x, y periodic
/// assert!(!admissible(k, e, DVec3::new(1.0, 1.0, 0.4), 0.5));
/// ```
pub fn admissible(kind: WallKind, edges: DVec3, point: DVec3, clearance: f64) -> bool {
    min_wall_distance(kind, edges, point) >= clearance
}

/// Bounding box of the container's interior (its lower corner is the origin).
fn bounding_box(kind: WallKind, edges: DVec3) -> DVec3 {
    match kind {
        WallKind::Cylinder { radius } => DVec3::new(2.0 * radius, 2.0 * radius, edges.z),
        WallKind::Wedge { alpha } => DVec3::new(edges.x, edges.x * alpha.tan(), edges.z),
        _ => edges,
    }
}

/// Radius of the largest horizontal disc (cylinder, wedge) or half the smallest walled
/// edge (slab, box) inside the container: admissible points exist iff clearance < this.
fn inradius(kind: WallKind, edges: DVec3) -> f64 {
    match kind {
        WallKind::Periodic => f64::INFINITY,
        WallKind::Cylinder { radius } => radius,
        WallKind::Wedge { alpha } => {
            // right triangle with legs l, l tan a and hypotenuse l / cos a
            0.5 * edges.x * (1.0 + alpha.tan() - 1.0 / alpha.cos())
        }
        WallKind::Slab => 0.5 * edges.z,
        WallKind::Box => 0.5 * edges.min_element(),
    }
}

/// A point uniformly distributed over the admissible set (distance >= `clearance` from
/// every wall), by rejection from the container's bounding box. `None` if the set is empty
/// or ten million trials fail.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallKind, admissible, random_admissible_point};
/// use magsep_systems::rng::particle_stream;
/// let (k, e) = (WallKind::Cylinder { radius: 2.0 }, DVec3::new(4.0, 4.0, 9.0));
/// let mut rng = particle_stream(1, 0);
/// let p = random_admissible_point(k, e, 0.5, &mut rng).unwrap();
/// assert!(admissible(k, e, p, 0.5));
/// assert!(random_admissible_point(k, e, 2.5, &mut rng).is_none());
/// ```
pub fn random_admissible_point<R: Rng + ?Sized>(
    kind: WallKind,
    edges: DVec3,
    clearance: f64,
    rng: &mut R,
) -> Option<DVec3> {
    if clearance >= inradius(kind, edges) {
        return None;
    }
    let b = bounding_box(kind, edges);
    for _ in 0..10_000_000u32 {
        let p = DVec3::new(
            rng.random::<f64>(),
            rng.random::<f64>(),
            rng.random::<f64>(),
        ) * b;
        if admissible(kind, edges, p, clearance) {
            return Some(p);
        }
    }
    None
}
