"""What makes each reading's sigma, set by set: 2σ cover, each term's share of σ², and cover under other shares.

Usage::

    python benchmarks/sigma_terms.py SET_DIR[:track] ... --config cal.yaml [--share NAME=VALUE ...]

Replays every ``SET_DIR`` (a folder written by ``rangebearing synth``; ``:track`` replays it with
tracking, as ``crowd-moving`` is measured) and keeps, for every reading matched to its truth, the
inputs :func:`rangebearing.core.uncertainty.reading_sigma` was given. Per set (the folder name up
to ``-s<seed>``, seeds pooled) it prints:

* the 2σ cover in range and bearing (issue 8: 90–98 %) and the factor ``p95(|error|/σ)/2`` by which
  that set's σ would have to be scaled for 95 % (below 1: σ too wide);
* each term's mean share of the reading's σ² (the term's constant set to 0, the rest kept): range
  ``noise`` (NOISE_SHARE), ``spread`` (SPREAD_SHARE: the row estimators' disagreement, merged bands
  included), ``fit`` (FIT_SPREAD: of the bands placed from their edges alone), ``merged`` (MERGED_PX),
  ``blur`` (CHROMA_SHARE), ``hidden`` (HIDDEN_SHARE_L, CUT_HIDDEN_SHARE_L), ``cut`` (CUT/SPLIT_SHARE_L),
  ``floor`` (EDGE_FLOOR_PX, MODEL_FLOOR); bearing ``column``, ``spread``, ``shading``, ``hidden``,
  ``cut``, ``floor``.

``--split tracked|kind|column|seed`` adds a line per set and frame type (tracked or full scan), kind of
reading (``whole``, ``cut1``/``cut2`` cut on one side/both, ``H`` partly hidden, ``M`` a merged band),
column source (the bands' ``moments`` or a ``limb``) or seed: a set's cover can hide groups that balance
each other (a 300-frame sequence is one seed: its robots share one light, so one bias).

``--share NAME=VALUE`` (a constant of ``core/uncertainty.py``, e.g. ``SPREAD_SHARE=0.7``; repeatable)
recomputes every sigma from the kept inputs with that value and prints the cover again, so a re-fit
can be tried on many sets without replaying them (``row_spread_px``'s inputs are kept too, so
``MERGED_PX`` and ``FIT_SPREAD`` count). The inputs themselves are not re-measured.
"""

from __future__ import annotations

import argparse
import os
import re
from collections import defaultdict
from typing import Dict, List, Optional, Sequence, Tuple

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from rangebearing import Pipeline, load_config
from rangebearing.cli.common import aligned_truth
from rangebearing.core import detect as detect_module
from rangebearing.core import pipeline as pipeline_module
from rangebearing.core import uncertainty as u
from rangebearing.core.limbs import CENTROID_SIGMA_X_PX
from rangebearing.evaluation.match import match_frame
from rangebearing.sources.recorded import iter_recorded

RANGE_TERMS = {"noise": ("NOISE_SHARE",), "spread": ("SPREAD_SHARE",), "fit": ("FIT_SPREAD",), "moment": ("MOMENT_PX",),
               "merged": ("MERGED_PX",), "blur": ("CHROMA_SHARE",),
               "hidden": ("HIDDEN_SHARE_L", "CUT_HIDDEN_SHARE_L"), "cut": ("CUT_SHARE_L", "SPLIT_SHARE_L"),
               "floor": ("EDGE_FLOOR_PX", "MODEL_FLOOR")}
BEARING_TERMS = {"column": ("COLUMN_SHARE",), "spread": ("SPREAD_X_SHARE",), "shading": ("SHADING_SHARE",),
                 "hidden": ("HIDDEN_SHARE", "CUT_HIDDEN_SHARE"), "cut": ("CUT_SHARE", "SPLIT_SHARE"),
                 "floor": ("BEARING_FLOOR_RAD",)}


SPREAD_ARG = 9  # reading_sigma's positional spread_l_px, as the pipeline passes it


def kind(args: tuple, kwargs: dict) -> str:
    """The reading's kind: ``cut1``/``cut2`` (cut on one side / both), ``H`` partly hidden, ``M`` a merged
    band, in that order (``whole``: none of them)."""
    cut = args[11] if len(args) > 11 else kwargs.get("cut", (False, False))
    spread = args[SPREAD_ARG] if len(args) > SPREAD_ARG else None
    label = ("cut2" if all(cut) else "cut1" if any(cut) else "") + ("H" if args[6] < 1.0 else "")
    label += "M" if isinstance(spread, Spread) and (spread[2] or spread[5]) else ""
    return label or "whole"


def column_source(args: tuple) -> str:
    """``moments`` when the column is the bands' saturation moments (σ_x their constant), else ``limb``."""
    return "moments" if args[4] == CENTROID_SIGMA_X_PX else "limb"


def seed_of(folder: str) -> str:
    found = re.search(r"-s(\d+)-", os.path.basename(os.path.normpath(folder)))
    return found.group(1) if found else os.path.basename(os.path.normpath(folder))


