#!/usr/bin/env python3
"""Check a magsep recording (MCAP) with the reference Python readers.

Usage: python3 read_recording.py FILE.mcap

Needs `pip install mcap mcap-protobuf-support`. Reads the file twice:

1. linearly with `mcap.stream_reader.StreamReader(validate_crcs=True)`, which checks every
   record, the chunk CRCs and the data-section CRC, and collects the metadata records;
2. with `mcap.reader.make_reader(validate_crcs=True)` and
   `mcap_protobuf.decoder.DecoderFactory`, decoding every message on every channel with the
   schemas embedded in the file.

It checks the layout of every /state message (byte lengths of the arrays against the particle
count, status_json is JSON), the /scene messages (entities in frame "world"; the box outline is
absent for unbounded runs such as the brownian pipeline's), the `magsep` metadata keys (and the
optional `plugins` and `extra` of newer files), the `magsep.summary` JSON, that log times never
decrease and that /state and /scene have one message per frame. Any other channel (one that a
plugin added) is decoded from the schema embedded in the file alone: protobuf channels through
`mcap_protobuf`, `json` channels as JSON.

On success it prints one JSON line `{"channels": {topic: count, ...}, "frames": n,
"pipeline": ..., "plugins": [names], "state_fields_documented": k, "extra_channels": {topic:
{"schema": name, "encoding": ..., "first_message": {...}}}}` and exits 0, where
`state_fields_documented` counts the /state fields whose comment (layout and unit) is embedded
in the schema (10 for current files, 0 for files written before the comments). On any failure it
prints the reason to stderr and exits 1.
"""

import base64
import json
import math
import sys

from google.protobuf.descriptor_pb2 import FileDescriptorSet
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap.records import DataEnd, Footer, Metadata
from mcap.stream_reader import StreamReader
from mcap_protobuf.decoder import DecoderFactory

STATE_TOPIC = "/state"
SCENE_TOPIC = "/scene"
STATE_SCHEMA = "magsep.ParticleState"
SCENE_SCHEMA = "foxglove.SceneUpdate"
METADATA_KEYS = {"scene_text", "seed", "version", "pipeline", "dt", "schedule"}

# Bytes per particle of each /state array field (little-endian 8-byte words).
PER_PARTICLE = {
    "ids": 8,  # u64
    "positions": 24,  # f64 x, y, z [m]
    "orientations": 32,  # f64 quaternion x, y, z, w
    "radii": 8,  # f64 [m]
    "half_lengths": 8,  # f64 [m]
    "rng_states": 32,  # 4 x u64 xoshiro256++ words
}


class CheckError(Exception):
    pass


def check(condition, message):
    if not condition:
        raise CheckError(message)


def linear_pass(path):
    """Validates every record and CRC; returns the metadata records by name."""
    metadata = {}
    saw_data_end = saw_footer = False
    with open(path, "rb") as f:
        for record in StreamReader(f, emit_chunks=True, validate_crcs=True).records:
            if isinstance(record, Metadata):
                metadata[record.name] = dict(record.metadata)
            elif isinstance(record, DataEnd):
                saw_data_end = True
            elif isinstance(record, Footer):
                saw_footer = True
    check(saw_data_end and saw_footer, "file has no data end record or footer (cut short?)")
    return metadata


def check_metadata(metadata):
    check("magsep" in metadata, f"no `magsep` metadata record (found {sorted(metadata)})")
    meta = metadata["magsep"]
    check(set(meta) >= METADATA_KEYS, f"`magsep` metadata lacks keys {METADATA_KEYS - set(meta)}")
    int(meta["seed"])
    float(meta["dt"])
    # Newer files: the schedule's plugins with their parameters, and plugins' key/values.
    plugins = json.loads(meta.get("plugins", "[]"))
    check(isinstance(plugins, list), "`plugins` is not a JSON array")
    for p in plugins:
        check(isinstance(p, dict) and isinstance(p.get("name"), str), f"bad plugin entry {p!r}")
    extra = json.loads(meta.get("extra", "{}"))
    check(
        isinstance(extra, dict) and all(isinstance(v, str) for v in extra.values()),
        "`extra` is not a JSON object of strings",
    )
    schedule = json.loads(meta["schedule"])
    check(isinstance(schedule, dict), "`schedule` is not a JSON object")
    for name, systems in schedule.items():
        check(
            isinstance(systems, list) and all(isinstance(s, str) for s in systems),
            f"schedule set {name!r} is not a list of system names",
        )
    summary = None
    if "magsep.summary" in metadata:
        check("summary" in metadata["magsep.summary"], "`magsep.summary` lacks key `summary`")
        summary = json.loads(metadata["magsep.summary"]["summary"])
    return meta, summary


def check_state(msg, index):
    n, rem = divmod(len(msg.ids), 8)
    check(rem == 0, f"/state #{index}: ids has {len(msg.ids)} bytes, not a multiple of 8")
    check(len(msg.box_edges) == 24, f"/state #{index}: box_edges has {len(msg.box_edges)} bytes")
    for field, size in PER_PARTICLE.items():
        got = len(getattr(msg, field))
        check(got == size * n, f"/state #{index}: {field} has {got} bytes, expected {size}*{n}")
    check(
        isinstance(json.loads(msg.status_json), dict),
        f"/state #{index}: status_json is not a JSON object",
    )
    check(not math.isnan(msg.time), f"/state #{index}: time is NaN")
    return n


