//! The liquid's flow around the fibres of a filter: the mean (interstitial) velocity U plus, for
//! each fibre, the perturbation of 2D potential flow past a circular cylinder, as in Watson's
//! theory of high-gradient magnetic separation (J. H. P. Watson, J. Appl. Phys. 44, 1973), which
//! describes the liquid around one wire of a magnetic filter this way.
//!
//! Around one infinite cylinder of radius a with axis ê, the velocity at the distance ρ from the
//! axis (unit radial vector n̂, perpendicular part of the far velocity U⊥ = U − (U·ê)ê) is
//!
//! `u = U + (a/ρ)² (U⊥ − 2 (U⊥·n̂) n̂)`,
//!
//! the gradient of the potential `U⊥·r (1 + a²/ρ²)`: divergence- and curl-free, tangential on
//! the surface (`u·n̂ = 0` at ρ = a), 2|U⊥| at the sides, zero at the two stagnation lines. The
//! axial part of U passes unchanged.
//!
//! Beyond an end face (`|s| > h` along the axis from the centre, h the half length) the liquid
//! flows as 3D potential flow past a sphere of radius a centred on the face,
//! `u = U + (a/r)³ (U − 3 (U·n̂) n̂) / 2`, tangential on that sphere. So the liquid meets a
//! spherocylinder that encloses the flat-ended fibre (the half sphere in front of each face is
//! still liquid): no streamline ends on a face, as none ends on the side. Inside the body the
//! liquid is at rest.
//!
//! What this model adds to a mean flow and what it does not:
//! - The side and end formulas meet at the face planes with a jump in the velocity off the
//!   surface (both are tangential on it); the true 3D flow around the ends is smoother.
//! - The perturbation falls as (a/ρ)² (beside) and (a/r)³ (beyond the ends); it is kept in full to `NEAR` radii and tapered smoothly
//!   (a cubic step) to zero at `CUTOFF` radii, where it is (1/8)² < 2 % of U. The truncation makes
//!   the field slightly divergent in the taper.
//! - Near several fibres the perturbations are blended, not added: each fibre's perturbation
//!   p_i (as if it were alone) is weighted by w_i = t_i / g_i², with g_i the gap to its body and
//!   t_i its taper, and the blend is Σ w_i p_i / Σ w_i. On a fibre's surface its own weight wins,
//!   so the liquid never flows into any fibre (a plain sum would push the liquid, and the
//!   particles in it, through a fibre wherever a neighbour's perturbation points at it, as at
//!   the contacts of a packing: a spurious capture of a third of the particles at 1 m/s in a
//!   φ = 0.1 column without any magnetic force). One fibre alone gets its exact flow; between
//!   fibres the blend is an interpolation that is neither divergence-free nor the true flow of
//!   the array (which the method of reflections or a cell model would approximate better).
//! - Potential flow has no viscous boundary layer: it is the flow outside the layer, fitting at
//!   the Reynolds numbers of fast filtration (Re = ρ U D / η of order 10-100 for 0.4 mm fibres at
//!   cm/s to dm/s); in creeping flow (Re ≪ 1) the liquid near the fibre is slower than this.
//!
//! The fibres are found through a uniform grid of cells built once ([`FibreFlow::new`]); the
//! reference [`FibreFlow::perturbation_direct`] visits every fibre in index order, and the grid
//! visits the same fibres in the same order, so both give bit-identical sums (tested).

use glam::{DVec3, IVec3};

/// Radii from the axis within which a fibre's perturbation is kept whole.
pub const NEAR: f64 = 4.0;
/// Radii from the axis beyond which a fibre's perturbation is zero.
pub const CUTOFF: f64 = 8.0;
/// The smallest gap of the blend's weights, in radii (keeps them finite on a surface).
const GAP_FLOOR: f64 = 1e-9;
/// The most grid cells (bounded memory; the cells grow for a larger column).
const MAX_CELLS: usize = 1 << 20;

