//! Collective overlap removal by FIRE minimisation of the overlap energy (not in the thesis).
//!
//! The thesis's single-particle rules (`moves`) relax an overlap network by local moves whose
//! length is capped by the particle's smallest overlap (eq. 3.9). Near jamming the network's
//! relaxation time diverges and the attempt budget runs out early: with 200 N moves per step
//! they stop at phi ~ 0.59-0.61 for monodisperse spheres (the thesis's own superball runs
//! stopped at 0.61, [T000 §4.5]). This scheme removes the same overlaps collectively: it minimises
//! U = sum_pairs delta^2 / 2 over all translations and rotations with FIRE (Bitzek, Koskinen,
//! Gaehler, Moseler, Gumbsch, PRL 97, 170201, 2006), whose iteration count grows like the
//! square root of the stiffness ratio instead of linearly. The compression driver, the
//! tolerance, revert and halving are unchanged; one FIRE iteration counts as N attempts.
//!
//! Forces: the contact (i, j) with overlap delta and unit normal n (from i towards j) pushes i
//! with -delta n at the middle of the overlap lens, r_c,i - delta/2 n (for rods
//! s u_i + (R_i - delta/2) n), and j with +delta n at r_c,j + delta/2 n. A wall contact
//! (virtual particle or deepest point) pushes i alone. Masses are the reduced volumes;
//! rotations use the largest principal moment (isotropic rotor), which changes the path of the
//! minimiser but not its minima. Parameters are Bitzek et al.'s (N_min 5, f_inc 1.1,
//! f_dec 0.5, alpha_0 0.1, f_alpha 0.99) with dt_0 = 0.1, dt_max = 1 (reduced units: D = 1,
//! unit stiffness, density 1), dt_max capped at the stability bound of the lightest body
//! ([`FireParams::for_state`]: 0.32 for unit spheres).
//!
//! **External forces.** With user force kernels ([`remove_overlaps_fire_with`], units and
//! scaling in [`super::external`]) FIRE minimises the overlap energy plus the kernels'
//! potential: their reduced forces and torques are added to the contact forces at every
//! iteration, and the minimisation ends when no overlap exceeds the tolerance *and* the
//! largest residual force is below 1 % of the largest external force at the start (the
//! particles have settled in the potential), or at the iteration budget, where it succeeds if
//! no overlap exceeds the tolerance (a potential without a minimum, like gravity in a periodic
//! box, never settles and uses the whole budget). The stagnation test watches the overlap
//! energy alone and fails only while an overlap exceeds the tolerance. FIRE itself needs no
//! energy, only forces (the power F·v).

use glam::{DQuat, DVec3};

use super::contact::pair_contact_if_close;
use super::external::PackingKernels;
use super::neighbour::NeighbourList;
use super::removal::{RemovalOutcome, turn_bound};
use super::sphere_pairs::{sphere_pair_forces, sphere_radii};
use super::state::{BodyKind, PackingState};
use super::walls::{WallKind, WallPlane, planes};

/// Iterations over which a stagnating energy ends the minimisation as failed.
pub const STAGNATION_WINDOW: u64 = 2000;

/// FIRE parameters (reduced units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FireParams {
    /// Initial time step.
    pub dt: f64,
    /// Largest time step.
    pub dt_max: f64,
}

/// Contacts per body assumed by the stability bound of [`FireParams::for_state`].
pub const STABLE_CONTACTS: f64 = 10.0;

impl FireParams {
    /// The defaults with `dt_max` capped at the (translational) stability bound of the explicit
    /// step for the lightest body of `state`: a body of mass m with z unit-stiffness contacts has
    /// omega_max^2 <= 2 z / m (Gershgorin on the overlap Hessian), and the semi-implicit Euler
    /// step is stable for dt < 2 / omega_max = 2 sqrt(m / (2 z)). With z =
    /// [`STABLE_CONTACTS`] this is 0.32 for unit spheres (m = pi / 6): above it FIRE
    /// oscillates, trips P < 0, halves dt and spends its iterations growing dt back (with
    /// dt_max = 1, 500 spheres took 7x more iterations to jamming). Bodies of mass
    /// m >= 5 (rods of aspect ratio above ~6.7) keep dt_max = 1.
    pub fn for_state(state: &PackingState) -> Self {
        let d = Self::default();
        let m_min = state
            .bodies
            .iter()
            .map(|b| b.volume)
            .fold(f64::INFINITY, f64::min);
        let bound = 2.0 * (m_min / (2.0 * STABLE_CONTACTS)).sqrt();
        if !(bound.is_finite() && bound > 0.0) {
            return d;
        }
        let dt_max = d.dt_max.min(bound);
        Self {
            dt: d.dt.min(dt_max),
            dt_max,
        }
    }
}

