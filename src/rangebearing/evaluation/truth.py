"""Ground-truth CSV: the landmarks each frame holds, at their exact range and bearing.

Header ``frame,range_m,bearing_rad`` (extra columns are allowed and ignored),
one row per landmark in view. ``frame`` is an image file name (``000012.png``)
or, for a video, the 0-based frame index. A frame with no rows holds no
landmark, so the frames themselves (the images, the video) say which exist.
"""

from __future__ import annotations

import csv
import math
import os
from typing import Dict, Iterable, List, Union

from .._compat import frozen
from ..errors import TruthError

COLUMNS = ("frame", "range_m", "bearing_rad")
PathLike = Union[str, "os.PathLike[str]"]


@frozen
class TruthRow:
    """One landmark in one frame: horizontal range to its axis, bearing positive left."""

    frame: str
    range_m: float
    bearing_rad: float


def write_truth(path: PathLike, rows: Iterable[TruthRow]) -> None:
    """Write rows as CSV (``%.6f``: micrometres and microradians)."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(COLUMNS)
        for row in rows:
            out.writerow([row.frame, f"{row.range_m:.6f}", f"{row.bearing_rad:.6f}"])


def _number(raw: str, column: str, where: str) -> float:
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise TruthError(f"{where}: {column} {raw!r} is not a number") from None
    if not math.isfinite(value):
        raise TruthError(f"{where}: {column} {raw!r} is not finite")
    return value


def read_truth(path: PathLike) -> Dict[str, List[TruthRow]]:
    """Read a truth CSV into ``{frame: [TruthRow, ...]}``, in file order.

    Raises
    ------
    TruthError
        The file cannot be read, lacks a header column, or has a row with an
        empty frame, a non-numeric or non-finite value, or a negative range;
        the message gives the file, the line and the reason.
    """
    name = os.fspath(path)
    out: Dict[str, List[TruthRow]] = {}
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames
            if header is None:
                raise TruthError(f"{name}:1: empty file, expected the header {','.join(COLUMNS)}")
            missing = [c for c in COLUMNS if c not in [h.strip() for h in header]]
            if missing:
                raise TruthError(f"{name}:1: missing column(s) {', '.join(missing)} "
                                 f"(header is {','.join(header)!r})")
            reader.fieldnames = [h.strip() for h in header]
            for rec in reader:
                where = f"{name}:{reader.line_num}"
                if any(rec.get(c) is None for c in COLUMNS):
                    raise TruthError(f"{where}: too few fields")
                frame = rec["frame"].strip()
                if not frame:
                    raise TruthError(f"{where}: empty frame")
                range_m = _number(rec["range_m"], "range_m", where)
                if range_m < 0:
                    raise TruthError(f"{where}: range_m {range_m} is negative")
                bearing = _number(rec["bearing_rad"], "bearing_rad", where)
                out.setdefault(frame, []).append(TruthRow(frame, range_m, bearing))
    except OSError as exc:
        raise TruthError(f"{name}: cannot read: {exc.strerror or exc}") from None
    except (csv.Error, UnicodeDecodeError) as exc:
        raise TruthError(f"{name}: not a readable CSV file: {exc}") from None
    return out
