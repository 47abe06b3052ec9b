"""magsep.run against `magsep run` (the same summary), scenes as paths, text and dicts,
overrides, the GIL, Ctrl-C, and bad input."""

import json
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import magsep
from conftest import ROOT, cli, cli_json, without_wall_time

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

# one scene of each pipeline, each a few seconds at most
SCENES = [
    "scenes/small_mixture.toml",
    "tests/data/brownian_short.toml",
    "tests/data/levitation_short.toml",
    "tests/data/coupled_short.toml",
]


@pytest.mark.parametrize("scene", SCENES)
def test_summary_equals_the_cli(scene):
    want = cli_json("run", scene, "--quiet", "--seed", "11")
    got = magsep.run(str(ROOT / scene), seed=11)
    assert without_wall_time(got) == without_wall_time(want)
    assert "wall_time_s" in got


def test_overrides_equal_the_cli_set_and_are_recorded(tmp_path):
    scene = "tests/data/brownian_short.toml"
    sets = ["brownian.duration=0.002", "particles[0].count=3"]
    want = cli_json("run", scene, "--quiet", *[a for s in sets for a in ("--set", s)])
    as_dict = magsep.run(ROOT / scene, overrides={"brownian.duration": 0.002, "particles[0].count": 3}, record=tmp_path / "o.mcap")
    as_list = magsep.run(ROOT / scene, overrides=sets)
    assert without_wall_time(as_dict) == without_wall_time(want) == without_wall_time(as_list)
    assert want["particles"] == 3
    extra = magsep.open_recording(tmp_path / "o.mcap").metadata["extra"]
    assert json.loads(extra["overrides"]) == sets


def test_a_dict_and_toml_text_run_as_the_file():
    path = ROOT / "tests" / "data" / "levitation_short.toml"
    text = path.read_text()
    from_file = magsep.run(path)
    assert without_wall_time(magsep.run(text)) == without_wall_time(from_file)
    assert without_wall_time(magsep.run(tomllib.loads(text))) == without_wall_time(from_file)


def test_validate_names_the_pipeline_and_every_bad_key():
    ok = magsep.validate(ROOT / "scenes" / "small_mixture.toml")
    assert ok["valid"] and ok["pipeline"] == "packing" and ok["particles"] == 80
    with pytest.raises(ValueError) as e:
        magsep.validate(ROOT / "scenes" / "small_mixture.toml", overrides={"particles[0].shape.radius": -1.0, "simulation.sed": 1})
    paths = [p for p, _ in e.value.errors]
    assert "particles[0].shape.radius" in paths and "simulation.sed" in paths


@pytest.mark.parametrize(
    "kwargs, path",
    [
        (dict(scene="scenes/missing.toml"), "(file)"),
        (dict(scene="[simulation]\npipeline = 'packing'\n"), "container"),
        (dict(scene={"simulation": {"pipeline": "packing", "seed": "x"}}), "simulation.seed"),
        (dict(scene={"simulation": {"pipeline": "packing"}, "container": {"kind": "periodic_box"}, "particles": [{"count": 5, "shape": {"kind": "sphere", "radius": None}}]}), "particles[0].shape.radius"),
        (dict(scene="scenes/small_mixture.toml", overrides={"simulation.sed": 3}), "simulation.sed"),
        (dict(scene="scenes/small_mixture.toml", overrides=["simulation.seed"]), "--set"),
        (dict(scene="scenes/small_mixture.toml", overrides="simulation.seed=3"), "overrides"),
        (dict(scene="scenes/small_mixture.toml", threads=0), "threads"),
        (dict(scene="scenes/small_mixture.toml", record="/nonexistent-dir/x.mcap"), "record"),
        (dict(scene="scenes/small_mixture.toml", record="scenes/small_mixture.toml", force=True), "record"),
        (dict(scene="scenes/small_mixture.toml", memory_budget=-1.0), "memory_budget"),
        (dict(scene="scenes/fibres_three.toml"), "(scene)"),
        (dict(scene=12), "(scene)"),
    ],
)
def test_bad_input_raises_value_error_naming_the_key(kwargs, path, monkeypatch):
    monkeypatch.chdir(ROOT)
    with pytest.raises(ValueError) as e:
        magsep.run(**kwargs)
    assert isinstance(e.value, magsep.SceneError)
    assert path in [p for p, _ in e.value.errors], str(e.value)


def test_an_existing_record_needs_force(tmp_path):
    out = tmp_path / "r.mcap"
    out.write_text("old")
    with pytest.raises(ValueError, match="exists"):
        magsep.run(ROOT / "tests/data/brownian_short.toml", record=out)
    magsep.run(ROOT / "tests/data/brownian_short.toml", record=out, force=True)
    assert len(magsep.open_recording(out)) > 0


def test_the_gil_is_released_and_progress_is_reported():
    calls = []
    result = {}
    t = threading.Thread(target=lambda: result.update(s=magsep.run(ROOT / "scenes/small_mixture.toml", progress=lambda *a: calls.append(a))))
    t.start()
    ticks = 0
    while t.is_alive():
        ticks += 1  # this thread runs while the run goes on
        time.sleep(0.005)
    t.join()
    assert result["s"]["pipeline"] == "packing"
    assert ticks > 50, ticks
    assert calls and all(isinstance(c[0], int) for c in calls)


def test_ctrl_c_stops_the_run_gracefully(tmp_path):
    rec = tmp_path / "stopped.mcap"
    script = textwrap.dedent(
        f"""
        import json, signal, sys, magsep
        # Ctrl-C's Python handler even when the parent ignores SIGINT (a background job of a
        # non-interactive shell passes SIG_IGN on, and Python then installs no handler)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        print("ready", flush=True)
        try:
            magsep.run({str(ROOT / 'tests/data/packing_long.toml')!r}, record={str(rec)!r})
        except magsep.RunInterrupted as e:
            assert isinstance(e, KeyboardInterrupt)
            print(json.dumps(e.summary), flush=True)
            sys.exit(3)
        print("not interrupted", flush=True)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(2.0)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 3, (out, err)
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["interrupted"] is True and summary["interrupted_by"] == "KeyboardInterrupt"
    r = magsep.open_recording(rec)
    assert r.truncated is None and r.damaged is None
    assert r.summary["interrupted"] is True
    assert "magsep.interrupted" in [name for name, _ in r.metadata_records]
    assert len(r) >= 1
