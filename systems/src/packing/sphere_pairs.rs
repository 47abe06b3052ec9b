//! Hot kernel: the pair forces of the overlap energy for packings of spheres only.
//!
//! What it does: for every listed pair (i, j, image) of spheres it forms the centre line
//! r = (x_j + shift) - x_i, the distance d = |r| and the overlap delta = (R_i + R_j) - d, and
//! for delta > 0 adds -delta n to i and +delta n to j (n = r / d), summing the energy
//! delta^2 / 2 and tracking the largest overlap.
//!
//! Why it exists: FIRE spends nearly all of a sphere packing's time here. `spheres_500`
//! evaluates ~2200 listed pairs in each of ~1e5 FIRE iterations (~2.3e8 pair evaluations per
//! run; ~8e5 iterations before FIRE's largest step was capped at the stability bound). The generic route (`PackingState::contact_warm` -> `body_contact` -> `pair_contact`)
//! rotates both body axes, branches on the body kinds and fills a whole `PairContact` per
//! pair, and the pairs used to be filtered out of the symmetric CSR list and collected into a
//! fresh `Vec` on every evaluation. Here the pairs come from the list's flat pair slice
//! (`NeighbourList::unique`, built once per list build) and the radii from a flat array.
//!
//! Branch-free: every listed pair takes the square root and one division,
//! f = ((R_i + R_j - d) / d) r, masked to zero for pairs apart. Near jamming about a third
//! of the listed pairs do not overlap and a branch on it mispredicts often; the divider, not
//! the arithmetic, bounds the loop (one square root and one division per pair instead of a
//! square root and three divisions for n = r / d).
//!
//! Same forces as the generic route up to rounding (a few ulp: (delta / d) r instead of
//! delta (r / d)), checked against it in the tests; energy and the largest overlap are the
//! same expressions. Torques are not formed: for two spheres the lever arm is parallel to
//! the force, the generic route's torque is rounding noise, and FIRE discards torques of
//! bodies that do not rotate.

use glam::DVec3;

use super::contact::pair_contact;
use super::neighbour::PairEntry;
use super::state::{BodyKind, PackingState};

/// The radii of `state`'s bodies when every body is a sphere (a rod of zero length), else
/// None (then the generic contact route applies).
pub fn sphere_radii(state: &PackingState) -> Option<Vec<f64>> {
    state
        .bodies
        .iter()
        .map(|b| (matches!(b.kind, BodyKind::Rod) && b.half_length == 0.0).then_some(b.radius))
        .collect()
}

/// Add the overlap forces of the sphere `pairs` (radii `radii`, see [`sphere_radii`]) to
/// `force`; returns (largest overlap, energy) of the pairs, the energy only `with_energy`
/// (else 0: FIRE reads it once per stagnation window).
///
/// The pairs come sorted by i, so i's force is summed in a register over its run of pairs and
/// stored once (the same additions in the same order as `force[i] -= f` pair by pair, without
/// a store-to-load round trip per pair). Pairs apart add exact zeros.
pub fn sphere_pair_forces(
    state: &PackingState,
    radii: &[f64],
    pairs: &[PairEntry],
    force: &mut [DVec3],
    with_energy: bool,
) -> (f64, f64) {
    if with_energy {
        pair_forces::<true>(state, radii, pairs, force)
    } else {
        pair_forces::<false>(state, radii, pairs, force)
    }
}

