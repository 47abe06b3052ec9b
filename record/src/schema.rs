//! Self-describing protobuf schemas for MCAP channels.
//!
//! [`protobuf_schema`] builds the `FileDescriptorSet` that an MCAP schema record of encoding
//! `protobuf` carries, for one proto3 message of scalar, string or bytes fields. Each field's
//! comment is stored in the descriptor's `SourceCodeInfo` (as a leading comment), so a reader
//! that has only the file — e.g. Python's `mcap-protobuf-support`, or `protoc --decode` after
//! extracting the schema — can decode the messages and read what each field means and in which
//! unit.
//!
//! ```
//! use magsep_record::{ProtoField, ProtoLabel, ProtoType, protobuf_schema};
//!
//! let schema = protobuf_schema(
//!     "magsep.plugins",
//!     "Energy",
//!     "Energies of the system at one step.",
//!     &[
//!         ProtoField::new("step", 1, ProtoType::Uint64, "schedule step"),
//!         ProtoField::new("kinetic_j", 2, ProtoType::Double, "kinetic energy [J]"),
//!         ProtoField::new("per_particle_j", 3, ProtoType::Double, "energy per particle [J]")
//!             .with_label(ProtoLabel::Repeated),
//!     ],
//! )?;
//! assert_eq!(schema.name, "magsep.plugins.Energy");
//! assert_eq!(schema.encoding, "protobuf");
//! # Ok::<(), magsep_record::RecordError>(())
//! ```

use super::RecordError;
use prost::Message as _;
use prost_types::source_code_info::Location;
use prost_types::{
    DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet, SourceCodeInfo,
};
use std::collections::BTreeSet;

pub use prost_types::field_descriptor_proto::{Label as ProtoLabel, Type as ProtoType};

/// `FileDescriptorProto.message_type` field number (path component in `SourceCodeInfo`).
const FILE_MESSAGE_TYPE: i32 = 4;
/// `DescriptorProto.field` field number (path component in `SourceCodeInfo`).
const MESSAGE_FIELD: i32 = 2;

/// One field of a message built by [`protobuf_schema`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProtoField<'a> {
    /// Field name (an identifier: letters, digits, `_`; not starting with a digit).
    pub name: &'a str,
    /// Field number (1..=536870911, outside the reserved 19000..=19999).
    pub number: i32,
    /// Scalar, `string` or `bytes` type (message, enum and group types are not supported).
    pub ty: ProtoType,
    /// [`ProtoLabel::Optional`] (a singular proto3 field) or [`ProtoLabel::Repeated`].
    pub label: ProtoLabel,
    /// What the field holds, with its unit; stored as the field's leading comment.
    pub comment: &'a str,
}

impl<'a> ProtoField<'a> {
    /// A singular field.
    pub const fn new(name: &'a str, number: i32, ty: ProtoType, comment: &'a str) -> Self {
        Self {
            name,
            number,
            ty,
            label: ProtoLabel::Optional,
            comment,
        }
    }

    /// The same field with another label (e.g. [`ProtoLabel::Repeated`]).
    pub const fn with_label(self, label: ProtoLabel) -> Self {
        Self { label, ..self }
    }
}

/// A protobuf schema ready for an MCAP schema record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProtobufSchema {
    /// Fully qualified message name, `package.Message` (the MCAP schema name).
    pub name: String,
    /// Schema encoding: always `protobuf`.
    pub encoding: String,
    /// The encoded `google.protobuf.FileDescriptorSet` (one file, one message).
    pub data: Vec<u8>,
}

