//! A fork-join team whose threads stay awake between many short parallel phases.
//!
//! The packing sweeps run thousands of parallel phases per second (one per colour of a cell
//! sweep, one per overlap scan), each a few hundred microseconds long, separated by short
//! serial write-backs. On rayon's pool a worker that finds no work sleeps after ~30 µs of
//! yielding, and the next phase wakes it again: measured on the 750-superball scene with two
//! threads, ~5 000 sleeps and wake-ups per second, the woken thread joining each phase late
//! and the sleeping protocol's yields costing a quarter of the one-thread run's CPU time.
//! A [`Team`] keeps its helpers waiting for the next phase by spinning, then yielding, and
//! only after a long serial stretch sleeping briefly, so a phase starts on every thread at
//! once.
//!
//! This is hand-written (no crate offers a scoped, lifetime-borrowing parallel map with
//! spinning helpers that coexists with rayon's pool) and small: the leader publishes a
//! phase, every thread claims task indices from one counter, and the leader returns once
//! every task is done and no helper still looks at the phase. Which thread runs which task
//! does not change any result: tasks write only their own slot.
//!
//! **Sided phases** ([`Team::map_sided`]). Two processors share data through their caches: a
//! line one of them wrote must travel to the other before it can read it. Profiled on the
//! 750-superball scene, the tasks of the sweeps and scans did ~1.4x the work of the one-thread
//! run when every thread claimed the next task from one counter, all of it in the code that
//! loads poses, Newton starts and cached contacts (the arithmetic of the contact solves took
//! the same time). In a sided phase the leader claims tasks from the front and the helpers
//! from the back; callers order the tasks by place (the packing's particles are numbered
//! along a space-filling curve, `crate::packing::systems::spatial_order`), so that a
//! particle's data stays with one processor from phase to phase while the load still
//! balances where the two ends meet.
//!
//! Helpers are OS threads of a [`std::thread::scope`] (one fewer than rayon's current
//! thread count), not rayon jobs, so the leader may still use rayon inside the team's scope
//! (rayon's idle threads help it as usual) without ever running a helper's wait loop itself.
//! Work that runs beside other work on the same cores (a study's replicates) should run on a
//! one-thread pool ([`super::on_one_thread`]): its team then has no helpers.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long an idle helper spins before it starts yielding its core.
const SPIN: Duration = Duration::from_micros(50);
/// How long an idle helper yields before it sleeps between checks.
const YIELD: Duration = Duration::from_millis(2);
/// The sleep of an idle helper after [`YIELD`].
const NAP: Duration = Duration::from_micros(100);

/// One parallel phase: `f(i)` for every `i < n`.
struct Phase<'a> {
    f: &'a (dyn Fn(usize) + Sync),
    n: usize,
    /// Tasks claimed from the front (low 32 bits) and from the back (high 32 bits).
    claims: AtomicU64,
    /// Whether helpers claim from the back (the leader always claims from the front).
    sided: bool,
    done: AtomicUsize,
}

impl Phase<'_> {
    /// Claim the next task from the front or the back; None when every task is claimed.
    #[inline]
    fn claim(&self, back: bool) -> Option<usize> {
        let mut cur = self.claims.load(Ordering::Relaxed);
        loop {
            let (f, b) = ((cur & 0xffff_ffff) as usize, (cur >> 32) as usize);
            if f + b >= self.n {
                return None;
            }
            let (next, i) = if back {
                (cur + (1 << 32), self.n - 1 - b)
            } else {
                (cur + 1, f)
            };
            match self
                .claims
                .compare_exchange_weak(cur, next, Ordering::Relaxed, Ordering::Relaxed)
            {
                Ok(_) => return Some(i),
                Err(now) => cur = now,
            }
        }
    }
}

/// What the leader and the helpers share.
#[derive(Default)]
struct Shared {
    /// The published phase (null between phases); its lifetime is erased while published
    /// (the leader does not return before no helper can reach it: see [`Team::map`]).
    phase: AtomicPtr<Phase<'static>>,
    /// Phases published so far.
    epoch: AtomicU64,
    /// Helpers that may be reading the published phase.
    active: AtomicUsize,
    stop: AtomicBool,
    /// The first panic of a task, re-raised by the leader.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

impl Shared {
    /// Claim and run tasks of `phase` until none is left.
    fn work(&self, phase: &Phase<'_>, helper: bool) {
        let back = helper && phase.sided;
        while let Some(i) = phase.claim(back) {
            if let Err(p) = catch_unwind(AssertUnwindSafe(|| (phase.f)(i))) {
                let mut slot = self.panic.lock().unwrap_or_else(|e| e.into_inner());
                slot.get_or_insert(p);
            }
            phase.done.fetch_add(1, Ordering::Release);
        }
    }

