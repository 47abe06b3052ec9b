//! Inertial particles in magnetised liquids (thesis 002, ch. 1-2): the quasi-static
//! ferrohydrodynamics of a paramagnetic liquid (magnet fields, apparent density, magnetic
//! buoyancy), the extended Maxey-Riley equation with the Basset history force, and the
//! exact unsteady-Stokes reference used to validate it.
//!
//! * [`magnet`]: magnet fields, apparent density, magnetic buoyancy, equilibrium heights.
//! * [`levitation`]: linear stability (node/spiral), critical diameter, levitation time.
//! * [`drag`]: Schiller-Naumann and rotational (Dennis) drag with implicit stiffnesses.
//! * [`flow`]: prescribed undisturbed flows (one-way coupling).
//! * [`motion`]: the equation of motion and its (linearly implicit or explicit) Euler step.
//! * [`rigid`]: quaternion kinematics and Euler's equations of axisymmetric bodies.
//! * [`single`]: one sphere moving vertically (the thesis's reduced 1-D system).
//! * [`spheroid`]: drag, lift, pitching and rotational torques on oblate spheroids (ch. 3-4),
//!   and the magnetic-buoyancy torque.
//! * [`systems`], [`spheroid_systems`], [`collide`]: the thin ECS systems of the particle-fluid
//!   pipeline.
//! * [`observe`]: the separation error e_m (eq. 2.51).
//! * [`channel`]: the two-way coupled channel-flow solver and its coupling to the particles.
//! * [`config`]: the pipeline's configuration resource.
//! * [`history`]: the Basset history integral: full-memory product integration and the
//!   window + exponential-tail kernel of van Hinsberg et al. (2011).
//! * [`stokes_reference`]: the exact velocity of a sphere released in unsteady Stokes flow
//!   (Basset-Boussinesq-Oseen), by numerical Laplace inversion.

pub mod channel;
pub mod collide;
pub mod config;
pub mod drag;
pub mod flow;
pub mod history;
pub mod levitation;
pub mod magnet;
pub mod motion;
pub mod observe;
pub mod rigid;
pub mod single;
pub mod spheroid;
pub mod spheroid_systems;
pub mod stokes_reference;
pub mod systems;