/// One fibre as the flow sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowFibre {
    /// Centre \[m\].
    pub center: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// Radius a \[m\].
    pub radius: f64,
    /// Half length h \[m\].
    pub half_length: f64,
}

/// What one fibre says of the liquid at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Local {
    /// Beyond the cutoff: nothing.
    Far,
    /// Inside the fibre's flow body: the liquid is at rest.
    Inside,
    /// Within the cutoff: the fibre's perturbation \[m/s\], the gap to its flow body \[m\] and
    /// the taper weight in [0, 1].
    Near {
        /// Perturbation velocity \[m/s\].
        velocity: DVec3,
        /// Distance to the body's surface \[m\], > 0.
        gap: f64,
        /// 1 to `NEAR` radii, falling to 0 at `CUTOFF`.
        taper: f64,
    },
}

impl FlowFibre {
    /// This fibre's perturbation at `x` in a far flow `u` \[m/s\] (as if it were alone).
    pub fn local(&self, u: DVec3, x: DVec3) -> Local {
        let r = x - self.center;
        let s = r.dot(self.axis);
        let a = self.radius;
        let (near, cut) = (NEAR * a, CUTOFF * a);
        if s.abs() <= self.half_length {
            // beside the cylinder: 2D potential flow of the perpendicular part
            let radial = r - s * self.axis;
            let rho2 = radial.length_squared();
            if rho2 >= cut * cut {
                return Local::Far;
            }
            if rho2 <= a * a {
                return Local::Inside;
            }
            let rho = rho2.sqrt();
            let n = radial / rho;
            let u_perp = u - u.dot(self.axis) * self.axis;
            let taper = taper(rho, near, cut);
            let w = (a / rho).powi(2) * taper;
            return Local::Near {
                velocity: w * (u_perp - 2.0 * u_perp.dot(n) * n),
                gap: (rho - a).max(GAP_FLOOR * a),
                taper,
            };
        }
        // beyond an end face: 3D potential flow past the sphere of radius a on the face's
        // centre, so the face lies inside the flow's body (a hemispherical cap of still liquid)
        let d = x - (self.center + self.half_length * s.signum() * self.axis);
        let r2 = d.length_squared();
        if r2 >= cut * cut {
            return Local::Far;
        }
        if r2 <= a * a {
            return Local::Inside;
        }
        let r = r2.sqrt();
        let n = d / r;
        let taper = taper(r, near, cut);
        let w = 0.5 * (a / r).powi(3) * taper;
        Local::Near {
            velocity: w * (u - 3.0 * u.dot(n) * n),
            gap: (r - a).max(GAP_FLOOR * a),
            taper,
        }
    }

    /// This fibre's perturbation velocity \[m/s\] at `x` in a far flow `u` as if it were
    /// alone (−u inside its body, where the liquid is at rest).
    pub fn perturbation(&self, u: DVec3, x: DVec3) -> DVec3 {
        match self.local(u, x) {
            Local::Far => DVec3::ZERO,
            Local::Inside => -u,
            Local::Near { velocity, .. } => velocity,
        }
    }

    /// Corners of the box outside which [`Self::perturbation`] is zero.
    fn reach(&self) -> (DVec3, DVec3) {
        let end = self.axis * self.half_length;
        let pad = DVec3::splat(CUTOFF * self.radius);
        let (p, q) = (self.center - end, self.center + end);
        (p.min(q) - pad, p.max(q) + pad)
    }
}

/// The fibres' perturbations weighted by taper / gap² (−u inside any body).
fn blend(u: DVec3, locals: impl Iterator<Item = Local>) -> DVec3 {
    let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
    for l in locals {
        match l {
            Local::Far => {}
            Local::Inside => return -u,
            Local::Near {
                velocity,
                gap,
                taper,
            } => {
                let w = taper / (gap * gap);
                sum += w * velocity;
                weight += w;
            }
        }
    }
    if weight > 0.0 {
        sum / weight
    } else {
        DVec3::ZERO
    }
}

/// 1 up to `near`, a cubic step down to 0 at `cut`.
fn taper(r: f64, near: f64, cut: f64) -> f64 {
    if r <= near {
        1.0
    } else {
        1.0 - smoothstep((r - near) / (cut - near))
    }
}