#[inline(always)]
fn pair_forces<const ENERGY: bool>(
    state: &PackingState,
    radii: &[f64],
    pairs: &[PairEntry],
    force: &mut [DVec3],
) -> (f64, f64) {
    let (x, edges) = (&state.positions[..], state.edges);
    let mut max_overlap: f64 = 0.0;
    let mut energy = 0.0;
    let mut current = usize::MAX;
    let mut fi = DVec3::ZERO;
    for p in pairs {
        let (i, j) = (p.i as usize, p.j as usize);
        if i != current {
            if current != usize::MAX {
                force[current] = fi;
            }
            current = i;
            fi = force[i];
        }
        let r = x[j] + p.shift(edges) - x[i];
        let d2 = r.length_squared();
        let (o, f) = if d2 > COINCIDENT {
            // a pair apart gets o = 0 by a max, not a branch (max(NaN, 0) = 0, but then
            // s = 0 / NaN = NaN: a NaN position still poisons the force)
            let d = d2.sqrt();
            let o = (radii[i] + radii[j] - d).max(0.0);
            (o, (o / d) * r) // = overlap * n with n = r / d
        } else {
            coincident(state, radii, i, j, r)
        };
        max_overlap = max_overlap.max(o);
        if ENERGY {
            energy += 0.5 * o * o;
        }
        fi -= f;
        if j == i {
            fi += f; // a particle and its own image
        } else {
            force[j] += f;
        }
    }
    if current != usize::MAX {
        force[current] = fi;
    }
    (max_overlap, energy)
}

/// Squared centre distance / D^2 at or below which two centres count as coincident (then the
/// generic route decides the normal).
const COINCIDENT: f64 = 1e-200;

/// Overlap and force on j of a pair with coincident centres (the generic route's normal).
#[cold]
fn coincident(state: &PackingState, radii: &[f64], i: usize, j: usize, r: DVec3) -> (f64, DVec3) {
    let c = pair_contact(
        state.axis(i),
        0.0,
        radii[i],
        r,
        state.axis(j),
        0.0,
        radii[j],
    );
    if c.overlap <= 0.0 {
        return (0.0, DVec3::ZERO);
    }
    (c.overlap, c.overlap * c.normal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::packing::fire::overlap_forces_generic;
    use crate::packing::insert::random_insertion;
    use crate::packing::neighbour::NeighbourList;
    use crate::packing::state::Body;
    use crate::rng::particle_stream;
    use magsep_components::shape::Shape;

    #[test]
    fn sphere_kernel_equals_generic_route_to_rounding() {
        let n = 300;
        // polydisperse spheres, compressed so that many pairs overlap
        let bodies: Vec<Body> = (0..n)
            .map(|i| {
                let radius = 0.5 + 0.1 * (i % 3) as f64;
                Body::from_shape(&Shape::Sphere { radius }, 1.0)
            })
            .collect();
        let v: f64 = bodies.iter().map(|b| b.volume).sum();
        let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(7, i)).collect();
        let mut state = random_insertion(
            &bodies,
            PackingState::periodic_cube((v / 0.3).cbrt()),
            &mut rngs,
        )
        .unwrap();
        state.scale(DVec3::splat(0.8));
        let mut list = NeighbourList::new(0.1);
        list.build(&mut state);
        let radii = sphere_radii(&state).unwrap();
        let mut f = vec![DVec3::ZERO; n];
        let (max, energy) = sphere_pair_forces(&state, &radii, list.unique(), &mut f, true);
        let (mut g, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let (max_g, energy_g, fallbacks) =
            overlap_forces_generic(&state, &mut list, &mut g, &mut t);
        assert!(max > 0.05 && energy > 0.0);
        // the overlap and energy are the same expressions; the force is (delta / d) r
        // instead of delta (r / d): a few ulp of the largest force per particle
        assert_eq!(
            (max.to_bits(), energy.to_bits(), fallbacks),
            (max_g.to_bits(), energy_g.to_bits(), 0)
        );
        let scale = g.iter().map(|v| v.abs().max_element()).fold(0.0, f64::max);
        assert!(scale > 0.05);
        for (a, b) in f.iter().zip(&g) {
            assert!((*a - *b).abs().max_element() <= 1e-14 * scale, "{a} vs {b}");
        }
    }

    #[test]
    fn rods_are_not_spheres() {
        let rod = Body::from_shape(
            &Shape::Spherocylinder {
                radius: 0.5,
                half_length: 1.0,
            },
            1.0,
        );
        let mut state = PackingState::periodic_cube(10.0);
        state.bodies.push(rod);
        state.positions.push(DVec3::ONE);
        state.orientations.push(glam::DQuat::IDENTITY);
        assert!(sphere_radii(&state).is_none());
    }
}
