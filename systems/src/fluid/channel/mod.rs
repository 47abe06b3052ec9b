//! The two-way coupled liquid of the separation channel (thesis 002, ch. 2 and 4): an
//! incompressible Navier-Stokes solver periodic in x and y between no-slip walls at z = 0 and
//! z = height, and the coupling of the particles to it.
//!
//! * [`grid`]: the collocation grid and the layout of physical fields.
//! * [`config`]: the scene options (`[liquid] solver`).
//! * [`coupling`]: the top-hat force filter, the filter average and the torque couple.
//! * [`self_induced`]: the self-induced velocity of a coupled particle and its correction.

pub mod config;
pub mod coupling;
pub mod grid;
pub mod self_induced;

#[cfg(test)]
mod coupling_tests;