/// 3t² − 2t³ on [0, 1].
fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The fibres of a filter and the grid that finds the ones near a point.
#[derive(Debug, Clone, PartialEq)]
pub struct FibreFlow {
    fibres: Vec<FlowFibre>,
    origin: DVec3,
    cell: f64,
    dims: IVec3,
    /// Fibre indices of each cell, ascending, in one array (`starts[c]..starts[c + 1]`).
    starts: Vec<u32>,
    members: Vec<u32>,
}

impl FibreFlow {
    /// The grid over `fibres` (none: no perturbation anywhere).
    pub fn new(fibres: Vec<FlowFibre>) -> Self {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut largest: f64 = 0.0;
        for f in &fibres {
            let (a, b) = f.reach();
            lo = lo.min(a);
            hi = hi.max(b);
            largest = largest.max(CUTOFF * f.radius);
        }
        if fibres.is_empty() || !(lo.is_finite() && hi.is_finite()) {
            return Self {
                fibres: Vec::new(),
                origin: DVec3::ZERO,
                cell: 1.0,
                dims: IVec3::ONE,
                starts: vec![0, 0],
                members: Vec::new(),
            };
        }
        let extent = (hi - lo).max(DVec3::splat(largest));
        let mut cell = largest.max(extent.max_element() / 256.0);
        while (extent / cell).ceil().element_product() > MAX_CELLS as f64 {
            cell *= 1.5;
        }
        let dims = (extent / cell).ceil().as_ivec3().max(IVec3::ONE);
        let count = dims.element_product() as usize;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); count];
        let clamp = |p: DVec3| {
            ((p - lo) / cell)
                .floor()
                .as_ivec3()
                .clamp(IVec3::ZERO, dims - 1)
        };
        for (k, f) in fibres.iter().enumerate() {
            let (a, b) = f.reach();
            let (ca, cb) = (clamp(a), clamp(b));
            for z in ca.z..=cb.z {
                for y in ca.y..=cb.y {
                    for x in ca.x..=cb.x {
                        let c = (x + dims.x * (y + dims.y * z)) as usize;
                        lists[c].push(k as u32);
                    }
                }
            }
        }
        let mut starts = Vec::with_capacity(count + 1);
        let mut members = Vec::new();
        starts.push(0);
        for l in lists {
            members.extend(l);
            starts.push(members.len() as u32);
        }
        Self {
            fibres,
            origin: lo,
            cell,
            dims,
            starts,
            members,
        }
    }

    /// The fibres.
    pub fn fibres(&self) -> &[FlowFibre] {
        &self.fibres
    }

    /// The fibres' perturbation \[m/s\] at `x` in a far flow `u` (blended, see the module
    /// header), through the grid.
    pub fn perturbation(&self, u: DVec3, x: DVec3) -> DVec3 {
        let c = ((x - self.origin) / self.cell).floor();
        if !c.is_finite()
            || c.min_element() < 0.0
            || c.cmpge(self.dims.as_dvec3()).any()
            || self.fibres.is_empty()
        {
            return DVec3::ZERO;
        }
        let c = c.as_ivec3();
        let k = (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize;
        let (s, e) = (self.starts[k] as usize, self.starts[k + 1] as usize);
        blend(
            u,
            self.members[s..e]
                .iter()
                .map(|&f| self.fibres[f as usize].local(u, x)),
        )
    }

    /// Reference: the same blend over every fibre in index order.
    pub fn perturbation_direct(&self, u: DVec3, x: DVec3) -> DVec3 {
        blend(u, self.fibres.iter().map(|f| f.local(u, x)))
    }

    /// The liquid's velocity \[m/s\] at `x` in a far flow `u`.
    pub fn velocity(&self, u: DVec3, x: DVec3) -> DVec3 {
        u + self.perturbation(u, x)
    }
}

#[cfg(test)]
#[path = "fibre_flow_tests.rs"]
mod tests;
