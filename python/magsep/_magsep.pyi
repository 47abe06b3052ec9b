"""Type stubs of the native module ``magsep._magsep`` (use the documented wrappers in
``magsep``; these are the raw functions they call)."""

from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

__version__: str

class SceneError(ValueError):
    """Bad input; ``errors`` lists (key path, message) pairs."""

    errors: List[Tuple[str, str]]

class RunError(RuntimeError):
    """A run failed; ``summary`` is the summary of the steps that ran, or None."""

    summary: Optional[Dict[str, Any]]

class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a run gracefully; ``summary`` is of the steps that ran."""

    summary: Optional[Dict[str, Any]]

class RecordingError(ValueError):
    """A recording could not be read."""

def field(
    fibres: Any,
    points: np.ndarray,
    external: Union[None, Sequence[float], Mapping[str, Any]] = None,
    gradient: bool = False,
    out: Optional[np.ndarray] = None,
) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]: ...
def field_scene_text(
    fibres: Any, external: Union[None, Sequence[float], Mapping[str, Any]] = None
) -> str: ...
def run(
    scene: Union[str, Mapping[str, Any]],
    overrides: Union[None, Mapping[str, Any], Sequence[str]] = None,
    record: Optional[str] = None,
    threads: Optional[int] = None,
    seed: Optional[int] = None,
    progress: Optional[Callable[[int, Optional[int], Optional[str]], Any]] = None,
    force: bool = False,
    memory_budget: Optional[float] = None,
) -> Dict[str, Any]: ...
def validate(
    scene: Union[str, Mapping[str, Any]],
    overrides: Union[None, Mapping[str, Any], Sequence[str]] = None,
    memory_budget: Optional[float] = None,
) -> Dict[str, Any]: ...

class Recording:
    @property
    def path(self) -> str: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def file_bytes(self) -> int: ...
    @property
    def truncated(self) -> Optional[str]: ...
    @property
    def damaged(self) -> Optional[str]: ...
    @property
    def metadata(self) -> Optional[Dict[str, Any]]: ...
    @property
    def summary(self) -> Optional[Dict[str, Any]]: ...
    @property
    def metadata_records(self) -> List[Tuple[str, Dict[str, str]]]: ...
    @property
    def channels(self) -> List[Dict[str, Any]]: ...
    @property
    def unit_count(self) -> int: ...
    def schema(self, topic: str) -> Optional[Dict[str, Any]]: ...
    def frame(self, index: int) -> Optional[Dict[str, Any]]: ...
    def unit_messages(
        self, unit: int, topic: Optional[str] = None
    ) -> Optional[List[Tuple[str, str, int, int, int, int, bytes]]]: ...

def open_recording(path: str) -> Recording: ...
def read_recording_frames(path: str) -> Tuple[List[Dict[str, Any]], Optional[str]]: ...
def contact_numbers(
    positions: np.ndarray,
    orientations: np.ndarray,
    radii: np.ndarray,
    half_lengths: np.ndarray,
    box_edges: np.ndarray,
) -> Dict[str, Any]: ...