impl Default for FireParams {
    fn default() -> Self {
        Self {
            dt: 0.1,
            dt_max: 1.0,
        }
    }
}

/// Forces and torques of the overlap energy (pairs and walls); returns (max overlap, energy,
/// contact-solver fallbacks). Sphere-only packings take the kernel of [`super::sphere_pairs`]
/// (same forces bit for bit; sphere torques exactly zero).
pub fn overlap_forces(
    state: &PackingState,
    list: &mut NeighbourList,
    force: &mut [DVec3],
    torque: &mut [DVec3],
) -> (f64, f64, u64) {
    let radii = sphere_radii(state);
    overlap_forces_with(
        state,
        list,
        radii.as_deref(),
        true,
        &mut Vec::new(),
        force,
        torque,
    )
}

/// [`overlap_forces`] by the generic contact route for every body (the reference of the
/// sphere kernel).
pub fn overlap_forces_generic(
    state: &PackingState,
    list: &mut NeighbourList,
    force: &mut [DVec3],
    torque: &mut [DVec3],
) -> (f64, f64, u64) {
    overlap_forces_with(state, list, None, true, &mut Vec::new(), force, torque)
}

/// [`overlap_forces`] with the sphere radii known (`Some` only when every body is a sphere);
/// the sphere kernel sums the pairs' energy only `with_energy`.
fn overlap_forces_with(
    state: &PackingState,
    list: &mut NeighbourList,
    sphere_radii: Option<&[f64]>,
    with_energy: bool,
    axes: &mut Vec<DVec3>,
    force: &mut [DVec3],
    torque: &mut [DVec3],
) -> (f64, f64, u64) {
    force.iter_mut().for_each(|f| *f = DVec3::ZERO);
    torque.iter_mut().for_each(|t| *t = DVec3::ZERO);
    let mut max_overlap: f64 = 0.0;
    let mut energy = 0.0;
    let mut fallbacks = 0;
    if let Some(radii) = sphere_radii {
        (max_overlap, energy) = sphere_pair_forces(state, radii, list.unique(), force, with_energy);
    } else {
        // rods only: each axis rotated once per evaluation instead of twice per pair (the
        // same values, so the same contacts bit for bit as `contact_warm`)
        let rods = state.bodies.iter().all(|b| matches!(b.kind, BodyKind::Rod));
        axes.clear();
        if rods {
            axes.extend((0..state.len()).map(|i| state.axis(i)));
        }
        for idx in 0..list.unique().len() {
            let p = list.unique()[idx];
            let (i, j, k) = (p.i as usize, p.j as usize, p.k as usize);
            let shift = list.entry(k).shift(state.edges);
            let c = if rods {
                let (bi, bj) = (&state.bodies[i], &state.bodies[j]);
                match pair_contact_if_close(
                    axes[i],
                    bi.half_length,
                    bi.radius,
                    state.positions[j] + shift - state.positions[i],
                    axes[j],
                    bj.half_length,
                    bj.radius,
                ) {
                    Some(c) => c,
                    None => continue, // no overlap (and rods never fall back)
                }
            } else {
                state.contact_warm(i, j, shift, list.warm_mut(k))
            };
            fallbacks += c.fallback as u64;
            if c.overlap <= 0.0 {
                continue;
            }
            max_overlap = max_overlap.max(c.overlap);
            energy += 0.5 * c.overlap * c.overlap;
            let f = c.overlap * c.normal;
            force[i] -= f;
            force[j] += f;
            let ri = c.rc_i - 0.5 * c.overlap * c.normal;
            let rj = c.rc_j + 0.5 * c.overlap * c.normal;
            torque[i] += ri.cross(-f);
            torque[j] += rj.cross(f);
        }
    }
    if state.walls == WallKind::Periodic {
        return (max_overlap, energy, fallbacks);
    }
    let mut walls = Vec::new();
    let flat = planes(state.walls, state.edges);
    for i in 0..state.len() {
        if far_from_flat_walls(state, &flat, i) {
            continue; // no virtual rod, so no wall contact
        }
        walls.clear();
        state.wall_contacts(i, 0.0, &mut walls);
        for c in walls.iter().filter(|c| c.overlap > 0.0) {
            max_overlap = max_overlap.max(c.overlap);
            energy += 0.5 * c.overlap * c.overlap;
            let f = c.overlap * c.normal;
            force[i] -= f;
            torque[i] += (c.rc_i - 0.5 * c.overlap * c.normal).cross(-f);
        }
    }
    (max_overlap, energy, fallbacks)
}

