"""Shared helpers: the repository root and the `magsep` CLI the package is compared with."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    path = Path(os.environ.get("MAGSEP_BIN", ROOT / "target" / "release" / "magsep"))
    assert path.is_file(), f"the magsep CLI is needed at {path} (cargo build --release, or set MAGSEP_BIN)"
    return path


def cli(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Run the CLI from the repository root."""
    p = subprocess.run([str(cli_path()), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
    if check:
        assert p.returncode == 0, f"magsep {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}"
    return p


def cli_json(*args: str):
    return json.loads(cli(*args).stdout)


def bits(a) -> np.ndarray:
    """The bit patterns of a float64 array (equality of these is equality bit for bit)."""
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64)).view(np.uint64)


# the summary keys measured by the wall clock: `wall_time_s` and the rate derived from it
TIMING_KEYS = ("wall_time_s", "particle_steps_per_s")


def without_wall_time(summary):
    """The summary without its wall-clock fields (the only ones that differ between runs)."""
    if isinstance(summary, dict):
        return {k: without_wall_time(v) for k, v in summary.items() if k not in TIMING_KEYS}
    if isinstance(summary, list):
        return [without_wall_time(v) for v in summary]
    return summary


@pytest.fixture
def root() -> Path:
    return ROOT
