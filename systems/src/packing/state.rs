//! Dense packing state in reduced units.
//!
//! The MCM's revised step size depends on the unit system (D-000-15 in docs/references.md: a move is at
//! most delta_min * dt * sqrt(2c/m)), so the kernels work in the thesis's units: lengths in
//! units of a reference diameter D (the smallest particle diameter of the scene, twice the
//! smallest semi-axis for superquadrics), density 1 (mass = reduced volume), c = 1.
//! [`PackingState::from_si`] and [`PackingState::to_si`] convert.
//!
//! The container is the box `[0, edges]` with the wall geometry of [`WallKind`]: periodic
//! along the axes the walls leave open, hard walls (virtual particles, [`super::walls`])
//! elsewhere.

use glam::{DQuat, DVec3};
use magsep_components::shape::Shape;

pub use super::body::{Body, BodyKind};
use super::contact::{
    PairContact, from_solver, pair_contact, solver_options, superquadric_contact,
};
use super::walls::{self, WallContact, WallKind};
use crate::geometry::superquadric::{WarmStart, contact_prepared_within, overlap_upper_bound};

/// Round-off margin / D of [`PackingState::contact_warm_above`]'s bound test (the bound's own
/// error is ~1e-15 D; the solver's, at the packing's Newton tolerance of 1e-10, is below
/// ~5e-11 D: [`super::contact::solver_options`]).
const BOUND_MARGIN: f64 = 1e-10;

/// What [`PackingState::contact_warm_above`] found for a pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Above {
    /// The contact, if its overlap is above the tolerance.
    pub contact: Option<PairContact>,
    /// Room / D left below the tolerance: the overlap is at most `tol` - 1e-10 - `room`
    /// (>= 0; negative infinity when no such bound is known: rod pairs, contacts above the
    /// tolerance, solver fall-backs). The overlap of two convex bodies changes by no more
    /// than how far their surface points move, so it stays at most the tolerance while the
    /// two ends together move their points by less than `room` (the overlap tracker's
    /// certificates).
    pub room: f64,
}

/// Positions, orientations and bodies of all particles in a container, reduced units.
#[derive(Debug, Clone, PartialEq)]
pub struct PackingState {
    /// Extent of the container's box / D; positions lie in `[0, edges)` along periodic axes.
    pub edges: DVec3,
    /// Wall geometry (periodic cube: [`WallKind::Periodic`]).
    pub walls: WallKind,
    /// Centres / D.
    pub positions: Vec<DVec3>,
    /// Orientations (body z = rod axis).
    pub orientations: Vec<DQuat>,
    /// Per-particle bodies.
    pub bodies: Vec<Body>,
}

impl PackingState {
    /// Build from SI data; `edges` \[m\] and `walls` (in reduced units) describe the container,
    /// `d` is the reference diameter \[m\].
    pub fn from_si(
        edges: DVec3,
        walls: WallKind,
        positions: &[DVec3],
        orientations: &[DQuat],
        shapes: &[Shape],
        d: f64,
    ) -> Self {
        Self {
            edges: edges / d,
            walls,
            positions: positions.iter().map(|p| *p / d).collect(),
            orientations: orientations.to_vec(),
            bodies: shapes.iter().map(|s| Body::from_shape(s, d)).collect(),
        }
    }

    /// A periodic cube of edge `edge` (reduced units) with no particles.
    pub fn periodic_cube(edge: f64) -> Self {
        Self {
            edges: DVec3::splat(edge),
            walls: WallKind::Periodic,
            positions: Vec::new(),
            orientations: Vec::new(),
            bodies: Vec::new(),
        }
    }

