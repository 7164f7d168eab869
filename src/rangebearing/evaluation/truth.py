"""Ground-truth CSV: the landmarks each frame holds, at their exact range and bearing.

Header ``frame,range_m,bearing_rad`` (extra columns are allowed and ignored),
one row per landmark in view. Optional columns, written by ``synth`` and read
when present (empty or absent = unknown): ``visible``, ``red_visible``,
``blue_visible`` (fractions 0–1 of the landmark's silhouette, red band and
blue band that the frame shows: not hidden by anything nearer, not cut off by
the frame edge), ``findable`` (1 when both bands are at least 60 % visible,
else 0) and ``robot`` (an identity that stays with one robot over the frames
of a sequence). ``frame`` is an image file name (``000012.png``)
or, for a video, the 0-based frame index. A frame with no rows holds no
landmark, so the frames themselves (the images, the video) say which exist.
"""

from __future__ import annotations

import csv
import math
import os
from typing import Dict, Iterable, List, Optional, Union

from .._compat import frozen
from ..errors import TruthError

COLUMNS = ("frame", "range_m", "bearing_rad")
OPTIONAL_COLUMNS = ("visible", "red_visible", "blue_visible", "findable", "robot")
PathLike = Union[str, "os.PathLike[str]"]


@frozen
class TruthRow:
    """One landmark in one frame: horizontal range to its axis, bearing positive left.

    The optional fields are None when the truth does not say (see the module
    docstring); a row without ``findable`` counts as findable.
    """

    frame: str
    range_m: float
    bearing_rad: float
    visible: Optional[float] = None
    red_visible: Optional[float] = None
    blue_visible: Optional[float] = None
    findable: Optional[bool] = None
    robot: Optional[int] = None

    @property
    def extras(self) -> bool:
        """Whether any optional field is set."""
        return any(getattr(self, c) is not None for c in OPTIONAL_COLUMNS)


def _cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return f"{value:.4f}"
    return str(value)


def write_truth(path: PathLike, rows: Iterable[TruthRow]) -> None:
    """Write rows as CSV (``%.6f``: micrometres and microradians).

    The optional columns are written when any row has one of them set.
    """
    rows = list(rows)
    extra = any(row.extras for row in rows)
    with open(path, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(COLUMNS + (OPTIONAL_COLUMNS if extra else ()))
        for row in rows:
            cells = [row.frame, f"{row.range_m:.6f}", f"{row.bearing_rad:.6f}"]
            if extra:
                cells += [_cell(getattr(row, c)) for c in OPTIONAL_COLUMNS]
            out.writerow(cells)


def _number(raw: str, column: str, where: str) -> float:
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise TruthError(f"{where}: {column} {raw!r} is not a number") from None
    if not math.isfinite(value):
        raise TruthError(f"{where}: {column} {raw!r} is not finite")
    return value


def _fraction(rec: Dict[str, Optional[str]], column: str, where: str) -> Optional[float]:
    raw = (rec.get(column) or "").strip()
    if not raw:
        return None
    value = _number(raw, column, where)
    if not 0.0 <= value <= 1.0:
        raise TruthError(f"{where}: {column} {value} is not a fraction between 0 and 1")
    return value


def _optional(rec: Dict[str, Optional[str]], where: str) -> Dict[str, object]:
    out: Dict[str, object] = {c: _fraction(rec, c, where) for c in ("visible", "red_visible", "blue_visible")}
    raw = (rec.get("findable") or "").strip().lower()
    if raw:
        if raw not in ("0", "1", "true", "false"):
            raise TruthError(f"{where}: findable {raw!r} is not 0 or 1")
        out["findable"] = raw in ("1", "true")
    raw = (rec.get("robot") or "").strip()
    if raw:
        try:
            out["robot"] = int(raw)
        except ValueError:
            raise TruthError(f"{where}: robot {raw!r} is not a whole number") from None
    return out


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
                extras = _optional(rec, where)
                out.setdefault(frame, []).append(TruthRow(frame, range_m, bearing, **extras))  # type: ignore[arg-type]
    except OSError as exc:
        raise TruthError(f"{name}: cannot read: {exc.strerror or exc}") from None
    except (csv.Error, UnicodeDecodeError) as exc:
        raise TruthError(f"{name}: not a readable CSV file: {exc}") from None
    return out
