//! Characterisation of packings: contact numbers, orientational order, pair correlation.

pub mod confinement;
pub mod contacts;
pub mod cubatic;
pub mod order;
pub mod wall_order;

pub use contacts::{ContactNumbers, contact_numbers};
pub use order::{nematic_order, symmetric_eigenvalues};