/// Whether rod or sphere `i` of a flat-walled container is farther than its radius (plus a
/// round-off margin) from every wall at both end points, i.e. has no virtual rod (`flat` are
/// the container's [`planes`]; empty for the cylinder, which is never skipped).
fn far_from_flat_walls(state: &PackingState, flat: &[WallPlane], i: usize) -> bool {
    let b = &state.bodies[i];
    if flat.is_empty() || !matches!(b.kind, BodyKind::Rod) {
        return false;
    }
    // an end point x +- h u is at least d(x) - h from a plane; lengths are / D <= 1000
    let x = state.positions[i];
    flat.iter()
        .all(|p| p.distance(x) - b.half_length > b.radius + 1e-9)
}

/// Largest residual force or (projected) torque.
fn residual(f: &[DVec3], t: &[DVec3]) -> f64 {
    f.iter()
        .zip(t)
        .map(|(f, t)| f.length().max(t.length()))
        .fold(0.0, f64::max)
}

/// Minimise the overlap energy until no overlap exceeds `tol`, with at most `max_iterations`
/// FIRE iterations. `attempts` of the outcome = iterations x N.
pub fn remove_overlaps_fire(
    state: &mut PackingState,
    list: &mut NeighbourList,
    params: FireParams,
    tol: f64,
    max_iterations: u64,
) -> RemovalOutcome {
    remove_overlaps_fire_with(state, list, params, tol, max_iterations, None)
}

