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
from typing import Dict, Iterable, List, Optional, Sequence, Tuple, Union

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


def _fraction(raw: str, column: str, where: str) -> Optional[float]:
    raw = raw.strip()
    if not raw:
        return None
    value = _number(raw, column, where)
    if not 0.0 <= value <= 1.0:
        raise TruthError(f"{where}: {column} {value} is not a fraction between 0 and 1")
    return value


def _optional(cells: List[str], columns: Sequence[Tuple[str, int]], where: str) -> Dict[str, object]:
    out: Dict[str, object] = {}
    for column, i in columns:
        raw = cells[i].strip() if i < len(cells) else ""
        if not raw:
            continue
        if column == "findable":
            if raw.lower() not in ("0", "1", "true", "false"):
                raise TruthError(f"{where}: findable {raw!r} is not 0 or 1")
            out[column] = raw.lower() in ("1", "true")
        elif column == "robot":
            try:
                out[column] = int(raw)
            except ValueError:
                raise TruthError(f"{where}: robot {raw!r} is not a whole number") from None
        else:
            out[column] = _fraction(raw, column, where)
    return out


def read_truth(path: PathLike) -> Dict[str, List[TruthRow]]:
    """Read a truth CSV into ``{frame: [TruthRow, ...]}``, in file order.

    A UTF-8 byte-order mark (Excel) is fine. Ranges must be > 0 and bearings within ±π.
    Rows are read as lists (no dict a row): three million rows take seconds, not minutes.

    Raises
    ------
    TruthError
        The file cannot be read or lacks a header column, or rows are bad (an
        empty frame, a value that is not a finite number or out of range): the
        message names every bad row (file, line, reason), not only the first.
    """
    name = os.fspath(path)
    out: Dict[str, List[TruthRow]] = {}
    problems: List[str] = []
    if os.path.exists(path) and not os.path.isfile(path) and not os.path.isdir(path):  # opening a FIFO waits
        raise TruthError(f"{name}: not a regular file (a FIFO, socket or device), expected a truth CSV")
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            reader = csv.reader(f)
            header = next(reader, None)
            while header == []:  # blank lines before the header skipped, as between rows
                header = next(reader, None)
            if header is None:
                raise TruthError(f"{name}:1: empty file, expected the header {','.join(COLUMNS)}")
            names = [h.strip() for h in header]
            missing = [c for c in COLUMNS if c not in names]
            if missing:
                raise TruthError(f"{name}:1: missing column(s) {', '.join(missing)} "
                                 f"(header is {','.join(header)!r})")
            doubled = sorted({h for h in names if names.count(h) > 1})
            if doubled:  # a reader by name would keep the last one silently
                raise TruthError(f"{name}:1: column(s) {', '.join(doubled)} given twice")
            at = [names.index(c) for c in COLUMNS]
            extra = [(c, names.index(c)) for c in OPTIONAL_COLUMNS if c in names]
            fields = max(at) + 1
            seen: Dict[Tuple[str, float, float], int] = {}
            for cells in reader:
                if not cells:
                    continue
                try:
                    row = _row(cells, at, fields, extra, name, reader.line_num)
                except TruthError as exc:
                    problems.append(str(exc))
                    continue
                key = (row.frame, row.range_m, row.bearing_rad)  # a second landmark there would be counted missed
                if key in seen:
                    problems.append(f"{name}:{reader.line_num}: the same landmark as line {seen[key]} "
                                    "(a duplicated row)")
                    continue
                seen[key] = reader.line_num
                rows = out.get(row.frame)
                if rows is None:
                    out[row.frame] = [row]
                else:
                    rows.append(row)
    except OSError as exc:
        raise TruthError(f"{name}: cannot read: {exc.strerror or exc}") from None
    except (csv.Error, UnicodeDecodeError) as exc:
        raise TruthError(f"{name}: not a readable CSV file: {exc}") from None
    if len(problems) == 1:
        raise TruthError(problems[0])
    if problems:
        more = f"\n  ... and {len(problems) - 20} more" if len(problems) > 20 else ""
        raise TruthError(f"{name}: {len(problems)} bad rows:\n  " + "\n  ".join(problems[:20]) + more)
    return out


