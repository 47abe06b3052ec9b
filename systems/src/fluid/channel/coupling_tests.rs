//! Tests of the coupling kernels: spec M5 (torque couple) and M6 (force filter).

use glam::{DQuat, DVec3};

use super::coupling::*;
use super::grid::ChannelGrid;

fn grid() -> ChannelGrid {
    ChannelGrid::new([16, 12, 33], [0.04, 0.03, 0.15]).unwrap()
}

fn integrate(g: &ChannelGrid, f: &[&mut [f64]; 3], rho: f64) -> DVec3 {
    let zw = g.z_quadrature_weights();
    let mut s = DVec3::ZERO;
    for k in 0..g.nz {
        for i in 0..g.nx {
            for j in 0..g.ny {
                let n = g.index(i, j, k);
                let dv = g.dx() * g.dy() * zw[k];
                s += DVec3::new(f[0][n], f[1][n], f[2][n]) * dv * rho;
            }
        }
    }
    s
}

#[test]
fn m6_the_filtered_force_integrates_to_the_particle_forces() {
    let g = grid();
    let zw = g.z_quadrature_weights();
    let zl = g.z_levels();
    let rho = 1400.0;
    let (mut a, mut b, mut c) = (vec![0.0; g.len()], vec![0.0; g.len()], vec![0.0; g.len()]);
    let mut total = DVec3::ZERO;
    // particles: mid-channel, straddling the periodic seam, touching the bottom wall, smaller
    // than a cell, a tilted flake
    let cases = [
        (DVec3::new(0.02, 0.015, 0.075), DVec3::splat(2e-3)),
        (DVec3::new(0.0395, 0.0001, 0.05), DVec3::splat(4e-3)),
        (DVec3::new(0.01, 0.02, 0.001), DVec3::splat(2e-3)),
        (DVec3::new(0.011, 0.007, 0.1), DVec3::splat(2e-4)),
        (
            DVec3::new(0.03, 0.02, 0.12),
            bounding_half_widths(4.3e-3, 0.43e-3, DQuat::from_rotation_y(0.7)),
        ),
    ];
    for (n, (x, h)) in cases.iter().enumerate() {
        let f = DVec3::new(1e-4 * n as f64, -2e-4, 3e-4 + 1e-5 * n as f64);
        let s = FilterStencil::new(&g, &zw, &zl, *x, *h).unwrap();
        // Σ P ΔV = 1 and no wall node
        let unit: f64 = s.weights.iter().sum();
        assert!((unit - 1.0).abs() < 1e-14);
        assert!(s.nodes.iter().all(|n| {
            let k = n / (g.nx * g.ny);
            k > 0 && k + 1 < g.nz
        }));
        s.spread(-f, rho, &mut [&mut a, &mut b, &mut c]);
        total += -f;
    }
    let got = integrate(&g, &[&mut a, &mut b, &mut c], rho);
    assert!(
        (got - total).length() < 1e-14 * total.length(),
        "{got} {total}"
    );
}

#[test]
fn the_filter_average_is_the_adjoint_of_spreading_and_exact_for_constants() {
    let g = grid();
    let zw = g.z_quadrature_weights();
    let zl = g.z_levels();
    let s = FilterStencil::new(
        &g,
        &zw,
        &zl,
        DVec3::new(0.021, 0.013, 0.07),
        DVec3::splat(3e-3),
    )
    .unwrap();
    let ones = vec![2.5; g.len()];
    assert!((s.average(&ones) - 2.5).abs() < 1e-14);
    // <spread(F), u> = F · average(u)
    let u: Vec<f64> = (0..g.len())
        .map(|n| ((n * 7919) % 101) as f64 / 50.0 - 1.0)
        .collect();
    let (mut a, mut b, mut c) = (vec![0.0; g.len()], vec![0.0; g.len()], vec![0.0; g.len()]);
    let force = DVec3::new(0.3, -0.2, 0.7);
    s.spread(force, 1.0, &mut [&mut a, &mut b, &mut c]);
    let mut inner = 0.0;
    for k in 0..g.nz {
        for i in 0..g.nx {
            for j in 0..g.ny {
                let n = g.index(i, j, k);
                inner += (a[n] + b[n] + c[n]) * u[n] * g.dx() * g.dy() * zw[k];
            }
        }
    }
    let avg = s.average(&u);
    assert!((inner - force.element_sum() * avg).abs() < 1e-13);
    // non-finite input is refused, not a panic
    assert!(FilterStencil::new(&g, &zw, &zl, DVec3::NAN, DVec3::ONE).is_none());
}

