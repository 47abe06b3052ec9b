//! cubatic (placeholder, being written).
