use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::*;
use crate::collision::toi::Plane;

/// Solid spheres with their state.
#[derive(Debug, Clone, PartialEq)]
struct Spheres {
    x: Vec<DVec3>,
    v: Vec<DVec3>,
    w: Vec<DVec3>,
    r: Vec<f64>,
    inv_m: Vec<f64>,
    inv_i: Vec<f64>,
    rho: Vec<f64>,
}

impl Spheres {
    fn new(x: Vec<DVec3>, v: Vec<DVec3>, radius: f64, density: f64) -> Self {
        let n = x.len();
        let m = density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        Self {
            x,
            v,
            w: vec![DVec3::ZERO; n],
            r: vec![radius; n],
            inv_m: vec![1.0 / m; n],
            inv_i: vec![1.0 / (0.4 * m * radius * radius); n],
            rho: vec![density; n],
        }
    }

    fn step(
        &mut self,
        engine: &mut CollisionEngine,
        domain: &CollisionDomain,
        model: &CollisionModel,
        h: f64,
    ) -> CollisionReport {
        let arrays = ParticleArrays {
            positions: &mut self.x,
            velocities: &mut self.v,
            angular_velocities: &mut self.w,
            radii: &self.r,
            inv_masses: &self.inv_m,
            inv_inertias: InverseInertia::Scalar(&self.inv_i),
            densities: &self.rho,
            spheroids: None,
        };
        engine.step(arrays, domain, model, h).unwrap()
    }

    fn momentum(&self) -> (DVec3, f64) {
        let p = self.v.iter().zip(&self.inv_m).map(|(v, w)| *v / *w);
        p.fold((DVec3::ZERO, 0.0), |(s, a), p| (s + p, a + p.length()))
    }

    fn kinetic_energy(&self) -> f64 {
        (0..self.x.len())
            .map(|i| {
                0.5 * self.v[i].length_squared() / self.inv_m[i]
                    + 0.5 * self.w[i].length_squared() / self.inv_i[i]
            })
            .sum()
    }
}

fn elastic() -> CollisionModel {
    CollisionModel::dry(1.0, 0.0, 0.0)
}

#[test]
fn head_on_equal_masses_exchange_velocities_at_the_right_time() {
    let mut s = Spheres::new(
        vec![DVec3::new(-0.01, 0.0, 0.0), DVec3::new(0.01, 0.0, 0.0)],
        vec![DVec3::new(1.0, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0)],
        1e-3,
        1000.0,
    );
    let mut engine = CollisionEngine::new(EngineConfig::default());
    let rep = s.step(&mut engine, &CollisionDomain::unbounded(), &elastic(), 0.02);
    assert_eq!(rep.stats.events, 1);
    let ev = rep.events[0];
    assert_eq!((ev.particle, ev.partner), (0, Partner::Particle(1)));
    assert!((ev.time - 0.009).abs() < 1e-15, "{}", ev.time);
    assert!((ev.approach_speed - 2.0).abs() < 1e-15);
    assert_eq!(
        s.v,
        vec![DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)]
    );
    assert!((s.x[0].x + 0.012).abs() < 1e-15 && (s.x[1].x - 0.012).abs() < 1e-15);
    let last = rep.last_collision[1].unwrap();
    assert_eq!(last.velocity_before, DVec3::new(-1.0, 0.0, 0.0));
    assert_eq!(last.velocity_after, DVec3::new(1.0, 0.0, 0.0));
    assert_eq!(rep.stats.max_overlap_after_projection, 0.0);
}

#[test]
fn fast_pairs_never_tunnel_at_any_step_size() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut engine = CollisionEngine::new(EngineConfig::default());
    for k in 0..40 {
        let h = 10f64.powf(-6.0 + 5.0 * k as f64 / 39.0);
        let speed = rng.random_range(1.0..300.0);
        let offset = rng.random_range(-1.5e-3..1.5e-3);
        let mut s = Spheres::new(
            vec![DVec3::new(-0.002, 0.0, 0.0), DVec3::new(0.002, offset, 0.0)],
            vec![DVec3::new(speed, 0.0, 0.0), DVec3::new(-speed, 0.0, 0.0)],
            1e-3,
            1000.0,
        );
        let t_hit = (0.004 - (4e-6 - offset * offset).sqrt()) / (2.0 * speed);
        let rep = s.step(&mut engine, &CollisionDomain::unbounded(), &elastic(), h);
        if t_hit <= h {
            assert_eq!(rep.stats.events, 1, "h {h}, speed {speed}");
            assert!((rep.events[0].time - t_hit).abs() < 1e-12 * t_hit.max(1e-9));
            assert!((s.x[1] - s.x[0]).length() >= 2e-3 * (1.0 - 1e-12));
        } else {
            assert_eq!(rep.stats.events, 0);
        }
    }
}

