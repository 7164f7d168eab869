"""Reading a config file as YAML, safely: whatever the file holds, the result is data or a
:class:`~rangebearing.errors.ConfigError` naming the file, quickly and in bounded memory.

``yaml.safe_load`` alone lets through: non-UTF-8 bytes (UnicodeDecodeError), nesting
2,000 deep (RecursionError), a 5,000-digit integer (ValueError), alias bombs (nine
aliases of nine aliases... expand to a billion values once anything walks them),
duplicate keys (silently last-wins), and syntax errors that say ``"<unicode string>"``.
Here each one is a problem with a line number, and the file is named by the error.

With libyaml present (PyYAML's ``yaml.cyaml``, as in the wheels) the text is scanned and
parsed in C and only the composition (where the limits are kept) runs in Python: ~1 ms
for the shipped config instead of ~10 ms at every start. What libyaml refuses is read again
by PyYAML's pure-Python parser, which words the problem (or takes the file: it accepts a
few things libyaml does not). Both give the same data wherever both parse; libyaml takes a
few files PyYAML refuses (a comment straight after a block scalar's ``|``, a tab before a
value), whose values then meet the same checks as any other. Without libyaml the
pure-Python parser does it all.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any, Dict, List, Optional, Union

import yaml
from yaml.composer import Composer
from yaml.constructor import SafeConstructor
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode
from yaml.resolver import Resolver

try:  # libyaml: scanner and parser in C (the events are flat, so no C recursion to bound)
    from yaml.cyaml import CParser
except ImportError:  # PyYAML built without libyaml
    CParser = None

from ..errors import ConfigError
from .file_bytes import read_bounded

MAX_BYTES = 64 * 1024  # the documented config with every comment is ~5 KB
MAX_DEPTH = 32  # sections are 2 levels deep, hue ranges 3
MAX_VALUES = 10_000  # values once aliases are expanded; the full config has ~100
MAX_DIGITS = 100  # an integer literal longer than this is not a setting
MERGE_TAG = "tag:yaml.org,2002:merge"


def cut(text: str, limit: int = 60) -> str:
    """``text`` cut to ``limit`` characters with an ellipsis: no value floods a message."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


class _Refused(yaml.MarkedYAMLError):
    """A document this loader will not build (too deep, too big, a duplicate key)."""


class _Limits:
    """The limits, for either parser: a depth limit, duplicate-key detection and short integers.

    Mixed in before PyYAML's own ``Composer`` and ``SafeConstructor``, whose methods these wrap.
    """

    name: str
    depth: int
    duplicates: List[str]

    def _limits(self, name: str) -> None:
        self.name = name  # marks (and so every YAML error) name the file, not "<unicode string>"
        self.depth = 0
        self.duplicates = []

    def compose_node(self, parent: Any, index: Any) -> Any:
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise _Refused(None, None, f"nesting deeper than {MAX_DEPTH} levels",
                               self.peek_event().start_mark)  # type: ignore[attr-defined]
            return super().compose_node(parent, index)  # type: ignore[misc]
        finally:
            self.depth -= 1

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        if isinstance(node, MappingNode):
            first: Dict[str, int] = {}
            for key_node, _ in node.value:
                if not isinstance(key_node, ScalarNode) or key_node.tag == MERGE_TAG:
                    continue
                line = key_node.start_mark.line + 1
                if key_node.value in first:
                    self.duplicates.append(
                        f"line {line}: duplicate key {cut(key_node.value)!r} (first at line {first[key_node.value]}); "
                        "YAML would silently keep the last one")
                else:
                    first[key_node.value] = line
        return super().construct_mapping(node, deep=deep)  # type: ignore[misc]

    def construct_yaml_int(self, node: Any) -> int:
        digits = sum(c.isdigit() for c in str(node.value))
        if digits > MAX_DIGITS:
            raise _Refused(None, None, f"an integer of {digits} digits is not a setting", node.start_mark)
        return super().construct_yaml_int(node)  # type: ignore[misc]


class _Loader(_Limits, yaml.SafeLoader):
    """PyYAML's pure-Python SafeLoader with the limits."""

    def __init__(self, text: str, name: str) -> None:
        super().__init__(text)
        self._limits(name)


_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_yaml_int)
_CLoader: Optional[type] = None

if CParser is not None:

    class _CLoader(_Limits, Composer, CParser, SafeConstructor, Resolver):  # type: ignore[no-redef]
        """libyaml's events, composed in Python (``Composer`` before ``CParser``) with the limits."""

        def __init__(self, text: str, name: str) -> None:
            stream = io.StringIO(text)
            stream.name = name  # type: ignore[misc]  # CParser's marks take the stream's name
            CParser.__init__(self, stream)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            Composer.__init__(self)
            self._limits(name)

    _CLoader.add_constructor("tag:yaml.org,2002:int", _CLoader.construct_yaml_int)


