use super::*;
use crate::brownian::stepper::advance;
use crate::rng::particle_stream;
use magsep_components::brownian::StepControl;

/// Particles with linear springs between listed pairs and a harmonic trap each (unit radius,
/// mobility and kT).
struct Springs {
    radii: Vec<f64>,
    mobile: Vec<bool>,
    /// (i, j, stiffness)
    pairs: Vec<(usize, usize, f64)>,
    trap: f64,
    /// √(2 kT μ): 0 for the deterministic limit.
    noise: f64,
}

impl Springs {
    fn force(&self, x: &[DVec3], i: usize) -> DVec3 {
        if !self.mobile[i] {
            return DVec3::ZERO; // fixed particles do not move
        }
        let mut f = -x[i] * self.trap;
        for &(a, b, k) in &self.pairs {
            if a == i {
                f -= (x[a] - x[b]) * k;
            } else if b == i {
                f -= (x[b] - x[a]) * k;
            }
        }
        f
    }
}

impl Dynamics for Springs {
    fn radii(&self) -> &[f64] {
        &self.radii
    }
    fn mobile(&self) -> &[bool] {
        &self.mobile
    }
    fn drift(&mut self, x: &[DVec3], v: &mut [DVec3]) {
        for (i, vi) in v.iter_mut().enumerate().take(x.len()) {
            *vi = self.force(x, i);
        }
    }
    fn noise(&mut self, w: &[DVec3], out: &mut [DVec3]) {
        for ((o, wi), &m) in out.iter_mut().zip(w).zip(&self.mobile) {
            *o = if m { *wi * self.noise } else { DVec3::ZERO };
        }
    }
}

impl LocalDynamics for Springs {
    fn drift_of(&mut self, x: &[DVec3], active: &[usize], v: &mut [DVec3]) {
        for &i in active {
            v[i] = self.force(x, i);
        }
    }
    fn partners(&mut self, _x: &[DVec3], i: usize, f: &mut dyn FnMut(usize)) {
        for &(a, b, _) in &self.pairs {
            if a == i {
                f(b);
            } else if b == i {
                f(a);
            }
        }
    }
}

fn springs(n: usize, pairs: Vec<(usize, usize, f64)>) -> Springs {
    Springs {
        radii: vec![1.0; n],
        mobile: vec![true; n],
        pairs,
        trap: 1.0,
        noise: 2f64.sqrt(),
    }
}

const TOL: f64 = 1e-2;

fn run(
    d: &mut Springs,
    ids: &[u64],
    steps: usize,
    dt: f64,
    multirate: bool,
    tol: f64,
) -> (Vec<DVec3>, BrownianStats) {
    let mut x: Vec<DVec3> = ids.iter().map(|&i| DVec3::X * (i as f64) * 0.1).collect();
    let mut rngs: Vec<_> = ids.iter().map(|&i| particle_stream(4, i)).collect();
    let mut stats = BrownianStats::default();
    for _ in 0..steps {
        if multirate {
            advance_multirate(d, &mut x, None, dt, (tol, 0.5, 30), &mut rngs, &mut stats);
        } else {
            let control = StepControl::Adaptive {
                tolerance: tol,
                max_displacement: 0.5,
                max_depth: 30,
            };
            let mut xv = x.clone();
            advance(d, &mut xv, None, dt, &control, &mut rngs, &mut stats);
            x = xv;
        }
    }
    (x, stats)
}

#[test]
fn independent_particles_take_their_own_global_paths_bit_for_bit() {
    // particle 0 sits in a stiff trap of its own (a self-spring to a fixed anchor 1), the
    // rest are free in the soft trap
    let n = 12;
    let ids: Vec<u64> = (0..n as u64).collect();
    let stiff = vec![(0, 1, 400.0)];
    let mut fixed_anchor = springs(n, stiff.clone());
    fixed_anchor.mobile[1] = false;
    let (xm, sm) = run(&mut fixed_anchor, &ids, 20, 1e-2, true, TOL);
    let mut global = springs(n, stiff);
    global.mobile[1] = false;
    let (xg, sg) = run(&mut global, &ids, 20, 1e-2, false, TOL);
    assert!(
        sg.rejections > 20,
        "the stiff particle must be refined: {sg:?}"
    );
    // the stiff particle: the same decisions, the same draws, the same path
    assert_eq!(xm[0], xg[0]);
    // the free ones: their path is the global scheme's when nothing fails (run without 0, 1)
    let rest: Vec<u64> = ids[2..].to_vec();
    let mut free = springs(n - 2, Vec::new());
    let (xf, sf) = run(&mut free, &rest, 20, 1e-2, false, TOL);
    assert_eq!(sf.rejections, 0);
    assert_eq!(&xm[2..], &xf[..]);
    // cost: the free particles took 2 sub-steps per step, particle 0 those of the global run
    assert_eq!(sm.particle_substeps, 2 * 20 * (n as u64 - 2) + sg.substeps);
}

