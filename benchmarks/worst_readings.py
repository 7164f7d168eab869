"""List a replayed set's worst readings: error in % and in sigma, with their truth and flags.

Usage::

    python benchmarks/worst_readings.py SET_DIR --config cal.yaml [--track] [--top 25] [--by range|bearing] [--missed]

Replays ``SET_DIR`` (a folder written by ``rangebearing synth``) through the pipeline, matches every
reading to its truth as ``replay --truth`` does, prints the range and bearing error summary and the
``--top`` readings sorted by their range (or bearing) error, with the reading's sigma, visible share,
box and the truth's visible shares. Signed errors: range positive = read too long, bearing positive
= read too far left. ``--missed`` lists instead the findable landmarks no reading matched, with their
truth (range, bearing, visible shares).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from typing import List, Optional, Sequence

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from rangebearing import Pipeline, load_config
from rangebearing.cli.common import aligned_truth
from rangebearing.evaluation.match import Match, accuracy
from rangebearing.sources.recorded import iter_recorded


def signed(m: Match) -> tuple:
    """(range error %, range error / sigma, bearing error deg, bearing error / sigma), signed."""
    f, t = m.found, m.truth
    dr = f.range_m - t.range_m
    db = f.bearing_rad - t.bearing_rad
    return (100 * dr / t.range_m, dr / max(f.range_sigma_m, 1e-9), math.degrees(db),
            db / max(f.bearing_sigma_rad, 1e-12))


def _missed(matches: Sequence[Match]) -> int:
    lost = [m for m in matches if m.found is None and m.truth.findable is not False]
    print(f"{len(lost)} findable landmarks missed")
    print("frame        range_m  bear_deg | tvis  rvis  bvis")
    for m in lost:
        t = m.truth
        print(f"{m.frame:12s} {t.range_m:6.3f} {math.degrees(t.bearing_rad):+8.2f} | {t.visible or float('nan'):.2f} "
              f"{t.red_visible or float('nan'):.2f} {t.blue_visible or float('nan'):.2f}")
    return 0


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("folder")
    p.add_argument("--config", required=True)
    p.add_argument("--track", action="store_true")
    p.add_argument("--top", type=int, default=25)
    p.add_argument("--by", choices=("range", "bearing"), default="range")
    p.add_argument("--missed", action="store_true", help="list the findable landmarks not found")
    args = p.parse_args(argv)
    truth = aligned_truth(args.folder, os.path.join(args.folder, "truth.csv"))
    pipe = Pipeline(load_config(args.config).pipeline, track=args.track)
    evaluated = [(n, pipe.process(img).landmarks, truth.get(n, [])) for n, img in iter_recorded(args.folder)]
    rep, matches = accuracy(evaluated)
    hits: List[Match] = [m for m in matches if m.found is not None]
    s = np.array([signed(m) for m in hits]) if hits else np.zeros((0, 4))
    print(f"{args.folder}: {len(hits)} readings, found {100 * rep.findable_rate:.1f} %, false {rep.false_landmarks}")
    if args.missed:
        return _missed(matches)
    if not hits:
        return 0
    print(f"range err mean/p95 {rep.range_err_pct_mean:.2f}/{rep.range_err_pct_p95:.2f} %, "
          f"signed mean {s[:, 0].mean():+.2f} %; bearing mean/p95 {rep.bearing_err_deg_mean:.3f}/"
          f"{rep.bearing_err_deg_p95:.3f} deg, signed mean {s[:, 2].mean():+.3f}; "
          f"2-sigma cover {100 * rep.range_cover:.1f}/{100 * rep.bearing_cover:.1f} %")
    key = 0 if args.by == "range" else 2
    order = np.argsort(-np.abs(s[:, key]))[: args.top]
    print("frame        range_m  bear_deg | dr%    dr/sig | db_deg  db/sig | vis  tvis  rvis  bvis | bbox")
    for i in order:
        m = hits[i]
        f, t = m.found, m.truth
        print(f"{m.frame:12s} {t.range_m:6.3f} {math.degrees(t.bearing_rad):+8.2f} | {s[i, 0]:+6.2f} {s[i, 1]:+6.1f} | "
              f"{s[i, 2]:+6.3f} {s[i, 3]:+6.1f} | {f.visible:.2f} {t.visible or float('nan'):.2f} "
              f"{t.red_visible or float('nan'):.2f} {t.blue_visible or float('nan'):.2f} | {getattr(f, 'bbox_px', '')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
