//! Per-entity loops that go parallel only when there is enough work.
//!
//! bevy's `par_iter_mut` opens a task scope on the compute pool on every call, even for one
//! entity: waking the pool's threads costs microseconds, far more than the per-particle work
//! of a small scene. [`par_for_each_mut!`](crate::par_for_each_mut) runs the loop in place
//! below [`PAR_MIN_ENTITIES`] matched entities and in parallel above. The body sees one
//! entity at a time and writes only that entity, so both paths give bitwise the same result.

/// Fewest matched entities for which a per-entity loop runs on the compute pool (below it,
/// the loop runs on the calling thread).
pub const PAR_MIN_ENTITIES: usize = 256;

/// Whether a loop over at most `upper` entities (a query iterator's size-hint bound; `None`:
/// unknown) is worth a parallel scope with `min` entities as the threshold.
#[inline]
pub fn worth_parallel(upper: Option<usize>, min: usize) -> bool {
    upper.is_none_or(|n| n >= min)
}

/// `query.par_iter_mut().for_each(body)`, or the same body in a plain loop when the query
/// matches fewer than `min` entities (default [`PAR_MIN_ENTITIES`]). The body must only touch
/// the entity it is given (as `par_iter_mut` requires anyway).
///
/// ```
/// use bevy_ecs::prelude::*;
/// #[derive(Component)]
/// struct X(f64);
/// fn double(mut q: Query<&mut X>) {
///     magsep_systems::par_for_each_mut!(q, |mut x| {
///         x.0 *= 2.0;
///     });
/// }
/// let mut world = World::new();
/// let e = world.spawn(X(1.5)).id();
/// let mut schedule = Schedule::default();
/// schedule.add_systems(double);
/// // one entity: the loop runs in place (no compute pool needed)
/// schedule.run(&mut world);
/// assert_eq!(world.get::<X>(e).unwrap().0, 3.0);
/// ```
#[macro_export]
macro_rules! par_for_each_mut {
    ($q:ident, $min:expr, |$item:pat_param| $body:block) => {
        if $crate::par::worth_parallel($q.iter().size_hint().1, $min) {
            $q.par_iter_mut().for_each(|$item| $body);
        } else {
            $q.iter_mut().for_each(|$item| $body);
        }
    };
    ($q:ident, |$item:pat_param| $body:block) => {
        $crate::par_for_each_mut!($q, $crate::par::PAR_MIN_ENTITIES, |$item| $body)
    };
}

/// Run `f` on a thread of rayon's pool (in place when already on one).
///
/// A bevy system runs on bevy's own task pool; each rayon parallel loop it starts from there
/// is injected into rayon's pool and the system's thread blocks on a latch until it is done,
/// two cross-thread wake-ups per loop. A kernel that runs many short parallel loops in a row
/// (the packing sweeps: one per batch of a few moves) spends much of its time in those
/// wake-ups. Inside `f` the loops are nested rayon jobs instead: no injection, no blocking
/// latch. The work, and so the result, is the same.
pub fn in_rayon_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() {
        f()
    } else {
        rayon::scope(|_| f())
    }
}

/// Run `f` on a rayon pool of one thread: for work that runs beside other such work (the
/// replicates of a study, the points of a sweep), so that its parallel phases do not start
/// helpers ([`team::Team`]) or split across threads the other jobs already occupy. Runs `f`
/// in place if the pool cannot be built.
pub fn on_one_thread<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool.install(f),
        Err(_) => f(),
    }
}

pub mod team;
