//! The per-particle component passes of the brownian systems: the workspace keeps the particles
//! in `ParticleId` order, the components live in bevy's tables, and these helpers move values
//! between the two in one linear pass, with lookups by entity for the particles the query does
//! not yield in workspace order.
//!
//! The passes run on the system's thread. They move a few bytes per particle; splitting them
//! among threads (bevy batches on its compute pool) cost more in wake-ups than it saved: the
//! 2-thread rate of the LAMMPS-mirror Brownian bench rose from 2.33 M to 2.74 M
//! particle-steps/s (mean of four interleaved rounds) when they went back to one thread. The
//! exception is the write-back of the fixed step ([`write_back_in_parts`]): it runs in the
//! step's parts, each thread copying the particles it updated, so that their data stays in its
//! cache.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;

use super::parts::{run_parts, split_at_bounds};
use super::systems::BrownianWorkspace;

/// The particles' positions and capture flags (those with a random stream, like the
/// workspace's).
pub type PositionRows<'w, 's> = Query<
    'w,
    's,
    (Entity, &'static mut Position, Option<&'static mut Captured>),
    With<ParticleRng>,
>;
/// The particles' random streams.
pub type StreamRows<'w, 's> = Query<'w, 's, (Entity, &'static mut ParticleRng), With<Position>>;

/// The write-back of positions, capture flags and random streams in the parts of the step
/// (`bounds`, see [`super::parts`]) when the particles fill one table in workspace order (the
/// usual case: the components are then contiguous slices, split like the workspace): each
/// thread copies the particles it updated, so their lines stay in its cache. Every component
/// is marked changed, as a write through `Mut` does. Returns false, having written nothing,
/// when the layout is another.
pub fn write_back_in_parts(
    ws: &BrownianWorkspace,
    bounds: &[usize],
    q: &mut PositionRows,
    streams: &mut StreamRows,
) -> bool {
    let n = ws.entities.len();
    if n != ws.positions.len() || n != ws.captured.len() || n != ws.rngs.len() {
        return false;
    }
    let (Ok(mut rows), Ok(mut rng_rows)) = (q.contiguous_iter_mut(), streams.contiguous_iter_mut())
    else {
        return false;
    };
    let (Some((es, mut pos, cap)), Some((es2, mut rng))) = (rows.next(), rng_rows.next()) else {
        return false;
    };
    if rows.next().is_some()
        || rng_rows.next().is_some()
        || es != ws.entities.as_slice()
        || es2 != es
    {
        return false;
    }
    pos.mark_all_as_changed();
    rng.mark_all_as_changed();
    let mut cap = cap;
    let cap: &mut [Captured] = match cap.as_mut() {
        Some(c) => {
            c.mark_all_as_changed();
            c.bypass_change_detection()
        }
        None => &mut [],
    };
    // no capture flags (no `Captured` in the table): empty parts (`split_at_bounds` clamps)
    let items: Vec<_> = split_at_bounds(pos.bypass_change_detection(), bounds)
        .into_iter()
        .zip(split_at_bounds(rng.bypass_change_detection(), bounds))
        .zip(split_at_bounds(cap, bounds))
        .collect();
    let (x, captured, rngs) = (
        ws.positions.as_slice(),
        ws.captured.as_slice(),
        ws.rngs.as_slice(),
    );
    run_parts(items, move |p, ((ps, rs), cs)| {
        let a = bounds[p];
        for (k, (pk, rk)) in ps.iter_mut().zip(rs.iter_mut()).enumerate() {
            pk.0 = x[a + k];
            rk.0.clone_from(&rngs[a + k]);
        }
        for (k, ck) in cs.iter_mut().enumerate() {
            ck.0 = captured[a + k];
        }
    });
    true
}

/// Call `f(k, item)` while the query's items come in the order of `entities` (the usual case:
/// particles spawned in `ParticleId` order share one table); returns how many matched, so the
/// caller looks the rest up by entity.
pub fn in_workspace_order<T>(
    entities: &[Entity],
    items: impl Iterator<Item = (Entity, T)>,
    mut f: impl FnMut(usize, T),
) -> usize {
    let mut k = 0;
    for (e, item) in items {
        if entities.get(k) != Some(&e) {
            break;
        }
        f(k, item);
        k += 1;
    }
    k
}

/// `set(component, values[k])` for the k-th of `entities`: one linear pass over the query
/// while it yields the workspace's entities in order, lookups by entity for the rest.
pub fn write_dense<T: Component<Mutability = bevy_ecs::component::Mutable>>(
    entities: &[Entity],
    values: &[DVec3],
    q: &mut Query<(Entity, &mut T)>,
    set: impl Fn(&mut T, DVec3),
) {
    let n = entities.len().min(values.len());
    let k = in_workspace_order(&entities[..n], q.iter_mut(), |k, mut c| {
        set(&mut c, values[k])
    });
    for (e, v) in entities[k..n].iter().zip(&values[k..n]) {
        if let Ok((_, mut c)) = q.get_mut(*e) {
            set(&mut c, *v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Component, Default)]
    struct F(DVec3);

    /// Each workspace entity gets its own value, entities out of workspace order and outside
    /// the workspace included.
    #[test]
    fn the_pass_writes_each_entity_its_value() {
        let mut world = World::new();
        let all: Vec<Entity> = (0..3000).map(|_| world.spawn(F::default()).id()).collect();
        let values_of = |entities: &[Entity]| -> Vec<DVec3> {
            (0..entities.len())
                .map(|k| DVec3::new(k as f64 + 1.0, 0.5 * k as f64, -1.0))
                .collect()
        };
        // in table order (the linear pass), then every third entity in reverse (lookups)
        let in_order: Vec<Entity> = all[..1000].to_vec();
        let reversed: Vec<Entity> = all.iter().rev().step_by(3).copied().collect();
        for entities in [in_order, reversed] {
            let values = values_of(&entities);
            let mut system =
                bevy_ecs::system::SystemState::<Query<(Entity, &mut F)>>::new(&mut world);
            let mut q = system.get_mut(&mut world).unwrap();
            write_dense(&entities, &values, &mut q, |c: &mut F, v| c.0 = v);
            for (e, v) in entities.iter().zip(&values) {
                assert_eq!(world.get::<F>(*e).unwrap().0, *v);
            }
        }
        // entity 1 is only in the first list: its value stays
        assert_eq!(
            world.get::<F>(all[1]).unwrap().0,
            DVec3::new(2.0, 0.5, -1.0)
        );
        // an entity in neither list keeps its default
        let outside = all[1000..]
            .iter()
            .rev()
            .skip(1)
            .step_by(3)
            .next()
            .copied()
            .unwrap();
        assert_eq!(world.get::<F>(outside).unwrap().0, DVec3::ZERO);
    }
}