#[test]
fn newtons_cradle_is_a_sequence_of_binary_collisions() {
    // three touching spheres at rest, hit by a fourth: with e = 1, μ = 0 only the last leaves
    let mut s = Spheres::new(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(-1.5, 0.0, 0.0),
        ],
        vec![
            DVec3::ZERO,
            DVec3::ZERO,
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
        ],
        0.5,
        3.0 / (4.0 * std::f64::consts::PI * 0.125),
    );
    let (p0, _) = s.momentum();
    let e0 = s.kinetic_energy();
    let mut engine = CollisionEngine::new(EngineConfig::default());
    let rep = s.step(&mut engine, &CollisionDomain::unbounded(), &elastic(), 1.0);
    assert_eq!(rep.stats.events, 3);
    let times: Vec<f64> = rep.events.iter().map(|e| e.time).collect();
    assert!(times.iter().all(|t| (t - 0.5).abs() < 1e-15), "{times:?}");
    let (p1, scale) = s.momentum();
    assert!((p1 - p0).length() <= 1e-15 * scale, "{p0} {p1}");
    assert!((s.kinetic_energy() - e0).abs() <= 1e-12 * e0);
    assert!((s.v[2] - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-12);
    assert!(s.v[0].length() < 1e-12 && s.v[1].length() < 1e-12 && s.v[3].length() < 1e-12);
    assert!((s.x[2].x - 2.5).abs() < 1e-12 && (s.x[3].x + 1.0).abs() < 1e-12);
}

#[test]
fn collision_across_the_periodic_boundary() {
    let domain = CollisionDomain::unbounded().with_periodic(0, 0.0, 0.01);
    let mut s = Spheres::new(
        vec![DVec3::new(0.0015, 0.0, 0.0), DVec3::new(0.0085, 0.0, 0.0)],
        vec![DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)],
        1e-3,
        1000.0,
    );
    let mut engine = CollisionEngine::new(EngineConfig::default());
    let rep = s.step(&mut engine, &domain, &elastic(), 1e-3);
    assert_eq!(rep.stats.events, 1);
    assert!((rep.events[0].time - 5e-4).abs() < 1e-15);
    assert!((s.v[0] - DVec3::X).length() < 1e-15 && (s.v[1] + DVec3::X).length() < 1e-15);
    // unwrapped: both back where they started
    assert!((s.x[0].x - 0.0015).abs() < 1e-15 && (s.x[1].x - 0.0085).abs() < 1e-15);
}

#[test]
fn dropped_sphere_comes_to_rest_on_the_wall() {
    let (r, g, h) = (1e-3, 9.81, 1e-3);
    let floor = Plane::new(DVec3::ZERO, DVec3::Y);
    let domain = CollisionDomain::unbounded().with_plane(floor);
    let model = CollisionModel::dry(0.8, 0.3, 3.0 * g * h);
    let mut s = Spheres::new(
        vec![DVec3::new(0.0, 0.01, 0.0)],
        vec![DVec3::new(0.02, 0.0, 0.0)],
        r,
        2500.0,
    );
    let m = 1.0 / s.inv_m[0];
    let energy = |s: &Spheres| s.kinetic_energy() + m * g * s.x[0].y;
    let e0 = energy(&s);
    let mut engine = CollisionEngine::new(EngineConfig::default());
    let mut rest_since = None;
    for step in 0..2000 {
        s.v[0].y -= g * h;
        let rep = s.step(&mut engine, &domain, &model, h);
        assert!(
            s.x[0].y - r >= -1e-12 * r,
            "penetration {} at step {step}",
            s.x[0].y - r
        );
        assert!(
            energy(&s) <= e0 * (1.0 + 1e-12),
            "energy gain at step {step}"
        );
        if rep.stats.resting > 0 && rest_since.is_none() {
            rest_since = Some(step);
        }
        if let Some(k) = rest_since
            && step > k + 5
        {
            assert!(
                (s.x[0].y - r).abs() <= 1e-12 * r,
                "jitter {} at step {step}",
                s.x[0].y - r
            );
            assert_eq!(s.v[0].y, 0.0);
        }
    }
    assert!(rest_since.unwrap() < 1000);
    // rolling with friction-limited spin: the tangential motion is untouched by e = 0 wall hits
    // with zero tangential contact velocity after the first sticking contact
    let contact_v = s.v[0] + s.w[0].cross(DVec3::new(0.0, -r, 0.0));
    assert!(contact_v.length() < 1e-12, "{contact_v}");
}

