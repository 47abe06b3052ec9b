//! Per-contribution forces (docs/architecture.md §2, schedule).
//!
//! Every force model writes its **own** component (`FieldForce`, `DipoleForce`, a user's
//! `MyForce`, ...), each implementing [`ForceContribution`]. The `Accumulate` set then sums the
//! registered contributions into [`NetForce`] / [`NetTorque`] in a fixed registration order, so
//! the sum is bitwise reproducible and each contribution stays inspectable.

use bevy_ecs::prelude::Component;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A force (and torque) contribution component.
///
/// ```
/// use bevy_ecs::prelude::Component;
/// use glam::DVec3;
/// use magsep_components::forces::ForceContribution;
///
/// /// Gravity on a particle [N].
/// #[derive(Component, Default, Clone, Copy)]
/// struct GravityForce(DVec3);
/// impl ForceContribution for GravityForce {
///     fn force(&self) -> DVec3 { self.0 }
///     fn clear(&mut self) { self.0 = DVec3::ZERO; }
/// }
/// let g = GravityForce(DVec3::new(0.0, 0.0, -9.81));
/// assert_eq!(g.torque(), DVec3::ZERO);
/// ```
pub trait ForceContribution:
    Component<Mutability = bevy_ecs::component::Mutable> + Default
{
    /// Force on the particle \[N\].
    fn force(&self) -> DVec3;
    /// Torque on the particle about its centre [N m]. Default: none.
    fn torque(&self) -> DVec3 {
        DVec3::ZERO
    }
    /// Reset to zero at the start of a step.
    fn clear(&mut self);
}

/// Sum of all registered contributions \[N\].
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NetForce(pub DVec3);

/// Sum of all registered torque contributions [N m].
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NetTorque(pub DVec3);

/// Define a force contribution component: a newtype around a force \[N\] implementing
/// [`ForceContribution`] (used by the built-in contributions and by plugins).
///
/// The expansion names `bevy_ecs`, `glam` and `serde` only through this crate, so it
/// compiles in a crate that depends on nothing but `magsep` (or `magsep_components`):
///
/// ```
/// use magsep_components::force_contribution;
/// use magsep_components::forces::ForceContribution;
/// force_contribution!(
///     /// A test force [N].
///     TestForce
/// );
/// let mut f = TestForce(glam::DVec3::X);
/// f.clear();
/// assert_eq!(f.force(), glam::DVec3::ZERO);
/// ```
#[macro_export]
macro_rules! force_contribution {
    ($(#[$doc:meta])* $name:ident) => {
        $crate::__contribution_type!($(#[$doc])* $name);

        impl $crate::forces::ForceContribution for $name {
            fn force(&self) -> $crate::__private::glam::DVec3 {
                self.0
            }
            fn clear(&mut self) {
                self.0 = $crate::__private::glam::DVec3::ZERO;
            }
        }
    };
}

/// Declare a torque-only contribution component: a newtype over the torque `DVec3` [N m]
/// that implements [`ForceContribution`] with zero force (paths as in [`force_contribution!`]).
#[macro_export]
macro_rules! torque_contribution {
    ($(#[$doc:meta])* $name:ident) => {
        $crate::__contribution_type!($(#[$doc])* $name);

        impl $crate::forces::ForceContribution for $name {
            fn force(&self) -> $crate::__private::glam::DVec3 {
                $crate::__private::glam::DVec3::ZERO
            }
            fn torque(&self) -> $crate::__private::glam::DVec3 {
                self.0
            }
            fn clear(&mut self) {
                self.0 = $crate::__private::glam::DVec3::ZERO;
            }
        }
    };
}

/// The newtype and its `Component`, `Serialize` and `Deserialize` impls, written out (not
/// derived) so that no path depends on the caller's imports. Serialisation is that of the
/// inner vector, as `#[derive]` gives a newtype struct in JSON and TOML.
#[doc(hidden)]
#[macro_export]
macro_rules! __contribution_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Default, Clone, Copy, PartialEq)]
        pub struct $name(pub $crate::__private::glam::DVec3);

        impl $crate::__private::bevy_ecs::component::Component for $name {
            const STORAGE_TYPE: $crate::__private::bevy_ecs::component::StorageType =
                $crate::__private::bevy_ecs::component::StorageType::Table;
            type Mutability = $crate::__private::bevy_ecs::component::Mutable;
        }

        impl $crate::__private::serde::Serialize for $name {
            fn serialize<S: $crate::__private::serde::Serializer>(
                &self,
                serializer: S,
            ) -> ::core::result::Result<S::Ok, S::Error> {
                serializer.serialize_newtype_struct(::core::stringify!($name), &self.0)
            }
        }

        impl<'de> $crate::__private::serde::Deserialize<'de> for $name {
            fn deserialize<D: $crate::__private::serde::Deserializer<'de>>(
                deserializer: D,
            ) -> ::core::result::Result<Self, D::Error> {
                <$crate::__private::glam::DVec3 as $crate::__private::serde::Deserialize>::deserialize(
                    deserializer,
                )
                .map($name)
            }
        }
    };
}

/// The sum of the registered external force kernels at the particle at the start of the step
/// (a built-in contribution, written by `magsep_systems::forces::compute_kernel_forces` when a
/// kernel is registered): force \[N\] and torque about the centre [N m]. Pipelines that
/// integrate with sub-steps re-evaluate the kernels themselves; this component is what the
/// step-start `NetForce` holds.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KernelForce {
    /// Force \[N\].
    pub force: DVec3,
    /// Torque about the centre [N m].
    pub torque: DVec3,
}

impl ForceContribution for KernelForce {
    fn force(&self) -> DVec3 {
        self.force
    }
    fn torque(&self) -> DVec3 {
        self.torque
    }
    fn clear(&mut self) {
        *self = Self::default();
    }
}
