//! The simulation container (a resource).

use bevy_ecs::prelude::Resource;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The region particles live in.
///
/// ```
/// use magsep_components::container::Container;
/// use glam::DVec3;
/// let c = Container::PeriodicBox { edges: DVec3::splat(2.0) };
/// assert_eq!(c.volume(), 8.0);
/// ```
#[derive(Resource, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Container {
    /// A box periodic in x, y and z, spanning `[0, edges)` on each axis.
    PeriodicBox {
        /// Edge lengths \[m\].
        edges: DVec3,
    },
    /// Unbounded fluid (the Brownian pipeline around fibres): no walls, no periodicity.
    Unbounded,
    /// A box `[0, edges]` bounded by hard walls of kind `walls` (thesis 000, ch. 2), periodic
    /// along the axes the walls leave open.
    Walled {
        /// The wall geometry.
        walls: Walls,
        /// Extent of the bounding box \[m\] (see [`Walls`] for what each edge means).
        edges: DVec3,
    },
}

/// Hard-wall geometries of a [`Container::Walled`]; coordinates are those of its box
/// `[0, edges]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Walls {
    /// A cylinder wall of radius `edges.x / 2` about the axis through (edges.x/2, edges.y/2),
    /// along z (edges.x = edges.y); periodic in z and compressed along z only.
    Cylinder,
    /// A right wedge prism: bottom plane y = 0, back plane x = edges.x, slope plane
    /// y = x tan(angle) through the z axis (edges.y = edges.x tan(angle)); periodic in z and
    /// compressed along z only.
    Wedge {
        /// Acute angle between the bottom and the slope \[rad\].
        angle: f64,
    },
    /// Two walls z = 0 and z = edges.z; periodic in x and y; compressed along z.
    Slab,
    /// Six walls; compressed isotropically.
    Box,
}

impl Container {
    /// Volume [m^3].
    pub fn volume(&self) -> f64 {
        match self {
            Container::PeriodicBox { edges } => edges.x * edges.y * edges.z,
            Container::Unbounded => f64::INFINITY,
            Container::Walled { walls, edges } => match walls {
                Walls::Cylinder => std::f64::consts::PI * 0.25 * edges.x * edges.x * edges.z,
                Walls::Wedge { .. } => 0.5 * edges.x * edges.y * edges.z,
                Walls::Slab | Walls::Box => edges.x * edges.y * edges.z,
            },
        }
    }

    /// The walls, if any.
    pub fn walls(&self) -> Option<Walls> {
        match self {
            Container::Walled { walls, .. } => Some(*walls),
            _ => None,
        }
    }

    /// Edge lengths of the (bounding) box \[m\] (zero when unbounded).
    pub fn edges(&self) -> DVec3 {
        match self {
            Container::PeriodicBox { edges } | Container::Walled { edges, .. } => *edges,
            Container::Unbounded => DVec3::ZERO,
        }
    }
}

/// One face of a hard-wall container, spawned as a boundary entity (its geometry follows the
/// [`Container`] resource, which compression changes).
#[derive(
    bevy_ecs::prelude::Component, Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize,
)]
pub enum WallFace {
    /// The cylinder's lateral wall.
    Cylinder,
    /// The wedge's bottom plane y = 0.
    WedgeBottom,
    /// The wedge's back plane x = edges.x.
    WedgeBack,
    /// The wedge's slope plane y = x tan(angle).
    WedgeSlope,
    /// The plane where coordinate `axis` (0 = x, 1 = y, 2 = z) is 0.
    Low {
        /// Axis index.
        axis: u8,
    },
    /// The plane where coordinate `axis` equals the box edge.
    High {
        /// Axis index.
        axis: u8,
    },
}

impl Walls {
    /// The faces of these walls.
    ///
    /// ```
    /// use magsep_components::container::Walls;
    /// assert_eq!(Walls::Box.faces().len(), 6);
    /// assert_eq!(Walls::Wedge { angle: 0.3 }.faces().len(), 3);
    /// ```
    pub fn faces(&self) -> Vec<WallFace> {
        match self {
            Walls::Cylinder => vec![WallFace::Cylinder],
            Walls::Wedge { .. } => vec![
                WallFace::WedgeBottom,
                WallFace::WedgeBack,
                WallFace::WedgeSlope,
            ],
            Walls::Slab => vec![WallFace::Low { axis: 2 }, WallFace::High { axis: 2 }],
            Walls::Box => (0..3)
                .flat_map(|axis| [WallFace::Low { axis }, WallFace::High { axis }])
                .collect(),
        }
    }
}
