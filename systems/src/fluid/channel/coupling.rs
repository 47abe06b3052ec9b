//! Two-way coupling kernels between point particles and the channel liquid (thesis 002,
//! eqs. 2.38-2.40 and 4.20-4.23).
//!
//! * **Filter** ([`FilterStencil`]): the top-hat of eq. (4.21). Its box is the particle's
//!   axis-aligned bounding box (orientation-adaptive for spheroids: half-widths
//!   `h_k = sqrt(Σ_j R_kj² s_j²)`, [`bounding_half_widths`]). The box is projected onto the grid's
//!   hat functions (the thesis's "nodes inside the box" would make the filter's width jump
//!   with the particle's position relative to the nodes, by a factor of up to 3 in volume when
//!   the box is two cells wide; the projection keeps its volume and centroid). The weights are normalised discretely
//!   with the solver's own node volumes
//!   (`dx·dy·w_k`, Clenshaw-Curtis in z) so that `Σ P ΔV = 1` exactly: the force the fluid
//!   receives integrates to the sum of the particle forces to round-off (spec M6). Wall nodes
//!   never receive force (the collocation solver overwrites wall rows with the boundary
//!   conditions, so a force there would be lost); a box reaching a wall is clipped to the
//!   interior.
//! * **Interpolation**: the particle samples the liquid with the same weights (the filter
//!   average, as the thesis states: "the same weights as for interpolation"); the spreading
//!   and the sampling are adjoint, so the coupling neither creates nor destroys energy.
//! * **Torque** ([`torque_couple`]): the reaction torque mapped to eight point forces on the
//!   corners of the host cell (eq. 4.23). The forces sum to zero and their moment is −T about
//!   any point (spec M5). A host cell touching a wall is moved one level inwards; the moment
//!   is unchanged because the forces sum to zero.
//!
//! Units: forces \[N\], torques \[N m\], positions \[m\]; the body force handed to the solver is
//! per unit mass [m/s²] (divide the force density [N/m³] by ρ_f).

use glam::{DMat3, DQuat, DVec3};

use super::grid::ChannelGrid;

/// Half-widths \[m\] of the axis-aligned bounding box of a spheroid with semi-axes
/// `(a, a, c)` (body z the symmetry axis) rotated by `q` (body → lab); a sphere has `a = c`.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::fluid::channel::coupling::bounding_half_widths;
/// let h = bounding_half_widths(2.0, 0.5, DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2));
/// assert!((h - DVec3::new(2.0, 0.5, 2.0)).length() < 1e-12);
/// ```
pub fn bounding_half_widths(equatorial: f64, polar: f64, q: DQuat) -> DVec3 {
    let r = DMat3::from_quat(q);
    let s2 = DVec3::new(
        equatorial * equatorial,
        equatorial * equatorial,
        polar * polar,
    );
    let row = |k: usize| {
        let v = DVec3::new(r.x_axis[k], r.y_axis[k], r.z_axis[k]);
        (v * v).dot(s2).sqrt()
    };
    DVec3::new(row(0), row(1), row(2))
}

/// The grid nodes of one particle's filter box with their weights.
///
/// The box is projected onto the piecewise-linear (hat) functions of the grid: a node's weight
/// is `∫ box φ_n / ∫ φ_n`. This keeps the box's volume and, along the periodic axes, its
/// centroid exactly wherever the particle sits relative to the nodes (the hats reproduce
/// linear functions), so the filter moves smoothly with the particle; a box smaller than a
/// cell spreads like a cloud-in-cell kernel. The weights are then scaled so that
/// `Σ P ΔV = 1` with the solver's node volumes.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterStencil {
    /// Flat node indices (see [`ChannelGrid::index`]).
    pub nodes: Vec<usize>,
    /// `P_n ΔV_n` per node (they sum to 1): the weights of the filter average.
    pub weights: Vec<f64>,
    /// `P_n` [1/m³] per node: the force density per unit force.
    pub densities: Vec<f64>,
}

/// `∫_lo^hi φ(x) dx` of the hat φ rising from 0 at `a` to 1 at `b` and falling to 0 at `c`.
fn hat_integral(lo: f64, hi: f64, a: f64, b: f64, c: f64) -> f64 {
    let mut sum = 0.0;
    let (p, q) = (lo.max(a), hi.min(b));
    if p < q {
        sum += ((q - a).powi(2) - (p - a).powi(2)) / (2.0 * (b - a));
    }
    let (p, q) = (lo.max(b), hi.min(c));
    if p < q {
        sum += ((c - p).powi(2) - (c - q).powi(2)) / (2.0 * (c - b));
    }
    sum
}

