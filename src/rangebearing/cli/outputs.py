"""Where commands write, checked before anything is written: nothing a user owns is lost.

An output may never be, contain, or lie inside one of the command's inputs (the
frames, the truth CSV, the config); an existing file or a non-empty folder is
refused unless ``--overwrite`` is given; files are written atomically (a
temporary file in the same folder, then one rename), so an interrupted run
leaves the old file or the new one, never half of one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterable, Optional, Union

from ..errors import OutputError

PathLike = Union[str, Path]


def _real(path: PathLike) -> Path:
    return Path(os.path.realpath(os.fspath(path)))


def _clash(out: Path, inputs: Iterable[Optional[PathLike]]) -> Optional[str]:
    for given in inputs:
        if not given:
            continue
        inp = _real(given)
        if out == inp:
            return f"it is the input {given}"
        if inp in out.parents:
            return f"it is inside the input {given}"
        if out in inp.parents:
            return f"it holds the input {given}"
    return None


def check_output_file(path: PathLike, flag: str, inputs: Iterable[Optional[PathLike]], overwrite: bool) -> Path:
    """``path`` as a file this command may write (its folder exists); OutputError otherwise."""
    out = _real(path)
    clash = _clash(out, inputs)
    if clash:
        raise OutputError(f"{flag}: will not write {path}: {clash}")
    if out.is_dir():
        raise OutputError(f"{flag}: {path} is a folder")
    if out.exists() and not overwrite:
        raise OutputError(f"{flag}: {path} exists (--overwrite replaces it)")
    if not out.parent.is_dir():
        raise OutputError(f"{flag}: cannot write {path}: No such file or directory ({out.parent} does not exist)")
    if not os.access(out.parent, os.W_OK):
        raise OutputError(f"{flag}: cannot write in {out.parent} ({_why_not_writable(out.parent)})")
    return out


def check_config_out(path: PathLike, flag: str, recording: Optional[PathLike]) -> Path:
    """``path`` as a config a command may write (an existing one is kept as ``.bak``); OutputError otherwise.

    Never the recording the command reads, nor one of its frames; a new file beside the frames (as
    ``synth`` writes camera.yaml) is fine.
    """
    from ..sources.recorded import IMAGE_SUFFIXES  # not on `run`'s start-up path

    out = check_output_file(path, flag, (), overwrite=True)
    if recording:
        rec = _real(recording)
        if out == rec or (rec in out.parents and out.suffix.lower() in IMAGE_SUFFIXES):
            raise OutputError(f"{flag}: will not write {path}: it is {'the input' if out == rec else 'a frame of'} "
                              f"{recording}")
    return out


def _why_not_writable(folder: Path) -> str:
    try:
        read_only = bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):  # no statvfs (Windows): say what access() said
        read_only = False
    return "a read-only file system" if read_only else "permission denied"


def check_output_dir(path: PathLike, flag: str, inputs: Iterable[Optional[PathLike]], overwrite: bool,
                     create: bool = True) -> Path:
    """``path`` as a folder this command may fill: new, empty, or ``overwrite``; created when ``create``."""
    out = _real(path)
    clash = _clash(out, inputs)
    if clash:
        raise OutputError(f"{flag}: will not write into {path}: {clash}")
    if out.exists() and not out.is_dir():
        raise OutputError(f"{flag}: {path} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise OutputError(f"{flag}: {path} is not empty (--overwrite writes into it anyway)")
    if create:
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"{flag}: cannot create {path}: {exc.strerror or exc}") from None
    return out


def write_bytes_atomic(path: PathLike, data: bytes, durable: bool = False) -> None:
    """``data`` into ``path`` through a temporary file and one rename (``durable``: fsync before the rename).

    A crash leaves the old file or the new one, never half of one.
    """
    out = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", dir=out.parent)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
                if durable:
                    f.flush()
                    os.fsync(f.fileno())
            os.replace(tmp, out)
        except BaseException:
            os.unlink(tmp)
            raise
    except OSError as exc:
        raise OutputError(f"cannot write {out}: {exc.strerror or exc}") from None


class AtomicText:
    """A text file written to a temporary name and renamed into place on a clean close."""

    def __init__(self, path: PathLike) -> None:
        self.path = Path(path)
        try:
            fd, self._tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", dir=self.path.parent)
        except OSError as exc:
            raise OutputError(f"cannot write {self.path}: {exc.strerror or exc}") from None
        self.file = os.fdopen(fd, "w", encoding="utf-8")

    def write(self, text: str) -> None:
        """Append ``text``; OutputError (the temporary file dropped) if it cannot be written (a full disk)."""
        try:
            self.file.write(text)
        except OSError as exc:
            self._fail(exc)

    def close(self, keep: bool = True) -> None:
        """Rename into place (``keep``), or drop the temporary file; OutputError if the text cannot be kept."""
        if self.file.closed:
            return
        try:
            self.file.close()
            if keep:
                os.replace(self._tmp, self.path)
                return
        except OSError as exc:
            self._fail(exc)
        with contextlib.suppress(OSError):
            os.unlink(self._tmp)

    def _fail(self, exc: OSError) -> None:
        with contextlib.suppress(OSError):
            self.file.close()  # the buffered rest may fail again: the file is dropped anyway
        with contextlib.suppress(OSError):
            os.unlink(self._tmp)
        raise OutputError(f"cannot write {self.path}: {exc.strerror or exc}") from None
