//! A fibre column packed by mechanical contraction to a chosen packing fraction: `n` rigid
//! spherocylinders in a hard cylinder (periodic along its axis z, compressed along z only), as a
//! magnetic filter is made by pressing fibres into a tube.
//!
//! The compression is the MCM driver of [`super::compress`] on the dense kernels, run until the
//! packing fraction reaches the target or the packing jams, whichever comes first. A target below
//! jamming gives a random, overlap-free packing at that density (not mechanically stable: a
//! filter held by its tube); a target above it gives the jammed packing and says so. SI units in
//! and out; the kernels work in reduced units (D = 2R = 1).

use glam::{DQuat, DVec3};
use magsep_components::container::{Container, Walls};
use magsep_components::packing::PackingConfig;
use magsep_components::shape::Shape;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::compress::{DriverParams, compression_step_to, initial_status};
use super::insert::random_insertion;
use super::neighbour::NeighbourList;
use super::state::Body;
use super::systems::{MCM_SKIN, state_from_si};
use crate::rng::{DRIVER_STREAM, particle_stream};

/// What to pack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodColumn {
    /// Number of fibres.
    pub count: usize,
    /// Fibre radius R \[m\].
    pub radius: f64,
    /// Length of a fibre's cylindrical part L \[m\] (the caps add 2R).
    pub cylinder_length: f64,
    /// Radius of the column \[m\].
    pub column_radius: f64,
    /// Target packing fraction φ (fibre volume over column volume).
    pub packing_fraction: f64,
    /// Start packing fraction φ₀ of the random insertion (< target).
    pub initial_packing_fraction: f64,
    /// Seed of the insertion and the driver.
    pub seed: u64,
}

/// A packed column.
#[derive(Debug, Clone, PartialEq)]
pub struct PackedColumn {
    /// Fibre centres \[m\] in the column's box: x, y in [0, 2 R_col], z in [0, height).
    pub centres: Vec<DVec3>,
    /// Unit axes of the fibres.
    pub axes: Vec<DVec3>,
    /// Height of the column's periodic cell \[m\].
    pub height: f64,
    /// Packing fraction reached.
    pub packing_fraction: f64,
    /// The compression stopped (jammed, or at the step limit) before reaching the target.
    pub jammed: bool,
    /// Accepted compression steps.
    pub steps: u64,
}

