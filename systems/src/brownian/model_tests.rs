//! Tests of the force model's pair kernels (split from `model.rs`).
use super::*;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// `n` positions uniform in the cube `[0, edge]^3` \[m\].
fn positions_in_box(rng: &mut Xoshiro256PlusPlus, n: usize, edge: f64) -> Vec<DVec3> {
    (0..n)
        .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * edge)
        .collect()
}

/// A force model in the uniform field `b_ext` \[T\] (no fibres), kT = 4e-21 J, with the
/// contact law `mie` and the dipole cut-off `cutoff` (mean radii).
fn uniform_field_model(b_ext: DVec3, mie: Option<Mie>, cutoff: f64) -> ForceModel {
    ForceModel {
        sources: Vec::new(),
        b_ext,
        tolerance: 1e-6,
        kt: 4e-21,
        mie,
        dipole_cutoff: Some(cutoff),
        field_patch: None,
    }
}

#[test]
fn the_pair_kernel_equals_the_direct_sums() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let n = 900;
    let x = positions_in_box(&mut rng, n, 4e-6);
    let radii: Vec<f64> = (0..n).map(|i| [75e-9, 100e-9, 50e-9][i % 3]).collect();
    let moments: Vec<DVec3> = (0..n)
        .map(|i| {
            if i % 11 == 5 {
                DVec3::ZERO // non-magnetic
            } else {
                DVec3::new(rng.random(), rng.random(), rng.random()) * 1e-16
            }
        })
        .collect();
    let laws = vec![MomentModel::default(); n];
    let model = uniform_field_model(DVec3::X, None, 12.0);
    // captured particles that keep interacting, and ones that do not
    let mobile: Vec<bool> = (0..n).map(|i| i % 7 != 2).collect();
    // one `PairLists` for all three passes: the per-pair buffer is reused with another
    // pair count each time (fewer pairs without the captured ones, then more again)
    let mut lists = PairLists::default();
    for interact in [true, false, true] {
        let exerts: Vec<bool> = mobile.iter().map(|&m| m || interact).collect();
        let view = ParticleView {
            radii: &radii,
            moments: &laws,
            mobile: &mobile,
            exerts: &exerts,
        };
        model.update_lists(&x, &view, &mut lists);
        assert!(lists.dipole.pair_count() > 10 * n, "dense enough to test");
        let (mut fast, mut direct) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        model.dipole_forces(&x, &moments, &view, &lists, &mut fast);
        model.dipole_forces_direct(&x, &moments, &view, &lists, &mut direct);
        let scale = direct.iter().map(|f| f.length()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for i in 0..n {
            assert!(
                (fast[i] - direct[i]).length() <= 1e-13 * scale,
                "{i}: {} {}",
                fast[i],
                direct[i]
            );
            if !mobile[i] {
                assert_eq!(fast[i], DVec3::ZERO);
            }
        }
    }
}

#[test]
fn cached_lists_give_the_forces_of_fresh_lists_bit_for_bit() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
    let n = 600;
    let a = 75e-9;
    let mut x = positions_in_box(&mut rng, n, 3e-6);
    let model = uniform_field_model(
        DVec3::new(0.3, 0.0, 1.0),
        Some(Mie::new(4e-19, 30.0, 15.0)),
        10.0,
    );
    let laws = vec![MomentModel::Saturated { moment: 1e-16 }; n];
    let (radii, mobile) = (vec![a; n], vec![true; n]);
    let view = ParticleView {
        radii: &radii,
        moments: &laws,
        mobile: &mobile,
        exerts: &mobile,
    };
    let (mut cached, mut fresh) = (PairLists::default(), PairLists::default());
    fresh.set_rebuild_always(true);
    let (mut pc, mut pf) = (ForceParts::zeros(n), ForceParts::zeros(n));
    for _ in 0..40 {
        model.evaluate(&x, &view, &mut cached, &mut pc);
        model.evaluate(&x, &view, &mut fresh, &mut pf);
        assert_eq!(pc, pf);
        for p in x.iter_mut() {
            *p += DVec3::new(rng.random(), rng.random(), rng.random()) * 8e-9 - 4e-9;
        }
    }
    assert!(pc.dipole.iter().any(|f| *f != DVec3::ZERO));
    assert!(
        cached.builds() > 2 && cached.builds() < 40,
        "{}",
        cached.builds()
    );
    assert_eq!(fresh.builds(), 80);
}