#[test]
fn bounding_boxes_follow_the_orientation() {
    // broadside flake: thin in z; edge-on about x: thin in y
    let (a, c) = (4.3e-3, 0.43e-3);
    let flat = bounding_half_widths(a, c, DQuat::IDENTITY);
    assert!((flat - DVec3::new(a, a, c)).length() < 1e-15);
    let edge = bounding_half_widths(a, c, DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2));
    assert!((edge - DVec3::new(a, c, a)).length() < 1e-15);
    // a sphere's box does not depend on the orientation
    let s = bounding_half_widths(
        1e-3,
        1e-3,
        DQuat::from_rotation_z(0.3) * DQuat::from_rotation_x(1.1),
    );
    assert!((s - DVec3::splat(1e-3)).length() < 1e-15);
}

#[test]
fn m5_the_torque_couple_has_no_net_force_and_the_reaction_moment() {
    let g = grid();
    let zw = g.z_quadrature_weights();
    for (x, t) in [
        (
            DVec3::new(0.0213, 0.0117, 0.0731),
            DVec3::new(1e-6, -2e-6, 3e-6),
        ),
        (
            DVec3::new(0.0399, 0.0299, 0.0004),
            DVec3::new(-4e-7, 1e-6, 2e-7),
        ),
        (DVec3::new(0.001, 0.0, 0.1499), DVec3::new(0.0, 0.0, 5e-6)),
    ] {
        let corners = torque_couple(&g, x, t).unwrap();
        let f: DVec3 = corners.iter().map(|c| c.force).sum();
        assert!(f.length() < 1e-15 * t.length() / g.dx());
        // the moment about any point is −T
        for origin in [DVec3::ZERO, x, DVec3::new(1.0, -2.0, 3.0)] {
            let m: DVec3 = corners
                .iter()
                .map(|c| (c.position - origin).cross(c.force))
                .sum();
            assert!((m + t).length() < 1e-12 * t.length(), "{m} {t}");
        }
        // every corner is an interior node; the host cell contains the particle in x and y
        for c in &corners {
            let k = c.node / (g.nx * g.ny);
            assert!(k > 0 && k + 1 < g.nz);
            assert!((c.position.x - x.x).abs() <= g.dx() && (c.position.y - x.y).abs() <= g.dy());
        }
        // through the grid: the discrete integrals of the spread couple
        let (mut a, mut b, mut cz) = (vec![0.0; g.len()], vec![0.0; g.len()], vec![0.0; g.len()]);
        let rho = 1400.0;
        spread_couple(&g, &zw, &corners, rho, &mut [&mut a, &mut b, &mut cz]);
        let mut net = DVec3::ZERO;
        let mut moment = DVec3::ZERO;
        for c in &corners {
            let k = c.node / (g.nx * g.ny);
            let dv = g.dx() * g.dy() * zw[k];
            let fd = DVec3::new(a[c.node], b[c.node], cz[c.node]) * rho * dv;
            net += fd;
            moment += (c.position - x).cross(fd);
        }
        assert!(net.length() < 1e-14 * t.length() / g.dx());
        assert!((moment + t).length() < 1e-12 * t.length());
    }
    assert!(torque_couple(&g, DVec3::INFINITY, DVec3::X).is_none());
}

#[test]
fn the_filter_is_centred_on_the_particle_and_has_the_box_volume() {
    // hat-projected box: the centroid along the periodic axes is the particle's position and
    // the spread is the box's, wherever the particle sits relative to the nodes
    let g = grid();
    let zw = g.z_quadrature_weights();
    let zl = g.z_levels();
    let h = DVec3::new(3.7e-3, 2.2e-3, 9e-3);
    for shift in [0.0, 0.1, 0.37, 0.5, 0.93] {
        let x = DVec3::new(0.02 + shift * g.dx(), 0.015 + 0.3 * shift * g.dy(), 0.075);
        let s = FilterStencil::new(&g, &zw, &zl, x, h).unwrap();
        let mut c = DVec3::ZERO;
        let mut var = 0.0;
        for (n, w) in s.nodes.iter().zip(&s.weights) {
            let (i, j) = ((n / g.ny) % g.nx, n % g.ny);
            c += DVec3::new(g.x(i), g.y(j), 0.0) * *w;
            var += w * (g.x(i) - x.x).powi(2);
        }
        assert!(
            (c.x - x.x).abs() < 1e-15 && (c.y - x.y).abs() < 1e-15,
            "{c} {x}"
        );
        // the spread is about the box's (h²/3) plus the hat's (Δx²/6; exact for boxes of whole
        // cells): the box keeps its size
        let want = h.x * h.x / 3.0 + g.dx() * g.dx() / 6.0;
        assert!((var - want).abs() < 1e-2 * want, "{var} {want}");
    }
}
