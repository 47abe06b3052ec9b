//! Virtual-particle walls (placeholder, being written).
