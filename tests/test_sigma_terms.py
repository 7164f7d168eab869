"""benchmarks/sigma_terms.py's ``--split`` labels: kind of reading, column source, seed."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parents[1] / "benchmarks"
if str(BENCH_DIR) not in sys.path:
    sys.path.insert(0, str(BENCH_DIR))
st = importlib.import_module("sigma_terms")


def _args(visible: float, sigma_x: float, cut=(False, False), merged=(False, False)) -> tuple:
    spread = st.Spread((10.0, 10.2, merged[0], 60.0, 60.1, merged[1], False, False))
    return (1.0, 0.1, 50.0, 0.05, sigma_x, 30.0, visible, 0.016, 634.0, spread, 0.1, cut, 0.0, 0.0)


def test_kind_labels_cut_hidden_merged_in_order() -> None:
    assert st.kind(_args(1.0, 0.15), {}) == "whole"
    assert st.kind(_args(0.8, 0.15), {}) == "H"
    assert st.kind(_args(1.0, 0.15, cut=(True, False)), {}) == "cut1"
    assert st.kind(_args(0.7, 0.15, cut=(True, True), merged=(False, True)), {}) == "cut2HM"


def test_column_source_and_seed() -> None:
    assert st.column_source(_args(1.0, st.CENTROID_SIGMA_X_PX)) == "moments"
    assert st.column_source(_args(1.0, 0.8)) == "limb"
    assert st.seed_of("/tmp/w/crowd-moving-s24010-n300-png-e1d6605b50/") == "24010"
    assert st.seed_of("/tmp/w/myset") == "myset"


def test_report_splits_a_set_by_label(capsys) -> None:
    rows = [(_args(1.0, 0.15), {}, 1.0, 0.1, {"seed": "1"}), (_args(1.0, 0.15), {}, 1.001, 0.1001, {"seed": "2"})]
    st.report({"paper": rows}, "seed")
    out = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in out] == ["paper", "paper", "paper/1", "paper/1", "paper/2", "paper/2"]
    assert "n=   2" in out[0] and "n=   1" in out[2]
