//! The 1:10 database: transcription, interpolation, held-out accuracy, limits.

use super::correlation_tests::stokes_factors;
use super::disc_model::*;
use super::disc_table::*;
use super::disc_validation::*;

/// Row sums (per angle) and column sums (per Re) of Tables 3.3-3.5 as printed, summed from the
/// printed text independently of the Rust arrays.
const ROW_SUMS: [[f64; 19]; 3] = [
    [
        138.03, 138.79, 141.21, 145.1, 150.49, 157.08, 164.79, 173.24, 182.0, 190.74, 199.33,
        207.35, 214.72, 221.28, 226.92, 231.14, 234.22, 235.86, 236.06,
    ],
    [
        0.01, 11.34, 22.36, 32.91, 42.6, 51.01, 57.72, 62.41, 64.84, 64.94, 62.97, 59.15, 53.72,
        47.03, 39.22, 30.43, 20.85, 10.74, 0.02,
    ],
    [
        0.04, 11.16, 22.02, 31.97, 40.88, 48.19, 53.61, 57.04, 58.32, 57.45, 54.94, 51.15, 46.17,
        40.26, 33.54, 26.03, 18.0, 9.36, 0.24,
    ],
];
const COL_SUMS: [[f64; 14]; 3] = [
    [
        1743.16, 445.25, 269.39, 173.12, 138.13, 119.29, 107.24, 98.73, 92.29, 87.23, 83.14, 79.75,
        76.98, 74.65,
    ],
    [
        205.35, 70.54, 52.4, 42.95, 40.01, 38.49, 37.53, 36.76, 36.14, 35.57, 35.13, 34.77, 34.47,
        34.16,
    ],
    [
        76.77, 64.3, 57.83, 51.42, 48.0, 45.56, 43.63, 42.08, 40.75, 39.64, 38.71, 37.93, 37.22,
        36.53,
    ],
];

#[test]
fn transcription_matches_the_printed_row_and_column_sums() {
    for (q, t) in [DRAG, LIFT, TORQUE].iter().enumerate() {
        for i in 0..19 {
            let s: f64 = t[i].iter().sum();
            assert!((s - ROW_SUMS[q][i]).abs() < 5e-9, "table {q} row {i}: {s}");
        }
        for j in 0..14 {
            let s: f64 = t.iter().map(|r| r[j]).sum();
            assert!(
                (s - COL_SUMS[q][j]).abs() < 5e-9,
                "table {q} column {j}: {s}"
            );
        }
    }
    // the printed column headers are the rounded Re_e
    let printed = [
        0.46, 2.32, 4.64, 9.28, 13.92, 18.57, 23.21, 27.85, 32.49, 37.13, 41.77, 46.42, 51.06, 55.7,
    ];
    for (j, p) in printed.iter().enumerate() {
        assert!((re_e(j) - p).abs() < 0.006, "{j}");
    }
}

#[test]
#[allow(clippy::needless_range_loop)]
fn run_time_model_interpolates_every_node() {
    let m = disc_model();
    let mut worst: f64 = 0.0;
    for i in 0..19 {
        for j in 0..14 {
            let c = m.coefficients(re_e(j), PHI_DEG[i].to_radians());
            for (q, v) in [c.drag, c.lift, c.torque].into_iter().enumerate() {
                let want = node_value(q, i, j, false);
                worst = worst.max((v - want).abs() / want.abs().max(1e-3));
            }
        }
    }
    assert!(worst < 1e-12, "{worst}");
}

/// The numbers reported for each method and split.
fn report(method: DiscMethod, split: Split) -> HeldOut {
    let h = held_out(method, split);
    println!(
        "{method:?} {split:?}: max rel (D, L, T) = {:.4?}, mean rel = {:.4?}, \
         max abs at 0/90 deg = {:.3?}, nodes {}, worst (deg, Re_e) {:.2?}",
        h.max_relative, h.mean_relative, h.max_absolute_at_symmetry, h.nodes, h.worst_node
    );
    h
}

#[test]
fn spline_reproduces_held_out_nodes_within_2_percent() {
    // Leave one Re column out, one angle row out, every other column out. The 2 % criterion
    // applies to the mean error everywhere and to the maximum for drag; the lift and torque
    // maxima are reported (≈ 3 % at held-out columns, 12-16 % at the held-out 85° row at the
    // highest Re, where they fall steeply to 0 at 90°). At 0° and 90° the lift and torque
    // error is absolute (against the printed noise values 0.01-0.08).
    for split in [
        Split::LeaveOneColumnOut,
        Split::LeaveOneRowOut,
        Split::EveryOtherColumn,
    ] {
        let h = report(DiscMethod::Spline, split);
        for q in 0..3 {
            assert!(
                h.mean_relative[q] < 0.006,
                "{split:?} {q}: {:?}",
                h.mean_relative
            );
        }
        assert!(h.max_relative[0] < 0.02, "{split:?}: {:?}", h.max_relative);
        assert!(h.max_absolute_at_symmetry[1] <= 0.011);
        assert!(h.max_absolute_at_symmetry[2] <= 0.081);
        if split != Split::LeaveOneRowOut {
            assert!(h.max_relative.iter().all(|&e| e < 0.03), "{split:?}: {h:?}");
        } else {
            assert!(h.max_relative.iter().all(|&e| e < 0.2), "{split:?}: {h:?}");
            // away from the 85° row the 2 % holds
            assert_eq!(h.worst_node[1], (85.0, re_e(13)));
        }
    }
}