/// Hat weights `∫ box φ_i / ∫ φ_i` of the periodic nodes overlapping `[c − h, c + h]`:
/// (wrapped index, weight in [0, 1]).
fn periodic_weights(centre: f64, half: f64, n: usize, d: f64) -> Vec<(usize, f64)> {
    let (lo, hi) = (centre - half, centre + half);
    let first = (lo / d).floor() as i64;
    let last = (hi / d).ceil() as i64;
    let mut out: Vec<(usize, f64)> = Vec::new();
    for m in first..=last {
        let x = m as f64 * d;
        let f = hat_integral(lo, hi, x - d, x, x + d) / d;
        if f > 0.0 {
            let i = m.rem_euclid(n as i64) as usize;
            match out.iter_mut().find(|(j, _)| *j == i) {
                Some(slot) => slot.1 += f, // a box wider than the period wraps onto itself
                None => out.push((i, f)),
            }
        }
    }
    out
}

/// Hat weights of the interior levels overlapping `[z − h, z + h]`; `levels` are the grid's
/// z levels (ascending).
fn level_weights(levels: &[f64], z: f64, half: f64) -> Vec<(usize, f64)> {
    let (lo, hi) = (z - half, z + half);
    let nz = levels.len();
    // levels whose hat [z_{k-1}, z_{k+1}] can overlap [lo, hi]
    let first = levels
        .partition_point(|v| *v <= lo)
        .saturating_sub(1)
        .max(1);
    let last = (levels.partition_point(|v| *v < hi) + 1).min(nz - 1);
    (first..last)
        .filter_map(|k| {
            let (a, b, c) = (levels[k - 1], levels[k], levels[k + 1]);
            let f = hat_integral(lo, hi, a, b, c) / (0.5 * (c - a));
            (f > 0.0).then_some((k, f))
        })
        .collect()
}

impl FilterStencil {
    /// The stencil of a box of half-widths `half` \[m\] centred at `centre` \[m\] (x and y are
    /// wrapped; along z only interior levels take part, a box reaching past them is clipped,
    /// and a box outside the interior falls back to the nearest interior level). `zw` are the
    /// grid's [`ChannelGrid::z_quadrature_weights`] and `levels` its [`ChannelGrid::z_levels`]
    /// (passed in because they cost a cosine each). `None` for a non-finite centre or box.
    pub fn new(
        grid: &ChannelGrid,
        zw: &[f64],
        levels: &[f64],
        centre: DVec3,
        half: DVec3,
    ) -> Option<Self> {
        if !(centre.is_finite() && half.is_finite()) {
            return None;
        }
        let (dx, dy) = (grid.dx(), grid.dy());
        let half = half.max(DVec3::splat(1e-12 * dx.min(dy)));
        let xs = periodic_weights(centre.x, half.x, grid.nx, dx);
        let ys = periodic_weights(centre.y, half.y, grid.ny, dy);
        let mut zs = level_weights(levels, centre.z, half.z);
        if zs.is_empty() {
            let k = grid.level_below(centre.z)?.clamp(1, grid.nz - 2);
            zs.push((k, 1.0));
        }
        let n = xs.len() * ys.len() * zs.len();
        let mut nodes = Vec::with_capacity(n);
        let mut raw = Vec::with_capacity(n);
        let mut volumes = Vec::with_capacity(n);
        for &(k, fz) in &zs {
            for &(i, fx) in &xs {
                for &(j, fy) in &ys {
                    nodes.push(grid.index(i, j, k));
                    raw.push(fx * fy * fz);
                    volumes.push(dx * dy * zw[k]);
                }
            }
        }
        let total: f64 = raw.iter().zip(&volumes).map(|(r, v)| r * v).sum();
        let densities: Vec<f64> = raw.iter().map(|r| r / total).collect();
        let weights = densities.iter().zip(&volumes).map(|(p, v)| p * v).collect();
        Some(Self {
            nodes,
            weights,
            densities,
        })
    }

