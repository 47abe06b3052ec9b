use super::*;
use crate::packing::insert::random_insertion;
use crate::packing::state::Body;
use crate::rng::particle_stream;
use magsep_components::shape::Shape;

/// All pairs (i <= j, image) with a gap below `skin`, by brute force over images.
fn brute(state: &PackingState, skin: f64) -> Vec<(usize, usize, [i16; 3])> {
    let n = state.len();
    let l = state.edges;
    let k = 3i16;
    let mut out = Vec::new();
    for i in 0..n {
        for j in i..n {
            for a in -k..=k {
                for b in -k..=k {
                    for c in -k..=k {
                        if i == j && [a, b, c] <= [0, 0, 0] {
                            continue;
                        }
                        let shift = DVec3::new(a as f64, b as f64, c as f64) * l;
                        let pc = state.contact(i, j, shift);
                        if -pc.overlap < skin {
                            out.push((i, j, [a, b, c]));
                        }
                    }
                }
            }
        }
    }
    out.sort();
    out
}

fn listed(state: &PackingState, list: &NeighbourList) -> Vec<(usize, usize, [i16; 3])> {
    let mut out: Vec<_> = list
        .unique_pairs(state.edges)
        .map(|(i, j, s)| (i, j, image_of(s, state.edges)))
        .collect();
    out.sort();
    out
}

fn check(shape: Shape, n: usize, phi: f64, seed: u64) {
    let bodies: Vec<Body> = (0..n).map(|_| Body::from_shape(&shape, 1.0)).collect();
    let v: f64 = bodies.iter().map(|b| b.volume).sum();
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(seed, i)).collect();
    let mut state = random_insertion(
        &bodies,
        PackingState::periodic_cube((v / phi).cbrt()),
        &mut rngs,
    )
    .unwrap();
    let mut list = NeighbourList::new(0.3);
    list.build(&mut state);
    let want = brute(&state, 0.3);
    let got = listed(&state, &list);
    // every pair within the skin is listed (the list may hold a few more: it tests < skin
    // on the segment distance, the same criterion, so the sets are equal)
    assert_eq!(got, want, "{shape:?} n {n} phi {phi}");
}

#[test]
fn net_displacements_keep_the_list_complete_until_it_asks_for_a_rebuild() {
    // random-walk the centres and compress; while the list claims to be valid, every
    // pair closer than contact + 0.1 skin must be listed
    use rand::RngExt;
    let n = 60;
    let bodies: Vec<Body> = (0..n)
        .map(|_| Body::from_shape(&Shape::Sphere { radius: 0.5 }, 1.0))
        .collect();
    let v: f64 = bodies.iter().map(|b| b.volume).sum();
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(5, i)).collect();
    let mut state = random_insertion(
        &bodies,
        PackingState::periodic_cube((v / 0.3).cbrt()),
        &mut rngs,
    )
    .unwrap();
    let mut list = NeighbourList::new(0.3);
    list.build(&mut state);
    let mut rng = particle_stream(9, 0);
    let (mut checked, mut rebuilds) = (0, 0);
    for step in 0..400 {
        if step % 50 == 0 {
            let s = DVec3::splat(0.995);
            state.scale(s);
            list.note_compression(s);
        }
        for x in &mut state.positions {
            let u = DVec3::new(rng.random(), rng.random(), rng.random());
            *x += 0.03 * (u - DVec3::splat(0.5));
        }
        list.note_displacements(&state.positions);
        if list.needs_rebuild() {
            list.build(&mut state);
            rebuilds += 1;
            continue;
        }
        if step % 5 != 0 {
            continue;
        }
        let want = brute(&state, 0.1);
        let got = listed(&state, &list);
        assert!(want.iter().all(|p| got.contains(p)), "step {step}");
        checked += 1;
    }
    assert!(
        checked > 20 && rebuilds > 2,
        "{checked} checks, {rebuilds} rebuilds"
    );
}

#[test]
fn verlet_list_equals_brute_force_over_all_images() {
    // cell-list path (box >= 3 cut-offs)
    check(Shape::Sphere { radius: 0.5 }, 200, 0.3, 1);
    check(
        Shape::Spherocylinder {
            radius: 0.5,
            half_length: 1.0,
        },
        150,
        0.25,
        2,
    );
    // all-images path: rods longer than the box, including contacts with own images
    check(
        Shape::Spherocylinder {
            radius: 0.5,
            half_length: 6.0,
        },
        6,
        0.2,
        3,
    );
    check(Shape::Sphere { radius: 0.5 }, 5, 0.2, 4);
}
