//! `foxglove.Grid` messages: a plane of scalar fields on a uniform grid, placed anywhere in
//! the scene's `world` frame, for channels that plugins add (e.g. slices of a liquid's
//! velocity). Foxglove's 3D panel draws them beside the `/scene` particles.

use foxglove::Encode;
use foxglove::messages::{
    Grid, PackedElementField, Pose, Quaternion, Vector2, Vector3, packed_element_field::NumericType,
};
use glam::{DQuat, DVec3};

use crate::writer::ChannelHandle;
use crate::{RecordError, RecordingWriter, SCENE_FRAME_ID};

/// A uniform 2-D grid of named float64 fields: `columns × rows` cells of `cell_size` \[m\],
/// its corner at `origin` \[m\], its plane spanned by `rotation · e_x` (columns) and
/// `rotation · e_y` (rows). Every field has `columns · rows` values, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct GridSlice<'a> {
    /// Log time of the slice \[ns\] (as the frame of the same step, see
    /// [`log_time_ns`](crate::log_time_ns)).
    pub log_time_ns: u64,
    /// Corner of the grid \[m\].
    pub origin: DVec3,
    /// Orientation of the grid plane.
    pub rotation: DQuat,
    /// Cell size along columns and rows \[m\].
    pub cell_size: [f64; 2],
    /// Number of columns.
    pub columns: usize,
    /// Number of rows.
    pub rows: usize,
    /// Named fields, each `columns · rows` values, row-major.
    pub fields: &'a [(&'a str, &'a [f64])],
}

impl GridSlice<'_> {
    /// The encoded `foxglove.Grid` message.
    ///
    /// # Errors
    /// [`RecordError::InvalidInput`] when a field has the wrong length or the grid is empty.
    pub fn encode(&self) -> Result<Vec<u8>, RecordError> {
        let cells = self.columns * self.rows;
        if cells == 0 || self.fields.is_empty() || self.fields.iter().any(|(_, f)| f.len() != cells)
        {
            return Err(RecordError::InvalidInput {
                detail: format!(
                    "a grid slice needs non-empty fields of {} x {} values",
                    self.columns, self.rows
                ),
            });
        }
        let stride = 8 * self.fields.len();
        let mut data = Vec::with_capacity(cells * stride);
        for c in 0..cells {
            for (_, f) in self.fields {
                data.extend_from_slice(&f[c].to_le_bytes());
            }
        }
        let grid = Grid {
            timestamp: Some(crate::scene::timestamp(self.log_time_ns)),
            frame_id: SCENE_FRAME_ID.to_string(),
            pose: Some(Pose {
                position: Some(Vector3 {
                    x: self.origin.x,
                    y: self.origin.y,
                    z: self.origin.z,
                }),
                orientation: Some(Quaternion {
                    x: self.rotation.x,
                    y: self.rotation.y,
                    z: self.rotation.z,
                    w: self.rotation.w,
                }),
            }),
            column_count: self.columns as u32,
            cell_size: Some(Vector2 {
                x: self.cell_size[0],
                y: self.cell_size[1],
            }),
            row_stride: (self.columns * stride) as u32,
            cell_stride: stride as u32,
            fields: self
                .fields
                .iter()
                .enumerate()
                .map(|(k, (name, _))| PackedElementField {
                    name: (*name).to_string(),
                    offset: (8 * k) as u32,
                    r#type: NumericType::Float64 as i32,
                })
                .collect(),
            data: data.into(),
        };
        let mut buf = Vec::with_capacity(grid.encoded_len().unwrap_or(0));
        grid.encode(&mut buf)
            .map_err(|e| RecordError::InvalidInput {
                detail: format!("encoding a grid slice: {e}"),
            })?;
        Ok(buf)
    }
}

/// Add a `foxglove.Grid` channel on `topic`.
///
/// # Errors
/// As [`RecordingWriter::add_channel`].
pub fn add_grid_channel(
    writer: &mut RecordingWriter,
    topic: &str,
) -> Result<ChannelHandle, RecordError> {
    let schema = <Grid as Encode>::get_schema().ok_or_else(|| RecordError::InvalidInput {
        detail: "foxglove provides no schema for Grid".into(),
    })?;
    let encoding = <Grid as Encode>::get_message_encoding();
    writer.add_channel(
        topic,
        &schema.name,
        &schema.encoding,
        &schema.data,
        &encoding,
    )
}
