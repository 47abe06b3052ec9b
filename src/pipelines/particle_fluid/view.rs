//! What a particle-fluid recording shows besides the particles: the apparent density of the
//! magnetised liquid as a stack of translucent slices (blue below ρ_f, red above, entity
//! `backdrop`), the magnets' faces as dark slabs, and the particles coloured by density on
//! the same scale (blue: lighter than the liquid, red: heavier).

use glam::DVec3;
use magsep_plugins::record::BackdropCube;
use magsep_systems::fluid::config::ParticleFluidConfig;
use magsep_systems::fluid::magnet::MagnetModel;

/// Slices of the colour map.
const SLICES: usize = 40;
/// Opacity of the slices.
const SLICE_ALPHA: f32 = 0.08;
/// Thickness of a drawn magnet face [m].
const FACE: f64 = 4e-3;

/// Diverging colour of `s` in [−1, 1] (blue, white, red) with opacity `alpha`.
pub fn diverging(s: f64, alpha: f32) -> [f32; 4] {
    let s = s.clamp(-1.0, 1.0) as f32;
    let white = [0.95f32, 0.95, 0.95];
    let end = if s < 0.0 {
        [0.2f32, 0.4, 0.9]
    } else {
        [0.9f32, 0.3, 0.2]
    };
    let t = s.abs();
    [
        white[0] + (end[0] - white[0]) * t,
        white[1] + (end[1] - white[1]) * t,
        white[2] + (end[2] - white[2]) * t,
        alpha,
    ]
}

/// Colour of a particle of density `rho_p` [kg/m³] (scaled by the sorting range, or by
/// 10 % of ρ_f without a magnet).
pub fn density_colour(cfg: &ParticleFluidConfig, rho_p: f64) -> [f32; 4] {
    let range = cfg.magnet.sorting_range(&cfg.liquid, cfg.gravity);
    let scale = if range > 0.0 {
        range
    } else {
        0.1 * cfg.liquid.density
    };
    diverging((rho_p - cfg.liquid.density) / scale, 1.0)
}

/// The backdrop of a container with box `edges` \[m\] (zero: unbounded, drawn over ±L about
/// the mid-plane and 0.1 m wide).
pub fn magnet_backdrop(cfg: &ParticleFluidConfig, edges: DVec3) -> Vec<BackdropCube> {
    let half = match cfg.magnet {
        MagnetModel::None => return Vec::new(),
        MagnetModel::Bottom { half_height, .. }
        | MagnetModel::Top { half_height, .. }
        | MagnetModel::Two { half_height, .. } => half_height,
    };
    let (lo_xy, size_xy, z0, z1) = if edges == DVec3::ZERO {
        (
            DVec3::new(-0.05, -0.05, 0.0),
            DVec3::new(0.1, 0.1, 0.0),
            cfg.mid_plane - half,
            cfg.mid_plane + half,
        )
    } else {
        (DVec3::ZERO, DVec3::new(edges.x, edges.y, 0.0), 0.0, edges.z)
    };
    let range = cfg
        .magnet
        .sorting_range(&cfg.liquid, cfg.gravity)
        .max(1e-300);
    let dz = (z1 - z0) / SLICES as f64;
    let centre_xy = lo_xy + 0.5 * size_xy;
    let mut cubes: Vec<BackdropCube> = (0..SLICES)
        .map(|k| {
            let z = z0 + (k as f64 + 0.5) * dz;
            let rho = cfg
                .magnet
                .apparent_density(&cfg.liquid, cfg.gravity, cfg.magnet_y(z));
            BackdropCube {
                center: DVec3::new(centre_xy.x, centre_xy.y, z),
                size: DVec3::new(size_xy.x, size_xy.y, dz),
                colour: diverging((rho - cfg.liquid.density) / range, SLICE_ALPHA),
            }
        })
        .collect();
    let face = |z: f64| BackdropCube {
        center: DVec3::new(centre_xy.x, centre_xy.y, z),
        size: DVec3::new(size_xy.x, size_xy.y, FACE),
        colour: [0.2, 0.2, 0.22, 0.9],
    };
    let (bottom, top) = (
        cfg.mid_plane - half - 0.5 * FACE,
        cfg.mid_plane + half + 0.5 * FACE,
    );
    match cfg.magnet {
        MagnetModel::Bottom { .. } => cubes.push(face(bottom)),
        MagnetModel::Top { .. } => cubes.push(face(top)),
        MagnetModel::Two { .. } => cubes.extend([face(bottom), face(top)]),
        MagnetModel::None => {}
    }
    cubes
}

#[cfg(test)]
mod tests {
    use super::*;
    use magsep_systems::fluid::config::{ForceTerms, HistoryChoice, Integrator};
    use magsep_systems::fluid::drag::DragLaw;
    use magsep_systems::fluid::flow::FlowModel;
    use magsep_systems::fluid::single::SphereInLiquid;

    #[test]
    fn a_levitating_particle_has_the_colour_of_its_slice() {
        // the thesis-002 rig of table 2.1 (liquid and bottom magnet)
        let rig = SphereInLiquid::table_2_1(5e-3);
        let cfg = ParticleFluidConfig {
            dt: 1e-3,
            steps: 1,
            gravity: rig.gravity,
            mid_plane: 0.075,
            liquid: rig.liquid,
            magnet: rig.magnet,
            flow: FlowModel::Quiescent,
            terms: ForceTerms::default(),
            drag_law: DragLaw::SchillerNaumann,
            history: HistoryChoice::default(),
            integrator: Integrator::Implicit,
            levitation_tolerance: 5e-4,
            observe_every: 1,
            spheroids: Default::default(),
            solver: None,
        };
        let cubes = magnet_backdrop(&cfg, DVec3::splat(0.15));
        assert_eq!(cubes.len(), SLICES + 1); // slices and the bottom face
        // heavy near the magnet (red), the liquid's own density far above (white)
        assert!(cubes[0].colour[0] > 0.8 && cubes[0].colour[2] < 0.4);
        assert!(cubes[SLICES - 1].colour.iter().take(3).all(|c| *c > 0.85));
        let z_e = cfg.equilibrium_height(1434.0).unwrap();
        let slice = cubes
            .iter()
            .take(SLICES)
            .min_by(|a, b| {
                (a.center.z - z_e)
                    .abs()
                    .total_cmp(&(b.center.z - z_e).abs())
            })
            .unwrap();
        let particle = density_colour(&cfg, 1434.0);
        for k in 0..3 {
            assert!(
                (slice.colour[k] - particle[k]).abs() < 0.05,
                "{slice:?} {particle:?}"
            );
        }
    }
}
