"""_compat.frozen keeps the code @dataclass generates between runs: the same classes, fewer compiles."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import pytest

from rangebearing._compat import frozen

PROBE = """
import builtins, sys
compiled = []
real = builtins.compile
builtins.compile = lambda *a, **k: compiled.append(a[0]) or real(*a, **k)
import rangebearing.core.types, rangebearing.config.schema, rangebearing.net.protocol
from rangebearing.core.types import CameraIntrinsics
c = CameraIntrinsics()
print(sum('__create_fn__' in s for s in compiled if isinstance(s, str)), repr(c) == repr(CameraIntrinsics()), hash(c))
"""


def test_a_second_run_compiles_no_dataclass_method_and_gets_the_same_classes(tmp_path: Path) -> None:
    env = {"RANGEBEARING_CACHE": str(tmp_path), "PATH": "/usr/bin:/bin", "PYTHONHASHSEED": "0"}
    runs = [subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
            .stdout.split() for _ in range(2)]
    assert int(runs[0][0]) > 20 and runs[1][0] == "0"  # every method's code came from the file the first run wrote
    assert runs[0][1:] == runs[1][1:] == [runs[0][1], runs[0][2]] and runs[0][1] == "True"
    assert list(tmp_path.glob("dataclass-methods-*.marshal"))


def test_a_frozen_class_behaves_as_dataclass_makes_it():
    @frozen
    class P:
        x_m: float
        n: int = 3

    p = P(1.5)
    assert p == P(1.5, 3) and hash(p) == hash(P(1.5)) and repr(p).endswith("P(x_m=1.5, n=3)")
    assert dataclasses.replace(p, n=4).n == 4 and P.__init__.__annotations__ == {"x_m": "float", "n": "int",
                                                                                  "return": None}
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.n = 5  # type: ignore[misc]
    assert not hasattr(dataclasses, "exec")  # the module is left as it was
