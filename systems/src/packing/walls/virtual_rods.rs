//! Virtual rods of a penetrating sphere or spherocylinder ([T000 §2.2.4]; construction,
//! exactness and the two-end bound in the parent module's header).

use glam::DVec3;

use super::{WallId, WallKind, cylinder_offset, planes};
use crate::packing::contact::{PairContact, pair_contact};

/// A virtual copy of a penetrating particle placed outside a wall, tangent to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VirtualRod {
    /// Centre / D (lab frame; not wrapped).
    pub centre: DVec3,
    /// Unit axis (in the wall plane; z for the cylinder).
    pub axis: DVec3,
    /// Radius R / D (the particle's).
    pub radius: f64,
    /// Half length h / D (the particle's).
    pub half_length: f64,
    /// The wall it stands for.
    pub wall: WallId,
    /// Geometric penetration depth of the end cap it was made for, R - distance(p) / D (> 0).
    pub depth: f64,
}

impl VirtualRod {
    /// Contact of the particle (centre `centre`, unit axis `axis`, `radius`, `half_length`)
    /// with this virtual rod: [`pair_contact`] with `r = self.centre - centre`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::packing::walls::{WallKind, virtual_rods};
    /// let (k, e) = (WallKind::Box, DVec3::splat(10.0));
    /// let (x, u) = (DVec3::new(5.0, 5.0, 0.8), DVec3::X);
    /// let mut v = Vec::new();
    /// virtual_rods(k, e, x, u, 0.5, 1.0, &mut v);
    /// assert!(v.is_empty()); // both end caps clear of z = 0
    /// // a rod lying 0.3 above the floor: both caps penetrate by 0.2
    /// let x = DVec3::new(5.0, 5.0, 0.3);
    /// virtual_rods(k, e, x, u, 0.5, 1.0, &mut v);
    /// assert_eq!(v.len(), 2);
    /// assert!((v[0].contact(x, u, 0.5, 1.0).overlap - 0.2).abs() < 1e-12);
    /// ```
    pub fn contact(
        &self,
        centre: DVec3,
        axis: DVec3,
        radius: f64,
        half_length: f64,
    ) -> PairContact {
        pair_contact(
            axis,
            half_length,
            radius,
            self.centre - centre,
            self.axis,
            self.half_length,
            self.radius,
        )
    }
}

/// Append to `out` one virtual rod per end point p = `centre` +- `half_length` `axis`
/// (one point for a sphere, `half_length` = 0) and per wall it penetrates
/// (distance(p) < `radius`). `axis` is a unit vector. Walls are listed in
/// [`super::wall_ids`] order, the + end first.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::walls::{WallId, WallKind, virtual_rods};
/// // a vertical rod in a cylinder of radius 2, its top end 0.2 from the wall
/// let (k, e) = (WallKind::Cylinder { radius: 2.0 }, DVec3::new(4.0, 4.0, 10.0));
/// let x = DVec3::new(3.5, 2.0, 5.0);
/// let u = DVec3::new(0.6, 0.0, 0.8);
/// let mut v = Vec::new();
/// virtual_rods(k, e, x, u, 0.5, 0.5, &mut v);
/// assert_eq!(v.len(), 1);
/// assert_eq!((v[0].wall, v[0].axis), (WallId::Cylinder, DVec3::Z));
/// assert!((v[0].centre - DVec3::new(4.5, 2.0, 5.4)).length() < 1e-14);
/// assert!((v[0].depth - 0.3).abs() < 1e-14);
/// ```
pub fn virtual_rods(
    kind: WallKind,
    edges: DVec3,
    centre: DVec3,
    axis: DVec3,
    radius: f64,
    half_length: f64,
    out: &mut Vec<VirtualRod>,
) {
    let ends = [centre + half_length * axis, centre - half_length * axis];
    let ends = if half_length == 0.0 {
        &ends[..1]
    } else {
        &ends[..]
    };
    let rod = |centre: DVec3, dir: DVec3, wall: WallId, depth: f64| VirtualRod {
        centre,
        axis: dir,
        radius,
        half_length,
        wall,
        depth,
    };
    match kind {
        WallKind::Periodic => {}
        WallKind::Cylinder { radius: r_cyl } => {
            for &p in ends {
                let off = cylinder_offset(r_cyl, p);
                let rho = off.length();
                if rho > r_cyl - radius {
                    // on the axis (only for particles wider than the cylinder): any direction
                    let rho_hat = if rho > 0.0 {
                        (off / rho).extend(0.0)
                    } else {
                        DVec3::X
                    };
                    let c = DVec3::new(r_cyl, r_cyl, p.z) + (r_cyl + radius) * rho_hat;
                    out.push(rod(c, DVec3::Z, WallId::Cylinder, rho + radius - r_cyl));
                }
            }
        }
        _ => {
            for plane in planes(kind, edges).iter() {
                let n = plane.normal;
                let dir = match plane.wall {
                    WallId::WedgeBottom => DVec3::X,
                    WallId::WedgeBack => DVec3::Y,
                    WallId::WedgeSlope => DVec3::new(n.y, -n.x, 0.0), // (cos a, sin a, 0)
                    WallId::Low { axis: a } | WallId::High { axis: a } => {
                        let proj = axis - axis.dot(n) * n;
                        let l2 = proj.length_squared();
                        if l2 > 1e-20 {
                            proj / l2.sqrt()
                        } else {
                            DVec3::AXES[(a as usize + 1) % 3]
                        }
                    }
                    WallId::Cylinder => DVec3::Z,
                };
                for &p in ends {
                    let d = plane.distance(p);
                    if d < radius {
                        out.push(rod(p + (d + radius) * n, dir, plane.wall, radius - d));
                    }
                }
            }
        }
    }
}
