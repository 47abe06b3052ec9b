//! The per-particle component passes of the brownian systems: the workspace keeps the particles
//! in `ParticleId` order, the components live in bevy's tables, and these helpers move values
//! between the two, in one linear pass on one thread or split into one batch of the query per
//! thread of the current rayon pool ([`rayon_batching`]). Each entity finds its workspace
//! index through a table by entity index ([`slots_of`], [`slot_in`]); every write is that
//! entity's own, so both paths give bitwise the same components.

use bevy_ecs::prelude::*;
use glam::DVec3;

use crate::par::{PAR_MIN_ENTITIES, rayon_batching};

/// Workspace index of each entity of `entities`, by entity index (`u32::MAX`: none).
pub fn slots_of(entities: &[Entity]) -> Vec<u32> {
    let len = entities.iter().map(|e| e.index_u32() as usize + 1).max();
    let mut slots = vec![u32::MAX; len.unwrap_or(0)];
    for (k, e) in entities.iter().enumerate() {
        slots[e.index_u32() as usize] = k as u32;
    }
    slots
}

/// Index of `e` in `entities` through its `slots` ([`slots_of`]); None when it is not there.
#[inline]
pub fn slot_in(entities: &[Entity], slots: &[u32], e: Entity) -> Option<usize> {
    let k = *slots.get(e.index_u32() as usize)? as usize;
    (entities.get(k) == Some(&e)).then_some(k)
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

/// `set(component, values[k])` for the k-th of `entities` (with `slots`, [`slots_of`]): one
/// linear pass over the query while it yields the workspace's entities in order, lookups by
/// entity for the rest; on a rayon pool of several threads, one batch of the query per thread.
pub fn write_dense<T: Component<Mutability = bevy_ecs::component::Mutable>>(
    (entities, slots): (&[Entity], &[u32]),
    values: &[DVec3],
    q: &mut Query<(Entity, &mut T)>,
    set: impl Fn(&mut T, DVec3) + Send + Sync + Clone,
) {
    let n = entities.len().min(values.len());
    if let Some(b) = rayon_batching(n, PAR_MIN_ENTITIES) {
        q.par_iter_mut()
            .batching_strategy(b)
            .for_each(|(e, mut c)| {
                if let Some(k) = slot_in(entities, slots, e).filter(|&k| k < n) {
                    set(&mut c, values[k]);
                }
            });
        return;
    }
    let k = in_workspace_order(&entities[..n], q.iter_mut(), |k, mut c| {
        set(&mut c, values[k])
    });
    for (e, v) in entities[k..n].iter().zip(&values[k..n]) {
        if let Ok((_, mut c)) = q.get_mut(*e) {
            set(&mut c, *v);
        }
    }
}

/// A row `(workspace index, net force, force outside the model)` of the integrator's read.
pub type ForceSplit = (usize, DVec3, DVec3);

/// Rows gathered by one batch of a parallel query pass, handed to `into` when the batch ends.
pub struct Gathered<'a> {
    /// This batch's rows.
    pub rows: Vec<ForceSplit>,
    /// Where every batch's rows end up.
    pub into: &'a std::sync::Mutex<Vec<Vec<ForceSplit>>>,
}

impl Drop for Gathered<'_> {
    fn drop(&mut self) {
        if let Ok(mut all) = self.into.lock() {
            all.push(std::mem::take(&mut self.rows));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Component, Default)]
    struct F(DVec3);

    /// The batched pass writes what the linear pass writes, entities out of workspace order
    /// and outside the workspace included.
    #[test]
    fn the_batched_pass_writes_what_the_linear_pass_writes() {
        bevy_tasks::ComputeTaskPool::get_or_init(bevy_tasks::TaskPool::default);
        let run = |threads: usize| {
            let mut world = World::new();
            let all: Vec<Entity> = (0..3000).map(|_| world.spawn(F::default()).id()).collect();
            // the workspace: every third entity, in reverse
            let entities: Vec<Entity> = all.iter().rev().step_by(3).copied().collect();
            let slots = slots_of(&entities);
            let values: Vec<DVec3> = (0..entities.len())
                .map(|k| DVec3::new(k as f64, 0.5 * k as f64, -1.0))
                .collect();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut system =
                    bevy_ecs::system::SystemState::<Query<(Entity, &mut F)>>::new(&mut world);
                let mut q = system.get_mut(&mut world).unwrap();
                write_dense((&entities, &slots), &values, &mut q, |c: &mut F, v| c.0 = v);
            });
            let got: Vec<DVec3> = world.query::<&F>().iter(&world).map(|f| f.0).collect();
            (got, entities, values)
        };
        let (one, entities, values) = run(1);
        let (two, _, _) = run(2);
        assert_eq!(one, two);
        // the workspace's entities got their values, the others stayed zero
        let set = one.iter().filter(|v| **v != DVec3::ZERO).count();
        assert_eq!(set, entities.len());
        assert_eq!(one[2999], values[0]);
        assert_eq!(one[0], DVec3::ZERO);
        assert_eq!(
            slot_in(&entities, &slots_of(&entities), entities[7]),
            Some(7)
        );
    }
}