def _expanded_size(root: Node) -> float:
    """How many values the node graph holds once every alias is expanded (inf for a cycle)."""
    sizes: Dict[int, float] = {}
    on_path: set = set()

    def size(node: Node) -> float:  # depth is bounded by MAX_DEPTH: recursion is safe
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in on_path:
            return float("inf")  # a recursive alias: a value that contains itself
        on_path.add(key)
        total = 1.0
        if isinstance(node, SequenceNode):
            total += sum(size(child) for child in node.value)
        elif isinstance(node, MappingNode):
            total += sum(size(k) + size(v) for k, v in node.value)
        on_path.discard(key)
        sizes[key] = total
        return total

    return size(root)


def _where(exc: yaml.MarkedYAMLError) -> str:
    mark = exc.problem_mark or exc.context_mark
    return f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""


def read_text(path: Union[str, Path]) -> str:
    """The file as text: at most :data:`MAX_BYTES`, UTF-8 (a leading BOM is dropped)."""
    source = str(path)
    try:  # bounded read: /dev/zero, a 2 GB file or a FIFO without a writer cost nothing
        data = read_bounded(path, MAX_BYTES)
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the path
        raise ConfigError([f"cannot read file: {getattr(exc, 'strerror', None) or exc}"], cut(source, 200)) from None
    if len(data) > MAX_BYTES:
        raise ConfigError([f"file is larger than {MAX_BYTES // 1024} KiB: not a rangebearing config"], source)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise ConfigError([f"line {line}: not UTF-8 text (byte 0x{data[exc.start]:02x}); save the file as UTF-8"],
                          source) from None
    return text[1:] if text.startswith("\ufeff") else text


def load_yaml(path: Union[str, Path], c_parser: Optional[bool] = None) -> Any:
    """Parse a config file into plain data (dicts, lists, scalars).

    ``c_parser``: parse with libyaml (default: when PyYAML has it). Whatever
    libyaml refuses is parsed again by PyYAML's pure-Python parser, which has
    the last word (libyaml refuses a few things PyYAML takes, e.g. a lone
    surrogate escape that the checks then name by its key) and words the
    problem; ``False`` takes the pure-Python parser only.

    Raises
    ------
    ConfigError
        Naming the file, with a line number where there is one: unreadable, too
        big, empty, not UTF-8, not YAML, nested deeper than :data:`MAX_DEPTH`, more than
        :data:`MAX_VALUES` values once aliases are expanded, or duplicate keys.
    """
    source = str(path)
    text = read_text(path)
    if not text.strip():  # a save cut short (a full disk) or the wrong file: never "all defaults" by accident
        raise ConfigError(["the file is empty (write {} in it to run on the defaults)"], source)
    if _CLoader is not None and c_parser is not False:
        try:
            return _parse(text, source, _CLoader)
        except ConfigError:
            pass  # the pure-Python parser decides, and says why
    return _parse(text, source, _Loader)


def _parse(text: str, source: str, loader_class: type) -> Any:
    try:
        loader = loader_class(text, source)
    except yaml.reader.ReaderError as exc:  # a control character, found before any parsing
        line = text[: exc.position].count("\n") + 1
        raise ConfigError([f"not valid YAML: line {line}: character {exc.character!r} is not allowed "
                           "(a control character)"], source) from None
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        if _expanded_size(node) > MAX_VALUES:
            raise ConfigError([f"more than {MAX_VALUES:,} values once aliases (*name) are expanded: "
                               "an alias bomb? write the values out"], source)
        data = loader.construct_document(node)
    except ConfigError:
        raise  # already says what is wrong (an alias bomb): not wrapped in "not valid YAML"
    except yaml.MarkedYAMLError as exc:
        raise ConfigError([cut(f"not valid YAML: {_where(exc)}{exc.problem or exc.context}", 300)], source) from None
    except yaml.YAMLError as exc:  # a ReaderError (a control character) has no mark attributes
        raise ConfigError([cut(f"not valid YAML: {exc}".replace("\n", " "), 300)], source) from None
    except (ValueError, TypeError, OverflowError, RecursionError) as exc:  # a value YAML cannot build
        raise ConfigError([cut(f"not valid YAML: {type(exc).__name__}: {exc}", 300)], source) from None
    finally:
        loader.dispose()
    if loader.duplicates:
        raise ConfigError(loader.duplicates, source)
    return data
