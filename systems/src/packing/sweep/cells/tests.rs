use glam::DVec3;
use magsep_components::shape::Shape;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::super::tests::{bits, overlapping, pool};
use super::super::{OverlapTracker, commit_counted, propose};
use super::*;
use crate::packing::removal::remove_overlaps;

const SUPERBALL: Shape = Shape::Superquadric {
    semi_axes: DVec3::splat(0.5),
    exponents: DVec3::splat(3.0),
};

const ROD: Shape = Shape::Spherocylinder {
    radius: 0.5,
    half_length: 0.5,
};

const REVISED: MoveRule = MoveRule::Revised { dt: 0.1 };

/// The serial order of the module header, move by move on the state itself: colours in turn,
/// cells in index order, a cell stopped after the move past the skin (the other cells of its
/// group finish), the list rebuilt before the next run, the budget tested before each run.
#[allow(clippy::too_many_arguments)]
fn reference_sweep(
    state: &mut PackingState,
    list: &mut NeighbourList,
    tracker: &mut OverlapTracker,
    order: &[usize],
    cells: &SweepCells,
    rule: MoveRule,
    tol: f64,
    budget: u64,
    attempts: &mut u64,
    _team: &Team<'_>,
) -> SweepCount {
    let mut count = SweepCount::default();
    let mut scratch = Vec::new();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0);
    let all = cells.queues(state, order);
    for queues in all.colours() {
        let mut pos = vec![0usize; queues.len()];
        loop {
            let live: Vec<usize> = (0..queues.len())
                .filter(|&c| pos[c] < queues[c].len())
                .collect();
            if live.is_empty() {
                break;
            }
            if *attempts >= budget {
                return count;
            }
            if list.needs_rebuild() {
                list.build(state);
            }
            // does a listed pair join particles still to move in two different cells?
            let cell_of = |i: usize| {
                live.iter()
                    .position(|&c| queues[c][pos[c]..].contains(&i))
                    .map(|k| live[k])
            };
            let joined = live.iter().any(|&c| {
                queues[c][pos[c]..].iter().any(|&i| {
                    list.of(i)
                        .iter()
                        .any(|nb| cell_of(nb.j as usize).is_some_and(|o| o != c))
                })
            });
            let groups: Vec<Vec<usize>> = if joined {
                live.iter().map(|&c| vec![c]).collect()
            } else {
                vec![live.clone()]
            };
            for g in groups {
                let mut stopped = false;
                for c in g {
                    while pos[c] < queues[c].len() {
                        let i = queues[c][pos[c]];
                        pos[c] += 1;
                        let p = propose(
                            state,
                            list,
                            Some(tracker),
                            i,
                            rule,
                            tol,
                            &mut scratch,
                            &mut rng,
                        );
                        let moved =
                            commit_counted(state, list, tracker, i, &p, attempts, &mut count);
                        if moved && list.exceeds_skin(list.moved_of(i)) {
                            stopped = true;
                            break;
                        }
                    }
                }
                if stopped {
                    break;
                }
            }
        }
    }
    count
}

/// One scan and one sweep from an overlapping state, by [`sweep_cells`] on `threads` threads
/// or by the reference: the state's bits, the moves and the list builds.
fn one_sweep(
    shape: Shape,
    n: usize,
    skin: f64,
    cells_of: impl Fn(&PackingState, &NeighbourList) -> SweepCells,
    budget: u64,
    threads: Option<usize>,
) -> (Vec<u64>, u64, u64) {
    let (mut state, _) = overlapping(shape, n, 0.45, 21);
    let mut list = NeighbourList::new(skin);
    list.build(&mut state);
    let mut tracker = OverlapTracker::new();
    let mut flags = Vec::new();
    let mut builds = 0;
    let mut moves = 0;
    let mut attempts = 0;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    for _ in 0..3 {
        list.ensure(&mut state);
        Team::scope(|team| tracker.scan(&state, &mut list, 1e-4, &mut flags, team));
        let mut order: Vec<usize> = (0..n).filter(|&i| flags[i]).collect();
        order.shuffle(&mut rng);
        let cells = cells_of(&state, &list);
        let before = list.builds;
        let (s, l, t) = (&mut state, &mut list, &mut tracker);
        let f = if threads.is_some() {
            sweep_cells
        } else {
            reference_sweep
        };
        moves += pool(threads.unwrap_or(1))
            .install(|| {
                Team::scope(|team| {
                    f(
                        s,
                        l,
                        t,
                        &order,
                        &cells,
                        REVISED,
                        1e-4,
                        budget,
                        &mut attempts,
                        team,
                    )
                })
            })
            .moves;
        builds += list.builds - before;
    }
    (bits(&state), moves, builds)
}

fn chosen(seed: u64) -> impl Fn(&PackingState, &NeighbourList) -> SweepCells {
    move |s, l| {
        SweepCells::choose(s, l, &mut Xoshiro256PlusPlus::seed_from_u64(seed))
            .expect("the box holds four cells")
    }
}