/// Pack `spec` with the MCM settings `config` (its reference diameter must be 2R; see
/// [`PackingConfig::defaults_for`]). Errors (as text) when the rods do not fit.
///
/// ```
/// use magsep_components::packing::PackingConfig;
/// use magsep_systems::packing::column::{RodColumn, pack_rod_column};
/// let spec = RodColumn {
///     count: 12, radius: 25e-6, cylinder_length: 250e-6, column_radius: 200e-6,
///     packing_fraction: 0.1, initial_packing_fraction: 0.02, seed: 1,
/// };
/// let config = PackingConfig::defaults_for(12, 50e-6);
/// let c = pack_rod_column(&spec, &config).unwrap();
/// assert!((c.packing_fraction - 0.1).abs() < 1e-6 && !c.jammed);
/// ```
pub fn pack_rod_column(spec: &RodColumn, config: &PackingConfig) -> Result<PackedColumn, String> {
    let d = 2.0 * spec.radius;
    let shape = Shape::Spherocylinder {
        radius: 0.5,
        half_length: 0.5 * spec.cylinder_length / d,
    };
    let bodies: Vec<Body> = (0..spec.count)
        .map(|_| Body::from_shape(&shape, 1.0))
        .collect();
    let volume: f64 = bodies.iter().map(|b| b.volume).sum();
    let r_col = spec.column_radius / d;
    let height = volume / spec.initial_packing_fraction / (std::f64::consts::PI * r_col * r_col);
    let container = Container::Walled {
        walls: Walls::Cylinder,
        edges: DVec3::new(2.0 * r_col, 2.0 * r_col, height),
    };
    let empty = state_from_si(&container, &[], &[], &[], 1.0);
    let mut rngs: Vec<Xoshiro256PlusPlus> = (0..spec.count as u64)
        .map(|i| particle_stream(spec.seed, i))
        .collect();
    let mut state = random_insertion(&bodies, empty, &mut rngs).map_err(|e| e.to_string())?;
    let mut reduced = config.clone();
    reduced.initial_packing_fraction = spec.initial_packing_fraction;
    let p = DriverParams::from_config(&reduced, d);
    let mut list = NeighbourList::new(MCM_SKIN);
    let mut rng = particle_stream(spec.seed, DRIVER_STREAM);
    let mut st = initial_status(&p, &state);
    // the last step is cut to land on the target (to rounding)
    let reached = |phi: f64| phi >= spec.packing_fraction * (1.0 - 1e-9);
    while st.stopped.is_none() && !reached(st.packing_fraction) {
        let target = Some(spec.packing_fraction);
        compression_step_to(&p, &mut st, &mut state, &mut list, &mut rng, target);
    }
    state.wrap_all();
    let axes = state
        .orientations
        .iter()
        .map(|q: &DQuat| *q * DVec3::Z)
        .collect();
    Ok(PackedColumn {
        centres: state.positions.iter().map(|x| *x * d).collect(),
        axes,
        height: state.edges.z * d,
        packing_fraction: state.packing_fraction(),
        jammed: !reached(st.packing_fraction),
        steps: st.compression_steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(phi: f64, seed: u64) -> RodColumn {
        RodColumn {
            count: 30,
            radius: 25e-6,
            cylinder_length: 475e-6,
            column_radius: 300e-6,
            packing_fraction: phi,
            initial_packing_fraction: 0.01,
            seed,
        }
    }

    fn pack(s: &RodColumn) -> PackedColumn {
        pack_rod_column(s, &PackingConfig::defaults_for(s.count, 2.0 * s.radius)).unwrap()
    }

    #[test]
    fn reaches_the_target_inside_the_tube_without_overlaps() {
        let s = spec(0.12, 4);
        let c = pack(&s);
        assert!(!c.jammed);
        assert!(
            c.packing_fraction >= 0.12 && c.packing_fraction < 0.13,
            "{c:?}"
        );
        // the fibre volume over the tube's volume is the packing fraction reported
        let v_rod = std::f64::consts::PI * s.radius.powi(2) * s.cylinder_length
            + 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3);
        let tube = std::f64::consts::PI * s.column_radius.powi(2) * c.height;
        assert!((30.0 * v_rod / tube / c.packing_fraction - 1.0).abs() < 1e-9);
        for (x, a) in c.centres.iter().zip(&c.axes) {
            assert!((a.length() - 1.0).abs() < 1e-12);
            assert!(x.z >= 0.0 && x.z < c.height);
            // both cap centres inside the tube, one radius from the wall (up to the tolerance)
            for end in [-1.0, 1.0] {
                let p = *x + *a * (0.5 * s.cylinder_length * end);
                let rho =
                    ((p.x - s.column_radius).powi(2) + (p.y - s.column_radius).powi(2)).sqrt();
                assert!(rho <= s.column_radius - s.radius * (1.0 - 1e-3), "{rho}");
            }
        }
    }

    #[test]
    fn seeds_give_different_packings_and_the_same_seed_the_same() {
        let (a, b, c) = (
            pack(&spec(0.08, 1)),
            pack(&spec(0.08, 1)),
            pack(&spec(0.08, 2)),
        );
        assert_eq!(a, b);
        assert_ne!(a.centres, c.centres);
    }

    #[test]
    fn an_unreachable_target_stops_at_jamming_and_says_so() {
        let c = pack(&spec(0.95, 3));
        assert!(c.jammed);
        assert!(
            c.packing_fraction > 0.2 && c.packing_fraction < 0.95,
            "{}",
            c.packing_fraction
        );
    }
}
