//! Integration tests, one binary: every module below was a test file of its own. One
//! binary links the crate once, which keeps CI's build time and disk use down.

mod channel;
mod cli;
mod common;
mod physics;
mod replay;
mod scene;
