//! Helpers shared by the integration tests.

use glam::DVec3;
use magsep::prelude::*;

/// Particle centres in `ParticleId` order [m].
pub fn sorted_positions(sim: &mut Simulation) -> Vec<DVec3> {
    let mut rows: Vec<(ParticleId, DVec3)> = sim
        .app
        .world
        .query::<(&ParticleId, &Position)>()
        .iter(&sim.app.world)
        .map(|(i, p)| (*i, p.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| r.1).collect()
}
