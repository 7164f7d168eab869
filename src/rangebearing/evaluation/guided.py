"""Guided calibration: ask for each station, check it live, record its frames with their truth.

The I/O that reaches a person is passed in (``ask`` reads an answer, ``say``
prints a line), so a script can answer for the operator; the frames come from
any :class:`~rangebearing.sources.base.FrameSource`. What is recorded (frames,
``truth.csv``, ``plan.csv``) is enough to redo the fit with plain
``rangebearing calibrate DIR --truth DIR/truth.csv``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable, List, Optional, Sequence, Tuple

import cv2
import numpy as np

from .._compat import frozen
from ..config import Config
from ..core.pipeline import Pipeline
from ..core.stations import Station, StationCheck, check_station
from ..errors import FrameError, SourceError
from ..sources.base import FrameSource
from .truth import TruthRow, write_truth

TRUTH_FILE = "truth.csv"
PLAN_FILE = "plan.csv"


@frozen
class StationResult:
    """One station: recorded (``frames`` names) or skipped (none), and the last check."""

    station: Station
    frames: Tuple[str, ...]
    check: Optional[StationCheck]


def _frames(source: FrameSource, n: int) -> List[np.ndarray]:
    out: List[np.ndarray] = []
    bad = 0
    while len(out) < n:
        try:
            frame = source.read()
        except FrameError:
            bad += 1
            if bad > 3 * n:
                raise
            continue
        if frame is None:
            raise SourceError("the source ended during guided calibration")
        out.append(frame.image)
    return out


def write_plan(path: Path, plan: Sequence[Station]) -> None:
    lines = ["name,range_m,bearing_deg"]
    lines += [f"{s.name},{s.range_m:.4f},{math.degrees(s.bearing_rad):.3f}" for s in plan]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def run_guided(
    source: FrameSource,
    cfg: Config,
    plan: Sequence[Station],
    record_dir: Path,
    ask: Callable[[str], str],
    say: Callable[[str], None],
    frames_per_station: int = 5,
    settle_frames: int = 3,
) -> List[StationResult]:
    """Walk the operator through ``plan``; frames of each accepted station go to ``record_dir``.

    Answers: Enter records the station, ``s`` skips it, ``q`` (or end of input)
    stops and keeps what was recorded. A station whose check fails is asked
    again. ``truth.csv`` and ``plan.csv`` are rewritten after every station, so
    an interrupted session leaves a consistent recording of the stations done.
    """
    record_dir.mkdir(parents=True, exist_ok=True)
    write_plan(record_dir / PLAN_FILE, plan)
    pipe = Pipeline(cfg.pipeline, track=False)
    results: List[StationResult] = []
    truth: List[TruthRow] = []
    for i, st in enumerate(plan, 1):
        prompt = f"[{i}/{len(plan)}] {st.name}: {st.instruction()}, then press Enter (s skip, q stop and fit)"
        check: Optional[StationCheck] = None
        while True:
            try:
                answer = ask(prompt).strip().lower()
            except EOFError:
                answer = "q"
            if answer in ("q", "s"):
                break
            _frames(source, settle_frames)  # frames exposed while the operator's hand was still in view
            images = _frames(source, frames_per_station)
            readings = [[(lm.range_m, lm.bearing_rad) for lm in pipe.process(im).landmarks] for im in images]
            check = check_station(st, readings)
            if check.ok:
                break
            say(f"  {st.name} not recorded: {check.reason}")
            prompt = f"  fix it and press Enter to try {st.name} again (s skip, q stop and fit)"
        if answer == "q":
            say(f"stopped at {st.name}: {len([r for r in results if r.frames])} station(s) recorded")
            break
        if answer == "s" or check is None:
            results.append(StationResult(st, (), check))
            continue
        names = []
        for k, im in enumerate(images):
            name = f"{st.name}_{k:02d}.png"
            if not cv2.imwrite(str(record_dir / name), im):
                raise SourceError(f"cannot write {record_dir / name}")
            names.append(name)
            truth.append(TruthRow(name, st.range_m, st.bearing_rad))
        write_truth(record_dir / TRUTH_FILE, truth)
        results.append(StationResult(st, tuple(names), check))
        say(f"  {st.name} recorded: {len(names)} frames, reads {check.range_m:.3f} m "
            f"{math.degrees(check.bearing_rad):+.1f}° before calibration")
    write_truth(record_dir / TRUTH_FILE, truth)
    return results