#[test]
fn first_column_is_stokes_plus_oseen_on_the_volume_equivalent_basis() {
    // C_D Re_e = 24 K (1 + (3/16) K Re_e) to first order (Brenner), K from the Stokes
    // resistance of the 1:10 spheroid
    let (ke, kb) = stokes_factors(ASPECT_RATIO);
    let re = re_e(0);
    for (k, c) in [(ke, DRAG[0][0]), (kb, DRAG[18][0])] {
        let oseen = 24.0 * k * (1.0 + 3.0 / 16.0 * k * re);
        assert!((c * re / oseen - 1.0).abs() < 0.03, "{} {oseen}", c * re);
    }
    // Stokes lift at 45 deg: C_L / C_D = (C_D90 − C_D0)/(C_D90 + C_D0)
    let ratio = (DRAG[18][0] - DRAG[0][0]) / (DRAG[18][0] + DRAG[0][0]);
    let table = LIFT[9][0] / DRAG[9][0];
    assert!((table / ratio - 1.0).abs() < 0.08, "{table} {ratio}");
}

#[test]
fn continuation_below_and_above_the_table() {
    let m = disc_model();
    let phi = 0.7;
    let at = m.continued(re_e(0), phi);
    for re in [0.0, 1e-6, 0.2] {
        let c = m.continued(re, phi);
        // drag and lift ∝ |u| (C·Re held), torque coefficient held
        assert!((c.0 - at.0).abs() < 1e-12 && (c.1 - at.1).abs() < 1e-12);
        assert!((c.2 - at.2).abs() < 1e-12);
    }
    let top = m.coefficients(re_e(13), phi);
    let far = m.coefficients(500.0, phi);
    assert!((far.drag - top.drag).abs() < 1e-12 && (far.torque - top.torque).abs() < 1e-12);
    // φ outside [0, π/2] is clamped; NaN gives zeros
    assert_eq!(m.continued(10.0, -0.3), m.continued(10.0, 0.0));
    assert_eq!(m.continued(f64::NAN, 0.3), (0.0, 0.0, 0.0));
    assert_eq!(m.continued(3.0, f64::NAN), (0.0, 0.0, 0.0));
    let inf = m.continued(f64::INFINITY, 0.3);
    assert!(inf.0.is_finite() && inf.1.is_finite() && inf.2.is_finite());
    // lift and torque vanish at 0 and 90 deg at every Re
    for re in [0.1, 1.0, 7.0, 40.0, 55.0] {
        for phi in [0.0, std::f64::consts::FRAC_PI_2] {
            let c = m.continued(re, phi);
            assert!(c.1.abs() < 1e-12 && c.2.abs() < 1e-12, "{re} {phi} {c:?}");
        }
    }
}

#[test]
fn held_out_features_of_the_database_are_kept() {
    // drag maximum near 80-85 deg at the highest Re (not at 90)
    let m = disc_model();
    let re = re_e(13);
    let at = |deg: f64| m.coefficients(re, deg.to_radians()).drag;
    assert!(at(82.5) > at(90.0));
    // lift at Re_e 50 is asymmetric about 45 deg
    let l = |deg: f64| m.coefficients(50.0, deg.to_radians()).lift;
    assert!(l(30.0) > l(60.0) * 1.1);
}

#[test]
#[ignore = "exploration of parametrisations; prints only"]
fn explore_parametrisations() {
    let mut variants = Vec::new();
    for shift in [0.0, 0.5, 1.0] {
        variants.push(Variant {
            times_re: [true, true, false],
            x_shift: shift,
            x_power: 0.0,
        });
    }
    for power in [0.25, 1.0 / 3.0, 0.5, 0.75] {
        for times_re in [[true, true, false], [true, true, true]] {
            variants.push(Variant {
                times_re,
                x_shift: 0.0,
                x_power: power,
            });
        }
    }
    for v in variants {
        for split in [Split::LeaveOneColumnOut, Split::EveryOtherColumn] {
            let h = held_out_variant(DiscMethod::Spline, v, split);
            println!(
                "{v:?} {split:?}: max {:.4?} mean {:.4?} worst {:.1?}",
                h.max_relative, h.mean_relative, h.worst_node
            );
        }
    }
}