def replay(folder: str, config: str, tracked: bool) -> List[Tuple[tuple, dict, float, float, Dict[str, str]]]:
    """``(reading_sigma's arguments, its keywords, true range, true bearing, labels)`` of every matched reading;
    the labels (``--split``): the frame ``tracked`` or ``full`` scan, the reading's :func:`kind`, its
    :func:`column_source`, the folder's seed.

    The arguments are kept with the spread's own inputs (``row_spread_px``'s, found by its value)
    in place of ``spread_l_px``, so ``MERGED_PX`` and ``FIT_SPREAD`` are re-evaluated too.
    """
    kept: List[tuple] = []
    spreads: Dict[float, tuple] = {}
    original, original_spread = pipeline_module.reading_sigma, detect_module.row_spread_px

    def keeping(*args, **kwargs):  # the pipeline's own call, its inputs kept
        out = original(*args, **kwargs)
        if len(args) > SPREAD_ARG and args[SPREAD_ARG] in spreads:
            args = (*args[:SPREAD_ARG], Spread(spreads[args[SPREAD_ARG]]), *args[SPREAD_ARG + 1 :])
        kept.append((args, kwargs, out))
        return out

    def spread_keeping(*args):
        out = original_spread(*args)
        spreads[out] = args
        return out

    truth = aligned_truth(folder, os.path.join(folder, "truth.csv"))
    pipe = Pipeline(load_config(config).pipeline, track=tracked)
    rows = []
    pipeline_module.reading_sigma = keeping
    detect_module.row_spread_px = spread_keeping
    try:
        for name, image in iter_recorded(folder):
            kept.clear()
            result = pipe.process(image)
            matches, _ = match_frame(name, result.landmarks, truth.get(name, []))
            for m in matches:
                if m.found is None:
                    continue
                for args, kwargs, _out in kept:  # args[0], args[1]: the reading's range and bearing
                    if args[0] == m.found.range_m and args[1] == m.found.bearing_rad:
                        labels = {"tracked": "tracked" if result.tracked else "full", "kind": kind(args, kwargs),
                                  "column": column_source(args), "seed": seed_of(folder)}
                        rows.append((args, kwargs, m.truth.range_m, m.truth.bearing_rad, labels))
                        break
    finally:
        pipeline_module.reading_sigma = original
        detect_module.row_spread_px = original_spread
    return rows


class Spread(tuple):
    """``row_spread_px``'s arguments standing for the spread: evaluated with the constants of the moment."""


def _evaluated(args: tuple) -> tuple:
    return tuple(u.row_spread_px(*a) if isinstance(a, Spread) else a for a in args)


def sigmas(rows: Sequence[tuple], zero: Sequence[str] = ()) -> np.ndarray:
    """``(n, 2)`` range and bearing sigma of the kept readings, with the constants in ``zero`` set to 0."""
    saved = {name: getattr(u, name) for name in zero}
    try:
        for name in zero:
            setattr(u, name, 0.0)
        return np.array([u.reading_sigma(*_evaluated(args), **kwargs) for args, kwargs, *_ in rows]).reshape(-1, 2)
    finally:
        for name, value in saved.items():
            setattr(u, name, value)


def report(sets: Dict[str, List[tuple]], split: str = "") -> None:
    """Cover, scale for 95 % and the terms' shares of σ², one line per set and quantity; with ``split`` (a
    label of :func:`replay`) one line per set and label value, the set's own lines first."""
    for name in sorted(sets):
        groups = {name: sets[name]}
        for row in sets[name] if split else ():
            groups.setdefault(f"{name}/{row[4][split]}", []).append(row)
        for label in sorted(groups, key=lambda g: (g != name, g)):
            _report_rows(label, groups[label])


def _report_rows(name: str, rows: List[tuple]) -> None:
    if rows:
        err = np.array([[abs(a[0] - tr), abs(a[1] - tb)] for a, _, tr, tb, *_ in rows]).reshape(-1, 2)
        s = sigmas(rows)
        z = err / np.maximum(s, 1e-12)
        for k, (label, terms) in enumerate((("range", RANGE_TERMS), ("bearing", BEARING_TERMS))):
            shares = []
            for term, consts in terms.items():
                without = sigmas(rows, consts)[:, k]
                shares.append(f"{term} {np.mean(1.0 - (without / np.maximum(s[:, k], 1e-12)) ** 2):.2f}")
            cover = 100.0 * np.mean(z[:, k] <= 2.0)
            flag = "" if 90.0 <= cover <= 98.0 else " x"
            print(f"{name:20s} {label:7s} n={len(rows):4d} cover {cover:5.1f} %{flag:2s} scale "
                  f"{np.percentile(z[:, k], 95) / 2:.2f}  shares: {', '.join(shares)}")


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("folders", nargs="+", metavar="SET_DIR[:track]")
    p.add_argument("--config", required=True)
    p.add_argument("--split", choices=("tracked", "kind", "column", "seed"), default="",
                   help="also one line per set and frame type / kind of reading / column source / seed")
    p.add_argument("--share", action="append", default=[], metavar="NAME=VALUE",
                   help="recompute the sigmas with this constant of core/uncertainty.py")
    args = p.parse_args(argv)
    changes = {}
    for item in args.share:
        name, _, value = item.partition("=")
        if not hasattr(u, name) or not isinstance(getattr(u, name), float):
            p.error(f"--share {item}: core/uncertainty.py has no float constant {name!r}")
        changes[name] = float(value)
    sets: Dict[str, List[tuple]] = defaultdict(list)
    for spec in args.folders:
        folder, _, mode = spec.partition(":")
        base = os.path.basename(os.path.normpath(folder))
        sets[re.sub(r"-s\d+-.*$", "", base)].extend(replay(folder, args.config, mode == "track"))
    print("as configured:")
    report(sets, args.split)
    if changes:
        for name, value in changes.items():
            setattr(u, name, value)
        print("with " + ", ".join(f"{k}={v:g}" for k, v in changes.items()) + ":")
        report(sets, args.split)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
