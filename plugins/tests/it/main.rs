//! Integration tests, one binary: every module below was a test file of its own. One
//! binary links the crate once, which keeps CI's build time and disk use down.

mod brownian_user_forces;
mod fluid_user_forces;
mod force_registration;
mod packing_user_forces;
mod recorder_gather;
