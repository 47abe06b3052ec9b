"""magsep from Python: the field of magnetised fibres, runs, and recordings, as numpy arrays.

Every number comes from the Rust library (the same code as the ``magsep`` CLI); this module
only converts. Units are SI throughout: metres, tesla, seconds, A/m.

>>> import numpy as np, magsep
>>> fibre = magsep.Cylinder(radius=300e-6, half_length=6e-3, magnetisation=(0, 0, 985e3))
>>> B = magsep.field([fibre], np.array([[0.0, 1e-3, 0.0]]))          # (1, 3) [T]
>>> summary = magsep.run("scenes/spheres_500.toml", overrides={"simulation.seed": 3})
>>> rec = magsep.open_recording("run.mcap")                          # streamed
>>> rec[-1].positions                                                # (N, 3) [m]

Bad input raises :class:`SceneError` (a ``ValueError``) naming the key path, e.g.
``fibres[0].radius``; Ctrl-C during :func:`run` ends the current step, closes the
recording and raises :class:`RunInterrupted` (a ``KeyboardInterrupt``) carrying the summary
of the steps that ran.
"""

from __future__ import annotations

import json
import os
import sys
from dataclasses import dataclass
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _magsep
from ._magsep import RecordingError, RunError, RunInterrupted, SceneError, __version__

