use glam::{DMat3, DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::*;
use crate::collision::toi::sphere_sphere_contact;

type Rng = Xoshiro256PlusPlus;

fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn vec(rng: &mut Rng, s: f64) -> DVec3 {
    DVec3::new(
        rng.random_range(-s..s),
        rng.random_range(-s..s),
        rng.random_range(-s..s),
    )
}

/// A body with random mass and a random anisotropic inertia tensor (returned with `I` itself).
struct Body {
    x: DVec3,
    mass: f64,
    inertia: DMat3,
    body: RigidBody,
}

fn random_body(rng: &mut Rng) -> Body {
    let mass = rng.random_range(0.2..5.0);
    let rot = DMat3::from_quat(DQuat::from_axis_angle(
        unit(rng),
        rng.random_range(0.0..6.3),
    ));
    let principal = DVec3::new(
        rng.random_range(0.05..2.0),
        rng.random_range(0.05..2.0),
        rng.random_range(0.05..2.0),
    );
    let inertia = rot * DMat3::from_diagonal(principal) * rot.transpose();
    let inv_inertia = rot * DMat3::from_diagonal(principal.recip()) * rot.transpose();
    Body {
        x: vec(rng, 2.0),
        mass,
        inertia,
        body: RigidBody {
            inv_mass: 1.0 / mass,
            inv_inertia,
            velocity: vec(rng, 3.0),
            angular_velocity: vec(rng, 3.0),
        },
    }
}

fn momentum(bodies: &[&Body], states: &[RigidBody]) -> (DVec3, DVec3, f64) {
    let mut p = DVec3::ZERO;
    let mut l = DVec3::ZERO;
    let mut scale = 0.0;
    for (b, s) in bodies.iter().zip(states) {
        p += s.velocity * b.mass;
        let li = b.x.cross(s.velocity) * b.mass + b.inertia * s.angular_velocity;
        l += li;
        scale += (s.velocity * b.mass).length() + li.length();
    }
    (p, l, scale)
}

fn energy(bodies: &[&Body], states: &[RigidBody]) -> f64 {
    bodies
        .iter()
        .zip(states)
        .map(|(b, s)| {
            0.5 * b.mass * s.velocity.length_squared()
                + 0.5 * s.angular_velocity.dot(b.inertia * s.angular_velocity)
        })
        .sum()
}

/// A random approaching contact between two random bodies sharing one contact point.
fn random_collision(rng: &mut Rng) -> (Body, Body, ContactGeometry) {
    loop {
        let a = random_body(rng);
        let b = random_body(rng);
        let c = (a.x + b.x) * 0.5 + vec(rng, 0.5);
        let contact = ContactGeometry {
            normal: unit(rng),
            r_a: c - a.x,
            r_b: c - b.x,
            gap: 0.0,
        };
        if relative_contact_velocity(&a.body, &b.body, &contact).dot(contact.normal) < -0.05 {
            return (a, b, contact);
        }
    }
}

fn random_law(rng: &mut Rng) -> CollisionLaw {
    CollisionLaw {
        normal_restitution: rng.random_range(0.0..1.0),
        tangential_restitution: if rng.random_bool(0.5) {
            0.0
        } else {
            rng.random_range(-1.0..1.0)
        },
        friction: if rng.random_bool(0.5) {
            rng.random_range(0.0..0.2)
        } else {
            rng.random_range(0.0..3.0)
        },
    }
}

#[test]
fn general_bodies_conserve_momentum_and_meet_restitution_and_coulomb() {
    let mut rng = Rng::seed_from_u64(11);
    let (mut sticks, mut slides, mut fallbacks) = (0, 0, 0);
    let (mut worst_p, mut worst_l, mut worst_e) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..20_000 {
        let (a, b, contact) = random_collision(&mut rng);
        let law = random_law(&mut rng);
        let hit = collision_impulse(&a.body, &b.body, &contact, &law).unwrap();
        let (mut sa, mut sb) = (a.body, b.body);
        hit.apply(&mut sa, &mut sb);
        let (p0, l0, scale) = momentum(&[&a, &b], &[a.body, b.body]);
        let (p1, l1, _) = momentum(&[&a, &b], &[sa, sb]);
        worst_p = worst_p.max((p1 - p0).length() / scale);
        worst_l = worst_l.max((l1 - l0).length() / scale);
        let n = contact.normal;
        let vm = relative_contact_velocity(&a.body, &b.body, &contact);
        let vp = relative_contact_velocity(&sa, &sb, &contact);
        let vscale = vm.length();
        let e_err = (vp.dot(n) + law.normal_restitution * vm.dot(n)).abs() / vscale;
        worst_e = worst_e.max(e_err);
        assert!(e_err < 1e-12, "normal restitution error {e_err}");
        let jn = hit.impulse.dot(n);
        let jt = (hit.impulse - n * jn).length();
        assert!(jn > 0.0);
        match hit.regime {
            FrictionRegime::Stick => {
                sticks += 1;
                assert!(jt <= law.friction * jn);
                let vt_m = vm - n * vm.dot(n);
                let vt_p = vp - n * vp.dot(n);
                let err = (vt_p + vt_m * law.tangential_restitution).length() / vscale;
                assert!(err < 1e-12, "stick tangential error {err}");
            }
            FrictionRegime::Slide => {
                slides += 1;
                assert!(
                    (jt - law.friction * jn).abs() <= 1e-12 * jn,
                    "{jt} vs {}",
                    law.friction * jn
                );
            }
            FrictionRegime::Frictionless => {
                fallbacks += 1;
                assert!(jt <= 1e-12 * jn);
                let k = collision_matrix(&a.body, &b.body, &contact);
                let vt = vm - n * vm.dot(n);
                let t = -vt.normalize();
                assert!(n.dot(k * (n + t * law.friction)) <= 0.0);
            }
        }
    }
    println!(
        "sticks {sticks} slides {slides} frictionless fallbacks {fallbacks}, worst |dP|/scale {worst_p:.2e}, |dL| {worst_l:.2e}, e {worst_e:.2e}"
    );
    assert!(sticks > 1000 && slides > 1000);
    assert!(worst_p < 1e-14 && worst_l < 1e-14, "{worst_p} {worst_l}");
}

#[test]
fn separating_and_static_pairs_get_no_impulse() {
    let mut rng = Rng::seed_from_u64(3);
    let (a, b, contact) = random_collision(&mut rng);
    let flipped = ContactGeometry {
        normal: -contact.normal,
        ..contact
    };
    let law = CollisionLaw::frictionless(0.5);
    assert!(collision_impulse(&a.body, &b.body, &flipped, &law).is_none());
    let mut wall = RigidBody::fixed();
    wall.velocity = DVec3::X;
    let touching = sphere_sphere_contact(DVec3::X, 0.5, 0.5);
    assert!(collision_impulse(&RigidBody::fixed(), &wall, &touching, &law).is_none());
    let mut nan = a.body;
    nan.velocity = DVec3::NAN;
    assert!(collision_impulse(&nan, &b.body, &contact, &law).is_none());
}

/// Hoomans' (2.33)-(2.35) in his own conventions (normal from b to a, v_ab = v_a,c − v_b,c, J on a),
/// with the momentum-conserving correction of (2.33). Returns the post-collision states.
fn hoomans_sphere_impulse(
    (ma, ra, va, wa): (f64, f64, DVec3, DVec3),
    (mb, rb, vb, wb): (f64, f64, DVec3, DVec3),
    n_ba: DVec3,
    law: &CollisionLaw,
) -> [DVec3; 4] {
    let m_ab = ma * mb / (ma + mb);
    let v_ab = (va - vb) - (wa * ra + wb * rb).cross(n_ba);
    let vn = v_ab.dot(n_ba);
    let vt_vec = v_ab - n_ba * vn;
    let t = vt_vec.normalize_or_zero();
    let jn = -(1.0 + law.normal_restitution) * m_ab * vn;
    let stick = 2.0 / 7.0 * (1.0 + law.tangential_restitution) * m_ab * v_ab.dot(t);
    let jt = if law.friction * jn >= stick {
        -stick
    } else {
        -law.friction * jn
    };
    let j = n_ba * jn + t * jt;
    let (ia, ib) = (0.4 * ma * ra * ra, 0.4 * mb * rb * rb);
    [
        va + j / ma,
        wa - n_ba.cross(j) * (ra / ia),
        vb - j / mb,
        wb - n_ba.cross(j) * (rb / ib),
    ]
}

#[test]
fn spheres_reduce_to_hoomans_and_never_gain_energy() {
    let mut rng = Rng::seed_from_u64(5);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        let (ra, rb) = (rng.random_range(0.1..1.0), rng.random_range(0.1..1.0));
        let (ma, mb) = (rng.random_range(0.1..3.0), rng.random_range(0.1..3.0));
        let n = unit(&mut rng);
        let sa = RigidBody::solid_sphere(ma, ra, vec(&mut rng, 2.0), vec(&mut rng, 5.0));
        let sb = RigidBody::solid_sphere(mb, rb, vec(&mut rng, 2.0), vec(&mut rng, 5.0));
        let contact = sphere_sphere_contact(n * (ra + rb), ra, rb);
        let mut law = random_law(&mut rng);
        law.tangential_restitution = law.tangential_restitution.abs();
        let Some(hit) = collision_impulse(&sa, &sb, &contact, &law) else {
            continue;
        };
        let (mut pa, mut pb) = (sa, sb);
        hit.apply(&mut pa, &mut pb);
        let h = hoomans_sphere_impulse(
            (ma, ra, sa.velocity, sa.angular_velocity),
            (mb, rb, sb.velocity, sb.angular_velocity),
            -n,
            &law,
        );
        let ours = [
            pa.velocity,
            pa.angular_velocity,
            pb.velocity,
            pb.angular_velocity,
        ];
        let scale = sa.velocity.length() + sb.velocity.length() + sa.angular_velocity.length() * ra;
        for (o, h) in ours.iter().zip(&h) {
            worst = worst.max((*o - *h).length() / scale);
        }
        let e = |s: &RigidBody, m: f64, r: f64| {
            0.5 * m * s.velocity.length_squared()
                + 0.2 * m * r * r * s.angular_velocity.length_squared()
        };
        let (e0, e1) = (
            e(&sa, ma, ra) + e(&sb, mb, rb),
            e(&pa, ma, ra) + e(&pb, mb, rb),
        );
        assert!(
            e1 <= e0 * (1.0 + 1e-13),
            "energy gain {e0} -> {e1}, {law:?}"
        );
    }
    println!("max deviation from Hoomans: {worst:.2e}");
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn general_bodies_with_equal_restitutions_never_gain_energy() {
    let mut rng = Rng::seed_from_u64(7);
    for _ in 0..20_000 {
        let (a, b, contact) = random_collision(&mut rng);
        let e = rng.random_range(0.0..1.0);
        let law = CollisionLaw {
            normal_restitution: e,
            tangential_restitution: e,
            friction: 1e6,
        };
        let hit = collision_impulse(&a.body, &b.body, &contact, &law).unwrap();
        if hit.regime != FrictionRegime::Stick {
            // the stick impulse would pull (J·n < 0): only possible for eccentric contacts
            continue;
        }
        let (mut sa, mut sb) = (a.body, b.body);
        hit.apply(&mut sa, &mut sb);
        let (e0, e1) = (
            energy(&[&a, &b], &[a.body, b.body]),
            energy(&[&a, &b], &[sa, sb]),
        );
        assert!(e1 <= e0 * (1.0 + 1e-13) + 1e-15, "{e0} -> {e1}");
        // ΔE = J·(v⁻ + v⁺)/2 = −(1 − e²)/2 v⁻ᵀK⁻¹v⁻
        let vm = relative_contact_velocity(&a.body, &b.body, &contact);
        let k = collision_matrix(&a.body, &b.body, &contact);
        let expect = -0.5 * (1.0 - e * e) * vm.dot(k.inverse() * vm);
        assert!(((e1 - e0) - expect).abs() < 1e-11 * e0.max(1.0));
    }
}

/// Documents the eccentric-impact defect of velocity restitution: with `e_n ≠ e_t` a non-spherical
/// stick collision can gain energy, iff `e_n² (n·K⁻¹n)(n·K n) > 1` (for `e_t = 0`), while random
/// samples mostly dissipate.
#[test]
fn eccentric_stick_with_unequal_restitution_can_gain_energy() {
    let mut rng = Rng::seed_from_u64(9);
    let (mut gains, mut total) = (0, 0);
    for _ in 0..20_000 {
        let (a, b, contact) = random_collision(&mut rng);
        let law = CollisionLaw {
            normal_restitution: rng.random_range(0.0..1.0),
            tangential_restitution: 0.0,
            friction: rng.random_range(0.0..1.0),
        };
        let hit = collision_impulse(&a.body, &b.body, &contact, &law).unwrap();
        let (mut sa, mut sb) = (a.body, b.body);
        hit.apply(&mut sa, &mut sb);
        let de = energy(&[&a, &b], &[sa, sb]) - energy(&[&a, &b], &[a.body, b.body]);
        total += 1;
        if de > 1e-12 {
            gains += 1;
            if hit.regime == FrictionRegime::Stick {
                let k = collision_matrix(&a.body, &b.body, &contact);
                let n = contact.normal;
                let c = law.normal_restitution.powi(2) * n.dot(k.inverse() * n) * n.dot(k * n);
                assert!(c > 1.0, "stick gain needs e_n^2 (nK^-1n)(nKn) > 1, got {c}");
            }
        }
    }
    println!("energy-gaining collisions with e_t = 0: {gains} of {total}");
    // A constructed case: a rod-like body hit off-centre, e_n = 1, e_t = 0, sticking.
    let rod = RigidBody {
        inv_mass: 1.0,
        inv_inertia: DMat3::from_diagonal(DVec3::new(100.0, 100.0, 0.01)),
        velocity: DVec3::ZERO,
        angular_velocity: DVec3::ZERO,
    };
    let contact = ContactGeometry {
        normal: DVec3::new(0.0, -0.6, -0.8),
        r_a: DVec3::ZERO,
        r_b: DVec3::new(0.3, 0.0, 0.0),
        gap: 0.0,
    };
    let k = collision_matrix(&RigidBody::fixed(), &rod, &contact);
    let n = contact.normal;
    // pick v⁻ = −K n: then K⁻¹v⁻ ∥ n, minimising v⁻ᵀK⁻¹v⁻ at fixed v⁻·n
    let mut incoming = rod;
    incoming.velocity = -(k * n);
    let law = CollisionLaw {
        normal_restitution: 1.0,
        tangential_restitution: 0.0,
        friction: 1e3,
    };
    let hit = collision_impulse(&RigidBody::fixed(), &incoming, &contact, &law).unwrap();
    assert_eq!(hit.regime, FrictionRegime::Stick);
    let mut after = incoming;
    after.velocity += hit.delta_velocity_b;
    after.angular_velocity += hit.delta_angular_velocity_b;
    let ke = |s: &RigidBody| 0.5 * s.velocity.length_squared();
    let rot = |s: &RigidBody| {
        let i = DVec3::new(0.01, 0.01, 100.0);
        0.5 * (s.angular_velocity * s.angular_velocity).dot(i)
    };
    let (e0, e1) = (ke(&incoming) + rot(&incoming), ke(&after) + rot(&after));
    println!("constructed eccentric stick collision: E {e0:.4} -> {e1:.4}");
    assert!(e1 > e0 * 1.01);
}

#[test]
fn sliding_sphere_on_wall_ends_rolling_with_two_sevenths_impulse() {
    let (m, r) = (0.3, 0.01);
    let vt = DVec3::new(1.7, 0.0, -0.4);
    let ball = RigidBody::solid_sphere(m, r, vt + DVec3::new(0.0, -0.9, 0.0), DVec3::ZERO);
    // floor below: normal from the ball (a) to the wall (b) is −y
    let contact = ContactGeometry {
        normal: -DVec3::Y,
        r_a: -DVec3::Y * r,
        r_b: DVec3::ZERO,
        gap: 0.0,
    };
    let law = CollisionLaw {
        normal_restitution: 0.6,
        tangential_restitution: 0.0,
        friction: 10.0,
    };
    let hit = collision_impulse(&ball, &RigidBody::fixed(), &contact, &law).unwrap();
    assert_eq!(hit.regime, FrictionRegime::Stick);
    let on_ball = -hit.impulse;
    let jt = on_ball - DVec3::Y * on_ball.y;
    assert!((jt + vt * (2.0 / 7.0 * m)).length() < 1e-15, "{jt}");
    assert!((on_ball.y - 1.6 * 0.9 * m).abs() < 1e-15);
    let mut after = ball;
    let mut wall = RigidBody::fixed();
    hit.apply(&mut after, &mut wall);
    assert_eq!(wall, RigidBody::fixed());
    // rolling: the contact point is at rest tangentially, ω × (−r ŷ) = −v_t
    let contact_v = after.point_velocity(-DVec3::Y * r);
    assert!(
        contact_v.x.abs() < 1e-15 && contact_v.z.abs() < 1e-15,
        "{contact_v}"
    );
    assert!((after.velocity.y - 0.6 * 0.9).abs() < 1e-15);
    assert!(
        ((after.angular_velocity * r).length() - after.velocity.with_y(0.0).length()).abs() < 1e-15
    );
    assert!((after.velocity.with_y(0.0) - vt * (5.0 / 7.0)).length() < 1e-15);
    // small friction: slides with |J_t| = μ J_n exactly, the wall takes the momentum
    let slippery = CollisionLaw {
        friction: 0.05,
        ..law
    };
    let hit = collision_impulse(&ball, &RigidBody::fixed(), &contact, &slippery).unwrap();
    assert_eq!(hit.regime, FrictionRegime::Slide);
    let jn = hit.impulse.dot(contact.normal);
    assert!(((hit.impulse - contact.normal * jn).length() - 0.05 * jn).abs() < 1e-12 * jn);
}