/// Builds a proto3 schema of one message `package.message_name` with `fields`, documented by
/// `message_comment` and each field's comment (in `SourceCodeInfo`). The descriptor's file is
/// named `<package with '/' for '.'>/<message_name>.proto`.
///
/// Fails with [`RecordError::InvalidInput`] for an invalid package, message or field name,
/// duplicate field names or numbers, a number out of range, a message, enum or group type,
/// or a `required` label.
pub fn protobuf_schema(
    package: &str,
    message_name: &str,
    message_comment: &str,
    fields: &[ProtoField<'_>],
) -> Result<ProtobufSchema, RecordError> {
    let file = format!("{}/{message_name}.proto", package.replace('.', "/"));
    build_schema(&file, package, message_name, message_comment, fields)
}

fn invalid(detail: String) -> RecordError {
    RecordError::InvalidInput { detail }
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Like [`protobuf_schema`] with an explicit descriptor file name.
pub(crate) fn build_schema(
    file_name: &str,
    package: &str,
    message_name: &str,
    message_comment: &str,
    fields: &[ProtoField<'_>],
) -> Result<ProtobufSchema, RecordError> {
    if !package.split('.').all(is_identifier) {
        return Err(invalid(format!(
            "protobuf package {package:?} is not a dotted list of identifiers"
        )));
    }
    if !is_identifier(message_name) {
        return Err(invalid(format!(
            "protobuf message name {message_name:?} is not an identifier"
        )));
    }
    let (mut names, mut numbers) = (BTreeSet::new(), BTreeSet::new());
    let mut field_protos = Vec::with_capacity(fields.len());
    let doc = |path: Vec<i32>, comment: &str| Location {
        path,
        span: vec![0, 0, 0],
        leading_comments: Some(format!(" {}\n", comment.trim())),
        ..Default::default()
    };
    let mut locations = vec![doc(vec![FILE_MESSAGE_TYPE, 0], message_comment)];
    for (k, f) in fields.iter().enumerate() {
        let what = format!("field {:?} of {package}.{message_name}", f.name);
        if !is_identifier(f.name) {
            return Err(invalid(format!("{what}: the name is not an identifier")));
        }
        if !(1..=536_870_911).contains(&f.number) || (19_000..=19_999).contains(&f.number) {
            return Err(invalid(format!(
                "{what}: number {} is outside 1..=536870911 or in the reserved 19000..=19999",
                f.number
            )));
        }
        if !names.insert(f.name) || !numbers.insert(f.number) {
            return Err(invalid(format!(
                "{what}: name or number {} repeats",
                f.number
            )));
        }
        if matches!(
            f.ty,
            ProtoType::Message | ProtoType::Enum | ProtoType::Group
        ) {
            return Err(invalid(format!(
                "{what}: type {:?} is not supported (scalars, string and bytes only)",
                f.ty
            )));
        }
        if f.label == ProtoLabel::Required {
            return Err(invalid(format!("{what}: proto3 has no required fields")));
        }
        field_protos.push(FieldDescriptorProto {
            name: Some(f.name.into()),
            number: Some(f.number),
            label: Some(f.label as i32),
            r#type: Some(f.ty as i32),
            json_name: Some(json_name(f.name)),
            ..Default::default()
        });
        if !f.comment.trim().is_empty() {
            locations.push(doc(
                vec![FILE_MESSAGE_TYPE, 0, MESSAGE_FIELD, k as i32],
                f.comment,
            ));
        }
    }
    let file = FileDescriptorProto {
        name: Some(file_name.into()),
        package: Some(package.into()),
        message_type: vec![DescriptorProto {
            name: Some(message_name.into()),
            field: field_protos,
            ..Default::default()
        }],
        source_code_info: Some(SourceCodeInfo {
            location: locations,
        }),
        syntax: Some("proto3".into()),
        ..Default::default()
    };
    Ok(ProtobufSchema {
        name: format!("{package}.{message_name}"),
        encoding: "protobuf".into(),
        data: FileDescriptorSet { file: vec![file] }.encode_to_vec(),
    })
}

/// protoc's JSON name: `lower_snake` -> `lowerSnake`.
fn json_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.push(c.to_ascii_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// The leading comment of each field of the first message of `fds` (empty when absent), in
/// field order; for readers and tests.
pub fn field_comments(fds: &FileDescriptorSet) -> Vec<(String, String)> {
    let Some(file) = fds.file.first() else {
        return Vec::new();
    };
    let Some(msg) = file.message_type.first() else {
        return Vec::new();
    };
    let locations = file
        .source_code_info
        .as_ref()
        .map_or(&[][..], |s| &s.location[..]);
    msg.field
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let path = [FILE_MESSAGE_TYPE, 0, MESSAGE_FIELD, k as i32];
            let comment = locations
                .iter()
                .find(|l| l.path == path)
                .and_then(|l| l.leading_comments.as_deref())
                .unwrap_or("")
                .trim()
                .to_string();
            (f.name().to_string(), comment)
        })
        .collect()
}
