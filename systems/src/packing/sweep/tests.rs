use glam::DVec3;
use magsep_components::packing::{OverlapRemovalScheme, PackingConfig};
use magsep_components::shape::Shape;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::*;
use crate::packing::compress::{DriverParams, compress, run_to_end};
use crate::packing::insert::random_insertion;
use crate::packing::removal::{overlap_scan, remove_overlaps, remove_overlaps_batched};
use crate::packing::state::Body;
use crate::rng::particle_stream;

const SUPERBALL: Shape = Shape::Superquadric {
    semi_axes: DVec3::splat(0.5),
    exponents: DVec3::splat(3.0),
};

/// `n` bodies of `shape` inserted at phi min(`phi`, 0.3) and compressed to `phi` (overlapping
/// above 0.3).
pub(super) fn overlapping(
    shape: Shape,
    n: usize,
    phi: f64,
    seed: u64,
) -> (PackingState, NeighbourList) {
    let bodies: Vec<Body> = (0..n).map(|_| Body::from_shape(&shape, 1.0)).collect();
    let v: f64 = bodies.iter().map(|b| b.volume).sum();
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(seed, i)).collect();
    let mut state = random_insertion(
        &bodies,
        PackingState::periodic_cube((v / phi.min(0.3)).cbrt()),
        &mut rngs,
    )
    .unwrap();
    let mut list = NeighbourList::new(0.1);
    list.build(&mut state);
    if phi > 0.3 {
        let dv = state.container_volume() - v / phi;
        compress(&mut state, &mut list, dv);
    }
    list.ensure(&mut state);
    (state, list)
}

pub(super) fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

pub(super) fn bits(s: &PackingState) -> Vec<u64> {
    let mut v = vec![s.edges.x.to_bits()];
    for (x, q) in s.positions.iter().zip(&s.orientations) {
        v.extend(x.to_array().map(f64::to_bits));
        v.extend(q.to_array().map(f64::to_bits));
    }
    v
}

#[test]
fn tracked_flags_equal_the_full_serial_scan_after_moves() {
    let tol = 1e-4;
    let (mut state, mut list) = overlapping(SUPERBALL, 80, 0.5, 3);
    let mut tracker = OverlapTracker::new();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    let (mut flags, mut want) = (Vec::new(), Vec::new());
    let mut partial_scans = 0;
    for round in 0..6 {
        list.ensure(&mut state);
        let builds = list.builds;
        let count = pool(2)
            .install(|| Team::scope(|team| tracker.scan(&state, &mut list, tol, &mut flags, team)));
        let mut reference = list.clone();
        overlap_scan(&state, &mut reference, tol, &mut want);
        assert_eq!(flags, want, "round {round}");
        assert!(want.iter().any(|f| *f), "the configuration overlaps");
        if round > 0 && list.builds == builds && count.contacts < list.unique().len() as u64 {
            partial_scans += 1;
        }
        // move a few particles, as a sweep would
        let order: Vec<usize> = (0..state.len()).filter(|i| flags[*i]).take(5).collect();
        assert!(serial_sweep(&mut state, &mut list, &mut tracker, &order, &mut rng) > 0);
    }
    assert!(
        partial_scans >= 3,
        "only the moved particles' pairs are re-evaluated"
    );
}

/// One serial sweep of `order` with the revised rule (tolerance 1e-4, no budget): the moves.
fn serial_sweep(
    state: &mut PackingState,
    list: &mut NeighbourList,
    tracker: &mut OverlapTracker,
    order: &[usize],
    rng: &mut Xoshiro256PlusPlus,
) -> u64 {
    let mut attempts = 0;
    let rule = MoveRule::Revised { dt: 0.1 };
    Team::scope(|team| {
        sweep(
            state,
            list,
            tracker,
            order,
            rule,
            1e-4,
            u64::MAX,
            &mut attempts,
            1,
            rng,
            team,
        )
    });
    attempts
}

fn removal_bits(
    shape: Shape,
    rule: MoveRule,
    threads: usize,
    batch: usize,
) -> (Vec<u64>, RemovalOutcome) {
    let (mut state, mut list) = overlapping(shape, 60, 0.5, 5);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let out = pool(threads).install(|| {
        remove_overlaps_batched(&mut state, &mut list, rule, 1e-4, 200 * 60, batch, &mut rng)
    });
    (bits(&state), out)
}

use super::super::removal::RemovalOutcome;

#[test]
fn batched_sweeps_are_the_serial_sweep_bit_for_bit() {
    let rod = Shape::Spherocylinder {
        radius: 0.5,
        half_length: 1.0,
    };
    for (shape, rule) in [
        (SUPERBALL, MoveRule::Revised { dt: 0.1 }),
        (
            rod,
            MoveRule::Original {
                beta: 0.5,
                xi: None,
            },
        ),
    ] {
        let (serial, out) = removal_bits(shape, rule, 1, 1);
        assert!(out.attempts > 100, "{out:?}");
        for (threads, batch) in [(1, 8), (2, 2), (2, 8), (2, 64)] {
            let (got, o) = removal_bits(shape, rule, threads, batch);
            assert_eq!(o, out, "{shape:?} threads {threads} batch {batch}");
            assert!(got == serial, "{shape:?} threads {threads} batch {batch}");
        }
    }
}

