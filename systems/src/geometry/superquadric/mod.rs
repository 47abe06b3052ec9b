//! Superquadric geometry and contact (placeholder, being written).
