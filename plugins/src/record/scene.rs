//! The `/scene` channel: one `foxglove.SceneUpdate` per frame.

use super::{FibreShape, ParticleFrame, SCENE_FRAME_ID};
use foxglove::messages::{
    Color, CylinderPrimitive, Duration, LinePrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneUpdate, SpherePrimitive, Timestamp, Vector3, line_primitive,
};
use glam::{DQuat, DVec3};

/// Entity id of the particles.
pub(crate) const PARTICLES_ENTITY: &str = "particles";
/// Entity id of the box outline.
pub(crate) const BOX_ENTITY: &str = "box";
/// Particle colour when none is given (RGBA, 0..1).
pub(crate) const DEFAULT_COLOUR: [f32; 4] = [0.35, 0.55, 0.85, 1.0];
/// Colour of the box edges (RGBA, 0..1).
const BOX_COLOUR: [f64; 4] = [0.8, 0.8, 0.8, 1.0];
/// Thickness of the box edges (screen pixels).
const BOX_LINE_PX: f64 = 1.5;

fn vec3(v: DVec3) -> Vector3 {
    Vector3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

fn pose(p: DVec3, q: DQuat) -> Option<Pose> {
    Some(Pose {
        position: Some(vec3(p)),
        orientation: Some(Quaternion {
            x: q.x,
            y: q.y,
            z: q.z,
            w: q.w,
        }),
    })
}

fn colour(c: [f32; 4]) -> Option<Color> {
    Some(Color {
        r: f64::from(c[0]),
        g: f64::from(c[1]),
        b: f64::from(c[2]),
        a: f64::from(c[3]),
    })
}

/// Foxglove timestamp of a log time in nanoseconds (seconds saturate at `u32::MAX`).
pub(crate) fn timestamp(log_time_ns: u64) -> Timestamp {
    let sec = u32::try_from(log_time_ns / 1_000_000_000).unwrap_or(u32::MAX);
    Timestamp::new(sec, (log_time_ns % 1_000_000_000) as u32)
}

/// The 12 edges of the box `[0, e)` as 24 end points (a `LINE_LIST`).
pub(crate) fn box_edge_points(e: DVec3) -> Vec<Point3> {
    let corner = |i: u8| {
        DVec3::new(
            if i & 1 != 0 { e.x } else { 0.0 },
            if i & 2 != 0 { e.y } else { 0.0 },
            if i & 4 != 0 { e.z } else { 0.0 },
        )
    };
    let mut points = Vec::with_capacity(24);
    for a in 0u8..8 {
        for bit in [1u8, 2, 4] {
            if a & bit == 0 {
                for p in [corner(a), corner(a | bit)] {
                    points.push(Point3 {
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    });
                }
            }
        }
    }
    points
}

/// Id of the fibres entity.
pub const FIBRES_ENTITY: &str = "fibres";
/// Colour of fibres (steel grey).
const FIBRE_COLOUR: [f32; 4] = [0.55, 0.57, 0.62, 1.0];

/// Builds the scene of `frame`: entity `particles` (a sphere of diameter 2R per sphere;
/// a cylinder of size (2R, 2R, 2h) plus two end spheres per capsule), entity `box`, and entity
/// `fibres` (one cylinder per fibre) when there are fibres.
///
/// `frame`'s arrays must have equal lengths; `colours`, if given, one entry per particle.
pub(crate) fn scene_update(
    frame: &ParticleFrame,
    colours: Option<&[[f32; 4]]>,
    fibres: &[FibreShape],
    log_time_ns: u64,
) -> SceneUpdate {
    let stamp = timestamp(log_time_ns);
    let mut spheres = Vec::with_capacity(frame.ids.len());
    let mut cylinders = Vec::new();
    for i in 0..frame.ids.len() {
        let (c, q) = (frame.positions[i], frame.orientations[i]);
        let (r, h) = (frame.radii[i], frame.half_lengths[i]);
        let col = colour(colours.map_or(DEFAULT_COLOUR, |cs| cs[i]));
        let d = 2.0 * r;
        let sphere = |centre: DVec3| SpherePrimitive {
            pose: pose(centre, q),
            size: Some(vec3(DVec3::splat(d))),
            color: col,
        };
        if h == 0.0 {
            spheres.push(sphere(c));
        } else {
            // Foxglove cylinders have their axis along local z; the orientation maps body z
            // (the capsule axis) to the world.
            cylinders.push(CylinderPrimitive {
                pose: pose(c, q),
                size: Some(vec3(DVec3::new(d, d, 2.0 * h))),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: col,
            });
            let axis = q * DVec3::Z;
            spheres.push(sphere(c + h * axis));
            spheres.push(sphere(c - h * axis));
        }
    }
    let entity = |id: &str| SceneEntity {
        timestamp: Some(stamp),
        frame_id: SCENE_FRAME_ID.into(),
        id: id.into(),
        lifetime: Some(Duration::new(0, 0)),
        ..Default::default()
    };
    let particles = SceneEntity {
        spheres,
        cylinders,
        ..entity(PARTICLES_ENTITY)
    };
    let outline = SceneEntity {
        lines: vec![LinePrimitive {
            r#type: line_primitive::Type::LineList as i32,
            pose: pose(DVec3::ZERO, DQuat::IDENTITY),
            thickness: BOX_LINE_PX,
            scale_invariant: true,
            points: box_edge_points(frame.box_edges),
            color: Some(Color {
                r: BOX_COLOUR[0],
                g: BOX_COLOUR[1],
                b: BOX_COLOUR[2],
                a: BOX_COLOUR[3],
            }),
            ..Default::default()
        }],
        ..entity(BOX_ENTITY)
    };
    let mut entities = vec![particles];
    // an unbounded run (the brownian pipeline) records zero edges: no outline
    if frame.box_edges != DVec3::ZERO {
        entities.push(outline);
    }
    if !fibres.is_empty() {
        entities.push(SceneEntity {
            cylinders: fibres
                .iter()
                .map(|f| CylinderPrimitive {
                    // Foxglove cylinders have their axis along local z
                    pose: pose(
                        f.center,
                        DQuat::from_rotation_arc(DVec3::Z, f.axis.normalize()),
                    ),
                    size: Some(vec3(DVec3::new(
                        2.0 * f.radius,
                        2.0 * f.radius,
                        2.0 * f.half_length,
                    ))),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: colour(FIBRE_COLOUR),
                })
                .collect(),
            ..entity(FIBRES_ENTITY)
        });
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}