#[test]
fn superball_packing_is_the_same_on_one_and_two_threads() {
    let n = 40;
    let mut cfg = PackingConfig::defaults_for(n, 1.0);
    cfg.scheme = OverlapRemovalScheme::Revised;
    cfg.max_attempts = PackingConfig::default_max_attempts(cfg.scheme, n);
    cfg.max_compression_steps = 120;
    let p = DriverParams::from_config(&cfg, 1.0);
    let run = |threads: usize| {
        let (mut state, mut list) = overlapping(SUPERBALL, n, 0.1, 7);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(13);
        let st = pool(threads).install(|| {
            assert_eq!(batch_for_threads(), if threads == 1 { 1 } else { 8 });
            run_to_end(&p, &mut state, &mut list, &mut rng, |_| {})
        });
        (bits(&state), st)
    };
    let (one, st1) = run(1);
    let (two, st2) = run(2);
    assert!(st1.attempts > 1000 && st1.packing_fraction > 0.3, "{st1:?}");
    assert_eq!(st1, st2);
    assert!(one == two, "final states differ");
}

#[test]
fn remove_overlaps_uses_the_pool_and_keeps_the_serial_result() {
    let (mut a, mut la) = overlapping(SUPERBALL, 50, 0.45, 2);
    let (mut b, mut lb) = (a.clone(), la.clone());
    let rule = MoveRule::Revised { dt: 0.1 };
    let mut ra = Xoshiro256PlusPlus::seed_from_u64(1);
    let mut rb = ra.clone();
    let oa = pool(1).install(|| remove_overlaps(&mut a, &mut la, rule, 1e-4, 10_000, &mut ra));
    let ob = pool(2).install(|| remove_overlaps(&mut b, &mut lb, rule, 1e-4, 10_000, &mut rb));
    assert_eq!(oa, ob);
    assert!(bits(&a) == bits(&b));
    assert!(oa.attempts > 1000, "{oa:?}");
}

#[test]
#[ignore = "timing (release): 750 superballs, 300 compression steps on 1 and 2 threads"]
fn superballs_750_steps_on_one_and_two_threads() {
    let n = 750;
    let mut cfg = PackingConfig::defaults_for(n, 1.0);
    cfg.scheme = OverlapRemovalScheme::Revised;
    cfg.max_attempts = PackingConfig::default_max_attempts(cfg.scheme, n);
    cfg.max_compression_steps = 300;
    let p = DriverParams::from_config(&cfg, 1.0);
    let run = |threads: usize| {
        let (mut state, mut list) = overlapping(SUPERBALL, n, 0.05, 1);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let t = std::time::Instant::now();
        let st = pool(threads).install(|| run_to_end(&p, &mut state, &mut list, &mut rng, |_| {}));
        let s = t.elapsed().as_secs_f64();
        eprintln!(
            "threads {threads}: {s:.2} s, phi {:.4}, attempts {}, contacts {}",
            st.packing_fraction, st.attempts, st.contact_evaluations
        );
        (bits(&state), st)
    };
    let (one, st1) = run(1);
    let (two, st2) = run(2);
    assert_eq!(st1, st2);
    assert!(one == two);
}

/// The reference of the sweep's contact cache: every cached contact is the contact a fresh
/// solve gives for the present poses (to the solver's accuracy), and no cached contact
/// survives a move of either end.
#[test]
fn cached_contacts_equal_fresh_solves_and_moves_invalidate_them() {
    let tol = 1e-4;
    let (mut state, mut list) = overlapping(SUPERBALL, 80, 0.5, 4);
    let mut tracker = OverlapTracker::new();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let mut flags = Vec::new();
    let (mut hits, mut compared_after_moves, mut below) = (0, 0, 0);
    for round in 0..4 {
        list.ensure(&mut state);
        pool(2)
            .install(|| Team::scope(|team| tracker.scan(&state, &mut list, tol, &mut flags, team)));
        for i in 0..state.len() {
            let first = list.entry_start(i);
            for k in first..first + list.of(i).len() {
                let nb = list.entry(k);
                let Some(c) = tracker.cached(&list, k, i, nb.j as usize) else {
                    continue;
                };
                hits += 1;
                compared_after_moves += usize::from(round > 0);
                let mut warm = None; // a cold solve: GJK/EPA seed, then Newton
                let f = state.contact_warm(i, nb.j as usize, nb.shift(state.edges), &mut warm);
                let Some(c) = c else {
                    // not solved: certainly at most the tolerance
                    below += 1;
                    assert!(f.overlap <= tol, "{f:?}");
                    continue;
                };
                assert!((c.overlap - f.overlap).abs() < 1e-10, "{c:?} {f:?}");
                if f.overlap > -0.02 {
                    assert!((c.normal - f.normal).length() < 1e-6, "{c:?} {f:?}");
                    assert!((c.rc - f.rc_i).length() < 1e-6, "{c:?} {f:?}");
                }
            }
        }
        let order: Vec<usize> = (0..state.len()).filter(|i| flags[*i]).take(8).collect();
        let builds = list.builds;
        let before = (state.positions.clone(), state.orientations.clone());
        assert!(serial_sweep(&mut state, &mut list, &mut tracker, &order, &mut rng) > 0);
        if list.builds == builds {
            let moved = |i: usize| {
                state.positions[i] != before.0[i] || state.orientations[i] != before.1[i]
            };
            for &i in order.iter().filter(|i| moved(**i)) {
                let first = list.entry_start(i);
                for k in first..first + list.of(i).len() {
                    let j = list.entry(k).j as usize;
                    assert!(tracker.cached(&list, k, i, j).is_none(), "moved {i}");
                    assert!(
                        tracker.cached(&list, list.twin(k), j, i).is_none(),
                        "moved {i}"
                    );
                }
            }
        }
    }
    assert!(
        hits > 500 && compared_after_moves > 100 && below > 50,
        "{hits} {compared_after_moves} {below}"
    );
}

