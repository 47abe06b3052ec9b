//! The fused fixed step against its reference (the stepper's generic fixed step).

use super::*;
use crate::brownian::stepper::advance;
use magsep_components::brownian::StepControl;
use rand::{RngExt, SeedableRng};

fn model() -> ForceModel {
    ForceModel {
        sources: Vec::new(),
        b_ext: DVec3::X,
        tolerance: 1e-6,
        kt: 4.1e-21,
        mie: None,
        dipole_cutoff: None,
        field_patch: None,
    }
}

/// Positions and random streams after one fused step and after the reference (drift from
/// `velocities`, then `advance` with fixed steps) are bitwise the same, with fixed particles,
/// mixed radii and a liquid flow, on one and on two threads.
#[test]
fn the_fused_fixed_step_is_the_generic_one_bit_for_bit() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(21);
    let n = 3000; // above the parallel threshold
    let x0: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 1e-5)
        .collect();
    let f: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 1e-13 - 5e-14)
        .collect();
    let radii: Vec<f64> = (0..n).map(|i| [75e-9, 50e-9, 120e-9][i % 3]).collect();
    let laws = vec![MomentModel::default(); n];
    let mobile: Vec<bool> = (0..n).map(|i| i % 13 != 4).collect();
    let streams: Vec<Xoshiro256PlusPlus> = (0..n as u64)
        .map(|i| Xoshiro256PlusPlus::seed_from_u64(1000 + i))
        .collect();
    let model = model();
    let extra = vec![DVec3::ZERO; n];
    let dt = 5e-6;
    let run = |fused: bool, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut lists = PairLists::default();
            let mut d = PipelineDynamics {
                model: &model,
                radii: &radii,
                laws: &laws,
                mobile: mobile.clone(),
                captured_interact: false,
                extra: &extra,
                kernels: None,
                ids: &[],
                shapes: &[],
                time: (0.0, dt),
                fraction: 0.0,
                kernel_out: Vec::new(),
                viscosity: 1e-3,
                kt: model.kt,
                flow: DVec3::new(1e-4, -2e-5, 0.0),
                flow_field: None,
                hydro: None,
                lists: &mut lists,
                start_moments: &[],
                list_builds: 0,
                hard_core: false,
                step: 0,
                captures: Vec::new(),
                parts: Default::default(),
                sweeps: 0,
                failure: None,
            };
            let (mut x, mut r) = (x0.clone(), streams.clone());
            let mut stats = BrownianStats::default();
            if fused {
                d.fixed_free_step(&mut x, |i| f[i], dt, &mut r, &mut stats);
            } else {
                let mut v0 = vec![DVec3::ZERO; n];
                d.velocities(&x, &f, &mut v0);
                let mut xv = x.clone();
                let control = StepControl::Fixed;
                advance(&mut d, &mut xv, Some(v0), dt, &control, &mut r, &mut stats);
                x = xv;
            }
            (x, r, stats.substeps, stats.particle_substeps)
        })
    };
    let (xr, rr, sr, pr) = run(false, 1);
    let bits = |x: &[DVec3]| -> Vec<[u64; 3]> {
        x.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
    };
    assert_eq!(
        xr.iter().zip(&x0).filter(|(a, b)| a != b).count(),
        n - n / 13 - 1
    );
    for threads in [1, 2] {
        let (xf, rf, sf, pf) = run(true, threads);
        assert!(bits(&xf) == bits(&xr), "{threads} threads");
        assert!(rf == rr, "random streams, {threads} threads");
        assert_eq!((sf, pf), (sr, pr));
    }
}
