//! Predicted events of the collision step and their deterministic total order.

use std::cmp::Ordering;

/// A predicted event. `hi ≥ N` encodes wall `hi − N`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Event {
    pub(super) time: f64,
    pub(super) lo: u32,
    pub(super) hi: u32,
    pub(super) owner: u32,
    pub(super) ver_lo: u32,
    pub(super) ver_hi: u32,
}

impl Event {
    fn key(&self) -> (u32, u32, u32) {
        (self.lo, self.hi, self.owner)
    }
}

impl PartialEq for Event {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Event {
    fn cmp(&self, other: &Self) -> Ordering {
        self.time
            .total_cmp(&other.time)
            .then_with(|| self.key().cmp(&other.key()))
            .then_with(|| (self.ver_lo, self.ver_hi).cmp(&(other.ver_lo, other.ver_hi)))
    }
}