/// The tracker's certificates hold: after random moves of up to 0.03 D and 0.06 rad (far
/// larger than the revised rule's), every pair still certified is below the tolerance by a
/// cold solve, and moves take certificates away.
#[test]
fn certified_pairs_stay_below_the_tolerance_as_their_ends_move() {
    use crate::packing::moves::Displacement;
    use glam::DQuat;
    use rand::RngExt;
    let tol = 1e-4;
    let (mut state, mut list) = overlapping(SUPERBALL, 80, 0.55, 6);
    let mut tracker = OverlapTracker::new();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
    let mut flags = Vec::new();
    let certified = |state: &PackingState, list: &NeighbourList, tracker: &OverlapTracker| {
        let mut out = Vec::new();
        for i in 0..state.len() {
            let first = list.entry_start(i);
            for k in first..first + list.of(i).len() {
                if tracker.certified(list, k, i, list.entry(k).j as usize) {
                    out.push(k);
                }
            }
        }
        out
    };
    let (mut checked, mut lost) = (0, 0);
    for round in 0..5 {
        list.ensure(&mut state);
        Team::scope(|team| tracker.scan(&state, &mut list, tol, &mut flags, team));
        let before = certified(&state, &list, &tracker);
        assert!(
            before.len() > 200,
            "round {round}: {} certified",
            before.len()
        );
        let builds = list.builds;
        let (mut attempts, mut count) = (0, SweepCount::default());
        for _ in 0..40 {
            let i = rng.random_range(0..state.len());
            let mut r = |s: f64| DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 * s - s;
            let d = Displacement {
                dx: r(0.03),
                rotation: DQuat::from_scaled_axis(r(0.06)),
            };
            let mut p = Proposal::default();
            p.set_displacement(&state.bodies[i], state.orientations[i], Some(d));
            commit_counted(
                &mut state,
                &mut list,
                &mut tracker,
                i,
                &p,
                &mut attempts,
                &mut count,
            );
        }
        assert_eq!(list.builds, builds);
        let after = certified(&state, &list, &tracker);
        lost += before.len() - after.len();
        for k in after {
            // the pair as the scan evaluates it, solved cold (GJK/EPA seed, then Newton)
            let e = list.unique()[list.pair_of_entry(k)];
            let mut cold = None;
            let c = state.contact_warm(e.i as usize, e.j as usize, e.shift(state.edges), &mut cold);
            assert!(c.overlap <= tol - 1e-10, "round {round} entry {k}: {c:?}");
            checked += 1;
        }
    }
    assert!(
        checked > 300 && lost > 100,
        "{checked} checked, {lost} lost"
    );
}

/// The turn bound is the chord 2 R sin(theta/2) that a rotation by theta moves a point at the
/// reach R, from tiny turns to half turns, and it bounds how far surface points move.
#[test]
fn turn_bound_is_the_chord_of_the_rotation() {
    use crate::packing::removal::turn_bound;
    use glam::DQuat;
    use rand::RngExt;
    let body = Body::from_shape(&SUPERBALL, 1.0);
    let reach = body.bounding_radius();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    for n in 0..2000 {
        let axis = DVec3::new(
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
        )
        .normalize();
        let angle = if n % 2 == 0 {
            std::f64::consts::PI * rng.random::<f64>()
        } else {
            1e-4 * rng.random::<f64>()
        };
        let q = DQuat::from_axis_angle(axis, angle);
        let chord = 2.0 * reach * (0.5 * angle).sin();
        let bound = turn_bound(&body, q);
        assert!(
            (bound - chord).abs() <= 1e-14 + 1e-12 * chord,
            "{angle}: {bound} {chord}"
        );
        let p = axis.any_orthonormal_vector() * reach;
        assert!((q * p - p).length() <= bound * (1.0 + 1e-12) + 1e-15);
    }
}
