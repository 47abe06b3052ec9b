//! Hard-particle collisions: impulses with restitution and Coulomb friction, wet restitution,
//! time of impact, and the event-driven collision step (thesis 002, ch. 2 and ch. 4).
//!
//! Pure kernels, no ECS:
//! * [`impulse`]: one impulse law for any two rigid bodies (Poisson restitution, tangential
//!   restitution, Coulomb friction; eq. 4.12–4.15, reducing to Hoomans' 2.33–2.35 for spheres).
//! * [`restitution`]: Izard et al.'s wet normal restitution (2.36) and the [`CollisionModel`]
//!   that gives the law of a pair or particle–wall impact at a given approach speed.
//! * [`toi`]: analytic sphere–sphere and sphere–plane time of impact and contact frames.
//! * [`spheroid`]: spheroid–spheroid/sphere common-normal contact (after Jain et al. 2019),
//!   closed-form spheroid–plane contact, and the time of impact of moving, rotating spheroids by
//!   separating-axis conservative advancement (thesis ch. 4, §4.2.1.3).
//! * [`domain`]: periodic axes and walls.
//! * [`engine`]: the event-driven collision step over a whole particle set ([`CollisionEngine`];
//!   spheres, and spheroids with orientations via [`SpheroidArrays`]):
//!   cell-grid candidates, a warm-started resting-contact solve, the time-ordered binary-collision
//!   loop and an overlap projection.
//! * `cells` (private): candidate pairs from a cell grid.
//!
//! Deviations from the thesis (errata and filled gaps) are listed in each module header: the
//! momentum-conserving sign of (2.33), the inverted restitution ratios (erratum E-002-9c), the clamp of
//! (2.36) below its threshold, the wall and unequal-sphere Stokes numbers, the rest speed, the
//! resting-contact solve, the approach tolerance, the event cap and the overlap projection.

mod cells;
pub mod domain;
pub mod engine;
pub mod impulse;
pub mod restitution;
pub mod spheroid;
pub mod toi;

pub use domain::{CollisionDomain, PeriodicAxis};
pub use engine::{
    CollisionEngine, CollisionError, CollisionEvent, CollisionReport, CollisionStats, EngineConfig,
    InverseInertia, LastCollision, ParticleArrays, Partner, SpheroidArrays,
};
pub use impulse::{CollisionImpulse, CollisionLaw, FrictionRegime, RigidBody, collision_impulse};
pub use restitution::{CollisionModel, Counterpart, Restitution};
pub use toi::{CollisionShape, ContactGeometry, Plane};