def _row(cells: List[str], at: List[int], fields: int, extra: Sequence[Tuple[str, int]], name: str,
         line: int) -> TruthRow:
    if len(cells) >= fields and not extra:  # the common row, checked without building a message
        frame = cells[at[0]].strip()
        try:
            range_m, bearing = float(cells[at[1]]), float(cells[at[2]])
        except ValueError:
            range_m = bearing = math.nan
        if frame and 0.0 < range_m < math.inf and -math.pi <= bearing <= math.pi:
            return TruthRow(frame, range_m, bearing)
    where = f"{name}:{line}"
    if len(cells) < fields:
        raise TruthError(f"{where}: too few fields")
    frame = cells[at[0]].strip()
    if not frame:
        raise TruthError(f"{where}: empty frame")
    range_m = _number(cells[at[1]], "range_m", where)
    if range_m <= 0:
        raise TruthError(f"{where}: range_m {range_m} is {'negative' if range_m < 0 else 'zero'}: must be > 0")
    bearing = _number(cells[at[2]], "bearing_rad", where)
    if not -math.pi <= bearing <= math.pi:
        raise TruthError(f"{where}: bearing_rad {bearing} is outside ±π (radians, not degrees?)")
    if not extra:
        return TruthRow(frame, range_m, bearing)
    return TruthRow(frame, range_m, bearing, **_optional(cells, extra, where))  # type: ignore[arg-type]


def _keys(name: str) -> List[str]:
    """The names a frame may be given by: as written, file name, any case, without extension, as a number."""
    base = name.replace("\\", "/").rsplit("/", 1)[-1]
    low = base.lower()
    stem = low.rsplit(".", 1)[0] if "." in low else low
    keys = [name, base, low, stem]
    if stem.isdigit():
        keys.append(str(int(stem)))
    return keys


def align_truth(
    truth: Dict[str, List[TruthRow]], frames: Sequence[str], source: str = "truth"
) -> Dict[str, List[TruthRow]]:
    """Truth keyed by the frames' own names, matched by file name, case, stem or number.

    ``samples/clip/000000.jpg``, ``000000.JPG``, ``000000`` and (for a video, whose
    frames are named by their 0-based index) ``0`` all name frame ``000000.jpg`` /
    frame 0.

    Raises
    ------
    TruthError
        Truth rows name frames that are not there (every such name is listed, up to 10).
    """
    index: Dict[str, Optional[str]] = {}
    for frame in frames:
        for key in _keys(frame):
            index[key] = frame if index.get(key, frame) == frame else None  # None: two frames share it
    out: Dict[str, List[TruthRow]] = {}
    unmatched: List[str] = []
    for name, rows in truth.items():
        frame = next((index[k] for k in _keys(name) if index.get(k)), None)
        if frame is None:
            unmatched.append(name)
            continue
        out.setdefault(frame, []).extend(rows)
    if unmatched:
        shown = ", ".join(repr(n) for n in unmatched[:10])
        shown += f" and {len(unmatched) - 10} more" if len(unmatched) > 10 else ""
        example = ", ".join(repr(f) for f in list(frames)[:3]) or "nothing: the recording holds no frames"
        raise TruthError(f"{source}: {len(unmatched)} of {len(truth)} truth frame(s) match no frame: {shown} "
                         f"(the frames are named like {example}; a video's frames by their 0-based index)")
    return out


def key_by_position(truth: Dict[str, List[TruthRow]], frame_times_ns: List[int]) -> Dict[str, List[TruthRow]]:
    """Truth for an MCAP recording, keyed as replay names its frames: by position in the file.

    A ``frame`` value is either that 0-based position (``12``) or the frame's
    capture timestamp in integer Unix nanoseconds as stored in the file
    (``1700000000123456000``: the ``timestamp`` of its ``foxglove.CompressedImage``,
    also the MCAP log time); a timestamp that matches a frame becomes its position.

    Raises
    ------
    TruthError
        A value is a timestamp (13 digits or more) that matches no frame.
    """
    where = {t: i for i, t in enumerate(frame_times_ns)}
    out: Dict[str, List[TruthRow]] = {}
    for key, rows in truth.items():
        if key.isdigit() and len(key) >= 13:
            if int(key) not in where:
                raise TruthError(f"truth frame {key}: no frame of the recording has this timestamp (ns)")
            key = str(where[int(key)])
        out.setdefault(key, []).extend(TruthRow(key, r.range_m, r.bearing_rad) for r in rows)
    return out