    /// A helper's loop: join every phase published until `stop`.
    fn help(&self) {
        // 0: a phase published before this helper started is joined too
        let mut seen = 0;
        let mut idle = Instant::now();
        let mut spins = 0u32;
        while !self.stop.load(Ordering::Acquire) {
            let e = self.epoch.load(Ordering::Acquire);
            if e == seen {
                spins = spins.wrapping_add(1);
                if spins.is_multiple_of(64) {
                    let waited = idle.elapsed();
                    if waited > YIELD {
                        std::thread::sleep(NAP);
                    } else if waited > SPIN {
                        std::thread::yield_now();
                    }
                }
                std::hint::spin_loop();
                continue;
            }
            seen = e;
            self.active.fetch_add(1, Ordering::SeqCst);
            let p = self.phase.load(Ordering::SeqCst);
            if !p.is_null() {
                // SAFETY: the leader nulls `phase` and then waits for `active` to drop to
                // zero before the phase goes out of scope; we raised `active` before
                // loading the pointer (both SeqCst), so the phase is alive until we lower it.
                self.work(unsafe { &*p }, true);
            }
            self.active.fetch_sub(1, Ordering::SeqCst);
            idle = Instant::now();
        }
    }
}

/// A fork-join team (see the module header). Made by [`Team::scope`].
pub struct Team<'s> {
    shared: &'s Shared,
    threads: usize,
}

impl Team<'_> {
    /// Run `f` with a team of rayon's current thread count (the calling thread and that many
    /// less one helpers, which exist only during `f`). With one thread `f` runs alone and the
    /// team's maps are plain loops.
    ///
    /// ```
    /// use magsep_systems::par::team::Team;
    /// let squares = Team::scope(|team| team.map(5, |i| i * i));
    /// assert_eq!(squares, vec![0, 1, 4, 9, 16]);
    /// ```
    pub fn scope<R>(f: impl FnOnce(&Team<'_>) -> R) -> R {
        let threads = rayon::current_num_threads().max(1);
        let shared = Shared::default();
        if threads == 1 {
            return f(&Team {
                shared: &shared,
                threads,
            });
        }
        std::thread::scope(|s| {
            for _ in 1..threads {
                // a helper that cannot be started is only missing: phases never wait for one
                let _ = std::thread::Builder::new().spawn_scoped(s, || shared.help());
            }
            let out = catch_unwind(AssertUnwindSafe(|| {
                f(&Team {
                    shared: &shared,
                    threads,
                })
            }));
            shared.stop.store(true, Ordering::Release);
            out.unwrap_or_else(|p| resume_unwind(p))
        })
    }

    /// Threads of the team (the leader included).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// `f(i)` for `i` in `0..n`, on every thread of the team, in index order. Only the
    /// leader (the thread that runs [`Team::scope`]'s closure) calls it, and never from
    /// inside a task (a team runs one phase at a time).
    pub fn map<R: Send>(&self, n: usize, f: impl Fn(usize) -> R + Sync) -> Vec<R> {
        self.map_with(n, false, f)
    }

    /// [`Team::map`] where the leader claims tasks from the front and the helpers from the
    /// back: tasks ordered by place (the leader's region first) keep each region's data in
    /// one processor's cache from phase to phase.
    pub fn map_sided<R: Send>(&self, n: usize, f: impl Fn(usize) -> R + Sync) -> Vec<R> {
        self.map_with(n, true, f)
    }

    fn map_with<R: Send>(&self, n: usize, sided: bool, f: impl Fn(usize) -> R + Sync) -> Vec<R> {
        // (more tasks than the 32-bit claim counters hold: no phase of the packing comes
        // near, but such a map still runs, on the leader alone)
        if self.threads == 1 || n <= 1 || n > u32::MAX as usize {
            return (0..n).map(f).collect();
        }
        let slots: Vec<Mutex<Option<R>>> = (0..n).map(|_| Mutex::new(None)).collect();
        let task = |i: usize| {
            let r = f(i);
            *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
        };
        let phase = Phase {
            f: &task,
            n,
            claims: AtomicU64::new(0),
            sided,
            done: AtomicUsize::new(0),
        };
        let sh = self.shared;
        // SAFETY (lifetime erasure): the pointer is withdrawn below, and the phase outlives
        // every helper that loaded it (`active`), before `phase` goes out of scope.
        let erased = &phase as *const Phase<'_> as *mut Phase<'static>;
        sh.phase.store(erased, Ordering::SeqCst);
        sh.epoch.fetch_add(1, Ordering::SeqCst);
        sh.work(&phase, false);
        while phase.done.load(Ordering::Acquire) < n {
            std::hint::spin_loop();
        }
        sh.phase.store(std::ptr::null_mut(), Ordering::SeqCst);
        while sh.active.load(Ordering::SeqCst) != 0 {
            std::hint::spin_loop();
        }
        if let Some(p) = sh.panic.lock().unwrap_or_else(|e| e.into_inner()).take() {
            resume_unwind(p);
        }
        slots
            .into_iter()
            .map(|s| {
                s.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every task of a finished phase stored its result")
            })
            .collect()
    }
}