/// [`remove_overlaps_fire`] with external force kernels (see the module documentation).
pub fn remove_overlaps_fire_with(
    state: &mut PackingState,
    list: &mut NeighbourList,
    params: FireParams,
    tol: f64,
    max_iterations: u64,
    kernels: Option<&PackingKernels>,
) -> RemovalOutcome {
    let n = state.len();
    let (kernel_scale, ext_max) = kernels.map_or((0.0, 0.0), |k| k.scale(state, tol));
    let kernels = kernels.filter(|_| kernel_scale > 0.0);
    let mut scratch = Vec::new();
    let mut axes = Vec::new();
    let mut f = vec![DVec3::ZERO; n];
    let mut t = vec![DVec3::ZERO; n];
    let mut v = vec![DVec3::ZERO; n];
    let mut w = vec![DVec3::ZERO; n];
    let mass: Vec<f64> = state.bodies.iter().map(|b| b.volume).collect();
    let inv_mass: Vec<f64> = mass.iter().map(|m| 1.0 / m).collect();
    let rot_inertia: Vec<f64> = state
        .bodies
        .iter()
        .map(|b| b.inertia.max_element())
        .collect();
    let rotates: Vec<bool> = state.bodies.iter().map(|b| b.rotates()).collect();
    let any_rotates = rotates.iter().any(|r| *r);
    let radii = sphere_radii(state);
    let axisymmetric: Vec<bool> = state
        .bodies
        .iter()
        .map(|b| matches!(b.kind, BodyKind::Rod))
        .collect();
    let (mut contacts, mut fallbacks) = (0u64, 0u64);
    let pairs_per_eval = |list: &NeighbourList| list.len() as u64 / 2;
    let (mut dt, mut alpha, mut since_negative) = (params.dt, 0.1, 0u64);
    let mut it = 0;
    let mut window_energy = f64::INFINITY;
    loop {
        list.ensure(state);
        let (max_overlap, energy, fb) = overlap_forces_with(
            state,
            list,
            radii.as_deref(),
            it % STAGNATION_WINDOW == 0,
            &mut axes,
            &mut f,
            &mut t,
        );
        if let Some(k) = kernels {
            k.add_reduced(state, kernel_scale, &mut scratch, &mut f, &mut t);
        }
        contacts += pairs_per_eval(list);
        fallbacks += fb;
        // (translations only: nothing reads t unless kernels wrote it)
        if any_rotates || kernels.is_some() {
            for i in 0..n {
                if !rotates[i] {
                    t[i] = DVec3::ZERO;
                } else if axisymmetric[i] {
                    let a = state.axis(i);
                    let along = t[i].dot(a);
                    t[i] -= along * a; // spin about the axis moves nothing
                }
            }
        }
        let outcome = |success: bool, it: u64| RemovalOutcome {
            success,
            attempts: it * n as u64,
            sweeps: it,
            contacts,
            fallbacks,
        };
        let settled = kernels.is_none() || residual(&f, &t) <= 0.01 * ext_max;
        if max_overlap <= tol && settled {
            return outcome(true, it);
        }
        // A jammed configuration relaxes to a minimum with finite energy: when the energy has
        // fallen by less than 2 % over the last STAGNATION_WINDOW iterations, give up early.
        if it % STAGNATION_WINDOW == 0 {
            if it > 0 && energy > 0.98 * window_energy && max_overlap > tol {
                return outcome(false, it);
            }
            window_energy = energy;
        }
        if it >= max_iterations {
            return outcome(kernels.is_some() && max_overlap <= tol, it);
        }
        it += 1;
        // FIRE mixing on the global (translation + rotation) velocity vector
        // (without rotating bodies t = w = 0, and adding their +0 terms changes no bit)
        let (mut p, mut vv, mut ff) = (0.0, 0.0, 0.0);
        if any_rotates {
            for i in 0..n {
                p += f[i].dot(v[i]) + t[i].dot(w[i]);
                vv += v[i].length_squared() + w[i].length_squared();
                ff += f[i].length_squared() + t[i].length_squared();
            }
        } else {
            for i in 0..n {
                p += f[i].dot(v[i]);
                vv += v[i].length_squared();
                ff += f[i].length_squared();
            }
        }
        // the mixing v <- (1 - alpha) v + scale F (None: P <= 0, stop), with the alpha and
        // dt before their update; the Euler step below takes the updated dt
        let mix = if p > 0.0 {
            let scale = if ff > 0.0 {
                alpha * (vv / ff).sqrt()
            } else {
                0.0
            };
            let keep = 1.0 - alpha;
            since_negative += 1;
            if since_negative > 5 {
                dt = (dt * 1.1).min(params.dt_max);
                alpha *= 0.99;
            }
            Some((keep, scale))
        } else {
            dt *= 0.5;
            alpha = 0.1;
            since_negative = 0;
            None
        };
        if !any_rotates {
            // translations only: mixing, Euler step and move in one pass; the list checks the
            // net displacements once per iteration
            for i in 0..n {
                let vi = match mix {
                    Some((keep, scale)) => keep * v[i] + scale * f[i],
                    None => DVec3::ZERO,
                };
                let vi = vi + f[i] * (dt * inv_mass[i]);
                v[i] = vi;
                state.positions[i] += dt * vi;
            }
            list.note_displacements(&state.positions);
            continue;
        }
        match mix {
            Some((keep, scale)) => {
                for i in 0..n {
                    v[i] = keep * v[i] + scale * f[i];
                    if rotates[i] {
                        w[i] = keep * w[i] + scale * t[i];
                    }
                }
            }
            None => {
                v.iter_mut().for_each(|x| *x = DVec3::ZERO);
                w.iter_mut().for_each(|x| *x = DVec3::ZERO);
            }
        }
        for i in 0..n {
            v[i] += dt * f[i] / mass[i];
            let dx = dt * v[i];
            state.positions[i] += dx;
            if !rotates[i] {
                // t = w = 0 (zeroed above): no turn
                list.note_move(i, dx, 0.0);
                continue;
            }
            w[i] += dt * t[i] / rot_inertia[i];
            let angle = w[i].length() * dt;
            let mut turn = 0.0;
            if angle > 0.0 {
                let r = DQuat::from_axis_angle(w[i] / w[i].length(), angle);
                state.orientations[i] = (r * state.orientations[i]).normalize();
                turn = turn_bound(&state.bodies[i], r);
            }
            list.note_move(i, dx, turn);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::packing::state::Body;
    use magsep_components::shape::Shape;

    fn state_of(shape: Shape) -> PackingState {
        let mut state = PackingState::periodic_cube(10.0);
        state.bodies.push(Body::from_shape(&shape, 1.0));
        state.positions.push(DVec3::ONE);
        state.orientations.push(DQuat::IDENTITY);
        state
    }

    /// The reference of the rod fast path: every listed pair by `PackingState::contact`
    /// (axes rotated per pair, the full contact frame) and every body's wall contacts.
    fn reference_forces(
        state: &PackingState,
        list: &NeighbourList,
    ) -> (Vec<DVec3>, Vec<DVec3>, f64, f64) {
        let n = state.len();
        let (mut f, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let (mut max_overlap, mut energy): (f64, f64) = (0.0, 0.0);
        let mut add = |i: usize, j: Option<usize>, c: crate::packing::contact::PairContact| {
            if c.overlap <= 0.0 {
                return;
            }
            max_overlap = max_overlap.max(c.overlap);
            energy += 0.5 * c.overlap * c.overlap;
            let fc = c.overlap * c.normal;
            f[i] -= fc;
            t[i] += (c.rc_i - 0.5 * c.overlap * c.normal).cross(-fc);
            if let Some(j) = j {
                f[j] += fc;
                t[j] += (c.rc_j + 0.5 * c.overlap * c.normal).cross(fc);
            }
        };
        for p in list.unique() {
            let (i, j) = (p.i as usize, p.j as usize);
            let shift = list.entry(p.k as usize).shift(state.edges);
            add(i, Some(j), state.contact(i, j, shift));
        }
        let mut walls = Vec::new();
        for i in 0..n {
            walls.clear();
            state.wall_contacts(i, 0.0, &mut walls);
            for c in walls.iter() {
                add(i, None, *c);
            }
        }
        (f, t, max_overlap, energy)
    }

    #[test]
    fn rod_forces_in_a_wedge_equal_the_per_pair_reference_bit_for_bit() {
        use crate::packing::walls::wedge_edges;
        use rand::{RngExt, SeedableRng};
        let alpha = 0.5;
        let mut state = PackingState::periodic_cube(1.0);
        state.walls = WallKind::Wedge { alpha };
        state.edges = wedge_edges(alpha, 12.0, 6.0);
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let rod = Shape::Spherocylinder {
            radius: 0.5,
            half_length: 1.0,
        };
        while state.len() < 60 {
            let x = DVec3::new(
                rng.random_range(0.0..12.0),
                rng.random_range(0.0..6.0),
                rng.random_range(0.0..6.0),
            );
            if x.y > x.x * alpha.tan() + 0.3 {
                continue; // outside the slope (a little overlap with it is kept)
            }
            let axis = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if axis.length() < 0.1 {
                continue;
            }
            state.bodies.push(Body::from_shape(&rod, 1.0));
            state.positions.push(x);
            state
                .orientations
                .push(DQuat::from_rotation_arc(DVec3::Z, axis.normalize()));
        }
        let mut list = NeighbourList::new(0.1);
        list.build(&mut state);
        let (want_f, want_t, want_max, want_e) = reference_forces(&state, &list);
        assert!(want_max > 0.0 && want_e > 0.0, "the test needs overlaps");
        let (mut f, mut t) = (vec![DVec3::ZERO; 60], vec![DVec3::ZERO; 60]);
        let (max_overlap, energy, fb) = overlap_forces(&state, &mut list, &mut f, &mut t);
        assert_eq!((max_overlap, energy, fb), (want_max, want_e, 0));
        assert_eq!((f, t), (want_f, want_t));
    }

    #[test]
    fn the_largest_step_is_the_stability_bound_of_the_lightest_body() {
        // unit spheres: 2 sqrt(m / 20) with m = pi / 6
        let p = FireParams::for_state(&state_of(Shape::Sphere { radius: 0.5 }));
        let want = 2.0 * (std::f64::consts::PI / 6.0 / 20.0).sqrt();
        assert!((p.dt_max - want).abs() < 1e-15 && (0.3..0.33).contains(&p.dt_max));
        assert_eq!(p.dt, 0.1);
        // heavy rods keep the defaults; an empty state too
        let rod = Shape::Spherocylinder {
            radius: 0.5,
            half_length: 5.0,
        };
        assert_eq!(FireParams::for_state(&state_of(rod)), FireParams::default());
        let empty = PackingState::periodic_cube(1.0);
        assert_eq!(FireParams::for_state(&empty), FireParams::default());
    }
}
