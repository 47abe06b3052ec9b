#!/usr/bin/env python3
"""Decode the `/langevin_trap/energy` channel of a langevin-trap recording from its embedded
schema alone.

Usage: python3 read_custom_channel.py FILE.mcap

Needs `pip install mcap mcap-protobuf-support`. The recording is written by the example
pipeline in examples/langevin_trap (`langevin-trap run SCENE --record FILE.mcap`). This script
knows nothing of the message type beyond its field names: `mcap_protobuf.decoder.DecoderFactory`
builds the message class from the `FileDescriptorSet` stored in the file's schema record.

It checks that the channel's schema is `langevin_trap.Energy` (encoding protobuf), that there is
one message per `/state` frame with the same log time, that steps increase, that every field is
finite with `mean_potential_energy_j = k * msd_m2 / 2` for the k of the recorded scene, that the
schema documents every field, and that late frames average <U> = 3/2 k_B T within 10 %. It
prints every message as a line, then a JSON summary line, and exits 0; on any failure it prints
the reason to stderr and exits 1.
"""

import json
import math
import sys
import tomllib

from google.protobuf import descriptor_pb2
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

TOPIC = "/langevin_trap/energy"
SCHEMA = "langevin_trap.Energy"
FIELDS = ["step", "time_s", "mean_potential_energy_j", "msd_m2"]
BOLTZMANN = 1.380649e-23  # J/K


class CheckError(Exception):
    pass


def check(condition, message):
    if not condition:
        raise CheckError(message)


def field_comments(schema_data):
    """Field name -> leading comment, from the schema's FileDescriptorSet."""
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema_data)
    check(len(fds.file) == 1, f"schema has {len(fds.file)} files, expected 1")
    f = fds.file[0]
    comments = {}
    for loc in f.source_code_info.location:
        # path [4, 0, 2, i]: message_type[0].field[i]
        if len(loc.path) == 4 and loc.path[0] == 4 and loc.path[2] == 2:
            comments[f.message_type[0].field[loc.path[3]].name] = loc.leading_comments.strip()
    return comments


def main(path):
    energy, state_times, scene_text, schema = [], [], None, None
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for record in reader.iter_metadata():
            if record.name == "magsep":
                scene_text = record.metadata.get("scene_text")
        for sch, channel, message, decoded in reader.iter_decoded_messages():
            if channel.topic == "/state":
                state_times.append(message.log_time)
            elif channel.topic == TOPIC:
                schema = sch
                energy.append((message.log_time, decoded))
    check(schema is not None, f"no messages on {TOPIC}")
    check(schema.name == SCHEMA, f"schema {schema.name!r}, expected {SCHEMA!r}")
    check(schema.encoding == "protobuf", f"schema encoding {schema.encoding!r}")
    comments = field_comments(schema.data)
    for name in FIELDS:
        check(comments.get(name), f"field {name} has no comment in the schema")
    check(
        len(energy) == len(state_times),
        f"{len(energy)} energy messages for {len(state_times)} /state frames",
    )
    check(scene_text is not None, "no `magsep` metadata record with the scene text")
    trap = tomllib.loads(scene_text)["trap"]
    k, temperature = trap["stiffness"], trap["temperature"]
    last_step = -1
    for (log_time, m), frame_time in zip(energy, state_times):
        names = [fd.name for fd in m.DESCRIPTOR.fields]
        check(names == FIELDS, f"fields {names}, expected {FIELDS}")
        check(log_time == frame_time, f"step {m.step}: log time {log_time} != frame {frame_time}")
        check(m.step > last_step, f"step {m.step} after {last_step}")
        last_step = m.step
        for name in FIELDS[1:]:
            check(math.isfinite(getattr(m, name)), f"step {m.step}: {name} not finite")
        u = 0.5 * k * m.msd_m2
        check(
            math.isclose(m.mean_potential_energy_j, u, rel_tol=1e-12, abs_tol=0.0),
            f"step {m.step}: U = {m.mean_potential_energy_j} J, k msd / 2 = {u} J",
        )
        print(
            f"step {m.step:6d}  t = {m.time_s:.6g} s  <U> = {m.mean_potential_energy_j:.6e} J"
            f"  msd = {m.msd_m2:.6e} m^2"
        )
    late = [m.mean_potential_energy_j for _, m in energy[len(energy) // 2 :]]
    mean_u = sum(late) / len(late)
    theory = 1.5 * BOLTZMANN * temperature
    check(
        abs(mean_u / theory - 1.0) < 0.1,
        f"late <U> = {mean_u} J, 3/2 k_B T = {theory} J",
    )
    print(
        json.dumps(
            {
                "topic": TOPIC,
                "schema": schema.name,
                "messages": len(energy),
                "last_step": last_step,
                "late_mean_potential_energy_j": mean_u,
                "theory_j": theory,
                "field_comments": comments,
            }
        )
    )


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    try:
        main(sys.argv[1])
    except (CheckError, OSError, KeyError, ValueError) as e:
        print(f"read_custom_channel: {e}", file=sys.stderr)
        sys.exit(1)
