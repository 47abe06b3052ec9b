"""magsep.field against `magsep field --points` (bit for bit), shapes, and bad input."""

import sys

import numpy as np
import pytest

import magsep
from conftest import ROOT, bits, cli

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def cli_field(scene_path, points, gradient, tmp_path):
    csv = tmp_path / "points.csv"
    # repr() is the shortest round-trip form: the CLI parses back the same doubles
    csv.write_text("x,y,z\n" + "".join(f"{x!r},{y!r},{z!r}\n" for x, y, z in points.tolist()))
    args = ["field", scene_path, "--points", csv] + (["--gradient"] if gradient else [])
    out = cli(*args).stdout.splitlines()
    rows = np.array([[float(v) for v in line.split(",")] for line in out[1:]], dtype=np.float64)
    return rows


def random_points(n, scale, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, size=(n, 3)) * np.asarray(scale)


def test_field_of_a_scene_file_equals_the_cli_bit_for_bit(tmp_path):
    scene = tomllib.loads((ROOT / "scenes" / "fibres_three.toml").read_text())
    # more than two of the library's chunks of 1024 points, and a partial one
    pts = random_points(2600, [3e-3, 3e-3, 3e-3], 1)
    b = magsep.field(scene["fibres"], pts, external=scene["external_field"])
    assert b.shape == (2600, 3) and b.dtype == np.float64
    rows = cli_field("scenes/fibres_three.toml", pts, False, tmp_path)
    assert np.array_equal(bits(rows[:, :3]), bits(pts))
    assert np.array_equal(bits(rows[:, 3:6]), bits(b))
    assert np.abs(b).max() > 1e-3  # the fibres' field, not only B_ext


def test_gradient_equals_the_cli_bit_for_bit(tmp_path):
    scene = tomllib.loads((ROOT / "scenes" / "fibres_three.toml").read_text())
    pts = random_points(1100, [3e-3, 3e-3, 3e-3], 2)
    b, g = magsep.field(scene["fibres"], pts, external=scene["external_field"], gradient=True)
    assert g.shape == (1100, 3, 3)
    rows = cli_field("scenes/fibres_three.toml", pts, True, tmp_path)
    assert np.array_equal(bits(rows[:, 3:6]), bits(b))
    # CSV columns dbx_dx, dbx_dy, dbx_dz, dby_dx, ...: G[n, i, j] = dB_i/dx_j
    assert np.array_equal(bits(rows[:, 6:]), bits(g.reshape(-1, 9)))


def test_typed_fibres_with_stoner_wohlfarth_equal_the_cli_on_the_generated_scene(tmp_path):
    fibres = [
        magsep.Cylinder(radius=300e-6, half_length=6e-3, axis=(1, 0, 0), saturation_magnetisation=985e3),
        magsep.Cylinder(radius=100e-6, half_length=2e-3, center=(0, 1e-3, 0), axis=(0, 1, 1), magnetisation=(1e5, 0, 2e5)),
    ]
    external = [0.3, 0.0, 0.4]
    scene = tmp_path / "scene.toml"
    scene.write_text(magsep.field_scene_text(fibres, external))
    pts = random_points(500, [8e-3, 2e-3, 2e-3], 3)
    b = magsep.field(fibres, pts, external=external)
    rows = cli_field(scene, pts, False, tmp_path)
    assert np.array_equal(bits(rows[:, 3:6]), bits(b))


def test_point_layouts_give_the_same_values():
    f = magsep.Cylinder(radius=300e-6, half_length=6e-3, magnetisation=(0, 0, 985e3))
    pts = random_points(64, [1e-3, 1e-3, 8e-3], 4)
    b = magsep.field([f], pts)
    # a strided view, a list, float32-free lists of lists, one point
    wide = np.zeros((64, 6))
    wide[:, ::2] = pts
    assert np.array_equal(bits(magsep.field([f], wide[:, ::2])), bits(b))
    assert np.array_equal(bits(magsep.field([f], pts.tolist())), bits(b))
    one = magsep.field(f, pts[5])
    assert one.shape == (3,) and np.array_equal(bits(one), bits(b[5]))
    assert magsep.field([f], np.zeros((0, 3))).shape == (0, 3)
    # contiguous but unaligned float64 (a buffer at an odd offset): copied, same values
    raw = bytearray(pts.nbytes + 1)
    unaligned = np.frombuffer(raw, dtype=np.float64, count=pts.size, offset=1).reshape(64, 3)
    unaligned[...] = pts
    assert not unaligned.flags.aligned and unaligned.flags.c_contiguous
    assert np.array_equal(bits(magsep.field([f], unaligned)), bits(b))
    # a uniform external field alone is B_ext everywhere
    assert np.array_equal(magsep.field([], pts, external=[0.0, 0.0, 0.5]), np.tile([0.0, 0.0, 0.5], (64, 1)))