#[test]
fn a_particle_squeezed_between_walls_hits_the_event_cap() {
    let r = 1e-3;
    let domain = CollisionDomain::unbounded()
        .with_plane(Plane::new(DVec3::ZERO, DVec3::Y))
        .with_plane(Plane::new(DVec3::new(0.0, 2.0 * r, 0.0), -DVec3::Y));
    let mut s = Spheres::new(vec![DVec3::new(0.0, r, 0.0)], vec![DVec3::Y], r, 1000.0);
    let mut engine = CollisionEngine::new(EngineConfig {
        max_events_per_particle: 10,
        ..EngineConfig::default()
    });
    let rep = s.step(&mut engine, &domain, &elastic(), 1e-3);
    assert_eq!(rep.stats.events, 10);
    assert_eq!(rep.stats.capped_particles, 1);
    assert!(rep.stats.max_overlap_after_projection < 1e-12);
}

#[test]
fn invalid_input_is_an_error() {
    let mut engine = CollisionEngine::default();
    let mut s = Spheres::new(vec![DVec3::ZERO; 2], vec![DVec3::ZERO; 2], 1e-3, 1000.0);
    s.rho.pop();
    let arrays = ParticleArrays {
        positions: &mut s.x,
        velocities: &mut s.v,
        angular_velocities: &mut s.w,
        radii: &s.r,
        inv_masses: &s.inv_m,
        inv_inertias: InverseInertia::Scalar(&s.inv_i),
        densities: &s.rho,
        spheroids: None,
    };
    let err = engine.step(arrays, &CollisionDomain::unbounded(), &elastic(), 1e-3);
    assert!(matches!(
        err,
        Err(CollisionError::LengthMismatch {
            name: "densities",
            ..
        })
    ));
    s.rho.push(1000.0);
    let arrays = ParticleArrays {
        positions: &mut s.x,
        velocities: &mut s.v,
        angular_velocities: &mut s.w,
        radii: &s.r,
        inv_masses: &s.inv_m,
        inv_inertias: InverseInertia::Scalar(&s.inv_i),
        densities: &s.rho,
        spheroids: None,
    };
    let err = engine.step(arrays, &CollisionDomain::unbounded(), &elastic(), f64::NAN);
    assert!(matches!(err, Err(CollisionError::InvalidStep(_))));
}

/// Spheres of radius `r` on a jittered lattice above a floor in an x/z-periodic box of `cells`
/// lattice sites per side, with small random velocities.
fn bed(n: usize, cells: usize, r: f64, seed: u64) -> (Spheres, CollisionDomain) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pitch = 2.5 * r;
    let len = cells as f64 * pitch;
    let domain = CollisionDomain::unbounded()
        .with_periodic(0, 0.0, len)
        .with_periodic(2, 0.0, len)
        .with_plane(Plane::new(DVec3::ZERO, DVec3::Y));
    let mut x = Vec::with_capacity(n);
    let mut v = Vec::with_capacity(n);
    for k in 0..n {
        let (ix, iz, iy) = (k % cells, (k / cells) % cells, k / (cells * cells));
        let jitter = DVec3::new(
            rng.random_range(-0.1..0.1),
            rng.random_range(-0.1..0.1),
            rng.random_range(-0.1..0.1),
        ) * r;
        x.push(DVec3::new(ix as f64 + 0.5, iy as f64 + 0.6, iz as f64 + 0.5) * pitch + jitter);
        v.push(DVec3::new(
            rng.random_range(-0.05..0.05),
            rng.random_range(-0.05..0.05),
            rng.random_range(-0.05..0.05),
        ));
    }
    (Spheres::new(x, v, r, 2500.0), domain)
}