def check_scene(msg, index, bounded):
    """`bounded`: the frame's box edges are not zero, so the box outline must be drawn."""
    ids = [e.id for e in msg.entities]
    check("particles" in ids, f"/scene #{index}: entities are {ids}")
    check(("box" in ids) == bounded, f"/scene #{index}: box outline {'missing' if bounded else 'drawn'} ({ids})")
    for e in msg.entities:
        check(e.frame_id == "world", f"/scene #{index}: entity {e.id} in frame {e.frame_id!r}")
    for box in (e for e in msg.entities if e.id == "box"):
        check(
            len(box.lines) == 1 and len(box.lines[0].points) == 24,
            f"/scene #{index}: the box is not 12 line segments",
        )


def documented_fields(schema):
    """Number of fields of the first message of a protobuf schema that carry a comment."""
    fds = FileDescriptorSet.FromString(schema.data)
    documented = 0
    for file in fds.file:
        for loc in file.source_code_info.location:
            path = list(loc.path)
            # [4, 0, 2, k]: message_type[0].field[k]
            if len(path) == 4 and path[:3] == [4, 0, 2] and loc.leading_comments.strip():
                documented += 1
    return documented


def decode_extra(factory, schema, channel, data):
    """Decodes a message of a plugin channel from the embedded schema; returns JSON-able data."""
    decoder = factory.decoder_for(channel.message_encoding, schema)
    if decoder is not None:
        try:  # protobuf >= 5.26 names the option so; older versions differently
            return MessageToDict(
                decoder(data),
                preserving_proto_field_name=True,
                always_print_fields_with_no_presence=True,
            )
        except TypeError:
            return MessageToDict(
                decoder(data), preserving_proto_field_name=True, including_default_value_fields=True
            )
    if channel.message_encoding == "json":
        return json.loads(data)
    return {"bytes_base64": base64.b64encode(data).decode()}


def main(path):
    metadata = linear_pass(path)

    meta, _ = check_metadata(metadata)
    counts = {}
    schemas = {}
    frames = 0
    last_log_time = -1
    # Log time -> whether that frame's box edges are non-zero (the scene then draws the box).
    bounded = {}
    pending_scenes = []
    extra = {}
    factory = DecoderFactory()
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        for channel in summary.channels.values():
            schema = summary.schemas.get(channel.schema_id)
            schemas[channel.topic] = schema.name if schema else ""
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            topic = channel.topic
            counts[topic] = counts.get(topic, 0) + 1
            check(
                message.log_time >= last_log_time or topic != STATE_TOPIC,
                f"{topic}: log time {message.log_time} after {last_log_time}",
            )
            check(message.publish_time == message.log_time, f"{topic}: publish != log time")
            if topic in (STATE_TOPIC, SCENE_TOPIC):
                decoded = factory.decoder_for(channel.message_encoding, schema)(message.data)
            if topic == STATE_TOPIC:
                last_log_time = message.log_time
                check_state(decoded, frames)
                bounded[message.log_time] = any(x != 0 for x in decoded.box_edges)
                frames += 1
            elif topic == SCENE_TOPIC:
                pending_scenes.append((message.log_time, decoded, counts[topic] - 1))
            elif topic not in extra:
                extra[topic] = {
                    "schema": schema.name if schema else "",
                    "encoding": channel.message_encoding,
                    "first_message": decode_extra(factory, schema, channel, message.data),
                }
            else:
                decode_extra(factory, schema, channel, message.data)
        stats = summary.statistics
        state_schema = next(
            (s for s in summary.schemas.values() if s.name == STATE_SCHEMA), None
        )

    for log_time, scene, index in pending_scenes:
        check(log_time in bounded, f"/scene #{index}: no /state message at log time {log_time}")
        check_scene(scene, index, bounded[log_time])

    check(schemas.get(STATE_TOPIC) == STATE_SCHEMA, f"/state schema is {schemas.get(STATE_TOPIC)}")
    check(schemas.get(SCENE_TOPIC) == SCENE_SCHEMA, f"/scene schema is {schemas.get(SCENE_TOPIC)}")
    check(
        counts.get(SCENE_TOPIC, 0) == frames,
        f"{frames} /state messages but {counts.get(SCENE_TOPIC, 0)} /scene messages",
    )
    check(
        stats is None or stats.message_count == sum(counts.values()),
        "message count differs from the summary statistics",
    )
    print(
        json.dumps(
            {
                "channels": counts,
                "frames": frames,
                "pipeline": meta["pipeline"],
                "plugins": [p["name"] for p in json.loads(meta.get("plugins", "[]"))],
                "state_fields_documented": documented_fields(state_schema) if state_schema else 0,
                "extra_channels": extra,
            }
        )
    )

if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    try:
        main(sys.argv[1])
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        print(f"read_recording.py: {sys.argv[1]}: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
