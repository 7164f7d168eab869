"""Config fuzzing: 1,000 mutations of the shipped config through ``load_config`` in-process.

Each either loads or raises ConfigError naming the file, in under a second of CPU time
(this thread's: other jobs on a shared machine do not count), with a message under 2 KB.
Seeded, so a failure names a case that fails again.
"""

from __future__ import annotations

import random
import re
import time
from pathlib import Path
from typing import List

import pytest

from rangebearing.config import load_config
from rangebearing.errors import ConfigError

SHIPPED = (Path(__file__).resolve().parents[2] / "config" / "rangebearing.yaml").read_text("utf-8")
N_CASES = 1000
VALUE = re.compile(r"(?<=: )[^#\n]+")  # a value after "key: ", up to a comment
HOSTILE_VALUES = [
    "1e400", "-1e400", ".nan", ".inf", "1" + "0" * 400, "9" * 5000, "0x7fffffff", "0o777", "-0", "1_000",
    "off", "yes", "~", "null", "''", '""', '"\\0"', '"\\ud800"', '"\\x1b[2J"', "[]", "{}", "[[]]", "[0, 10]",
    "[[0, 400]]", "[1, 2, 3]", "&a [*a]", "*nope", "!!binary AAAA", "!!python/name:os.system", "!!set {a}",
    "2001-12-14", "2001-13-45", "\u00b2.1.1.1", "'255.255.255.255'", "[" * 100 + "]" * 100,
    "{a: {b: {c: {d: 1}}}}", '"' + "x" * 5000 + '"', "|\n  multi\n  line", ">-", "[a, b, c, d, e, f, g, h]",
    "'::1:47800'", "['127.0.0.1:47800', '127.0.0.1:47800']", "['host:0']", "['[::1]:5']", "'zumo 7'",
]
TOKENS = ["&x ", "*x", "<<: ", "- ", ": ", "{", "}", "[", "]", "'", '"', "\t", "\x00", "\x85", "\ufeff", "%YAML 1.2\n",
          "---\n", "...\n", "? ", "!", "|", "#", "\\"]


def _mutate(rng: random.Random, text: str) -> str:
    kind = rng.randrange(7)
    if kind == 0:  # a value replaced by a hostile one
        matches = list(VALUE.finditer(text))
        if not matches:
            return text + "\ncamera: {fx_px: " + rng.choice(HOSTILE_VALUES) + "}"
        m = rng.choice(matches)
        return text[: m.start()] + rng.choice(HOSTILE_VALUES) + text[m.end():]
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    if kind == 1:  # a line removed, or duplicated elsewhere
        line = lines.pop(i)
        if rng.random() < 0.5:
            lines.insert(rng.randrange(len(lines) + 1), line)
        return "\n".join(lines)
    if kind == 2:  # indentation broken
        lines[i] = " " * rng.randrange(5) + lines[i].lstrip()
        return "\n".join(lines)
    pos = rng.randrange(len(text) + 1)
    if kind == 3:  # a YAML token inserted
        return text[:pos] + rng.choice(TOKENS) + text[pos:]
    if kind == 4:  # a character deleted or replaced by any code point
        return text[:pos] + (chr(rng.randrange(0x20, 0x3000)) if rng.random() < 0.5 else "") + text[pos + 1:]
    if kind == 5:  # truncated
        return text[:pos]
    # an alias bomb grafted on
    depth = rng.randrange(2, 9)
    bomb = ["b0: &b0 [x, x, x, x, x, x, x, x, x]"] + [
        f"b{k}: &b{k} [{', '.join([f'*b{k - 1}'] * 9)}]" for k in range(1, depth)]
    return "\n".join(bomb) + f"\ndetection: {{red_hue: *b{depth - 1}}}\n" + text


def _cases() -> List[bytes]:
    rng = random.Random(9)
    out = []
    for _ in range(N_CASES):
        text = SHIPPED
        for _ in range(rng.randrange(1, 4)):
            text = _mutate(rng, text)
        data = text.encode("utf-8", "surrogatepass")
        if rng.random() < 0.03:  # raw bytes that are not UTF-8
            at = rng.randrange(len(data) + 1)
            data = data[:at] + bytes([rng.randrange(0x80, 0x100)]) + data[at:]
        out.append(data)
    return out


def test_mutated_configs_load_or_raise_only_config_error(tmp_path: Path) -> None:
    f = tmp_path / "fuzzed.yaml"
    loaded = refused = 0
    worst_s = 0.0
    for n, data in enumerate(_cases()):
        f.write_bytes(data)
        t0 = time.thread_time()
        try:
            load_config(f)
            loaded += 1
        except ConfigError as exc:
            refused += 1
            text = str(exc)
            assert str(f) in text, n
            assert len(text.encode("utf-8", "replace")) < 2048, (n, text[:300])
        except Exception as exc:  # the point of the test: name the escapee and its case
            pytest.fail(f"case {n}: {type(exc).__name__}: {exc!s:.300}")
        took = time.thread_time() - t0
        worst_s = max(worst_s, took)
        assert took < 1.0, (n, took)
    assert loaded + refused == N_CASES >= 1000
    assert loaded > 50 and refused > 500  # both outcomes are exercised
    print(f"\n{N_CASES} mutated configs: {loaded} loaded, {refused} refused, worst load {worst_s * 1000:.0f} ms")