fn settle(
    s: &mut Spheres,
    domain: &CollisionDomain,
    steps: usize,
    h: f64,
    check: bool,
) -> (CollisionStats, Vec<f64>) {
    let g = 9.81;
    let model = CollisionModel {
        tangential_restitution: 0.0,
        ..CollisionModel::dry(0.5, 0.3, 5.0 * g * h)
    };
    let mut engine = CollisionEngine::new(EngineConfig {
        record_events: check,
        ..EngineConfig::default()
    });
    let mut total = CollisionStats::default();
    let mut kinetic = Vec::with_capacity(steps);
    for step in 0..steps {
        for v in &mut s.v {
            v.y -= g * h;
        }
        let (p0, _) = s.momentum();
        let rep = s.step(&mut engine, domain, &model, h);
        let st = rep.stats;
        total.events += st.events;
        total.wall_events += st.wall_events;
        total.resting += st.resting;
        total.stick += st.stick;
        total.slide += st.slide;
        total.capped_particles += st.capped_particles;
        total.skipped_events += st.skipped_events;
        total.rebuilds += st.rebuilds;
        total.resting_contacts += st.resting_contacts;
        total.resting_sweeps += st.resting_sweeps;
        total.projection_sweeps += st.projection_sweeps;
        let worst = st.max_overlap_before_projection;
        total.max_overlap_before_projection = total.max_overlap_before_projection.max(worst);
        let worst = st.max_overlap_after_projection;
        total.max_overlap_after_projection = total.max_overlap_after_projection.max(worst);
        kinetic.push(s.kinetic_energy());
        if check {
            let (p1, scale) = s.momentum();
            let from_walls: DVec3 = rep
                .events
                .iter()
                .filter(|e| matches!(e.partner, Partner::Wall(_)))
                .map(|e| e.impulse)
                .sum();
            let err = (p1 - p0 - from_walls).length();
            assert!(
                err <= 1e-12 * scale.max(1e-30),
                "momentum bookkeeping {err:e} at step {step}"
            );
            let lowest =
                s.x.iter()
                    .zip(&s.r)
                    .map(|(x, r)| x.y - r)
                    .fold(f64::INFINITY, f64::min);
            assert!(
                lowest >= -1e-12 * s.r[0],
                "below the floor by {lowest:e} at step {step}"
            );
            assert!(worst < 1e-3, "overlap {worst:e} d at step {step}");
        }
    }
    (total, kinetic)
}

#[test]
fn settling_bed_stays_above_the_floor_without_overlaps() {
    let (mut s, domain) = bed(1000, 10, 1e-3, 7);
    let (stats, kinetic) = settle(&mut s, &domain, 600, 2.5e-4, true);
    let peak = kinetic.iter().copied().fold(0.0, f64::max);
    let last = *kinetic.last().unwrap();
    println!(
        "bed: {stats:?}\nKE peak {peak:.3e} J, final {last:.3e} J, top {:.2} mm",
        s.x.iter().map(|x| x.y).fold(0.0, f64::max) * 1e3
    );
    assert!(stats.events > 10_000 && stats.wall_events > 0);
    assert!(last < 1e-3 * peak, "{last} vs {peak}");
    // the kinetic energy decays over the last third (settled bed, no pumping)
    let third = kinetic.len() / 3;
    let late = kinetic[2 * third..].iter().copied().fold(0.0, f64::max);
    assert!(late < 1e-2 * peak);
}

#[test]
fn steps_are_bitwise_deterministic() {
    let (a0, domain) = bed(300, 6, 1e-3, 11);
    let (mut a, mut b) = (a0.clone(), a0);
    settle(&mut a, &domain, 80, 5e-4, false);
    settle(&mut b, &domain, 80, 5e-4, false);
    assert_eq!(a, b);
}

