"""Small helpers that keep the package working from Python 3.9 up."""

from __future__ import annotations

import importlib
import sys
from dataclasses import dataclass
from typing import Any, Callable, Dict, TypeVar

T = TypeVar("T")

_SLOTS: dict[str, Any] = {"slots": True} if sys.version_info >= (3, 10) else {}


def frozen(cls: type[T]) -> type[T]:
    """``@dataclass(frozen=True, slots=True)``, without slots before Python 3.10."""
    deco: Callable[[type[T]], type[T]] = dataclass(frozen=True, **_SLOTS)
    return deco(cls)


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
