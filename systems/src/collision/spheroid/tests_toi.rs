//! Time of impact against a brute-force time scan, and random 1:10 pair collisions resolved
//! with the impulse law (no missed contact, no penetration beyond the tolerance, no NaN, no
//! energy gain).

use glam::{DMat3, DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::tests::{random_rotation, unit};
use super::*;
use crate::collision::impulse::{CollisionLaw, RigidBody, collision_impulse};
use crate::collision::toi::{Ballistic, Plane};

type Rng = Xoshiro256PlusPlus;

fn at(b: &Ballistic, t: f64) -> (DVec3, DQuat) {
    let q = DQuat::from_scaled_axis(b.angular_velocity * t) * b.orientation;
    (b.position + b.velocity * t, q)
}

fn gap_at(sa: &Spheroid, a: &Ballistic, sb: &Spheroid, b: &Ballistic, t: f64) -> f64 {
    let (xa, qa) = at(a, t);
    let (xb, qb) = at(b, t);
    let pa = PosedSpheroid::new(*sa, xa, qa);
    let pb = PosedSpheroid::new(*sb, xb, qb);
    spheroid_contact(&pa, &pb, None).map_or(f64::NAN, |c| c.geometry.gap)
}

/// A random approaching pair: shapes, states. `w` is the aspect ratio of both (None: random).
fn random_scenario(rng: &mut Rng, w: Option<f64>) -> (Spheroid, Ballistic, Spheroid, Ballistic) {
    loop {
        let (sa, a, sb, b) = random_scenario_any(rng, w);
        if gap_at(&sa, &a, &sb, &b, 0.0) > 0.0 {
            return (sa, a, sb, b);
        }
    }
}

fn random_scenario_any(
    rng: &mut Rng,
    w: Option<f64>,
) -> (Spheroid, Ballistic, Spheroid, Ballistic) {
    let ws = [1.0, 0.5, 0.2, 0.1];
    let pick = |rng: &mut Rng| w.unwrap_or(ws[rng.random_range(0..4)]);
    let sa = Spheroid::new(1.0, pick(rng));
    let rb = rng.random_range(0.7..1.3);
    let sb = Spheroid::new(rb, rb * pick(rng));
    let dir = unit(rng);
    let dist = (sa.bounding_radius() + sb.bounding_radius()) * rng.random_range(0.5..2.0);
    // edge-on: axes perpendicular to the line of centres with probability 1/4
    let orient = |rng: &mut Rng| {
        if rng.random_bool(0.25) {
            let (t1, _) = dir.any_orthonormal_pair();
            DQuat::from_rotation_arc(DVec3::Z, t1)
                * DQuat::from_rotation_z(rng.random_range(0.0..6.3))
        } else {
            random_rotation(rng)
        }
    };
    let (qa, qb) = (orient(rng), orient(rng));
    let spin = |rng: &mut Rng| {
        if rng.random_bool(0.3) {
            unit(rng) * rng.random_range(0.0..30.0)
        } else {
            unit(rng) * rng.random_range(0.0..2.0)
        }
    };
    let a = Ballistic {
        position: DVec3::ZERO,
        orientation: qa,
        velocity: unit(rng) * rng.random_range(0.0..0.5),
        angular_velocity: spin(rng),
    };
    // b heads for a with a random impact offset (grazing included)
    let offset = unit(rng) * rng.random_range(0.0..1.5);
    let b = Ballistic {
        position: dir * dist,
        orientation: qb,
        velocity: (offset - dir * dist).normalize() * rng.random_range(0.5..4.0),
        angular_velocity: spin(rng),
    };
    (sa, a, sb, b)
}

#[test]
fn pair_toi_matches_a_fine_time_scan() {
    let mut rng = Rng::seed_from_u64(21);
    let horizon = 1.0;
    let scan = 4000;
    let (mut hits, mut misses, mut worst_late) = (0, 0, 0.0f64);
    for _ in 0..120 {
        let (sa, a, sb, b) = random_scenario(&mut rng, None);
        let l = sa.min_semi_axis().min(sb.min_semi_axis());
        let (d_hit, d_pen) = (
            SPHEROID_CONTACT_TOLERANCE * l,
            SPHEROID_PENETRATION_TOLERANCE * l,
        );
        let toi = spheroid_pair_toi(&sa, &a, &sb, &b, horizon, 0.0, None);
        let end = toi.map_or(horizon, |i| i.time);
        // no penetration beyond the tolerance before the reported impact
        let mut first_touch = None;
        for k in 0..=scan {
            let t = horizon * k as f64 / scan as f64;
            let g = gap_at(&sa, &a, &sb, &b, t);
            if t <= end {
                assert!(
                    g >= -d_pen * 1.01 - 1e-12,
                    "missed: gap {g} at {t} before {end}"
                );
            }
            if g <= 0.0 && first_touch.is_none() {
                first_touch = Some(t);
            }
        }
        match toi {
            Some(i) => {
                hits += 1;
                let g = gap_at(&sa, &a, &sb, &b, i.time);
                assert!(g <= d_hit * 1.01 && g >= -d_pen * 1.01, "gap at impact {g}");
                assert!(i.approach_speed > 0.0);
                if let Some(tb) = first_touch {
                    // reported no later than the first scanned touch (penetration-limited)
                    worst_late = worst_late.max(i.time - tb);
                }
            }
            None => misses += 1,
        }
    }
    println!(
        "hits {hits}, no impact {misses}, latest report after the scanned touch {worst_late:.2e} s"
    );
    assert!(hits > 30 && misses > 5);
    assert!(worst_late <= 1e-3 * horizon, "{worst_late}");
}

#[test]
fn plane_toi_matches_a_fine_time_scan() {
    let mut rng = Rng::seed_from_u64(22);
    let floor = Plane::new(DVec3::ZERO, DVec3::Z);
    let s = Spheroid::new(1.0, 0.1);
    for _ in 0..200 {
        let a = Ballistic {
            position: DVec3::new(0.0, 0.0, rng.random_range(0.05..2.5)),
            orientation: random_rotation(&mut rng),
            velocity: unit(&mut rng) * rng.random_range(0.0..3.0),
            angular_velocity: unit(&mut rng) * rng.random_range(0.0..20.0),
        };
        let start = PosedSpheroid::new(s, a.position, a.orientation);
        if spheroid_plane_contact(&start, &floor).gap <= 0.0 {
            continue;
        }
        let toi = spheroid_plane_toi(&s, &a, &floor, 1.0, 0.0);
        let end = toi.map_or(1.0, |i| i.time);
        for k in 0..=20_000 {
            let t = k as f64 / 20_000.0;
            if t > end {
                break;
            }
            let (x, q) = at(&a, t);
            let g = spheroid_plane_contact(&PosedSpheroid::new(s, x, q), &floor).gap;
            let pen = SPHEROID_PENETRATION_TOLERANCE * s.polar;
            assert!(g >= -pen * 1.01, "missed wall contact: {g} at {t}");
        }
        if let Some(i) = toi {
            let (x, q) = at(&a, i.time);
            let g = spheroid_plane_contact(&PosedSpheroid::new(s, x, q), &floor).gap;
            let (hit, pen) = (
                SPHEROID_CONTACT_TOLERANCE * s.polar,
                SPHEROID_PENETRATION_TOLERANCE * s.polar,
            );
            assert!(g <= hit * 1.01 && g >= -pen * 1.01, "{g}");
        }
    }
}

/// Mass and body inverse inertia of a homogeneous spheroid of unit density.
fn inertia(s: &Spheroid) -> (f64, DVec3) {
    let (a, c) = (s.equatorial, s.polar);
    let m = 4.0 / 3.0 * std::f64::consts::PI * a * a * c;
    let ix = m * (a * a + c * c) / 5.0;
    let iz = 0.4 * m * a * a;
    (m, DVec3::new(1.0 / ix, 1.0 / ix, 1.0 / iz))
}

#[derive(Default, Debug)]
struct PairStats {
    events: usize,
    worst_penetration: f64,
    worst_energy_gain: f64,
}

/// Resolves all collisions of one random 1:10 pair over a unit horizon with the impulse law and
/// checks every ballistic segment with a time scan.
fn run_pair(rng: &mut Rng, stats: &mut PairStats) {
    let (sa, mut a, sb, mut b) = random_scenario(rng, Some(0.1));
    // the thesis's law (e = 0.1, μ = 0.05) half the time, otherwise random with e_n ≤ 0.3
    let law = if rng.random_bool(0.5) {
        CollisionLaw {
            normal_restitution: 0.1,
            tangential_restitution: 0.0,
            friction: 0.05,
        }
    } else {
        CollisionLaw {
            normal_restitution: rng.random_range(0.0..0.3),
            tangential_restitution: 0.0,
            friction: rng.random_range(0.0..0.5),
        }
    };
    let (ma, ia) = inertia(&sa);
    let (mb, ib) = inertia(&sb);
    let l = sa.min_semi_axis().min(sb.min_semi_axis());
    let mut now = 0.0;
    let mut warm = None;
    for _ in 0..50 {
        let toi = spheroid_pair_toi(&sa, &a, &sb, &b, 1.0 - now, 0.0, warm);
        let seg = toi.map_or(1.0 - now, |i| i.time);
        for k in 0..=64 {
            let g = gap_at(&sa, &a, &sb, &b, seg * k as f64 / 64.0);
            assert!(!g.is_nan(), "NaN gap");
            stats.worst_penetration = stats.worst_penetration.max(-g / l);
        }
        let Some(hit) = toi else { break };
        let (xa, qa) = at(&a, hit.time);
        let (xb, qb) = at(&b, hit.time);
        (a.position, a.orientation) = (xa, qa.normalize());
        (b.position, b.orientation) = (xb, qb.normalize());
        now += hit.time;
        let pa = PosedSpheroid::new(sa, xa, qa);
        let pb = PosedSpheroid::new(sb, xb, qb);
        let c = spheroid_contact(&pa, &pb, Some(hit.normal)).expect("contact");
        warm = Some(c.geometry.normal);
        let body = |m: f64, i: DVec3, q: DQuat, st: &Ballistic| RigidBody {
            inv_mass: 1.0 / m,
            inv_inertia: world_inverse_inertia(i, q),
            velocity: st.velocity,
            angular_velocity: st.angular_velocity,
        };
        let (mut ra, mut rb) = (body(ma, ia, qa, &a), body(mb, ib, qb, &b));
        let energy = |r: &RigidBody, m: f64, i: DVec3, q: DQuat| {
            let inv = world_inverse_inertia(i, q);
            let big_i = inv.inverse();
            let _ = DMat3::IDENTITY;
            0.5 * m * r.velocity.length_squared()
                + 0.5 * r.angular_velocity.dot(big_i * r.angular_velocity)
        };
        let e0 = energy(&ra, ma, ia, qa) + energy(&rb, mb, ib, qb);
        if let Some(j) = collision_impulse(&ra, &rb, &c.geometry, &law) {
            j.apply(&mut ra, &mut rb);
            stats.events += 1;
        } else {
            // grazing at the tolerance: nothing to do but move on
            break;
        }
        let e1 = energy(&ra, ma, ia, qa) + energy(&rb, mb, ib, qb);
        assert!(e1.is_finite(), "NaN energy");
        stats.worst_energy_gain = stats.worst_energy_gain.max((e1 - e0) / e0);
        (a.velocity, a.angular_velocity) = (ra.velocity, ra.angular_velocity);
        (b.velocity, b.angular_velocity) = (rb.velocity, rb.angular_velocity);
    }
}

fn random_pair_collisions(n: usize) -> PairStats {
    let mut rng = Rng::seed_from_u64(77);
    let mut stats = PairStats::default();
    for _ in 0..n {
        run_pair(&mut rng, &mut stats);
    }
    println!("{n} pairs: {stats:?}");
    // the stated bound for sustained contacts of at most 50 impacts: δ_pen (1 + 50/100)
    assert!(
        stats.worst_penetration <= SPHEROID_PENETRATION_TOLERANCE * 1.5,
        "penetration {} L",
        stats.worst_penetration
    );
    assert!(
        stats.worst_energy_gain <= 1e-12,
        "energy gain {}",
        stats.worst_energy_gain
    );
    assert!(stats.events > n / 3, "{} events", stats.events);
    stats
}

#[test]
fn random_disc_pair_collisions_500() {
    random_pair_collisions(500);
}

#[test]
#[ignore = "release tier: cargo test --release -- --ignored"]
fn random_disc_pair_collisions_10000_release() {
    random_pair_collisions(10_000);
}
