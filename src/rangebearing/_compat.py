"""Small helpers that keep the package working from Python 3.9 up."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Any, Callable, TypeVar

T = TypeVar("T")

_SLOTS: dict[str, Any] = {"slots": True} if sys.version_info >= (3, 10) else {}


def frozen(cls: type[T]) -> type[T]:
    """``@dataclass(frozen=True, slots=True)``, without slots before Python 3.10."""
    deco: Callable[[type[T]], type[T]] = dataclass(frozen=True, **_SLOTS)
    return deco(cls)
