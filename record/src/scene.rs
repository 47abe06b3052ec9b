//! The `/scene` channel: one `foxglove.SceneUpdate` per frame.

use crate::frame::WallShape as Walls;
use crate::{BackdropCube, FibreShape, ParticleFrame, SCENE_FRAME_ID};
use foxglove::messages::{
    Color, CubePrimitive, CylinderPrimitive, Duration, LinePrimitive, Point3, Pose, Quaternion,
    SceneEntity, SceneUpdate, SpherePrimitive, Timestamp, TriangleListPrimitive, Vector3,
    line_primitive,
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

/// What a scene update draws besides the particles.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct SceneDecor {
    /// Fibres (entity `fibres`).
    pub fibres: Vec<FibreShape>,
    /// Hard walls (entity `walls`), sized from the frame's box edges.
    pub walls: Option<Walls>,
    /// Per-particle superquadric semi-axes (zero: sphere or rod); empty: none.
    pub semi_axes: Vec<DVec3>,
    /// Boxes drawn behind the particles (entity `backdrop`); empty: none.
    pub backdrop: Vec<BackdropCube>,
}

/// Id of the backdrop entity (e.g. a magnet field's colour map).
pub const BACKDROP_ENTITY: &str = "backdrop";

/// Id of the walls entity.
pub const WALLS_ENTITY: &str = "walls";
/// Colour of walls (translucent grey).
const WALL_COLOUR: [f32; 4] = [0.7, 0.7, 0.75, 0.25];

/// The wall primitives of `walls` in the box `[0, e]`: a cylinder, the wedge's three faces
/// as triangles, or the slab's two plates (a closed box is its outline).
fn wall_entity(walls: Walls, e: DVec3, entity: SceneEntity) -> SceneEntity {
    let col = colour(WALL_COLOUR);
    let p3 = |x: f64, y: f64, z: f64| Point3 { x, y, z };
    match walls {
        Walls::Cylinder => SceneEntity {
            cylinders: vec![CylinderPrimitive {
                pose: pose(0.5 * e, DQuat::IDENTITY),
                size: Some(vec3(e)),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: col,
            }],
            ..entity
        },
        Walls::Wedge { .. } => {
            // faces: bottom (y = 0), back (x = e.x), slope (through the z axis), two triangles each
            let quads = [
                [
                    p3(0.0, 0.0, 0.0),
                    p3(e.x, 0.0, 0.0),
                    p3(e.x, 0.0, e.z),
                    p3(0.0, 0.0, e.z),
                ],
                [
                    p3(e.x, 0.0, 0.0),
                    p3(e.x, e.y, 0.0),
                    p3(e.x, e.y, e.z),
                    p3(e.x, 0.0, e.z),
                ],
                [
                    p3(0.0, 0.0, 0.0),
                    p3(e.x, e.y, 0.0),
                    p3(e.x, e.y, e.z),
                    p3(0.0, 0.0, e.z),
                ],
            ];
            let mut points = Vec::with_capacity(18);
            for q in quads {
                for k in [0, 1, 2, 0, 2, 3] {
                    points.push(q[k]);
                }
            }
            SceneEntity {
                triangles: vec![TriangleListPrimitive {
                    pose: pose(DVec3::ZERO, DQuat::IDENTITY),
                    points,
                    color: col,
                    ..Default::default()
                }],
                ..entity
            }
        }
        Walls::Slab => {
            let plate = |z: f64| CubePrimitive {
                pose: pose(DVec3::new(0.5 * e.x, 0.5 * e.y, z), DQuat::IDENTITY),
                size: Some(vec3(DVec3::new(e.x, e.y, 1e-3 * e.x.max(e.y)))),
                color: col,
            };
            SceneEntity {
                cubes: vec![plate(0.0), plate(e.z)],
                ..entity
            }
        }
        Walls::Box => entity,
    }
}

/// Id of the fibres entity.
pub const FIBRES_ENTITY: &str = "fibres";
/// Colour of fibres (steel grey).
const FIBRE_COLOUR: [f32; 4] = [0.55, 0.57, 0.62, 1.0];

