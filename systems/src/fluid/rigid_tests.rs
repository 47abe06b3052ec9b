use super::*;
use crate::fluid::motion::rotate;
use glam::DMat3;

/// The thesis's direction-cosine matrix (eq. 4.2), scalar-last (q1, q2, q3, q4).
fn thesis_dcm(q: [f64; 4]) -> DMat3 {
    let [q1, q2, q3, q4] = q;
    // rows as printed; glam takes columns, so transpose at the end
    DMat3::from_cols_array(&[
        q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4,
        2.0 * (q1 * q2 + q3 * q4),
        2.0 * (q1 * q3 - q2 * q4),
        2.0 * (q1 * q2 - q3 * q4),
        -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4,
        2.0 * (q2 * q3 + q1 * q4),
        2.0 * (q1 * q3 + q2 * q4),
        2.0 * (q2 * q3 - q1 * q4),
        -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4,
    ])
    .transpose()
}

/// The thesis's rate equation (4.3), scalar-last.
fn thesis_rate(q: [f64; 4], w: DVec3) -> [f64; 4] {
    let [q1, q2, q3, q4] = q;
    [
        0.5 * (q4 * w.x - q3 * w.y + q2 * w.z),
        0.5 * (q3 * w.x + q4 * w.y - q1 * w.z),
        0.5 * (-q2 * w.x + q1 * w.y + q4 * w.z),
        0.5 * (-q1 * w.x - q2 * w.y - q3 * w.z),
    ]
}

fn some_quaternion(k: u32) -> DQuat {
    let t = f64::from(k);
    DQuat::from_axis_angle(
        DVec3::new((1.3 * t).sin(), (0.7 * t).cos(), 0.4 + (2.1 * t).sin()).normalize(),
        0.37 + 1.9 * t,
    )
}

#[test]
fn m1_thesis_dcm_is_the_transpose_of_the_rotation_and_its_rows_are_the_body_axes() {
    for k in 0..20 {
        let q = some_quaternion(k);
        let c = thesis_dcm([q.x, q.y, q.z, q.w]);
        let r = DMat3::from_quat(q);
        assert!(
            (c - r.transpose())
                .abs()
                .to_cols_array()
                .iter()
                .all(|d| *d < 1e-14)
        );
        // rows of C = body axes in lab coordinates
        for (row, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
            assert!((c.row(row) - q * axis).length() < 1e-14);
        }
        // orthogonal to 1e-12
        let ctc = c * c.transpose();
        assert!(
            (ctc - DMat3::IDENTITY)
                .abs()
                .to_cols_array()
                .iter()
                .all(|d| *d < 1e-12)
        );
    }
}

#[test]
fn m1_quaternion_rate_is_the_thesis_equation() {
    for k in 0..20 {
        let q = some_quaternion(k);
        let w = DVec3::new(0.3 * f64::from(k), -1.2, 2.0 + f64::from(k).cos());
        let mine = quaternion_rate(q, w);
        let thesis = thesis_rate([q.x, q.y, q.z, q.w], w);
        let diff = [
            mine.x - thesis[0],
            mine.y - thesis[1],
            mine.z - thesis[2],
            mine.w - thesis[3],
        ];
        assert!(diff.iter().all(|d| d.abs() < 1e-14), "{diff:?}");
    }
}

#[test]
fn m1_thesis_step_converges_with_first_order_and_stays_normalised() {
    let omega = DVec3::new(0.4, -1.1, 2.3);
    let q0 = some_quaternion(3);
    let t_end = 1.0;
    let exact = DQuat::from_axis_angle(omega.normalize(), omega.length() * t_end) * q0;
    let mut errs = Vec::new();
    for n in [200, 400, 800] {
        let dt = t_end / f64::from(n);
        let mut q = q0;
        for _ in 0..n {
            q = thesis_quaternion_step(q, omega, dt);
            assert!((q.length() - 1.0).abs() < 1e-14);
        }
        errs.push((q * DVec3::Z - exact * DVec3::Z).length());
    }
    // first order at least (the thesis's claim); for constant Ω the renormalised Euler step
    // turns by 2 atan(|Ω|Δt/2) about the exact axis, so it is in fact second order
    let order = (errs[0] / errs[2]).log2() / 2.0;
    assert!((order - 2.0).abs() < 0.1, "order {order}, errors {errs:?}");
    // the pipeline's exponential update is exact for constant Ω
    let mut q = q0;
    for _ in 0..800 {
        q = rotate(q, omega, t_end / 800.0);
    }
    assert!((q * DVec3::Z - exact * DVec3::Z).length() < 1e-12);
}

#[test]
fn suppressed_spin_keeps_omega_perpendicular_and_relaxes_implicitly() {
    let orientation = DQuat::from_rotation_arc(DVec3::Z, DVec3::new(0.3, -0.2, 0.9).normalize());
    let axis = orientation * DVec3::Z;
    let inertia = DVec3::new(2.0, 2.0, 3.5);
    // start with an axial spin: it is removed at once
    let w = angular_velocity_step(
        axis * 5.0,
        DVec3::ZERO,
        orientation,
        inertia,
        0.0,
        0.1,
        SpinModel::Suppressed,
    );
    assert!(w.length() < 1e-15);
    // linear drag T = -k Ω, k dt / I = 50: implicit Euler stays bounded and monotone
    let (k, dt) = (10.0, 10.0);
    let mut w = axis.any_orthonormal_vector() * 1.0;
    for _ in 0..10 {
        let next = angular_velocity_step(
            w,
            -k * w,
            orientation,
            inertia,
            k,
            dt,
            SpinModel::Suppressed,
        );
        assert!(next.length() < w.length() && next.dot(axis).abs() < 1e-15);
        w = next;
    }
    // explicit (stiffness 0) diverges beyond dt = 2 τ_r and converges below
    let tau = rotational_relaxation_time(inertia.x, k);
    for (dt, grows) in [(2.5 * tau, true), (1.5 * tau, false)] {
        let mut w = axis.any_orthonormal_vector();
        for _ in 0..50 {
            w = angular_velocity_step(
                w,
                -k * w,
                orientation,
                inertia,
                0.0,
                dt,
                SpinModel::Suppressed,
            );
        }
        assert_eq!(w.length() > 1.0, grows, "dt/τ = {}", dt / tau);
    }
}