    /// Edges \[m\] and positions \[m\] for reference diameter `d`.
    pub fn to_si(&self, d: f64) -> (DVec3, Vec<DVec3>) {
        (
            self.edges * d,
            self.positions.iter().map(|p| *p * d).collect(),
        )
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Total particle volume / D^3.
    pub fn particle_volume(&self) -> f64 {
        self.bodies.iter().map(|b| b.volume).sum()
    }

    /// Container volume / D^3.
    pub fn container_volume(&self) -> f64 {
        walls::container_volume(self.walls, self.edges)
    }

    /// Packing fraction (particle volume over container volume, [T000 eq. 3.1]).
    pub fn packing_fraction(&self) -> f64 {
        self.particle_volume() / self.container_volume()
    }

    /// Which axes are periodic.
    #[inline]
    pub fn periodic(&self) -> [bool; 3] {
        walls::periodic_axes(self.walls)
    }

    /// Axis (body z in the lab frame) of particle `i`.
    #[inline]
    pub fn axis(&self, i: usize) -> DVec3 {
        self.orientations[i] * DVec3::Z
    }

    /// Contact of particles `i` and `j`, with `j` seen through the periodic image `shift`.
    #[inline]
    pub fn contact(&self, i: usize, j: usize, shift: DVec3) -> PairContact {
        body_contact(
            &self.bodies[i],
            self.positions[i],
            self.orientations[i],
            &self.bodies[j],
            self.positions[j] + shift,
            self.orientations[j],
        )
    }

    /// Whether the contact of `i` and `j` is the superquadric solver's (not both rods).
    #[inline]
    pub fn is_superquadric_pair(&self, i: usize, j: usize) -> bool {
        !matches!(
            (self.bodies[i].kind, self.bodies[j].kind),
            (BodyKind::Rod, BodyKind::Rod)
        )
    }

    /// [`Self::contact`] with the cached superquadric solution of the pair, updated.
    #[inline]
    pub fn contact_warm(
        &self,
        i: usize,
        j: usize,
        shift: DVec3,
        warm: &mut Option<WarmStart>,
    ) -> PairContact {
        let (xi, qi) = (self.positions[i], self.orientations[i]);
        let (xj, qj) = (self.positions[j] + shift, self.orientations[j]);
        self.contact_warm_at(i, (xi, qi), j, (xj, qj), warm)
    }

    /// [`Self::contact_warm`] with the poses (centre, orientation) of `i` and of `j` given (j's
    /// centre with its image shift), as a sweep sees them before its moves are written back.
    #[inline]
    pub fn contact_warm_at(
        &self,
        i: usize,
        (xi, qi): (DVec3, DQuat),
        j: usize,
        (xj, qj): (DVec3, DQuat),
        warm: &mut Option<WarmStart>,
    ) -> PairContact {
        let (bi, bj) = (&self.bodies[i], &self.bodies[j]);
        if let (BodyKind::Rod, BodyKind::Rod) = (bi.kind, bj.kind) {
            return body_contact(bi, xi, qi, bj, xj, qj);
        }
        superquadric_contact(bi, xi, qi, bj, xj, qj, warm)
    }

    /// [`Self::contact_warm`] if the pair overlaps by more than `tol` (see [`Above`]). A
    /// superquadric pair whose overlap is certainly at most `tol` (its separating-axis bound
    /// along the cached contact normal, [`overlap_upper_bound`], below `tol` less a round-off
    /// margin) is not solved and keeps its cached Newton start: its solved overlap would be
    /// below `tol` too (to the solver's accuracy, ~5e-11 D at most, inside the margin).
    #[inline]
    pub fn contact_warm_above(
        &self,
        i: usize,
        j: usize,
        shift: DVec3,
        warm: &mut Option<WarmStart>,
        tol: f64,
    ) -> Above {
        let (xi, qi) = (self.positions[i], self.orientations[i]);
        let (xj, qj) = (self.positions[j] + shift, self.orientations[j]);
        self.contact_warm_above_at(i, (xi, qi), j, (xj, qj), warm, tol)
    }

    /// [`Self::contact_warm_above`] with the poses given (see [`Self::contact_warm_at`]).
    #[inline]
    pub fn contact_warm_above_at(
        &self,
        i: usize,
        pose_i: (DVec3, DQuat),
        j: usize,
        pose_j: (DVec3, DQuat),
        warm: &mut Option<WarmStart>,
        tol: f64,
    ) -> Above {
        let (bi, bj) = (&self.bodies[i], &self.bodies[j]);
        if !self.is_superquadric_pair(i, j) {
            let c = self.contact_warm_at(i, pose_i, j, pose_j, warm);
            return Above {
                contact: (c.overlap > tol).then_some(c),
                room: f64::NEG_INFINITY,
            };
        }
        let (ci, cj) = (&bi.contact_shape, &bj.contact_shape);
        let bound = overlap_upper_bound(
            ci,
            pose_i.0,
            pose_i.1,
            cj,
            pose_j.0,
            pose_j.1,
            warm.as_ref(),
        );
        if bound <= tol - BOUND_MARGIN {
            return Above {
                contact: None,
                room: tol - BOUND_MARGIN - bound,
            };
        }
        // the bound is above the tolerance, so far above the solver's gap cut-off: the
        // solver's centre-line reject cannot end the call
        let (xi, qi, xj, qj) = (pose_i.0, pose_i.1, pose_j.0, pose_j.1);
        let opts = solver_options();
        let r = contact_prepared_within(ci, xi, qi, cj, xj, qj, &opts, warm.as_ref());
        let c = from_solver(r, bi, bj, warm);
        if c.overlap > tol {
            return Above {
                contact: Some(c),
                room: f64::NEG_INFINITY,
            };
        }
        let room = tol - BOUND_MARGIN - c.overlap;
        Above {
            contact: None,
            room: if c.fallback || room.is_nan() {
                f64::NEG_INFINITY
            } else {
                room
            },
        }
    }

    /// Wall contacts of particle `i` with overlap > `-margin` (virtual rods for spheres and
    /// spherocylinders, the deepest-point rule for superquadrics), appended to `out`.
    pub fn wall_contacts(&self, i: usize, margin: f64, out: &mut Vec<PairContact>) {
        if self.walls == WallKind::Periodic {
            return;
        }
        let b = &self.bodies[i];
        let (x, q) = (self.positions[i], self.orientations[i]);
        match b.kind {
            BodyKind::Rod => {
                let mut virt = Vec::new();
                walls::virtual_rods(
                    self.walls,
                    self.edges,
                    x,
                    q * DVec3::Z,
                    b.radius,
                    b.half_length,
                    &mut virt,
                );
                for v in &virt {
                    let c = pair_contact(
                        q * DVec3::Z,
                        b.half_length,
                        b.radius,
                        v.centre - x,
                        v.axis,
                        v.half_length,
                        v.radius,
                    );
                    if c.overlap > -margin {
                        out.push(c);
                    }
                }
            }
            BodyKind::Superquadric(_) => {
                let mut wc: Vec<WallContact> = Vec::new();
                let support = |d: DVec3| b.support(q, d);
                walls::convex_wall_contacts(self.walls, self.edges, x, &support, margin, &mut wc);
                out.extend(
                    wc.iter()
                        .map(|w| PairContact::wall(w.overlap, w.normal, w.rc)),
                );
            }
        }
    }

    /// Largest wall penetration depth of particle `i` / D (<= 0: inside).
    pub fn wall_penetration(&self, i: usize) -> f64 {
        let b = &self.bodies[i];
        let q = self.orientations[i];
        let support = |d: DVec3| b.support(q, d);
        walls::penetration_depth(self.walls, self.edges, self.positions[i], &support)
    }

    /// Wrap particle `i` into `[0, edges)` along the periodic axes.
    #[inline]
    pub fn wrap(&mut self, i: usize) {
        let periodic = self.periodic();
        let p = &mut self.positions[i];
        for a in 0..3 {
            if periodic[a] {
                let l = self.edges[a];
                p[a] -= l * (p[a] / l).floor();
                if p[a] >= l {
                    p[a] = 0.0;
                }
            }
        }
    }

    /// Scale the box and all centres by `s` along each axis (affine compression;
    /// orientations unchanged). Centres are not wrapped (images scale with them), see
    /// `NeighbourList::build`.
    pub fn scale(&mut self, s: DVec3) {
        self.edges *= s;
        for p in &mut self.positions {
            *p *= s;
        }
    }

    /// Wrap every centre into the box along periodic axes.
    pub fn wrap_all(&mut self) {
        for i in 0..self.len() {
            self.wrap(i);
        }
    }
}

/// Contact of body `a` at (`xa`, `qa`) with body `b` at (`xb`, `qb`).
pub fn body_contact(a: &Body, xa: DVec3, qa: DQuat, b: &Body, xb: DVec3, qb: DQuat) -> PairContact {
    match (a.kind, b.kind) {
        (BodyKind::Rod, BodyKind::Rod) => pair_contact(
            qa * DVec3::Z,
            a.half_length,
            a.radius,
            xb - xa,
            qb * DVec3::Z,
            b.half_length,
            b.radius,
        ),
        _ => superquadric_contact(a, xa, qa, b, xb, qb, &mut None),
    }
}
