"""One frame's detector defect stays that frame's: the boundary between the pipeline and the loops that run it.

The pipeline is pure array code, but a defect in it (an index past an array's end
on a frame nobody tried before) must not end the daemon or a replay of a
thousand frames. :func:`process_or_skip` runs one frame; any exception that is
not already one of the project's errors becomes a :class:`DetectorFault` (a
:class:`FrameError`, so every loop skips and counts it like a bad frame) naming
the exception and where it was raised, and the pipeline's tracks are reset (a
failure half-way through a tracked frame may have left them inconsistent; ids
keep counting, so none is reused).
"""

from __future__ import annotations

import traceback
from typing import Callable, Optional, Tuple, TypeVar

import numpy as np

from ..errors import DetectorFault, RangeBearingError
from .pipeline import Pipeline
from .types import FrameResult
from .yuv import Yuv420

__all__ = ["DetectorFault", "process_or_skip", "scan_later_or_skip", "where"]

T = TypeVar("T")


def where(exc: BaseException) -> str:
    """``file.py:line in function`` of the innermost frame that raised ``exc``."""
    tb = traceback.extract_tb(exc.__traceback__)
    if not tb:
        return "unknown place"
    last = tb[-1]
    return f"{last.filename.rsplit('/', 1)[-1]}:{last.lineno} in {last.name}"


def process_or_skip(pipe: Pipeline, image: np.ndarray, t_s: Optional[float] = None,
                    search: Optional[Yuv420] = None) -> FrameResult:
    """``pipe.process(image, ...)``, with a defect turned into this frame's :class:`DetectorFault`.

    Raises
    ------
    FrameError
        The frame is unusable (as from :meth:`Pipeline.process`), or the detector
        failed on it (:class:`DetectorFault`, its cause chained).
    """
    return _guarded(pipe, lambda: pipe.process(image, t_s=t_s, search=search))


def scan_later_or_skip(pipe: Pipeline, image: np.ndarray, t_s: Optional[float] = None,
                       search: Optional[Yuv420] = None
                       ) -> Tuple[FrameResult, Optional[Callable[[], FrameResult]]]:
    """:meth:`Pipeline.process_scan_later` guarded as :func:`process_or_skip`, and so is the scan it leaves."""
    result, finish = _guarded(pipe, lambda: pipe.process_scan_later(image, t_s, search))
    if finish is None:
        return result, None
    return result, lambda: _guarded(pipe, finish)


def _guarded(pipe: Pipeline, run: Callable[[], T]) -> T:
    try:
        return run()
    except RangeBearingError:
        raise
    except Exception as exc:  # deliberately broad: a defect on one frame must not end the run
        pipe.reset()
        raise DetectorFault(f"detector failed on this frame ({type(exc).__name__} at {where(exc)}: {exc}); "
                            "tracks restarted") from exc