def test_out_receives_b_and_bad_out_is_refused():
    f = magsep.Cylinder(radius=300e-6, half_length=6e-3, magnetisation=(0, 0, 985e3))
    pts = random_points(2000, [1e-3, 1e-3, 8e-3], 5)
    want = magsep.field([f], pts)
    out = np.full((2000, 3), np.nan)
    got = magsep.field([f], pts, out=out)
    assert got is out and np.array_equal(bits(out), bits(want))
    b, g = magsep.field([f], pts, gradient=True, out=out)
    assert b is out and g.shape == (2000, 3, 3)
    for bad in [np.zeros((1999, 3)), np.zeros((2000, 3), dtype=np.float32), np.zeros((3, 2000)).T, [[0.0] * 3] * 2000, pts]:
        with pytest.raises(ValueError, match="out"):
            magsep.field([f], pts, out=bad)
    readonly = np.zeros((2000, 3))
    readonly.setflags(write=False)
    with pytest.raises(ValueError, match="out"):
        magsep.field([f], pts, out=readonly)


GOOD = {"kind": "cylinder", "radius": 1e-4, "half_length": 1e-3, "axis": [0, 0, 1], "magnetisation": [0, 0, 1e6]}


@pytest.mark.parametrize(
    "fibres, points, external, path",
    [
        ([dict(GOOD, radius=-1.0)], [[0, 0, 1]], None, "fibres[0].radius"),
        ([GOOD, dict(GOOD, radus=1.0)], [[0, 0, 1]], None, "fibres[1].radus"),
        ([dict(GOOD, radius=None)], [[0, 0, 1]], None, "fibres[0].radius"),
        ([dict(GOOD, axis=[0, 0, 0])], [[0, 0, 1]], None, "fibres[0].axis"),
        ([dict(GOOD, kind="cube")], [[0, 0, 1]], None, "fibres[0]"),
        ([{k: v for k, v in GOOD.items() if k != "magnetisation"}], [[0, 0, 1]], None, "fibres[0].magnetisation"),
        ([dict(GOOD, magnetisation=None, saturation_magnetisation=1e6)], [[0, 0, 1]], None, "fibres[0].magnetisation"),
        ([{k: v for k, v in GOOD.items() if k != "magnetisation"} | {"saturation_magnetisation": 1e6}], [[0, 0, 1]], None, "fibres[0].saturation_magnetisation"),
        (5, [[0, 0, 1]], None, "fibres"),
        ([], [[0, 0, 1]], None, "fibres"),
        ([GOOD], [[0, 0, 1]], [0, 0, 1e9], "external_field.flux_density[2]"),
        ([GOOD], [[0, 0, 1]], {"flux_density": [0, 0, 1], "tolerance": 1}, "external_field.tolerance"),
        ([GOOD], [[0, 0, 1]], {"field_tolerance": 2.0}, "external_field.field_tolerance"),
        ([GOOD], [[0, 0, 1], [0, np.nan, 0]], None, "points[1]"),
        ([GOOD], [[0, 0, 1], [0, 0, np.inf]], None, "points[1]"),
        ([GOOD], [[0, 0], [1, 1]], None, "points"),
        ([GOOD], "abc", None, "points"),
        ([GOOD], [[0, 0, "x"]], None, "points"),
        ([{1: 2}], [[0, 0, 1]], None, "fibres[0]"),
        ([dict(GOOD, radius=2**70)], [[0, 0, 1]], None, "fibres[0].radius"),
    ],
)
def test_bad_input_raises_value_error_naming_the_key(fibres, points, external, path):
    with pytest.raises(ValueError) as e:
        magsep.field(fibres, points, external=external)
    assert isinstance(e.value, magsep.SceneError)
    paths = [p for p, _ in e.value.errors]
    assert any(p == path or p.startswith(path + ".") or p.startswith(path + "[") for p in paths), (paths, str(e.value))
    assert path in str(e.value)
