"""Small helpers that keep the package working from Python 3.9 up."""

from __future__ import annotations

import atexit
import builtins
import dataclasses
import importlib
import marshal
import os
import sys
import threading
from dataclasses import dataclass
from types import CodeType
from typing import Any, Callable, Dict, Optional, TypeVar

T = TypeVar("T")

_SLOTS: dict[str, Any] = {"slots": True} if sys.version_info >= (3, 10) else {}


def cache_dir() -> Optional[str]:
    """The package's cache directory (``RANGEBEARING_CACHE``, else ``$XDG_CACHE_HOME`` or ``~/.cache``), None if off."""
    named = os.environ.get("RANGEBEARING_CACHE", "")
    if named == "off":
        return None
    if named:
        return named
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "rangebearing")


class _GeneratedMethods:
    """The code of the methods ``@dataclass`` generates, compiled once and kept between runs.

    ``dataclass`` writes each method as source text and ``exec``s it (~6 a
    frozen class, ~0.2 ms each: ~40 ms of a daemon's start-up for its ~30
    classes). While :func:`frozen` runs, the ``exec`` that ``dataclasses``
    calls is this one: the same text gives the same code object, compiled as
    ``exec`` would (no inherited ``__future__`` flags), looked up by that text
    in a file of this Python's marshal format. A missing, unreadable or
    unwritable file only costs the compiling.
    """

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self._code: Optional[Dict[str, CodeType]] = None
        self._added = False

    def _path(self) -> Optional[str]:
        where = cache_dir()
        tag = f"{sys.implementation.cache_tag}-{sys.hexversion:x}"
        return None if where is None else os.path.join(where, f"dataclass-methods-{tag}.marshal")

    def _load(self) -> Dict[str, CodeType]:
        path = self._path()
        try:
            with open(path, "rb") as f:  # type: ignore[arg-type]
                code = marshal.load(f)
        except (OSError, TypeError, ValueError, EOFError):
            return {}
        ok = isinstance(code, dict) and all(isinstance(k, str) and isinstance(v, CodeType) for k, v in code.items())
        return code if ok else {}

    def exec(self, source: Any, globals_: Any = None, locals_: Any = None) -> None:
        if not isinstance(source, str):
            return builtins.exec(source, globals_, locals_)
        if self._code is None:
            self._code = self._load()
        code = self._code.get(source)
        if code is None:
            code = self._code[source] = compile(source, "<string>", "exec", dont_inherit=True)
            if not self._added:
                self._added = True
                atexit.register(self.save)
        return builtins.exec(code, globals_, locals_)

    def save(self) -> None:
        """Write the code compiled in this run (at exit); never raises."""
        path = self._path()
        if path is None or not self._code:
            return
        try:
            os.makedirs(os.path.dirname(path), mode=0o700, exist_ok=True)
            tmp = f"{path}.{os.getpid()}"
            with open(tmp, "wb") as f:
                marshal.dump({**self._load(), **self._code}, f)
            os.replace(tmp, path)  # atomic: a reader sees a whole file or the old one
        except (OSError, ValueError):
            pass


_METHODS = _GeneratedMethods()


def frozen(cls: type[T]) -> type[T]:
    """``@dataclass(frozen=True, slots=True)``, without slots before Python 3.10 (its methods' code cached)."""
    deco: Callable[[type[T]], type[T]] = dataclass(frozen=True, **_SLOTS)
    with _METHODS.lock:
        dataclasses.exec = _METHODS.exec  # type: ignore[attr-defined]  # found before the builtin
        try:
            return deco(cls)
        finally:
            del dataclasses.exec  # type: ignore[attr-defined]


def lazy_attributes(package: str, table: Dict[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` (PEP 562) that imports ``table[name]`` (relative to ``package``) on first use.

    The value is cached in the package's namespace, so the import runs once.
    """
    module = sys.modules[package]

    def __getattr__(name: str) -> Any:
        if name in table:
            value = getattr(importlib.import_module(table[name], package), name)
            setattr(module, name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