#[test]
fn cell_sweeps_are_the_serial_order_on_any_thread_count() {
    // skin 0.1 (the packing's): no rebuild in a sweep; skin 0.004: cells stop at the skin
    for (shape, n, skin) in [
        (SUPERBALL, 260, 0.1),
        (SUPERBALL, 260, 0.004),
        (ROD, 300, 0.01),
    ] {
        let reference = one_sweep(shape, n, skin, chosen(3), u64::MAX, None);
        assert!(reference.1 > 200, "{shape:?}: {} moves", reference.1);
        if skin < 0.05 {
            assert!(
                reference.2 > 0,
                "{shape:?} skin {skin}: no rebuild in the sweeps"
            );
        }
        for threads in [1, 2, 3] {
            let got = one_sweep(shape, n, skin, chosen(3), u64::MAX, Some(threads));
            assert!(got == reference, "{shape:?} skin {skin} threads {threads}");
        }
    }
}

#[test]
fn cells_joined_by_listed_pairs_run_one_after_the_other() {
    // 16 slabs along x, narrower than the list's reach: neighbouring cells of one colour are
    // joined by listed pairs, so the colour's cells run serially; the budget cuts the sweep
    let slabs = |s: &PackingState, _: &NeighbourList| SweepCells {
        n: [16, 1, 1],
        offset: DVec3::new(0.1, 0.0, 0.0),
        edges: s.edges,
    };
    let reference = one_sweep(SUPERBALL, 260, 0.1, slabs, 300, None);
    assert!(reference.1 >= 300 && reference.1 < 600, "{}", reference.1);
    let got = one_sweep(SUPERBALL, 260, 0.1, slabs, 300, Some(2));
    assert!(got == reference);
    // without the check they would not be
    let (state, mut list) = overlapping(SUPERBALL, 260, 0.45, 21);
    list.ensure(&mut state.clone());
    let cells = slabs(&state, &list);
    let all: Vec<usize> = (0..state.len()).collect();
    let first = cells.queues(&state, &all);
    let queues = &first.colours().next().unwrap();
    let mut marks = Marks {
        cell: vec![NONE; state.len()],
        slot: vec![NONE; state.len()],
    };
    let live: Vec<usize> = (0..queues.len()).collect();
    let pos = vec![0; queues.len()];
    mark(&mut marks, queues, &live, &pos);
    assert_eq!(groups(&list, &marks, queues, &live, &pos).len(), live.len());
}

#[test]
fn queues_hold_every_particle_once_in_cells_a_width_apart() {
    let (mut state, mut list) = overlapping(SUPERBALL, 260, 0.45, 4);
    list.ensure(&mut state);
    let cells = chosen(9)(&state, &list);
    let split: Vec<usize> = (0..3).filter(|&a| cells.n[a] > 1).collect();
    assert!(!split.is_empty());
    let per_colour: usize = split.iter().map(|&a| cells.n[a] / 2).product();
    assert!(per_colour >= MIN_CELLS_PER_COLOUR.min(4), "{cells:?}");
    let mut order: Vec<usize> = (0..state.len()).collect();
    order.shuffle(&mut Xoshiro256PlusPlus::seed_from_u64(2));
    let all = cells.queues(&state, &order);
    let queues: Vec<Vec<&[usize]>> = all.colours().collect();
    let mut seen: Vec<usize> = queues
        .iter()
        .flatten()
        .flat_map(|q| q.iter())
        .copied()
        .collect();
    seen.sort_unstable();
    assert_eq!(seen, (0..state.len()).collect::<Vec<_>>());
    let width = list.centre_range() + list.skin;
    for colour in &queues {
        // particles of different cells of one colour are at least a width apart along a
        // cut axis (periodic distance), and each cell keeps the order's order
        for (a, qa) in colour.iter().enumerate() {
            let rank = |i: &usize| order.iter().position(|o| o == i);
            assert!(qa.windows(2).all(|w| rank(&w[0]) < rank(&w[1])));
            for qb in &colour[a + 1..] {
                for &i in qa.iter() {
                    for &j in qb.iter() {
                        let (xi, xj) = (state.positions[i], state.positions[j]);
                        let far = split.iter().any(|&ax| {
                            let l = state.edges[ax];
                            let d = (xi[ax] - xj[ax]).rem_euclid(l);
                            d.min(l - d) >= l / cells.n[ax] as f64 - 1e-9 * l
                        });
                        assert!(far, "{i} and {j} too close");
                        assert_eq!(cells.locate(xi).0, cells.locate(xj).0);
                    }
                }
            }
        }
    }
    for &ax in &split {
        assert!(state.edges[ax] / cells.n[ax] as f64 >= width);
    }
}

#[test]
fn small_boxes_and_random_rules_keep_the_plain_order() {
    let (mut state, mut list) = overlapping(SUPERBALL, 60, 0.5, 4);
    list.ensure(&mut state);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let before = rng.clone();
    assert!(SweepCells::choose(&state, &list, &mut rng).is_none());
    assert_eq!(rng, before, "no number drawn");
}

#[test]
fn removal_with_cells_is_the_same_on_one_two_and_three_threads() {
    let run = |threads: usize| {
        let (mut state, mut list) = overlapping(SUPERBALL, 260, 0.52, 8);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        assert!(SweepCells::choose(&state, &list, &mut rng.clone()).is_some());
        let out = pool(threads)
            .install(|| remove_overlaps(&mut state, &mut list, REVISED, 1e-4, 200 * 260, &mut rng));
        (bits(&state), out)
    };
    let one = run(1);
    assert!(one.1.attempts > 1000, "{:?}", one.1);
    assert_eq!(run(2), one);
    assert_eq!(run(3), one);
}