/// A slice that the tasks of one [`Team::map`] phase read and write at disjoint indices.
///
/// Made from an exclusive borrow, so nothing else reaches the slice while it lives; every
/// access is `unsafe` because the caller must guarantee that no two tasks touch one index.
pub struct Scatter<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: a `Scatter` is an exclusive borrow split by index; the caller of `read`/`write`
// guarantees that each index is used by one task only (see the methods).
unsafe impl<T: Send> Sync for Scatter<'_, T> {}
unsafe impl<T: Send> Send for Scatter<'_, T> {}

impl<'a, T: Copy> Scatter<'a, T> {
    /// Borrow `slice` for disjoint accesses.
    pub fn new(slice: &'a mut [T]) -> Self {
        Self {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _borrow: std::marker::PhantomData,
        }
    }

    /// The element at `i`.
    ///
    /// # Safety
    /// No other task of the phase writes index `i`.
    #[inline]
    pub unsafe fn read(&self, i: usize) -> T {
        assert!(i < self.len, "index {i} out of {}", self.len);
        // SAFETY: in bounds; no concurrent write to `i` (the caller's guarantee)
        unsafe { self.ptr.add(i).read() }
    }

    /// Store `v` at `i`.
    ///
    /// # Safety
    /// No other task of the phase reads or writes index `i`.
    #[inline]
    pub unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len, "index {i} out of {}", self.len);
        // SAFETY: in bounds; no concurrent access to `i` (the caller's guarantee)
        unsafe { self.ptr.add(i).write(v) }
    }
}

#[cfg(test)]
mod tests {
    use super::Team;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Many short phases in a row, plain and sided, give every task's result in order, on 1-3
    /// threads.
    #[test]
    fn phases_return_every_result_in_order() {
        for threads in 1..=3 {
            let sums = pool(threads).install(|| {
                Team::scope(|team| {
                    assert_eq!(team.threads(), threads);
                    (0..2000)
                        .map(|k| {
                            let f = |i| i * 1000 + k;
                            let r = if k % 2 == 0 {
                                team.map(k % 7, f)
                            } else {
                                team.map_sided(k % 7, f)
                            };
                            assert_eq!(r, (0..k % 7).map(f).collect::<Vec<_>>());
                            r.iter().sum::<usize>()
                        })
                        .collect::<Vec<_>>()
                })
            });
            for (k, s) in sums.iter().enumerate() {
                let n = k % 7;
                assert_eq!(*s, (0..n).map(|i| i * 1000 + k).sum::<usize>(), "{threads}");
            }
        }
    }

    /// A task that panics is re-raised by the leader after the phase, and the team ends.
    #[test]
    fn a_panicking_task_is_re_raised_after_its_phase() {
        let r = std::panic::catch_unwind(|| {
            pool(2).install(|| {
                Team::scope(|team| {
                    team.map(8, |i| {
                        assert!(i != 5, "task five");
                        i
                    })
                })
            })
        });
        assert!(r.is_err());
    }

    /// Tasks of a phase write disjoint indices of one slice.
    #[test]
    fn scattered_writes_land_at_their_indices() {
        let mut v = vec![0u64; 1000];
        pool(2).install(|| {
            Team::scope(|team| {
                let s = super::Scatter::new(&mut v);
                team.map(10, |c| {
                    for i in (c..1000).step_by(10) {
                        // SAFETY: index i belongs to task i % 10 only
                        unsafe { s.write(i, s.read(i) + i as u64 * 3) };
                    }
                });
            })
        });
        assert!(v.iter().enumerate().all(|(i, x)| *x == i as u64 * 3));
    }

    /// The leader may use rayon inside the scope.
    #[test]
    fn rayon_works_inside_the_scope() {
        use rayon::prelude::*;
        let s = pool(2).install(|| {
            Team::scope(|team| {
                let a: u64 = (0..10_000u64).into_par_iter().sum();
                let b: Vec<u64> = team.map(4, |i| i as u64);
                a + b.iter().sum::<u64>()
            })
        });
        assert_eq!(s, 49_995_000 + 6);
    }
}