/// The fused pass (dipole gather and contact sum of a particle together) gives bit for bit
/// the separate passes' forces, on one, two and three threads (parts), with captured particles in the
/// mix (some exerting, some not).
#[test]
fn the_fused_pair_pass_equals_the_separate_passes_bit_for_bit() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(21);
    let n = 1500;
    let a = 75e-9;
    // dense enough for contacts (Mie range 2.1 a) and many dipole pairs
    let x = positions_in_box(&mut rng, n, 2.2e-6);
    let model = uniform_field_model(
        DVec3::new(0.2, 0.0, 1.0),
        Some(Mie::new(4e-21, 12.0, 6.0)),
        8.0,
    );
    let laws = vec![MomentModel::Saturated { moment: 1e-17 }; n];
    let radii = vec![a; n];
    let mobile: Vec<bool> = (0..n).map(|i| i % 13 != 6).collect();
    let moments: Vec<DVec3> = (0..n)
        .map(|i| {
            if i % 17 == 3 {
                DVec3::ZERO
            } else {
                DVec3::new(1.0, rng.random::<f64>() - 0.5, 0.1) * 1e-17
            }
        })
        .collect();
    for interact in [true, false] {
        let exerts: Vec<bool> = mobile.iter().map(|&m| m || interact).collect();
        let view = ParticleView {
            radii: &radii,
            moments: &laws,
            mobile: &mobile,
            exerts: &exerts,
        };
        let mut lists = PairLists::default();
        model.update_lists(&x, &view, &mut lists);
        let (mut d, mut c) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        model.dipole_forces(&x, &moments, &view, &lists, &mut d);
        model.contact_forces(&x, &view, &lists, &mut c);
        assert!(
            c.iter().filter(|f| **f != DVec3::ZERO).count() > 10,
            "contacts"
        );
        assert!(d.iter().filter(|f| **f != DVec3::ZERO).count() > n / 2);
        // three threads: a middle part, whose pairs come from the parts on both sides
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (mut fd, mut fc) = (vec![DVec3::X; n], vec![DVec3::X; n]);
            pool.install(|| model.pair_forces(&x, &moments, &view, &lists, (&mut fd, &mut fc)));
            let bits = |v: &[DVec3]| -> Vec<[u64; 3]> {
                v.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
            };
            assert!(
                bits(&fd) == bits(&d),
                "dipole, {threads} threads, {interact}"
            );
            assert!(
                bits(&fc) == bits(&c),
                "contact, {threads} threads, {interact}"
            );
            // bounds moved as far as the learnt balance moves them, either way: the same bits
            for sign in [-1.0, 1.0] {
                let shift = sign * 0.4 / threads as f64;
                lists.balance.set(threads, n, vec![shift; threads - 1]);
                let (mut sd, mut sc) = (vec![DVec3::X; n], vec![DVec3::X; n]);
                pool.install(|| model.pair_forces(&x, &moments, &view, &lists, (&mut sd, &mut sc)));
                assert!(
                    bits(&sd) == bits(&d) && bits(&sc) == bits(&c),
                    "shift {shift}"
                );
            }
            lists.balance.set(threads, n, Vec::new());
        }
    }
}

/// The step's start with a uniform field's moments in the parts of the lists' displacement
/// tests gives the moments, field forces and lists of the two separate calls, on one and two
/// threads (a first call that builds the lists, a second that they serve).
#[test]
fn the_fused_step_start_equals_the_separate_calls() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let n = 2100;
    let x = positions_in_box(&mut rng, n, 3.0e-6);
    let model = uniform_field_model(
        DVec3::new(0.0, 0.3, 1.0),
        Some(Mie::new(4e-21, 12.0, 6.0)),
        8.0,
    );
    // runs of laws, some non-magnetic
    let laws: Vec<MomentModel> = (0..n)
        .map(|i| match (i / 300) % 3 {
            0 => MomentModel::Saturated { moment: 1e-17 },
            1 => MomentModel::None,
            _ => MomentModel::Saturated { moment: 2e-17 },
        })
        .collect();
    let radii = vec![75e-9; n];
    let mobile = vec![true; n];
    let exerts = vec![true; n];
    let view = ParticleView {
        radii: &radii,
        moments: &laws,
        mobile: &mobile,
        exerts: &exerts,
    };
    let mut reference = PairLists::default();
    let (mut m0, mut f0) = (vec![DVec3::ZERO; n], vec![DVec3::X; n]);
    model.moments_and_field(&x, &view, &mut reference.patches, &mut m0, &mut f0);
    let builds = model.update_lists(&x, &view, &mut reference);
    assert_eq!(builds, 2);
    assert_eq!(m0.iter().filter(|m| **m == DVec3::ZERO).count(), 600);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut lists = PairLists::default();
        let (mut m, mut f) = (vec![DVec3::Y; n], vec![DVec3::X; n]);
        // the first call builds the lists, the second finds them serving
        for round in 0..2 {
            let built = pool.install(|| model.prepare_step(&x, &view, &mut lists, &mut m, &mut f));
            assert_eq!(built, if round == 0 { 2 } else { 0 }, "{threads} threads");
            assert_eq!(m, m0, "moments, {threads} threads, round {round}");
            assert_eq!(f, f0, "field forces, {threads} threads, round {round}");
        }
        assert_eq!(lists.dipole.pair_count(), reference.dipole.pair_count());
    }
}
