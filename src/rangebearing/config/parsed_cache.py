"""A config file's parsed data kept between starts, so ``run`` need not import PyYAML to read it again.

PyYAML's import is ~10 % of the daemon's start-up (it compiles its reader's and
resolver's regular expressions in pure Python). The data parsed from a file's
exact bytes is stored as JSON with every value's type kept (floats by ``repr``,
mappings as key-value pairs, so keys of any scalar type survive) under a key
made of those bytes and the parser's own version; a start with the same file
reads it back and validates it as it would a fresh parse (only the parse is
skipped, never a check). Anything unusual (data that is not plain YAML
scalars, lists and mappings; a cache that cannot be read or written) falls
back to parsing, silently. ``RANGEBEARING_CACHE`` names the directory
(default ``$XDG_CACHE_HOME/rangebearing`` or ``~/.cache/rangebearing``);
``off`` turns the cache off.
"""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Any, Callable, Optional, Union

from .. import _compat
from .file_bytes import is_regular, read_bounded

try:  # CPython's own BLAKE2: hashlib would load OpenSSL's libcrypto (~2.5 ms of every start)
    from _blake2 import blake2b as _blake2b
except ImportError:  # pragma: no cover - another Python
    from hashlib import blake2b as _blake2b

VERSION = 2  # of the stored form (2: keys are BLAKE2b)
READ_LIMIT = 64 * 1024  # yaml_safe.MAX_BYTES (not imported: that imports PyYAML)


class _NotPlain(Exception):
    """A value the stored form does not carry exactly."""


def cache_dir() -> Optional[Path]:
    """Where parsed configs are kept (the package's cache directory), or None when the cache is off."""
    where = _compat.cache_dir()
    return None if where is None else Path(where)


def parsed(path: Union[str, Path], parse: Callable[[Union[str, Path]], Any]) -> Any:
    """``parse(path)``, or the data a parse of the same bytes gave before."""
    where = cache_dir()
    if where is None or not is_regular(path):  # a pipe or FIFO can be read once only: by the parser
        return parse(path)
    try:
        raw: Optional[bytes] = read_bounded(path, READ_LIMIT)  # a 2 GB file is the parser's to refuse, unread
    except (OSError, ValueError):  # unreadable, or a NUL in the path: the parser words it
        raw = None
    if where is None or raw is None or len(raw) > READ_LIMIT:
        return parse(path)  # it words a file it cannot read
    entry = where / f"config-{_key(raw)}.json"
    try:
        return _decode(json.loads(entry.read_text(encoding="utf-8"))["data"])
    except (OSError, ValueError, KeyError, TypeError, _NotPlain):
        pass
    data = parse(path)
    with contextlib.suppress(OSError, ValueError, TypeError, RecursionError, _NotPlain):
        _store(where, entry, {"v": VERSION, "data": _encode(data)})
    return data


def _key(raw: bytes) -> str:
    """The file's bytes and everything that decides what they parse to (this package's parser)."""
    from .. import __version__

    parser = Path(__file__).with_name("yaml_safe.py")
    try:
        st = parser.stat()
        stamp = f"{st.st_size}:{st.st_mtime_ns}"
    except OSError:
        stamp = "?"
    h = _blake2b(f"{VERSION}|{__version__}|{stamp}|".encode(), digest_size=20)
    h.update(raw)
    return h.hexdigest()[:40]


def _store(where: Path, entry: Path, doc: Any) -> None:
    where.mkdir(mode=0o700, parents=True, exist_ok=True)
    tmp = entry.with_name(f".{entry.name}.{os.getpid()}")
    tmp.write_text(json.dumps(doc, allow_nan=False), encoding="utf-8")
    os.replace(tmp, entry)  # atomic: a reader sees the whole entry or none


def _encode(v: Any) -> Any:
    t = type(v)
    if v is None or t is bool or t is int or t is str:
        return v
    if t is float:
        return {"f": repr(v)}  # exact, inf and nan included
    if t is list:
        return [_encode(x) for x in v]
    if t is dict:
        return {"m": [[_encode(k), _encode(x)] for k, x in v.items()]}
    raise _NotPlain(t.__name__)


def _decode(v: Any) -> Any:
    if isinstance(v, list):
        return [_decode(x) for x in v]
    if isinstance(v, dict):
        if "f" in v:
            return float(v["f"])
        return {_decode(k): _decode(x) for k, x in v["m"]}
    if v is None or isinstance(v, (bool, int, str)):
        return v
    raise _NotPlain(type(v).__name__)