__all__ = [
    "Cylinder",
    "field",
    "field_scene_text",
    "run",
    "validate",
    "open_recording",
    "contact_numbers",
    "Recording",
    "Frame",
    "Message",
    "SceneError",
    "RunError",
    "RunInterrupted",
    "RecordingError",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


def _scene_error(path: str, message: str) -> SceneError:
    err = SceneError(f"{path}: {message}")
    err.errors = [(path, message)]
    return err


@dataclass
class Cylinder:
    """A ``[[fibres]]`` entry of ``kind = "cylinder"``: a uniformly magnetised finite cylinder.

    Give either ``magnetisation`` (a fixed vector M [A/m]) or ``saturation_magnetisation``
    (M_s [A/m]; its direction follows from the external field by Stoner-Wohlfarth, so an
    external field is then required).
    """

    radius: float
    """Radius R [m]."""
    half_length: float
    """Half of the fibre's length L [m]."""
    axis: Sequence[float] = (0.0, 0.0, 1.0)
    """Axis direction (any length > 0)."""
    center: Sequence[float] = (0.0, 0.0, 0.0)
    """Centre [m]."""
    magnetisation: Optional[Sequence[float]] = None
    """Fixed magnetisation M [A/m]."""
    saturation_magnetisation: Optional[float] = None
    """Saturation magnetisation M_s [A/m]."""

    def to_dict(self) -> Dict[str, Any]:
        """The scene's ``[[fibres]]`` table of this fibre."""
        d: Dict[str, Any] = {
            "kind": "cylinder",
            "radius": self.radius,
            "half_length": self.half_length,
            "axis": list(self.axis),
            "center": list(self.center),
        }
        if self.magnetisation is not None:
            d["magnetisation"] = list(self.magnetisation)
        if self.saturation_magnetisation is not None:
            d["saturation_magnetisation"] = self.saturation_magnetisation
        return d


FibreLike = Union[Cylinder, Mapping[str, Any]]


def _fibre_dicts(fibres: Union[FibreLike, Sequence[FibreLike]]) -> Any:
    if isinstance(fibres, (Cylinder, Mapping)):
        fibres = [fibres]
    if not isinstance(fibres, (list, tuple)):
        return fibres  # the Rust side names the type in its error
    return [f.to_dict() if hasattr(f, "to_dict") else f for f in fibres]


def _points(points: Any) -> Tuple[np.ndarray, bool]:
    try:
        pts = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise _scene_error("points", f"expected an (N, 3) array of numbers [m]: {e}") from None
    if pts.shape == (3,):
        return pts.reshape(1, 3), True
    return pts, False


def field(
    fibres: Union[FibreLike, Sequence[FibreLike]],
    points: Any,
    external: Union[None, Sequence[float], Mapping[str, Any]] = None,
    gradient: bool = False,
    out: Optional[np.ndarray] = None,
) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """The magnetic flux density B [T] of ``fibres`` and ``external`` at ``points`` [m].

    ``fibres``: :class:`Cylinder` objects or dicts of the scene's ``[[fibres]]`` keys
    (``kind``, ``radius``, ``half_length``, ``center``, ``axis``, ``magnetisation`` or
    ``saturation_magnetisation``), or one of them. ``points``: an (N, 3) float64 array (used
    without copying when C-contiguous) or one point of shape (3,). ``external``: B_ext [T]
    as three numbers, or a dict of the ``[external_field]`` keys (``flux_density``,
    ``field_tolerance``). ``out``: a C-contiguous float64 (N, 3) array to write B into (reused
    between calls it saves allocating and faulting in a new array each time).

    Returns B as an array of the points' shape; with ``gradient=True`` a tuple ``(B, G)``
    with ``G[n, i, j] = dB_i/dx_j`` [T/m]. The values are those ``magsep field --points``
    prints for the same scene (see :func:`field_scene_text`), bit for bit. The GIL is
    released and all of the library's threads (rayon) are used.

    Raises :class:`SceneError` (a ``ValueError``) naming the key path of bad input, e.g.
    ``fibres[1].radius`` or ``points[7]``.
    """
    pts, single = _points(points)
    if single:
        res = _magsep.field(_fibre_dicts(fibres), pts, external, gradient, None)
        if out is not None:
            np.copyto(out, res[0] if gradient else res)
        return (res[0][0], res[1][0]) if gradient else res[0]
    return _magsep.field(_fibre_dicts(fibres), pts, external, gradient, out)


def field_scene_text(
    fibres: Union[FibreLike, Sequence[FibreLike]],
    external: Union[None, Sequence[float], Mapping[str, Any]] = None,
) -> str:
    """The scene file (TOML) that :func:`field` evaluates for ``fibres`` and ``external``:
    ``magsep field SCENE --points POINTS.csv`` gives the same numbers."""
    return _magsep.field_scene_text(_fibre_dicts(fibres), external)


SceneLike = Union[PathLike, str, Mapping[str, Any]]
Overrides = Union[None, Mapping[str, Any], Sequence[str]]


def _print_progress(done: int, total: Optional[int], message: Optional[str]) -> None:
    of = f"/{total}" if total else ""
    sys.stderr.write(f"\r{done}{of} steps {message or ''}\x1b[K")
    sys.stderr.flush()


def run(
    scene: SceneLike,
    overrides: Overrides = None,
    record: Optional[PathLike] = None,
    threads: Optional[int] = None,
    *,
    seed: Optional[int] = None,
    progress: Union[bool, Callable[[int, Optional[int], Optional[str]], Any]] = False,
    force: bool = False,
    memory_budget: Optional[float] = None,
) -> Dict[str, Any]:
    """Run a scene to its end, as ``magsep run`` does; returns the JSON summary as a dict.

    ``scene``: a path (``str`` ending in ``.toml`` or naming a file, or ``os.PathLike``), TOML
    text, or a dict of the scene's tables. ``overrides``: ``{key path: value}`` or a list of
    ``"PATH=VALUE"`` strings, as ``magsep run --set`` (e.g. ``{"brownian.duration": 2.0}``).
    ``record``: write an MCAP recording there (an existing file only with ``force=True``).
    ``threads``: worker threads (1 runs single-threaded; the first value given sets the
    library's global pool). ``seed`` overrides ``simulation.seed``. ``progress``: True
    prints steps to stderr; a callable gets ``(steps_done, total_or_None, message_or_None)``
    about twice a second. ``memory_budget`` [GiB] as ``--memory-budget``.

    The summary's keys are the pipeline's (see the README's pipeline sections), e.g.
    ``packing_fraction`` for packing, ``capture_fraction`` for brownian; ``wall_time_s`` is the
    run's wall time [s]. The GIL is released while the run goes on.

    Raises :class:`SceneError` (``ValueError``) for bad input, naming the key path;
    :class:`RunError` when the run fails (``.summary``: what ran); :class:`RunInterrupted`
    (``KeyboardInterrupt``) on Ctrl-C, after the current step, with the recording closed and
    ``.summary`` of the steps that ran.
    """
    if isinstance(scene, Mapping):
        scene = dict(scene)
    elif isinstance(scene, os.PathLike):
        scene = os.fspath(scene)
    if progress is True:
        callback = _print_progress
    elif progress is False or progress is None:
        callback = None
    else:
        callback = progress
    rec = os.fspath(record) if record is not None else None
    return _magsep.run(scene, overrides, rec, threads, seed, callback, force, memory_budget)


def validate(scene: SceneLike, overrides: Overrides = None, memory_budget: Optional[float] = None) -> Dict[str, Any]:
    """Validate a scene (as ``magsep validate``): a dict with ``valid``, ``pipeline``,
    ``particles``, ``fibres`` and ``overrides``, or :class:`SceneError` listing every
    problem with its key path (``.errors``)."""
    if isinstance(scene, os.PathLike):
        scene = os.fspath(scene)
    return _magsep.validate(scene, overrides, memory_budget)


@dataclass
class Frame:
    """One recorded ``/state`` frame: the particles' exact state at one step (SI units)."""

    step: int
    """Step number."""
    time: float
    """Simulated time [s] (0 for packing)."""
    box_edges: np.ndarray
    """Edges of the periodic box [m], shape (3,)."""
    ids: np.ndarray
    """Particle ids, shape (N,), uint64."""
    positions: np.ndarray
    """Centres [m], shape (N, 3)."""
    orientations: np.ndarray
    """Unit quaternions (x, y, z, w), shape (N, 4)."""
    radii: np.ndarray
    """Radii [m], shape (N,)."""
    half_lengths: np.ndarray
    """Half lengths of the cylindrical part [m] (0 for spheres), shape (N,)."""
    rng_states: np.ndarray
    """Each particle's random-number state, shape (N, 4), uint64."""
    status_json: str
    """The pipeline's per-frame status as JSON text."""

    @property
    def status(self) -> Any:
        """The per-frame status, parsed."""
        return json.loads(self.status_json) if self.status_json else None

    def to_pandas(self) -> "Any":
        """A pandas DataFrame with one row per particle: id, x, y, z [m], qx, qy, qz, qw,
        radius [m], half_length [m] (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "id": self.ids,
                "x": self.positions[:, 0],
                "y": self.positions[:, 1],
                "z": self.positions[:, 2],
                "qx": self.orientations[:, 0],
                "qy": self.orientations[:, 1],
                "qz": self.orientations[:, 2],
                "qw": self.orientations[:, 3],
                "radius": self.radii,
                "half_length": self.half_lengths,
            }
        )


@dataclass
class Message:
    """One message of a channel, as stored (its payload in the channel's encoding)."""

    topic: str
    schema_name: str
    channel_id: int
    sequence: int
    log_time_ns: int
    publish_time_ns: int
    data: bytes


class Recording:
    """An MCAP recording, streamed: opening reads its summary section (or scans it once),
    each frame is read when asked for, one chunk in memory at a time, so a file of any size
    opens at once and in bounded memory. ``rec[i]`` (negative too), ``len(rec)`` and
    ``for frame in rec`` give :class:`Frame` objects in file order."""

    def __init__(self, inner: "_magsep.Recording"):
        self._r = inner

    @property
    def path(self) -> str:
        """The file's path."""
        return os.fspath(self._r.path)

    @property
    def metadata(self) -> Optional[Dict[str, Any]]:
        """The run's metadata (``scene_text``, ``seed``, ``version``, ``pipeline``,
        ``schedule``, ``dt`` [s], ``plugins``, ``extra``), or None."""
        return self._r.metadata

    @property
    def scene_text(self) -> Optional[str]:
        """The scene file's text as run (overrides applied)."""
        m = self._r.metadata
        return m["scene_text"] if m else None

    @property
    def seed(self) -> Optional[int]:
        """The run's seed."""
        m = self._r.metadata
        return m["seed"] if m else None

    @property
    def schedule(self) -> Optional[Dict[str, List[str]]]:
        """The resolved schedule: set name -> system names in run order."""
        m = self._r.metadata
        return m["schedule"] if m else None

    @property
    def summary(self) -> Optional[Dict[str, Any]]:
        """The run's summary (None for a run that was killed)."""
        return self._r.summary

    @property
    def truncated(self) -> Optional[str]:
        """None for a complete file; else where and why it ends early (a killed run: the
        frames before the cut are readable)."""
        return self._r.truncated

    @property
    def damaged(self) -> Optional[str]:
        """None unless a damaged record ends the readable part, damaged chunks were skipped
        (known once the reading has reached them) or bytes follow the footer."""
        return self._r.damaged

    @property
    def file_bytes(self) -> int:
        """Size of the file [bytes]."""
        return self._r.file_bytes

    @property
    def channels(self) -> List[Dict[str, Any]]:
        """The channels: dicts of ``id``, ``topic``, ``schema_name``, ``schema_encoding``,
        ``message_encoding``, ``message_count``."""
        return self._r.channels

    @property
    def metadata_records(self) -> List[Tuple[str, Dict[str, str]]]:
        """Every metadata record: (name, entries)."""
        return self._r.metadata_records

    def schema(self, topic: str) -> Optional[Dict[str, Any]]:
        """The schema of the channel on ``topic``: ``name``, ``encoding`` and ``data`` (bytes;
        a protobuf ``FileDescriptorSet`` for protobuf channels), or None."""
        return self._r.schema(topic)

    def __len__(self) -> int:
        return self._r.frame_count

    def frame(self, index: int) -> Frame:
        """Frame ``index`` (negative counts from the end)."""
        n = len(self)
        i = index + n if index < 0 else index
        f = self._r.frame(i) if i >= 0 else None
        if f is None:
            raise IndexError(f"frame {index} of a recording of {n} frames")
        return Frame(**f)

    def __getitem__(self, index: Union[int, slice]) -> Union[Frame, List[Frame]]:
        if isinstance(index, slice):
            return [self.frame(i) for i in range(*index.indices(len(self)))]
        return self.frame(int(index))

    def __iter__(self) -> Iterator[Frame]:
        i = 0
        while True:
            f = self._r.frame(i)
            if f is None:
                return
            yield Frame(**f)
            i += 1

    def messages(self, topic: Optional[str] = None) -> Iterator[Message]:
        """The messages on ``topic`` (every channel for None) in file order, as raw bytes with
        their schema names: a plugin's channel is decoded with its schema (:meth:`schema`).
        A chunk whose bytes are damaged is skipped and the rest read; the damage is then
        raised (:class:`RecordingError`) after the last message, as by iterating the frames."""
        unit = 0
        while True:
            batch = self._r.unit_messages(unit, topic)
            if batch is None:
                return
            for m in batch:
                yield Message(*m)
            unit += 1

    def to_pandas(self, frames: Optional[Sequence[int]] = None) -> "Any":
        """One row per particle and frame (columns ``step``, ``time`` and those of
        :meth:`Frame.to_pandas`) for the frames at ``frames`` (all when None: this holds the
        whole recording in memory). Needs pandas."""
        import pandas as pd

        chosen = (self.frame(i) for i in frames) if frames is not None else iter(self)
        tables = []
        for f in chosen:
            t = f.to_pandas()
            t.insert(0, "time", f.time)
            t.insert(0, "step", f.step)
            tables.append(t)
        if not tables:
            return pd.DataFrame(columns=["step", "time", "id", "x", "y", "z", "qx", "qy", "qz", "qw", "radius", "half_length"])
        return pd.concat(tables, ignore_index=True)

    def __repr__(self) -> str:
        state = " (truncated)" if self.truncated else ""
        return f"<magsep.Recording {self.path!r}: {len(self)} frames{state}>"


def contact_numbers(frame: Frame) -> Dict[str, Any]:
    """Contact numbers of a recorded packing frame (spheres and spherocylinders in a periodic
    box), by the packing pipeline's own analysis: ``mean`` (<C> extrapolated to zero gap, as
    the summary's ``mean_contact_number``), ``mean_at_1e-4`` (gap below 1e-4 D),
    ``histogram`` (``histogram[k]``: particles touching k others, gap below 1e-8 D),
    ``samples`` ((gap / D, <C>) pairs of the fit), ``max_overlap`` (/ D) and
    ``reference_diameter`` D [m] (the smallest particle diameter)."""
    return _magsep.contact_numbers(
        np.ascontiguousarray(frame.positions, dtype=np.float64),
        np.ascontiguousarray(frame.orientations, dtype=np.float64),
        np.ascontiguousarray(frame.radii, dtype=np.float64),
        np.ascontiguousarray(frame.half_lengths, dtype=np.float64),
        np.ascontiguousarray(frame.box_edges, dtype=np.float64),
    )


def open_recording(path: PathLike) -> Recording:
    """Open the recording at ``path`` (streamed: see :class:`Recording`). Raises
    :class:`RecordingError` (a ``ValueError``) for a file that is not a recording or is
    damaged before its first frame; a truncated file opens, with :attr:`Recording.truncated`
    set."""
    return Recording(_magsep.open_recording(os.fspath(path)))
