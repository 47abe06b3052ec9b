//! The two-way coupled liquid of the separation channel (thesis 002, ch. 2 and 4): an
//! incompressible Navier-Stokes solver periodic in x and y between no-slip walls at z = 0 and
//! z = height, and the coupling of the particles to it.
//!
//! * [`grid`]: the collocation grid and the layout of physical fields.

pub mod grid;