#[test]
fn without_noise_it_converges_to_the_ode_solution() {
    // a stiff pair inside a soft chain: the interpolated neighbours couple fast and slow
    // particles; the error of one step must fall with the tolerance
    let n = 8;
    let ids: Vec<u64> = (0..n as u64).collect();
    let mut pairs: Vec<(usize, usize, f64)> = (0..n - 1).map(|i| (i, i + 1, 1.0)).collect();
    pairs.push((3, 4, 300.0));
    let quiet = |p: &Vec<(usize, usize, f64)>| Springs {
        noise: 0.0,
        ..springs(n, p.clone())
    };
    let x0: Vec<DVec3> = ids
        .iter()
        .map(|&i| DVec3::new(i as f64 * 0.1, (i % 3) as f64 * 0.2, 0.0))
        .collect();
    // reference: 2^14 fixed Euler steps
    let (dt, fine) = (0.1, 1 << 14);
    let mut xr = x0.clone();
    let mut d = quiet(&pairs);
    let mut rngs: Vec<_> = ids.iter().map(|&i| particle_stream(4, i)).collect();
    let mut stats = BrownianStats::default();
    for _ in 0..fine {
        advance(
            &mut d,
            &mut xr,
            None,
            dt / fine as f64,
            &StepControl::Fixed,
            &mut rngs,
            &mut stats,
        );
    }
    let mut errs = Vec::new();
    for tol in [1e-2, 1e-3, 1e-4] {
        let mut x = x0.clone();
        let mut d = quiet(&pairs);
        let mut rngs: Vec<_> = ids.iter().map(|&i| particle_stream(4, i)).collect();
        let mut st = BrownianStats::default();
        advance_multirate(&mut d, &mut x, None, dt, (tol, 0.5, 30), &mut rngs, &mut st);
        assert!(st.rejections > 0, "the stiff pair is refined");
        errs.push(
            x.iter()
                .zip(&xr)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0, f64::max),
        );
    }
    assert!(errs[0] > 0.0 && errs[0] < 0.05, "{errs:?}");
    // local error control: the global error falls like √tol
    assert!(errs[2] < 0.2 * errs[0], "{errs:?}");
}

#[test]
fn a_stiff_pair_samples_its_boltzmann_distribution() {
    // two particles in unit traps joined by a spring of 300, among free soft ones: the
    // relative coordinate has E|x1 − x2|² = 3 · 2/(1 + 2·300) (kT = μ = 1), the sum's
    // E|x1 + x2|² = 3 · 2/1
    let n = 6;
    let ids: Vec<u64> = (0..n as u64).collect();
    let mut d = springs(n, vec![(0, 1, 300.0)]);
    let mut x = vec![DVec3::ZERO; n];
    let mut rngs: Vec<_> = ids.iter().map(|&i| particle_stream(21, i)).collect();
    let mut stats = BrownianStats::default();
    let (mut rel, mut sum, mut samples) = (0.0, 0.0, 0.0);
    // (at tolerance 1e-2 the explicit update's own bias on the stiff mode is ~12 %)
    for step in 0..20_000 {
        advance_multirate(
            &mut d,
            &mut x,
            None,
            0.05,
            (1e-3, 0.5, 30),
            &mut rngs,
            &mut stats,
        );
        if step >= 200 {
            rel += (x[0] - x[1]).length_squared();
            sum += (x[0] + x[1]).length_squared();
            samples += 1.0;
        }
    }
    let (rel, sum) = (rel / samples, sum / samples);
    let want_rel = 6.0 / 601.0;
    assert!((rel / want_rel - 1.0).abs() < 0.05, "{rel} vs {want_rel}");
    assert!((sum / 6.0 - 1.0).abs() < 0.15, "{sum} vs 6");
    // the free particles were not refined along
    let per = stats.particle_substeps as f64 / (20_000.0 * n as f64);
    assert!(
        per < 0.5 * stats.substeps as f64 / 20_000.0,
        "{per} {stats:?}"
    );
}

#[test]
fn one_stiff_pair_does_not_refine_everyone() {
    let n = 400;
    let ids: Vec<u64> = (0..n as u64).collect();
    let pairs = vec![(10, 11, 500.0), (11, 12, 1.0)];
    let (xm, sm) = run(&mut springs(n, pairs.clone()), &ids, 10, 1e-2, true, TOL);
    let (_, sg) = run(&mut springs(n, pairs), &ids, 10, 1e-2, false, TOL);
    let mr = sm.particle_substeps as f64 / (10.0 * n as f64);
    let gl = sg.substeps as f64 / 10.0;
    assert!(gl > 8.0, "the global scheme bisects everyone: {gl}");
    assert!(mr < 3.0, "multirate: {mr} sub-steps per particle-step");
    assert!(xm.iter().all(|p| p.is_finite()));
}
