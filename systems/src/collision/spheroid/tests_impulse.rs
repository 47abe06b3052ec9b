//! The impulse law on real spheroid contacts (thesis acceptance M3): random spheroid pairs of
//! aspect ratio 1 to 1:10 touching at random orientations, lever arms from the common-normal
//! contact, homogeneous-spheroid inertia tensors. (General anisotropic bodies with arbitrary
//! contact points are covered in `collision/impulse/tests.rs`.)

use glam::{DMat3, DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::tests::{random_rotation, unit};
use super::*;
use crate::collision::impulse::{
    CollisionLaw, FrictionRegime, RigidBody, collision_impulse, collision_matrix,
    relative_contact_velocity,
};
use crate::collision::toi::ContactGeometry;

type Rng = Xoshiro256PlusPlus;

struct Body {
    x: DVec3,
    mass: f64,
    inertia: DMat3,
    state: RigidBody,
}

/// A homogeneous spheroid body of density 1000 at `x` with orientation `q`.
fn spheroid_body(rng: &mut Rng, s: &Spheroid, x: DVec3, q: DQuat) -> Body {
    let (a, c) = (s.equatorial, s.polar);
    let mass = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * a * a * c;
    let principal = DVec3::new(
        mass * (a * a + c * c) / 5.0,
        mass * (a * a + c * c) / 5.0,
        0.4 * mass * a * a,
    );
    let r = DMat3::from_quat(q);
    Body {
        x,
        mass,
        inertia: r * DMat3::from_diagonal(principal) * r.transpose(),
        state: RigidBody {
            inv_mass: 1.0 / mass,
            inv_inertia: world_inverse_inertia(principal.recip(), q),
            velocity: unit(rng) * rng.random_range(0.0..2.0),
            angular_velocity: unit(rng) * rng.random_range(0.0..500.0),
        },
    }
}

/// A touching pair (gap within 1e-12 of the size) with an approaching contact, and the lab
/// symmetry axis of *a*.
fn touching_pair(rng: &mut Rng) -> (Body, Body, ContactGeometry, DVec3) {
    let ws = [1.0, 0.5, 0.2, 0.1];
    loop {
        let sa = Spheroid::new(1e-3, 1e-3 * ws[rng.random_range(0..4)]);
        let rb = rng.random_range(0.5e-3..1.5e-3);
        let sb = Spheroid::new(rb, rb * ws[rng.random_range(0..4)]);
        let (qa, qb) = (random_rotation(rng), random_rotation(rng));
        let dir = unit(rng);
        let pa = PosedSpheroid::new(sa, DVec3::ZERO, qa);
        let (mut lo, mut hi) = (0.0, sa.bounding_radius() + sb.bounding_radius());
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            let gap = spheroid_contact(&pa, &PosedSpheroid::new(sb, dir * mid, qb), None)
                .map_or(f64::NAN, |c| c.geometry.gap);
            if gap > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let pb = PosedSpheroid::new(sb, dir * hi, qb);
        let c = spheroid_contact(&pa, &pb, None).expect("contact").geometry;
        let a = spheroid_body(rng, &sa, pa.centre, qa);
        let b = spheroid_body(rng, &sb, pb.centre, qb);
        if relative_contact_velocity(&a.state, &b.state, &c).dot(c.normal) < -0.01 {
            return (a, b, c, pa.axis);
        }
    }
}

fn energy(b: &Body, s: &RigidBody) -> f64 {
    0.5 * b.mass * s.velocity.length_squared()
        + 0.5 * s.angular_velocity.dot(b.inertia * s.angular_velocity)
}

#[test]
fn spheroid_contacts_conserve_momentum_meet_restitution_coulomb_and_lose_energy() {
    let mut rng = Rng::seed_from_u64(31);
    let (mut sticks, mut slides) = (0, 0);
    let (mut worst_p, mut worst_l, mut worst_gain, mut worst_ecc) =
        (0.0f64, 0.0f64, f64::MIN, 0.0f64);
    for k in 0..5000 {
        let (a, b, c, _) = touching_pair(&mut rng);
        // the thesis law half the time, otherwise random restitution up to 0.3 and friction
        let law = if k % 2 == 0 {
            CollisionLaw {
                normal_restitution: 0.1,
                tangential_restitution: 0.0,
                friction: 0.05,
            }
        } else {
            CollisionLaw {
                normal_restitution: rng.random_range(0.0..0.3),
                tangential_restitution: 0.0,
                friction: rng.random_range(0.0..1.0),
            }
        };
        let hit = collision_impulse(&a.state, &b.state, &c, &law).expect("approaching");
        let (mut sa, mut sb) = (a.state, b.state);
        hit.apply(&mut sa, &mut sb);
        // linear momentum and angular momentum about the origin (a fixed point)
        let p = |s: &RigidBody, m: f64| s.velocity * m;
        let l = |body: &Body, s: &RigidBody| {
            body.x.cross(s.velocity) * body.mass + body.inertia * s.angular_velocity
        };
        let scale = p(&a.state, a.mass).length()
            + p(&b.state, b.mass).length()
            + l(&a, &a.state).length()
            + l(&b, &b.state).length();
        let dp = p(&sa, a.mass) + p(&sb, b.mass) - p(&a.state, a.mass) - p(&b.state, b.mass);
        let dl = l(&a, &sa) + l(&b, &sb) - l(&a, &a.state) - l(&b, &b.state);
        worst_p = worst_p.max(dp.length() / scale);
        worst_l = worst_l.max(dl.length() / scale);
        // restitution exact, Coulomb
        let n = c.normal;
        let vm = relative_contact_velocity(&a.state, &b.state, &c);
        let vp = relative_contact_velocity(&sa, &sb, &c);
        let e_err = (vp.dot(n) + law.normal_restitution * vm.dot(n)).abs() / vm.length();
        assert!(e_err < 1e-11, "restitution error {e_err}");
        let jn = hit.impulse.dot(n);
        let jt = (hit.impulse - n * jn).length();
        match hit.regime {
            FrictionRegime::Stick => {
                sticks += 1;
                assert!(jt <= law.friction * jn * (1.0 + 1e-12));
                let vt = vp - n * vp.dot(n);
                assert!(
                    vt.length() < 1e-11 * vm.length(),
                    "stick slip {}",
                    vt.length()
                );
            }
            FrictionRegime::Slide => {
                slides += 1;
                assert!(
                    (jt - law.friction * jn).abs() <= 1e-11 * jn,
                    "{jt} vs {}",
                    law.friction * jn
                );
            }
            FrictionRegime::Frictionless => {}
        }
        let e0 = energy(&a, &a.state) + energy(&b, &b.state);
        let e1 = energy(&a, &sa) + energy(&b, &sb);
        worst_gain = worst_gain.max((e1 - e0) / e0);
        let kmat = collision_matrix(&a.state, &b.state, &c);
        worst_ecc = worst_ecc.max(n.dot(kmat.inverse() * n) * n.dot(kmat * n));
    }
    println!(
        "sticks {sticks} slides {slides}; worst |dP| {worst_p:.2e}, |dL| {worst_l:.2e}, energy change {worst_gain:.2e}, max (n·K⁻¹n)(n·Kn) {worst_ecc:.2}"
    );
    assert!(sticks > 200 && slides > 200);
    assert!(worst_p < 1e-13 && worst_l < 1e-13, "{worst_p} {worst_l}");
    assert!(worst_gain <= 1e-13, "energy gain {worst_gain}");
}

#[test]
fn suppressed_axial_spin_is_left_unchanged_and_sphere_limit_is_hoomans() {
    let mut rng = Rng::seed_from_u64(32);
    for k in 0..500 {
        let (mut a, b, c, axis) = touching_pair(&mut rng);
        // I_z → ∞: zero axial inverse moment about a's real symmetry axis
        let qa = DQuat::from_rotation_arc(DVec3::Z, axis);
        let ix = a.state.inv_inertia * axis.any_orthonormal_vector();
        a.state.inv_inertia = world_inverse_inertia(DVec3::new(ix.length(), ix.length(), 0.0), qa);
        let law = CollisionLaw {
            normal_restitution: 0.1,
            tangential_restitution: 0.0,
            friction: if k % 2 == 0 { 0.0 } else { 0.05 },
        };
        let Some(hit) = collision_impulse(&a.state, &b.state, &c, &law) else {
            continue;
        };
        let dw = hit.delta_angular_velocity_a;
        assert!(
            dw.dot(axis).abs() <= 1e-12 * dw.length(),
            "axial spin changed"
        );
        if law.friction == 0.0 {
            // a normal impulse on a body of revolution has no torque about its axis
            let torque = c.r_a.cross(hit.impulse);
            assert!(
                torque.dot(axis).abs() <= 1e-6 * c.r_a.length() * hit.impulse.length(),
                "{torque} {axis}"
            );
        }
    }
    // sphere limit: J_t = −(2/7) m_ab v_t when sticking, J_n = −(1 + e) m_ab v_n
    let s = Spheroid::sphere(1e-3);
    let pa = PosedSpheroid::new(s, DVec3::ZERO, DQuat::IDENTITY);
    let pb = PosedSpheroid::new(
        Spheroid::sphere(1e-3),
        DVec3::new(2e-3, 0.0, 0.0),
        DQuat::IDENTITY,
    );
    let c = spheroid_contact(&pa, &pb, None).unwrap().geometry;
    let mass = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 1e-9;
    let a = RigidBody::solid_sphere(mass, 1e-3, DVec3::new(1.0, 0.02, 0.0), DVec3::ZERO);
    let b = RigidBody::solid_sphere(mass, 1e-3, DVec3::new(-1.0, 0.0, 0.01), DVec3::ZERO);
    let law = CollisionLaw {
        normal_restitution: 0.1,
        tangential_restitution: 0.0,
        friction: 0.5,
    };
    let hit = collision_impulse(&a, &b, &c, &law).unwrap();
    let m_ab = mass / 2.0;
    let v = relative_contact_velocity(&a, &b, &c);
    let vt = v - c.normal * v.dot(c.normal);
    let jt = hit.impulse - c.normal * hit.impulse.dot(c.normal);
    assert_eq!(hit.regime, FrictionRegime::Stick);
    assert!((jt + vt * (2.0 / 7.0 * m_ab)).length() < 1e-14 * jt.length());
    assert!((hit.impulse.dot(c.normal) + 1.1 * m_ab * v.dot(c.normal)).abs() < 1e-14 * m_ab);
}