#[test]
fn free_symmetric_top_conserves_energy_and_precesses_like_the_exact_solution() {
    // torque-free oblate top: in the lab, L is constant and the axis cones about L at the
    // rate |L|/I1
    let (i1, i3) = (1.0, 1.8);
    let inertia = DVec3::new(i1, i1, i3);
    let q0 = DQuat::IDENTITY;
    let w0 = DVec3::new(0.6, 0.0, 1.5); // lab = body at t = 0
    let l = DVec3::new(i1 * w0.x, i1 * w0.y, i3 * w0.z);
    let energy = |w: DVec3, q: DQuat| {
        let b = q.inverse() * w;
        0.5 * (i1 * (b.x * b.x + b.y * b.y) + i3 * b.z * b.z)
    };
    let e0 = energy(w0, q0);
    let t_end = 3.0;
    let exact_axis =
        DQuat::from_axis_angle(l.normalize(), l.length() / i1 * t_end) * (q0 * DVec3::Z);
    let mut errs = Vec::new();
    for n in [1000, 2000, 4000] {
        let dt = t_end / f64::from(n);
        let (mut q, mut w) = (q0, w0);
        for _ in 0..n {
            w = angular_velocity_step(w, DVec3::ZERO, q, inertia, 0.0, dt, SpinModel::Free);
            q = rotate(q, w, dt);
            let rel = (energy(w, q) - e0).abs() / e0;
            assert!(rel < 1e-10, "energy drift {rel}");
        }
        errs.push((q * DVec3::Z - exact_axis).length());
    }
    assert!(errs[2] < 1e-2, "{errs:?}");
    let order = (errs[0] / errs[2]).log2() / 2.0;
    assert!(order > 0.9, "order {order}, errors {errs:?}");
}

#[test]
fn free_spin_reduces_to_the_suppressed_model_without_axial_spin_or_torque() {
    let q = some_quaternion(5);
    let axis = q * DVec3::Z;
    let inertia = DVec3::new(1.3, 1.3, 2.1);
    let w = axis.cross(DVec3::X).normalize() * 0.7;
    let t = axis.cross(DVec3::Y) * 0.2;
    let a = angular_velocity_step(w, t, q, inertia, 0.4, 0.01, SpinModel::Free);
    let b = angular_velocity_step(w, t, q, inertia, 0.4, 0.01, SpinModel::Suppressed);
    assert!((a - b).length() < 1e-14, "{a} vs {b}");
}

/// The stiff rotation of a thin disc: the 1:10 flake p3 (d_e = 2.657 mm, PVC-U in MnCl2(aq))
/// spun up to 100 rad/s about a diameter (as a collision leaves it) relaxes under Zastawny's
/// rotational resistance. τ_r = I₁/k(Ω) ≈ 1.2 ms at 100 rad/s: the explicit update diverges
/// for Δt above about 2τ_r, the linearly implicit one decays monotonically at any step.
#[test]
fn thin_disc_rotation_explicit_fails_beyond_two_relaxation_times_implicit_does_not() {
    use crate::fluid::spheroid::{SpheroidHydro, rotational_resistance};
    use magsep_components::fluid::InertialBody;
    let (de, w, rho_p) = (2.657e-3, 0.1_f64, 1434.0);
    let a = 0.5 * de / w.cbrt();
    let body = InertialBody::spheroid(a, w * a, rho_p);
    let hydro = SpheroidHydro::new(2.0 * a, w, 1403.0, rho_p, 5.54e-3);
    let q = DQuat::from_rotation_x(0.3);
    let w0 = (q * DVec3::X) * 100.0;
    let (_, k) = rotational_resistance(&hydro, -w0);
    let tau = rotational_relaxation_time(body.inertia.x, k);
    assert!(tau > 5e-4 && tau < 3e-3, "τ_r = {tau}");
    let run = |dt: f64, implicit: bool| {
        let mut omega = w0;
        let mut peak = 0.0_f64;
        for _ in 0..200 {
            let (torque, k) = rotational_resistance(&hydro, -omega);
            let stiffness = if implicit { k } else { 0.0 };
            let next = angular_velocity_step(
                omega,
                torque,
                q,
                body.inertia,
                stiffness,
                dt,
                SpinModel::Suppressed,
            );
            if implicit {
                assert!(next.length() <= omega.length() && next.dot(omega) >= 0.0);
            }
            omega = next;
            peak = peak.max(omega.length());
            if !omega.is_finite() {
                return f64::INFINITY;
            }
        }
        peak
    };
    // below the limit both decay; above it the explicit update overshoots and grows
    assert!(run(0.5 * tau, false) <= 100.0 + 1e-9);
    assert!(
        run(4.0 * tau, false) > 100.0,
        "explicit should fail at 4 τ_r"
    );
    for dt in [0.5 * tau, 4.0 * tau, 100.0 * tau] {
        assert!(run(dt, true) <= 100.0 + 1e-9);
    }
}
