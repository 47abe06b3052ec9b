//! Geometry kernels: volumes, inertia, closest points. Plain functions on `f64`/`DVec3`.

pub mod segment;
pub mod shape;
pub mod superquadric;

pub use segment::{SegmentClosest, segment_closest};
pub use shape::{bounding_radius, inertia_body_unit_density, volume};
