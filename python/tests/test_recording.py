"""magsep.open_recording: frames equal to the library's whole-file reader bit for bit,
metadata and channels as `magsep info` gives them, truncated files, plugin channels, pandas."""

import numpy as np
import pytest

import magsep
from magsep import _magsep
from conftest import ROOT, bits, cli_json

FIELDS = ["step", "time", "box_edges", "ids", "positions", "orientations", "radii", "half_lengths", "rng_states", "status_json"]


def assert_frame_equal(frame, want):
    for name in FIELDS:
        got, ref = getattr(frame, name), want[name]
        if isinstance(ref, np.ndarray) and ref.dtype == np.float64:
            assert got.shape == ref.shape and np.array_equal(bits(got), bits(ref)), name
        elif isinstance(ref, np.ndarray):
            assert got.dtype == ref.dtype and np.array_equal(got, ref), name
        else:
            assert got == ref, name


@pytest.fixture(scope="module")
def packing(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "mixture.mcap"
    summary = magsep.run(ROOT / "scenes/small_mixture.toml", record=path)
    return path, summary


def test_frames_equal_the_rust_reader_bit_for_bit(packing):
    path, summary = packing
    want, truncated = _magsep.read_recording_frames(str(path))
    rec = magsep.open_recording(path)
    assert truncated is None and rec.truncated is None and rec.damaged is None
    assert len(rec) == len(want) >= 3
    for frame, ref in zip(rec, want):
        assert_frame_equal(frame, ref)
    # random access, negative indices and slices read the same frames
    assert_frame_equal(rec[-1], want[-1])
    assert_frame_equal(rec[1], want[1])
    assert [f.step for f in rec[::2]] == [w["step"] for w in want[::2]]
    with pytest.raises(IndexError):
        rec[len(want)]
    last = rec[-1]
    assert last.positions.shape == (80, 3) and last.orientations.shape == (80, 4)
    assert np.all(last.radii == 0.5)
    assert sorted(set(last.half_lengths.tolist())) == [0.0, 0.5]
    assert rec.summary == summary  # the recorded summary is the returned one


def test_metadata_and_channels_match_magsep_info(packing):
    path, _ = packing
    info = cli_json("info", path, "--json")
    rec = magsep.open_recording(path)
    assert rec.seed == 7 and rec.metadata["pipeline"] == "packing"
    assert rec.scene_text == (ROOT / "scenes/small_mixture.toml").read_text()
    assert rec.schedule and all(isinstance(v, list) for v in rec.schedule.values())
    topics = {c["topic"]: c for c in rec.channels}
    assert topics["/state"]["message_count"] == len(rec)
    assert topics["/state"]["schema_name"] == "magsep.ParticleState"
    text = str(info)
    assert str(len(rec)) in text and "/state" in text


def test_messages_are_raw_bytes_with_schema_names(packing):
    path, _ = packing
    rec = magsep.open_recording(path)
    state = list(rec.messages("/state"))
    assert len(state) == len(rec)
    assert all(m.schema_name == "magsep.ParticleState" and isinstance(m.data, bytes) for m in state)
    everything = list(rec.messages())
    counts = {c["topic"]: c["message_count"] for c in rec.channels}
    assert len(everything) == sum(counts.values())
    schema = rec.schema("/state")
    assert schema["name"] == "magsep.ParticleState" and schema["encoding"] == "protobuf" and len(schema["data"]) > 0
    assert list(rec.messages("/no-such-topic")) == []


def test_the_liquid_channels_of_a_particle_fluid_run(tmp_path):
    path = tmp_path / "coupled.mcap"
    magsep.run(ROOT / "tests/data/coupled_short.toml", record=path)
    rec = magsep.open_recording(path)
    plugin = [c for c in rec.channels if c["topic"] not in ("/state", "/scene")]
    assert plugin, rec.channels
    for c in plugin:
        msgs = list(rec.messages(c["topic"]))
        assert len(msgs) == c["message_count"] > 0
        assert all(m.schema_name == c["schema_name"] for m in msgs)


@pytest.mark.parametrize("fraction", [0.5, 0.8, 0.95])
def test_a_truncated_recording_opens_and_reports_truncation(packing, tmp_path, fraction):
    path, _ = packing
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * fraction)])
    want, truncated = _magsep.read_recording_frames(str(cut))
    rec = magsep.open_recording(cut)
    assert rec.truncated is not None and truncated is not None
    assert "ends" in rec.truncated
    if fraction == 0.5:
        # cut among the frames: a strict prefix of them, and no summary yet
        assert 0 < len(want) < len(magsep.open_recording(path))
        assert rec.summary is None
    assert len(rec) == len(want)
    frames = list(rec)
    assert len(frames) == len(want)
    for frame, ref in zip(frames, want):
        assert_frame_equal(frame, ref)


def test_a_damaged_chunk_is_skipped_and_the_rest_read():
    """A bit flip inside one chunk of the corpus's recording: frames and messages skip that
    chunk, read every other one (equal to the intact file's frames bit for bit), and the
    damage is raised only after the last of them."""
    corpus = ROOT / "tests/data/bad_recordings"
    intact = {f.step: f for f in magsep.open_recording(corpus / "base.mcap")}
    rec = magsep.open_recording(corpus / "flip_chunk_data.mcap")
    frames, messages = [], []
    with pytest.raises(magsep.RecordingError, match="skipped"):
        for f in rec:
            frames.append(f)
    with pytest.raises(magsep.RecordingError, match="skipped"):
        for m in rec.messages("/state"):
            messages.append(m)
    assert len(frames) == len(messages) == 4 < len(intact)
    for f in frames:
        ref = intact[f.step]
        for name in ["time", "ids", "positions", "orientations", "radii", "half_lengths"]:
            got, want = getattr(f, name), getattr(ref, name)
            if isinstance(want, np.ndarray) and want.dtype == np.float64:
                assert np.array_equal(bits(got), bits(want)), name
            else:
                assert np.array_equal(got, want), name
    assert "corrupt recording at byte 6265" in rec.damaged


def test_bad_files_raise_value_errors(tmp_path):
    text = tmp_path / "x.mcap"
    text.write_text("not a recording")
    for p in [text, tmp_path / "missing.mcap", tmp_path]:
        with pytest.raises(ValueError):
            magsep.open_recording(p)


def test_to_pandas_has_one_row_per_particle_and_frame(packing):
    pd = pytest.importorskip("pandas")
    path, _ = packing
    rec = magsep.open_recording(path)
    table = rec.to_pandas()
    assert isinstance(table, pd.DataFrame)
    assert len(table) == 80 * len(rec)
    last = rec[-1]
    t = table[table.step == last.step]
    assert np.array_equal(t.x.to_numpy(), last.positions[:, 0])
    assert np.array_equal(t.qw.to_numpy(), last.orientations[:, 3])
    assert list(rec.to_pandas(frames=[0]).step.unique()) == [rec[0].step]


def test_contact_numbers_of_the_final_frame_are_the_summary_s(packing):
    path, summary = packing
    rec = magsep.open_recording(path)
    cn = magsep.contact_numbers(rec[-1])
    assert cn["mean"] == summary["mean_contact_number"]
    assert cn["mean_at_1e-4"] == summary["mean_contact_number_at_1e-4"]
    assert sum(cn["histogram"]) == 80
    bad = rec[-1]
    bad.radii = bad.radii.copy()
    bad.radii[3] = -1.0
    with pytest.raises(ValueError, match=r"radii\[3\]"):
        magsep.contact_numbers(bad)
