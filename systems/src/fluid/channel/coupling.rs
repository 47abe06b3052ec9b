//! Two-way coupling kernels between point particles and the channel liquid (thesis 002,
//! eqs. 2.38-2.40 and 4.20-4.23).
//!
//! * **Filter** ([`FilterStencil`]): the top-hat of eq. (4.21). Its box is the particle's
//!   axis-aligned bounding box (orientation-adaptive for spheroids: half-widths
//!   `h_k = sqrt(Σ_j R_kj² s_j²)`, [`bounding_half_widths`]), widened per axis to the local grid
//!   spacing when the particle is smaller than a cell, so that it always covers a node. Its
//!   weights are normalised discretely with the solver's own node volumes
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
//! Units: forces [N], torques [N m], positions [m]; the body force handed to the solver is
//! per unit mass [m/s²] (divide the force density [N/m³] by ρ_f).

use glam::{DMat3, DQuat, DVec3};

use super::grid::ChannelGrid;

/// Half-widths [m] of the axis-aligned bounding box of a spheroid with semi-axes
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

/// The grid nodes of one particle's filter box, with the weight `P` [1/m³] of each (the same
/// for every node, `Σ P ΔV = 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct FilterStencil {
    /// Flat node indices (see [`ChannelGrid::index`]).
    pub nodes: Vec<usize>,
    /// Node volumes ΔV [m³] in the order of `nodes`.
    pub volumes: Vec<f64>,
    /// The filter value P [1/m³] at every node of the box.
    pub weight: f64,
}

/// Indices of the periodic nodes within `half` of `centre` along an axis with `n` nodes of
/// spacing `d` (the nearest node when none is): wrapped indices.
fn periodic_span(centre: f64, half: f64, n: usize, d: f64) -> Vec<usize> {
    let s = centre / d;
    let lo = (s - half / d).floor() as i64;
    let hi = (s + half / d).ceil() as i64;
    let mut out: Vec<usize> = (lo..=hi)
        .filter(|m| ((*m as f64) * d - centre).abs() < half)
        .map(|m| m.rem_euclid(n as i64) as usize)
        .collect();
    out.truncate(n);
    if out.is_empty() {
        out.push((s.round() as i64).rem_euclid(n as i64) as usize);
    }
    out
}

/// Interior z levels (1 ..= nz − 2) within `half` of `z` (the nearest interior level when
/// none is).
fn interior_levels(grid: &ChannelGrid, z: f64, half: f64) -> Vec<usize> {
    let mut out: Vec<usize> = (1..grid.nz - 1)
        .filter(|k| (grid.z(*k) - z).abs() < half)
        .collect();
    if out.is_empty() {
        let k = (1..grid.nz - 1)
            .min_by(|a, b| {
                let da = (grid.z(*a) - z).abs();
                let db = (grid.z(*b) - z).abs();
                da.total_cmp(&db)
            })
            .unwrap_or(1);
        out.push(k);
    }
    out
}

impl FilterStencil {
    /// The stencil of a box of half-widths `half` [m] centred at `centre` [m] (x and y are
    /// wrapped; z is clipped to the interior). `zw` are the grid's
    /// [`ChannelGrid::z_quadrature_weights`]. `None` for a non-finite centre or box.
    pub fn new(grid: &ChannelGrid, zw: &[f64], centre: DVec3, half: DVec3) -> Option<Self> {
        if !(centre.is_finite() && half.is_finite()) {
            return None;
        }
        let (dx, dy) = (grid.dx(), grid.dy());
        let xs = periodic_span(centre.x, half.x.max(0.0), grid.nx, dx);
        let ys = periodic_span(centre.y, half.y.max(0.0), grid.ny, dy);
        let zs = interior_levels(grid, centre.z, half.z.max(0.0));
        let mut nodes = Vec::with_capacity(xs.len() * ys.len() * zs.len());
        let mut volumes = Vec::with_capacity(nodes.capacity());
        for &k in &zs {
            for &i in &xs {
                for &j in &ys {
                    nodes.push(grid.index(i, j, k));
                    volumes.push(dx * dy * zw[k]);
                }
            }
        }
        let total: f64 = volumes.iter().sum();
        Some(Self {
            nodes,
            volumes,
            weight: 1.0 / total,
        })
    }

    /// The filter average of a nodal field (`Σ P f ΔV`).
    pub fn average(&self, field: &[f64]) -> f64 {
        let s: f64 = self
            .nodes
            .iter()
            .zip(&self.volumes)
            .map(|(n, v)| field[*n] * v)
            .sum();
        s * self.weight
    }

    /// The filter average of a vector field given as three nodal components.
    pub fn average3(&self, field: [&[f64]; 3]) -> DVec3 {
        DVec3::new(
            self.average(field[0]),
            self.average(field[1]),
            self.average(field[2]),
        )
    }

    /// Add the force density `P·force/ρ_f` [m/s²] of `force` [N] to the body-force fields.
    pub fn spread(&self, force: DVec3, fluid_density: f64, out: &mut [&mut [f64]; 3]) {
        let a = force * (self.weight / fluid_density);
        for n in &self.nodes {
            out[0][*n] += a.x;
            out[1][*n] += a.y;
            out[2][*n] += a.z;
        }
    }
}

/// One of the eight point forces of a torque couple: node index, node position [m] (unwrapped,
/// next to the particle) and force [N].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerForce {
    /// Flat node index.
    pub node: usize,
    /// Node position [m], unwrapped to the particle's side of the periodic cell.
    pub position: DVec3,
    /// Force [N] (the node's force density times its volume).
    pub force: DVec3,
}

/// The eight corner forces that apply the reaction `−torque` [N m] of a particle at `centre`
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
