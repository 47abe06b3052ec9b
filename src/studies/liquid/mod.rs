//! Studies of the two-way coupled liquid (thesis 002, ch. 2 and 4).
//!
//! * [`bench`](mod@bench): `magsep bench fluid`.
//! * [`chart`]: `magsep chart coupling`.
//! * [`solver_chart`]: `magsep chart liquid-solver`.
//! * [`settling`]: a single sphere settling in the coupled liquid, against the grid, with and
//!   without the self-induced-velocity correction.

pub mod bench;
pub mod chart;
pub mod settling;
pub mod solver_chart;
