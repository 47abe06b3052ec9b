//! Brownian dynamics of magnetic nanoparticles around magnetised fibres (thesis 000, ch. 6).
//!
//! * [`hydro`]: mobilities (free draining, Rotne-Prager-Yamakawa) and Brownian displacements
//!   (dense Cholesky, TEA-HI, Krylov/Lanczos square root).

pub mod balance;
pub mod cells;
pub mod contact;
pub mod dynamics;
pub mod fibre_flow;
pub mod hydro;
pub mod model;
pub mod pair;
pub mod parts;
pub mod passes;
pub mod patch;
pub mod stepper;
pub mod systems;
pub mod verlet;
