//! Per-particle shape, orientation and inertia of the collision step: the dispatch between the
//! analytic sphere path and the spheroid kernels of [`crate::collision::spheroid`].
//!
//! A pair uses the sphere formulas iff both particles are round (no [`super::SpheroidArrays`],
//! or equal semi-axes); otherwise the common-normal contact and the conservative-advancement
//! TOI (a round partner enters them as a spheroid with equal semi-axes). Orientations advance
//! ballistically with the particle's local time, `q(t) = exp(½ Ω (t − t_i)) q_i`, renormalised;
//! the world inverse inertia of [`InverseInertia::Principal`] is recomputed from the current
//! orientation at every use.

use glam::{DMat3, DQuat, DVec3};

use super::{InverseInertia, Sim};
use crate::collision::spheroid::{
    Impact, PosedSpheroid, Spheroid, spheroid_contact, spheroid_pair_toi, spheroid_plane_contact,
    spheroid_plane_toi, world_inverse_inertia,
};
use crate::collision::toi::{
    Ballistic, ContactGeometry, Plane, sphere_plane_contact, sphere_sphere_contact,
};

/// `exp(½ Ω dt) q`, renormalised (unchanged for a zero rotation).
pub(super) fn rotated(q: DQuat, omega: DVec3, dt: f64) -> DQuat {
    let phi = omega * dt;
    if phi == DVec3::ZERO || !phi.is_finite() {
        return q;
    }
    (DQuat::from_scaled_axis(phi) * q).normalize()
}

impl Sim<'_, '_> {
    /// Whether particle `i` is a sphere (analytic path).
    #[inline]
    pub(super) fn is_round(&self, i: usize) -> bool {
        self.p
            .spheroids
            .as_ref()
            .is_none_or(|s| s.shapes[i].is_sphere())
    }

    /// Shape of particle `i` (a sphere of its radius when round).
    pub(super) fn shape(&self, i: usize) -> Spheroid {
        match &self.p.spheroids {
            Some(s) => s.shapes[i],
            None => Spheroid::sphere(self.p.radii[i]),
        }
    }

    /// Orientation of particle `i` at time `t` (identity without shapes).
    pub(super) fn orientation_at(&self, i: usize, t: f64) -> DQuat {
        match &self.p.spheroids {
            Some(s) => rotated(
                s.orientations[i],
                self.p.angular_velocities[i],
                t - self.eng.local_time[i],
            ),
            None => DQuat::IDENTITY,
        }
    }

    /// Rotates particle `i` to time `t` (before its local time is updated).
    pub(super) fn advance_orientation(&mut self, i: usize, t: f64) {
        let q = self.orientation_at(i, t);
        if let Some(s) = &mut self.p.spheroids {
            s.orientations[i] = q;
        }
    }

    /// Diameter for the wet restitution: `2r` for spheres, the volume-equivalent `2 (a² c)^{1/3}`
    /// for spheroids \[m\].
    pub(super) fn diameter(&self, i: usize) -> f64 {
        if self.is_round(i) {
            2.0 * self.eng.radius[i]
        } else {
            let s = self.shape(i);
            2.0 * (s.equatorial * s.equatorial * s.polar).cbrt()
        }
    }

    /// World inverse inertia of particle `i` at its current orientation.
    #[inline]
    pub(super) fn inv_inertia(&self, i: usize) -> DMat3 {
        match self.p.inv_inertias {
            InverseInertia::Scalar(s) => DMat3::from_diagonal(DVec3::splat(s[i])),
            InverseInertia::Tensor(t) => t[i],
            InverseInertia::Principal(p) => {
                world_inverse_inertia(p[i], self.orientation_at(i, self.eng.local_time[i]))
            }
        }
    }

    fn posed(&self, i: usize, x: DVec3, t: f64) -> PosedSpheroid {
        PosedSpheroid::new(self.shape(i), x, self.orientation_at(i, t))
    }

    /// Contact of particles `i` and `j` at time `t` with `dx = x_j − x_i` (minimum image);
    /// `None` for invalid shapes or poses.
    pub(super) fn pair_contact(
        &self,
        i: usize,
        j: usize,
        xi: DVec3,
        dx: DVec3,
        t: f64,
    ) -> Option<ContactGeometry> {
        if self.is_round(i) && self.is_round(j) {
            return Some(sphere_sphere_contact(
                dx,
                self.eng.radius[i],
                self.eng.radius[j],
            ));
        }
        let a = self.posed(i, xi, t);
        let b = self.posed(j, xi + dx, t);
        spheroid_contact(&a, &b, None).map(|c| c.geometry)
    }

    /// Contact of particle `i` (at `x`, time `t`) with a wall.
    pub(super) fn wall_contact(
        &self,
        i: usize,
        x: DVec3,
        t: f64,
        plane: &Plane,
    ) -> ContactGeometry {
        if self.is_round(i) {
            sphere_plane_contact(x, self.eng.radius[i], plane)
        } else {
            spheroid_plane_contact(&self.posed(i, x, t), plane)
        }
    }

    fn ballistic(&self, i: usize, x: DVec3, t: f64) -> Ballistic {
        Ballistic {
            position: x,
            orientation: self.orientation_at(i, t),
            velocity: self.p.velocities[i],
            angular_velocity: self.p.angular_velocities[i],
        }
    }

    /// Spheroid TOI of the non-round pair `(i, j)` from time `now` (`xi` the position of `i`,
    /// `dx` the minimum-image offset of `j`), approaching faster than `min_approach`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn spheroid_pair_impact(
        &self,
        i: usize,
        j: usize,
        xi: DVec3,
        dx: DVec3,
        now: f64,
        horizon: f64,
        min_approach: f64,
    ) -> Option<Impact> {
        let a = self.ballistic(i, xi, now);
        let b = self.ballistic(j, xi + dx, now);
        spheroid_pair_toi(
            &self.shape(i),
            &a,
            &self.shape(j),
            &b,
            horizon,
            min_approach,
            None,
        )
    }

    /// Spheroid TOI of the non-round particle `i` with a wall.
    pub(super) fn spheroid_wall_impact(
        &self,
        i: usize,
        xi: DVec3,
        now: f64,
        plane: &Plane,
        horizon: f64,
        min_approach: f64,
    ) -> Option<Impact> {
        let a = self.ballistic(i, xi, now);
        spheroid_plane_toi(&self.shape(i), &a, plane, horizon, min_approach)
    }

    /// Fills the per-particle bounding radii (the radii themselves without shapes).
    pub(super) fn fill_radii(&mut self) {
        let r = &mut self.eng.radius;
        r.clear();
        match &self.p.spheroids {
            None => r.extend_from_slice(self.p.radii),
            Some(s) => r.extend(s.shapes.iter().map(|s| s.bounding_radius())),
        }
    }
}
