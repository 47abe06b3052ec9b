//! The two-way coupled liquid of the separation channel (thesis 002, ch. 2 and 4): an
//! incompressible Navier-Stokes solver periodic in x and y between no-slip walls at z = 0 and
//! z = height, and the coupling of the particles to it.
//!
//! * [`grid`]: the collocation grid and the layout of physical fields.
//! * [`cheb`]: Chebyshev collocation operators, Clenshaw-Curtis weights, the
//!   matrix-diagonalisation Helmholtz solver.
//! * [`fft`]: plane transforms in the periodic directions (with 3/2-rule padding).
//! * [`solver`]: the method (Kim-Moin-Moser formulation), [`ChannelParams`], [`ChannelError`].
//! * [`stepper`]: [`ChannelSolver`] and its time step.
//! * [`state`]: setting the velocity, diagnostics, lossless state bytes.
//! * [`orr_sommerfeld`]: the Orr-Sommerfeld eigenmode of plane Poiseuille flow and the growth
//!   of its Tollmien-Schlichting wave in the solver (validation and the accuracy chart).
//! * [`config`]: the scene options (`[liquid] solver`).
//! * [`coupling`]: the top-hat force filter, the filter average and the torque couple.
//! * [`self_induced`]: the self-induced velocity of a coupled particle and its correction.
//! * [`systems`]: the thin ECS systems of the coupled liquid.

// dense kernels index several per-level arrays in one loop
#![allow(clippy::needless_range_loop)]

pub mod cheb;
pub mod config;
pub mod coupling;
pub mod fft;
pub mod grid;
pub mod orr_sommerfeld;
pub mod self_induced;
pub mod solver;
pub mod state;
pub mod stepper;
pub mod systems;

pub use cheb::clenshaw_curtis_weights;
pub use solver::{ChannelError, ChannelParams};
pub use stepper::ChannelSolver;

#[cfg(test)]
mod budget_tests;
#[cfg(test)]
mod coupling_tests;
#[cfg(test)]
mod os_tests;
#[cfg(test)]
mod solver_tests;