/// Builds the scene of `frame`: entity `particles` (a sphere of diameter 2R per sphere;
/// a cylinder of size (2R, 2R, 2h) plus two end spheres per capsule; an ellipsoid of the
/// semi-axes per superquadric), entity `box`, entity `walls` when there are hard walls, and
/// entity `fibres` (one cylinder per fibre) when there are fibres.
///
/// `frame`'s arrays must have equal lengths; `colours`, if given, one entry per particle.
#[cfg(test)]
pub(crate) fn scene_update(
    frame: &ParticleFrame,
    colours: Option<&[[f32; 4]]>,
    decor: &SceneDecor,
    log_time_ns: u64,
) -> SceneUpdate {
    let stamp = timestamp(log_time_ns);
    let mut entities = frame_entities(frame, colours, decor, Some(stamp));
    entities.extend(static_entities(decor, Some(stamp)));
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// An empty entity `id` in the scene frame with timestamp `stamp`, kept until replaced.
fn entity(id: &str, stamp: Option<Timestamp>) -> SceneEntity {
    SceneEntity {
        timestamp: stamp,
        frame_id: SCENE_FRAME_ID.into(),
        id: id.into(),
        lifetime: Some(Duration::new(0, 0)),
        ..Default::default()
    }
}

/// The entities that change from frame to frame: particles, box outline, walls.
#[cfg(test)]
fn frame_entities(
    frame: &ParticleFrame,
    colours: Option<&[[f32; 4]]>,
    decor: &SceneDecor,
    stamp: Option<Timestamp>,
) -> Vec<SceneEntity> {
    let mut entities = vec![particles_entity(frame, colours, decor, stamp)];
    entities.extend(box_entities(frame.box_edges, decor.walls, stamp));
    entities
}

/// The particles entity of `frame`.
fn particles_entity(
    frame: &ParticleFrame,
    colours: Option<&[[f32; 4]]>,
    decor: &SceneDecor,
    stamp: Option<Timestamp>,
) -> SceneEntity {
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
        let semi = decor.semi_axes.get(i).copied().unwrap_or(DVec3::ZERO);
        if semi != DVec3::ZERO {
            // a superquadric, drawn as the ellipsoid of its semi-axes
            spheres.push(SpherePrimitive {
                pose: pose(c, q),
                size: Some(vec3(2.0 * semi)),
                color: col,
            });
        } else if h == 0.0 {
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
    SceneEntity {
        spheres,
        cylinders,
        ..entity(PARTICLES_ENTITY, stamp)
    }
}

/// The entities drawn from the box edges `edges` alone: the box outline (none for zero
/// edges) and the walls.
fn box_entities(edges: DVec3, walls: Option<Walls>, stamp: Option<Timestamp>) -> Vec<SceneEntity> {
    let entity = |id: &str| entity(id, stamp);
    let outline = SceneEntity {
        lines: vec![LinePrimitive {
            r#type: line_primitive::Type::LineList as i32,
            pose: pose(DVec3::ZERO, DQuat::IDENTITY),
            thickness: BOX_LINE_PX,
            scale_invariant: true,
            points: box_edge_points(edges),
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
    let mut entities = Vec::new();
    // an unbounded run (the brownian pipeline) records zero edges: no outline
    if edges != DVec3::ZERO {
        entities.push(outline);
    }
    if let Some(w) = walls {
        entities.push(wall_entity(w, edges, entity(WALLS_ENTITY)));
    }
    entities
}

/// The entities that are the same in every frame but for their timestamp: backdrop, fibres.
fn static_entities(decor: &SceneDecor, stamp: Option<Timestamp>) -> Vec<SceneEntity> {
    let fibres = &decor.fibres;
    let entity = |id: &str| entity(id, stamp);
    let mut entities = Vec::new();
    if !decor.backdrop.is_empty() {
        entities.push(SceneEntity {
            cubes: decor
                .backdrop
                .iter()
                .map(|b| CubePrimitive {
                    pose: pose(b.center, DQuat::IDENTITY),
                    size: Some(vec3(b.size)),
                    color: colour(b.colour),
                })
                .collect(),
            ..entity(BACKDROP_ENTITY)
        });
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
    entities
}

/// Entity encodings that frames reuse, without their timestamps (see
/// [`encode_scene_update`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct SceneCache {
    /// The static entities (backdrop, fibres); `None` once the decoration changed.
    statics: Option<Vec<Vec<u8>>>,
    /// The entities drawn from the box edges (outline, walls).
    boxed: Option<BoxedEntities>,
}

/// The encoded entities drawn from the box edges, with the edges' bit patterns and the walls
/// they were built for.
type BoxedEntities = ([u64; 3], Option<Walls>, Vec<Vec<u8>>);

impl SceneCache {
    /// Forget the static entities (the backdrop or the fibres changed).
    pub(crate) fn clear_statics(&mut self) {
        self.statics = None;
    }
}

/// [`scene_update`] encoded into `out` (cleared first), byte for byte as prost encodes it.
/// Only the particles entity is encoded anew at every frame: the static entities (backdrop,
/// fibres) are encoded once into `cache`, and the box outline and walls whenever the box
/// edges (bit for bit) or the walls change; they are most of the bytes of a small frame (a
/// magnet's colour map, a filter's fibres, the outline's 24 points). prost writes a message's
/// fields in tag order, so an entity's encoding is its timestamp (tag 1) followed by the
/// encoding of the same entity without one, and a scene update's is the concatenation of its
/// entities' (tag 2).
pub(crate) fn encode_scene_update(
    frame: &ParticleFrame,
    colours: Option<&[[f32; 4]]>,
    decor: &SceneDecor,
    log_time_ns: u64,
    cache: &mut SceneCache,
    out: &mut Vec<u8>,
) {
    use prost::Message;
    use prost::encoding::{WireType, encode_key, encode_varint};
    let stamp = timestamp(log_time_ns);
    out.clear();
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![particles_entity(frame, colours, decor, Some(stamp))],
    }
    .encode_raw(out);
    let e = frame.box_edges;
    let key = [e.x.to_bits(), e.y.to_bits(), e.z.to_bits()];
    if !matches!(&cache.boxed, Some((k, w, _)) if *k == key && *w == decor.walls) {
        let bodies = box_entities(e, decor.walls, None)
            .iter()
            .map(Message::encode_to_vec)
            .collect();
        cache.boxed = Some((key, decor.walls, bodies));
    }
    let statics = cache.statics.get_or_insert_with(|| {
        static_entities(decor, None)
            .iter()
            .map(Message::encode_to_vec)
            .collect()
    });
    let stamp_bytes = SceneEntity {
        timestamp: Some(stamp),
        ..Default::default()
    }
    .encode_to_vec();
    let boxed = cache.boxed.iter().flat_map(|(_, _, b)| b.iter());
    for body in boxed.chain(statics.iter()) {
        encode_key(2, WireType::LengthDelimited, out);
        encode_varint((stamp_bytes.len() + body.len()) as u64, out);
        out.extend_from_slice(&stamp_bytes);
        out.extend_from_slice(body);
    }
}
