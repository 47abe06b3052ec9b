//! confinement (placeholder, being written).
