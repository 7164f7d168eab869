"""Write thresholds into a config file atomically, keeping the old file as ``FILE.bak``.

The file's own lines are edited in place where each key is a one-line value
inside a block-style ``detection:`` section, so its comments survive; any other
layout is rewritten from the parsed mapping (comments lost, the ``.bak`` keeps
them). Either way the result is parsed back and checked before anything is
replaced: a write never leaves a half-written or invalid config behind.
"""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple, Union

import yaml

from ..errors import ConfigError, OutputError
from .thresholds import KEYS, Thresholds

_TOP = re.compile(r"^[^\s#]")


def _flow(v: Any) -> str:
    return yaml.safe_dump(v, default_flow_style=True, width=1 << 16).strip().removesuffix("...").strip()


def _edit_lines(text: str, values: Dict[str, Any]) -> Optional[str]:
    """``text`` with the detection keys set line by line, or None when the layout does not allow it."""
    lines = text.splitlines(keepends=True)
    start = next((i for i, ln in enumerate(lines) if re.match(r"^detection:\s*(#.*)?$", ln)), None)
    if start is None:
        if any(ln.startswith("detection:") for ln in lines):
            return None  # flow style: detection: {...}
        tail = "" if not text or text.endswith("\n") else "\n"
        return text + tail + "detection:\n" + "".join(f"  {k}: {_flow(v)}\n" for k, v in values.items())
    end = next((i for i in range(start + 1, len(lines)) if _TOP.match(lines[i])), len(lines))
    indent = "  "
    for i in range(start + 1, end):
        m = re.match(r"^(\s+)\S", lines[i])
        if m and not lines[i].lstrip().startswith("#"):
            indent = m.group(1)
            break
    missing: List[str] = []
    for key, val in values.items():
        hits = [i for i in range(start + 1, end) if re.match(rf"^\s+{key}\s*:", lines[i])]
        if not hits:
            missing.append(f"{indent}{key}: {_flow(val)}\n")
            continue
        m = re.match(rf"^(\s+{key}\s*:\s*)([^#\s][^#]*?)(\s+#.*)?(\r?\n)?$", lines[hits[-1]])
        if len(hits) > 1 or m is None:
            return None  # a value over several lines, or a repeated key
        lines[hits[-1]] = m.group(1) + _flow(val) + (m.group(3) or "") + (m.group(4) or "\n")
    lines[start + 1 : start + 1] = missing
    return "".join(lines)


def updated_text(text: str, thresholds: Thresholds, source: str) -> str:
    """The config text with ``thresholds`` written into its ``detection`` section, validated.

    Raises
    ------
    ConfigError
        The current file is not a valid config, or the result would not be one.
    """
    from ..config import config_from_mapping

    try:
        data = yaml.safe_load(text) if text.strip() else {}
    except yaml.YAMLError as exc:
        raise ConfigError([f"not valid YAML: {exc}".replace("\n", " ")], source) from None
    data = {} if data is None else data
    if not isinstance(data, dict) or not isinstance(data.get("detection", {}) or {}, dict):
        raise ConfigError(["the file is not a mapping of sections with a 'detection' mapping"], source)
    values = {k: v for k, v in thresholds.as_json().items() if k in KEYS}
    want = dict(data)
    want["detection"] = {**(data.get("detection") or {}), **values}
    new = _edit_lines(text, values)
    if new is None or yaml.safe_load(new) != want:
        new = yaml.safe_dump(want, sort_keys=False, default_flow_style=None)
    config_from_mapping(yaml.safe_load(new), source)  # never write what the loader would refuse
    return new


def _atomic_write(path: Path, data: bytes, mode: int) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    try:
        dir_fd = os.open(path.parent, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(dir_fd)
    finally:
        os.close(dir_fd)


def save_thresholds(path: Union[str, Path], thresholds: Thresholds) -> Tuple[Path, Path]:
    """Write ``thresholds`` into the config file at ``path``; return ``(path, backup)``.

    The old file is first copied to ``path.bak`` (itself written atomically),
    then the new text replaces ``path`` by a rename, so a reader sees either the
    old file or the new one, never a mix.

    Raises
    ------
    ConfigError
        The file is not a valid config, or the new one would not be.
    OutputError
        The file or its backup cannot be read or written (permissions, read-only file system).
    """
    path = Path(path)
    backup = path.with_name(path.name + ".bak")
    try:
        old = path.read_bytes()
        mode = path.stat().st_mode & 0o7777
    except OSError as exc:
        raise OutputError(f"cannot read {path}: {exc.strerror or exc}") from None
    new = updated_text(old.decode("utf-8"), thresholds, str(path))
    try:
        _atomic_write(backup, old, mode)
        _atomic_write(path, new.encode("utf-8"), mode)
    except OSError as exc:
        raise OutputError(f"cannot write {exc.filename or path}: {exc.strerror or exc}") from None
    return path, backup
