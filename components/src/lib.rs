//! # magsep-components
//!
//! Data only: ECS components, resources and validated newtypes shared by every magsep crate.
//! No systems and no I/O live here (docs/architecture.md §1, layout). All quantities are SI unless a
//! field's documentation says otherwise.
//!
//! ```
//! use magsep_components::prelude::*;
//! let shape = Shape::Spherocylinder { radius: 0.5, half_length: 2.0 };
//! assert_eq!(shape.radius(), 0.5);
//! ```

#![warn(missing_docs)]

/// What the exported macros name, so that their expansions compile in a crate that does not
/// depend on these crates itself.
#[doc(hidden)]
pub mod __private {
    pub use bevy_ecs;
    pub use glam;
    pub use serde;
}

pub mod brownian;
pub mod clock;
pub mod container;
pub mod fibre;
pub mod fluid;
pub mod forces;
pub mod health;
pub mod packing;
pub mod particle;
pub mod shape;

/// Everything a user usually needs, in one import.
pub mod prelude {
    pub use crate::brownian::{
        BrownianConfig, BrownianStats, CaptureCurve, CaptureEvent, Captured, ContactForce,
        ContactModel, DipoleForce, FieldForce, InitialPosition, MagneticMoment, MobilityChoice,
        MomentModel, StepControl,
    };
    pub use crate::clock::StepClock;
    pub use crate::container::{Container, Walls};
    pub use crate::fibre::{ExternalField, Fibre, FibreId};
    pub use crate::fluid::{
        AngularVelocity, BuoyancyForce, DragForce, FluidSample, GravityForce, HistoryForce,
        InertialBody, Levitation, LiftForce, MagneticBuoyancyForce, MagneticTorque,
        ParticleFluidStats, PitchingTorque, RotationalDragTorque, UndisturbedFlowForce, Velocity,
    };
    pub use crate::forces::{ForceContribution, NetForce, NetTorque};
    pub use crate::health::Health;
    pub use crate::packing::{
        OverlapRemovalScheme, PackingConfig, PackingStatus, StopReason, VolumeStepRule,
    };
    pub use crate::particle::{
        Orientation, ParticleBundle, ParticleId, ParticleRng, Position, Species,
    };
    pub use crate::shape::Shape;
}