#[test]
fn a_resting_column_neither_sinks_nor_jitters() {
    let (r, g, h) = (1e-3, 9.81, 2.5e-4);
    let domain = CollisionDomain::unbounded().with_plane(Plane::new(DVec3::ZERO, DVec3::Y));
    let model = CollisionModel::dry(0.5, 0.3, 5.0 * g * h);
    let x: Vec<DVec3> = (0..10)
        .map(|k| DVec3::new(0.0, r * (1.0 + 2.0 * k as f64), 0.0))
        .collect();
    let mut s = Spheres::new(x.clone(), vec![DVec3::ZERO; 10], r, 2500.0);
    let mut engine = CollisionEngine::new(EngineConfig::default());
    let mut sweeps = Vec::new();
    for step in 0..400 {
        for v in &mut s.v {
            v.y -= g * h;
        }
        let rep = s.step(&mut engine, &domain, &model, h);
        sweeps.push(rep.stats.resting_sweeps);
        assert_eq!(rep.stats.resting_contacts, 10);
        assert!(
            rep.stats.max_overlap_after_projection < 5e-4,
            "{:?}",
            rep.stats
        );
        assert!(s.x[0].y >= r * (1.0 - 1e-12));
        if step >= 10 {
            assert_eq!(rep.stats.events, 0, "step {step}");
            for (k, (a, b)) in s.x.iter().zip(&x).enumerate() {
                assert!(
                    (a.y - b.y).abs() < 2e-4 * r,
                    "sphere {k} moved {:e} at step {step}",
                    a.y - b.y
                );
            }
            let fastest = s.v.iter().map(|v| v.length()).fold(0.0, f64::max);
            // what is left: the solve's tolerance and speculative closing of projection gaps
            assert!(
                fastest < 0.25 * g * h,
                "residual speed {fastest:e} at step {step}"
            );
        }
    }
    // the warm start makes the steady column converge in a few sweeps, not O(height²)
    let late = &sweeps[10..];
    let mean = late.iter().sum::<usize>() as f64 / late.len() as f64;
    let worst = late.iter().copied().max().unwrap();
    println!(
        "resting sweeps: first {:?}, after step 10: mean {mean:.1}, max {worst}",
        &sweeps[..5]
    );
    assert!(mean < 5.0 && worst < 100);
}

/// The fast kernels (projection with stamps, PGS resting sweeps on compact bodies) against the plain
/// reference kernels: bitwise the same reports and states, step after step, on a settling bed
/// with friction, a floor and periodic sides (resting contacts, projections and events all
/// occur).
#[test]
fn fast_kernels_match_the_reference_kernels_bitwise() {
    let (g, h) = (9.81, 5e-4);
    let (a0, domain) = bed(400, 6, 1e-3, 13);
    let (mut a, mut b) = (a0.clone(), a0);
    let model = CollisionModel {
        tangential_restitution: 0.0,
        ..CollisionModel::dry(0.5, 0.3, 5.0 * g * h)
    };
    let pgs = EngineConfig {
        nncg_sweeps: 0,
        ..EngineConfig::default()
    };
    let mut fast = CollisionEngine::new(pgs);
    let mut reference = CollisionEngine::new(pgs);
    reference.reference = true;
    let mut total = CollisionStats::default();
    for step in 0..160 {
        for s in [&mut a, &mut b] {
            for v in &mut s.v {
                v.y -= g * h;
            }
        }
        let ra = a.step(&mut fast, &domain, &model, h);
        let rb = b.step(&mut reference, &domain, &model, h);
        assert_eq!(ra, rb, "report at step {step}");
        assert_eq!(a, b, "state at step {step}");
        total.events += ra.stats.events;
        total.resting_contacts += ra.stats.resting_contacts;
        total.resting_sweeps = total.resting_sweeps.max(ra.stats.resting_sweeps);
        total.projection_sweeps = total.projection_sweeps.max(ra.stats.projection_sweeps);
    }
    // the comparison covered every kernel
    assert!(total.events > 1000, "{total:?}");
    assert!(total.resting_contacts > 1000, "{total:?}");
    assert!(
        total.resting_sweeps > 3 && total.projection_sweeps > 3,
        "{total:?}"
    );
}

mod nncg;