    /// The filter average of a nodal field (`Σ P f ΔV`).
    pub fn average(&self, field: &[f64]) -> f64 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(n, w)| field[*n] * w)
            .sum()
    }

    /// The filter average of a vector field given as three nodal components.
    pub fn average3(&self, field: [&[f64]; 3]) -> DVec3 {
        DVec3::new(
            self.average(field[0]),
            self.average(field[1]),
            self.average(field[2]),
        )
    }

    /// Add the force density `P·force/ρ_f` [m/s²] of `force` \[N\] to the body-force fields.
    pub fn spread(&self, force: DVec3, fluid_density: f64, out: &mut [&mut [f64]; 3]) {
        let a = force / fluid_density;
        for (n, p) in self.nodes.iter().zip(&self.densities) {
            out[0][*n] += a.x * p;
            out[1][*n] += a.y * p;
            out[2][*n] += a.z * p;
        }
    }
}

/// One of the eight point forces of a torque couple: node index, node position \[m\] (unwrapped,
/// next to the particle) and force \[N\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerForce {
    /// Flat node index.
    pub node: usize,
    /// Node position \[m\], unwrapped to the particle's side of the periodic cell.
    pub position: DVec3,
    /// Force \[N\] (the node's force density times its volume).
    pub force: DVec3,
}

/// The eight corner forces that apply the reaction `−torque` \[N m\] of a particle at `centre`
/// to the liquid (eq. 4.23): host cell `[x_i, x_i+1] × [y_j, y_j+1] × [z_k, z_k+1]` (moved off
/// the walls), corner `(a, b, c) ∈ {0, 1}³`, `s = 2·index − 1`:
/// `F = ⅛ (s_b T_z/δ_y − s_c T_y/δ_z, s_c T_x/δ_z − s_a T_z/δ_x, s_a T_y/δ_x − s_b T_x/δ_y)`.
/// `None` for a non-finite centre.
pub fn torque_couple(grid: &ChannelGrid, centre: DVec3, torque: DVec3) -> Option<[CornerForce; 8]> {
    if !(centre.is_finite() && torque.is_finite()) {
        return None;
    }
    let (dx, dy) = (grid.dx(), grid.dy());
    let i0 = (centre.x / dx).floor();
    let j0 = (centre.y / dy).floor();
    let k0 = grid.level_below(centre.z)?.clamp(1, grid.nz - 3);
    let dz = grid.z(k0 + 1) - grid.z(k0);
    let base = DVec3::new(i0 * dx, j0 * dy, grid.z(k0));
    let t = torque;
    let mut out = [CornerForce {
        node: 0,
        position: DVec3::ZERO,
        force: DVec3::ZERO,
    }; 8];
    for (n, slot) in out.iter_mut().enumerate() {
        let (a, b, c) = (n & 1, (n >> 1) & 1, (n >> 2) & 1);
        let s = |m: usize| if m == 1 { 1.0 } else { -1.0 };
        let (sa, sb, sc) = (s(a), s(b), s(c));
        let force = 0.125
            * DVec3::new(
                sb * t.z / dy - sc * t.y / dz,
                sc * t.x / dz - sa * t.z / dx,
                sa * t.y / dx - sb * t.x / dy,
            );
        let i = (i0 as i64 + a as i64).rem_euclid(grid.nx as i64) as usize;
        let j = (j0 as i64 + b as i64).rem_euclid(grid.ny as i64) as usize;
        *slot = CornerForce {
            node: grid.index(i, j, k0 + c),
            position: base + DVec3::new(a as f64 * dx, b as f64 * dy, c as f64 * dz),
            force,
        };
    }
    Some(out)
}

/// Add the corner forces of [`torque_couple`] to the body-force fields as force densities per
/// unit mass (force / (ρ_f ΔV_node)); `zw` are the grid's z quadrature weights.
pub fn spread_couple(
    grid: &ChannelGrid,
    zw: &[f64],
    corners: &[CornerForce; 8],
    fluid_density: f64,
    out: &mut [&mut [f64]; 3],
) {
    let area = grid.dx() * grid.dy();
    for c in corners {
        let k = c.node / (grid.nx * grid.ny);
        let a = c.force / (fluid_density * area * zw[k]);
        out[0][c.node] += a.x;
        out[1][c.node] += a.y;
        out[2][c.node] += a.z;
    }
}
