use magsep_components::packing::*;
use magsep_components::shape::Shape;
use magsep_systems::analysis::{contact_numbers, nematic_order};
use magsep_systems::packing::{
    compress::*, insert::random_insertion, neighbour::NeighbourList, state::Body,
};
use magsep_systems::rng::particle_stream;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    let hl: f64 = args[2].parse().unwrap();
    let scheme = match args[3].as_str() {
        "o" => OverlapRemovalScheme::Original,
        "fire" => OverlapRemovalScheme::Fire,
        _ => OverlapRemovalScheme::Revised,
    };
    let rule = if args[4] == "f" {
        VolumeStepRule::Fixed
    } else {
        VolumeStepRule::Adaptive
    };
    let seed: u64 = args[5].parse().unwrap();
    let budget_mult: u64 = args.get(6).map(|s| s.parse().unwrap()).unwrap_or(200);
    let shape = if hl == 0.0 {
        Shape::Sphere { radius: 0.5 }
    } else {
        Shape::Spherocylinder {
            radius: 0.5,
            half_length: hl,
        }
    };
    let mut cfg = PackingConfig::defaults_for(n, 1.0);
    cfg.scheme = scheme;
    cfg.volume_step_rule = rule;
    cfg.max_attempts = budget_mult * n as u64;
    if let Ok(v) = std::env::var("DT") {
        cfg.revised_dt = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("XI") {
        cfg.original_xi = Some(v.parse().unwrap());
    }
    if let Ok(v) = std::env::var("BETA") {
        cfg.original_beta = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("FRAC") {
        cfg.adaptive_initial_fraction = v.parse().unwrap();
    }
    if hl > 10.0 {
        cfg.initial_packing_fraction = 0.01;
    }
    let p = DriverParams::from_config(&cfg, 1.0);
    let bodies: Vec<Body> = (0..n).map(|_| Body::from_shape(&shape, 1.0)).collect();
    let vp: f64 = bodies.iter().map(|b| b.volume).sum();
    let edge = (vp / cfg.initial_packing_fraction).cbrt();
    let mut rngs: Vec<_> = (0..n).map(|i| particle_stream(seed, i as u64)).collect();
    let mut state = random_insertion(&bodies, edge, &mut rngs).unwrap();
    let mut list = NeighbourList::new(
        std::env::var("SKIN")
            .map(|v| v.parse().unwrap())
            .unwrap_or(0.3),
    );
    let mut rng = particle_stream(seed, u64::MAX);
    let t = std::time::Instant::now();
    let mut st = initial_status(&p, &state);
    let debug = std::env::var("DBG").is_ok();
    let mut prev = state.clone();
    while st.stopped.is_none() {
        prev = state.clone();
        let before = st.compression_steps;
        let dvv = next_volume_step(&p, &st, &state);
        compression_step(&p, &mut st, &mut state, &mut list, &mut rng);
        if std::env::var("TRACE").is_ok() {
            eprintln!(
                "phi {:.4} dv {:.3e} its {} ok {}",
                st.packing_fraction,
                dvv,
                st.last_attempts / n as u64,
                st.compression_steps != before
            );
        }
        if debug && st.compression_steps != before && st.compression_steps.is_multiple_of(20) {
            let b = brute_max_overlap(&state);
            if b > 1e-4 {
                println!(
                    "step {} phi {:.4} brute max overlap {b:.3e} last_attempts {}",
                    st.compression_steps, st.packing_fraction, st.last_attempts
                );
                break;
            }
        }
    }
    let el = t.elapsed().as_secs_f64();
    if std::env::var("DIAG").is_ok() {
        diagnose(&p, &prev, p.min_volume_step());
    }
    let cn = contact_numbers(&state);
    state.wrap_all();
    let axes: Vec<_> = (0..n).map(|i| state.axis(i)).collect();
    println!(
        "n={n} hl={hl} {:?} {:?} seed={seed} phi={:.4} C={:.3} C4={:.3} S={:.3} steps={} failed={} attempts={} builds={} t={el:.2}s stop={:?} maxov={:.2e}",
        scheme,
        rule,
        st.packing_fraction,
        cn.extrapolated,
        cn.at_1e_4,
        nematic_order(&axes),
        st.compression_steps,
        st.failed_steps,
        st.attempts,
        list.builds,
        st.stopped,
        cn.max_overlap
    );
}
#[allow(dead_code)]
pub fn brute_max_overlap(state: &magsep_systems::packing::state::PackingState) -> f64 {
    let n = state.len();
    let l = state.edge;
    let mut m: f64 = 0.0;
    for i in 0..n {
        for j in i + 1..n {
            let mut r = state.positions[j] - state.positions[i];
            r -= (r / l).round() * l;
            let c = magsep_systems::packing::contact::pair_contact(
                state.axis(i),
                state.bodies[i].half_length,
                state.bodies[i].radius,
                r,
                state.axis(j),
                state.bodies[j].half_length,
                state.bodies[j].radius,
            );
            m = m.max(c.overlap);
        }
    }
    m
}
#[allow(dead_code)]
pub fn diagnose(p: &DriverParams, state: &magsep_systems::packing::state::PackingState, dv: f64) {
    use magsep_systems::packing::removal::*;
    let mut s = state.clone();
    let mut list = NeighbourList::new(0.3);
    compress(&mut s, &mut list, dv);
    let mut rng = particle_stream(9, 9);
    let mut flags = Vec::new();
    for k in 0..40 {
        list.ensure(&mut s);
        let tot = overlap_scan(&s, &list, p.tolerance, &mut flags);
        let nov = flags.iter().filter(|f| **f).count();
        println!("chunk {k}: total overlap {tot:.4e} overlapping particles {nov}");
        let out = remove_overlaps(
            &mut s,
            &mut list,
            p.rule,
            p.tolerance,
            20 * state.len() as u64,
            &mut rng,
        );
        if out.success {
            println!("converged in chunk {k}");
            break;
        }
    }
}
