//! wall_order (placeholder, being written).
