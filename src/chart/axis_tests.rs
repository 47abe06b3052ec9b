//! Range, tick and label tests.

use super::*;

fn labels(t: &Ticks) -> Vec<&str> {
    t.major.iter().map(|t| t.1.as_str()).collect()
}

fn lin(lo: f64, hi: f64) -> Axis {
    Axis { log: false, lo, hi }
}

fn log(lo: f64, hi: f64) -> Axis {
    Axis { log: true, lo, hi }
}

#[test]
fn linear_ticks_are_nice_and_labelled_exactly() {
    assert_eq!(
        labels(&axis_ticks(&lin(0.0, 1.0), 6, false)),
        ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]
    );
    assert_eq!(
        labels(&axis_ticks(&lin(-0.4, 10.4), 6, false)),
        ["0", "2", "4", "6", "8", "10"]
    );
    assert_eq!(
        labels(&axis_ticks(&lin(0.0, 3e6,), 4, false)),
        ["0", "1e6", "2e6", "3e6"]
    );
    assert_eq!(
        labels(&axis_ticks(&lin(0.0, 4e-4), 5, false)),
        ["0", "1e-4", "2e-4", "3e-4", "4e-4"]
    );
    for (lo, hi) in [
        (0.0, 1.0),
        (-7.3, 2.2),
        (1e-6, 3e-6),
        (1234.0, 98765.0),
        (0.91, 1.002),
    ] {
        let t = axis_ticks(&lin(lo, hi), 8, false);
        assert!(
            (2..=8).contains(&t.major.len()),
            "{lo}..{hi}: {:?}",
            labels(&t)
        );
        assert!(t.major.iter().all(|m| m.0 >= lo && m.0 <= hi));
        let step = t.major[1].0 - t.major[0].0;
        let mant = step / 10f64.powf(step.log10().floor());
        assert!(
            [1.0, 2.0, 5.0].iter().any(|m| (mant - m).abs() < 1e-6),
            "step {step}"
        );
    }
    assert_eq!(format_sci(9.999_999_999e5, 5), "1e6");
    assert_eq!(format_sci(-2.5e-7, -8), "-2.5e-7");
}

#[test]
fn log_decades_and_minors() {
    let t = axis_ticks(&log(-3.2, 2.1), 8, true);
    assert_eq!(labels(&t), ["1e-3", "0.01", "0.1", "1", "10", "100"]);
    assert!(t.minor.iter().any(|&m| (m - 2f64.log10()).abs() < 1e-12));
    assert!(t.minor.iter().all(|&m| (-3.2..=2.1).contains(&m)));
    assert!(axis_ticks(&log(-3.2, 2.1), 8, false).minor.is_empty());
    // Many decades are thinned.
    let t = axis_ticks(&log(-30.5, 30.5), 8, true);
    assert!(
        (2..=8).contains(&t.major.len()) && labels(&t).contains(&"1e10"),
        "{:?}",
        labels(&t)
    );
}

#[test]
fn log_narrow_ranges_still_get_ticks() {
    let t = axis_ticks(&log(2f64.log10(), 8f64.log10()), 8, true);
    assert_eq!(labels(&t), ["2", "3", "4", "5", "6", "7", "8"]);
    let t = axis_ticks(&log(0.15f64.log10(), 9.5f64.log10()), 6, true);
    assert_eq!(labels(&t), ["0.2", "0.5", "1", "2", "5"]);
    let t = axis_ticks(&log(1.01f64.log10(), 1.05f64.log10()), 8, true);
    assert!(t.major.len() >= 2 && labels(&t).iter().all(|l| l.starts_with("1.0")));
    assert!(axis_ticks(&log(1.0, 1.0), 8, true).major.is_empty());
}

#[test]
fn ranges() {
    let a = resolve_axis(&[0.0, 10.0], false, None);
    assert_eq!((a.lo, a.hi), (-0.5, 10.5));
    let a = resolve_axis(&[], false, None);
    assert_eq!((a.lo, a.hi), (0.0, 1.0));
    let a = resolve_axis(&[3.0, 3.0], false, None);
    assert!(a.lo < 3.0 && a.hi > 3.0);
    let a = resolve_axis(&[1.0], true, None);
    assert_eq!((a.lo, a.hi), (0.5, 1.5));
    let a = resolve_axis(&[0.0, 1.0], false, Some((5.0, -5.0)));
    assert_eq!((a.lo, a.hi), (-5.0, 5.0));
    let a = resolve_axis(&[0.0, 1.0], false, Some((f64::NAN, 2.0)));
    assert_eq!((a.lo, a.hi), (-0.05, 2.0));
    let a = resolve_axis(&[0.0, 2.0], true, Some((-1.0, 1000.0)));
    assert_eq!((a.lo, a.hi), (-0.1, 3.0));
    let a = resolve_axis(&[0.0, 1.0], false, Some((4.0, 4.0)));
    assert!(a.lo < 4.0 && a.hi > 4.0);
}

#[test]
fn chosen_labels_never_overlap() {
    let axes = [
        lin(-0.05, 1.05),
        lin(-1.234e7, 9.87e8),
        lin(0.999_999, 1.000_001),
        log(-3.2, 2.1),
        log(-15.3, 0.2),
        log(-300.0, 300.0),
        log(0.3, 0.9),
    ];
    for axis in &axes {
        for len in [10.0, 40.0, 150.0, 600.0] {
            for horizontal in [true, false] {
                let t = choose_ticks(axis, len, horizontal, 11.0);
                assert!(t.major.len() <= 8, "{axis:?}");
            }
        }
        assert!(
            choose_ticks(axis, 400.0, false, 11.0).major.len() >= 3,
            "{axis:?}"
        );
    }
}

#[test]
fn plot_axis_maps_log_and_linear() {
    let a = log(0.0, 2.0);
    let p = PlotAxis::new(&a, &axis_ticks(&a, 8, true));
    assert_eq!(p.map(&10.0, (0, 100)), 50);
    let bold = p.key_points(plotters::coord::ranged1d::BoldPoints(8));
    assert_eq!(bold, vec![1.0, 10.0, 100.0]);
    assert_eq!(p.key_points(8usize).len(), 16, "light: 2..9 in two decades");
    let l = lin(0.0, 4.0);
    let p = PlotAxis::new(&l, &axis_ticks(&l, 5, false));
    assert_eq!(p.map(&1.0, (0, 100)), 25);
    assert_eq!(label_of(&l, &axis_ticks(&l, 5, false), 2.0), "2");
}
