"""List every false reading of replayed sets, and every real landmark a full scan's checks dropped.

Usage::

    python benchmarks/false_readings.py SET_DIR [SET_DIR ...] --config cal.yaml [--track] [--misses]

Replays each ``SET_DIR`` (a folder written by ``rangebearing synth``) through the pipeline and
matches its readings to the truth as ``replay --truth`` does. For every reading no truth matches
(a false landmark) it prints the frame, whether it came from a full scan (S) or a tracked frame
(T), its range, bearing, band spacing, box, the candidate's flags (``Rm``/``Bm`` band merged,
``cL``/``cR`` cut side, ``wh`` the white height the structure search found) and the nearest truth
landmark by bearing. ``DROPPED`` lines name the real landmarks (missed, within 3 deg and half the
range of a candidate) that verification (:mod:`rangebearing.core.verify`) or
:func:`rangebearing.core.stacked.drop_stacked` rejected, with the reason; ``--misses`` also lists
every findable landmark missed. The last line per set counts frames, false readings (and those
on frames without a landmark) and real landmarks dropped.
"""

from __future__ import annotations

import argparse
import math
import os
from typing import Dict, List, Optional, Sequence

os.environ.setdefault("OMP_NUM_THREADS", "1")

from rangebearing import Pipeline, load_config
from rangebearing.cli.common import aligned_truth
from rangebearing.core import pipeline as pipeline_module
from rangebearing.core import verify
from rangebearing.core.detect import BandCentroids
from rangebearing.evaluation.match import match_frame
from rangebearing.evaluation.truth import TruthRow
from rangebearing.sources.recorded import iter_recorded


class Recorder:
    """Wraps the pipeline's ``verified`` and ``drop_stacked`` to keep each full scan's candidates and verdicts."""

    def __init__(self) -> None:
        self.stage: Dict[str, list] = {}
        self._verified, self._stacked = pipeline_module.verified, pipeline_module.drop_stacked
        pipeline_module.verified, pipeline_module.drop_stacked = self.verified, self.drop_stacked

    def verified(self, bgr, found, geometry, model=None, cam=None):  # the pipeline calls it so
        self.stage["refined"] = list(found)
        judge = getattr(verify, "verdicts", None)  # older checkouts (PYTHONPATH): each against all the others
        self.stage["reasons"] = (judge(bgr, found, geometry, model, cam) if judge is not None else
                                 [verify.rejection(bgr, c, geometry, model, cam, found) for c in found])
        return self._verified(bgr, found, geometry, model, cam)

    def drop_stacked(self, found, **kw):
        out = self._stacked(found, **kw)
        self.stage["stacked"] = [c for c in found if c not in out]
        return out


def flags(c: BandCentroids) -> str:
    cd = c.candidate
    if cd is None:
        return ""
    named = (("Rm", cd.red_merged), ("Bm", cd.blue_merged), ("cL", cd.cut_left), ("cR", cd.cut_right),
             ("body", cd.body_cols_px is not None))
    return "".join(k for k, v in named if v) + f" wh{cd.white_px:.1f}"


def nearest(bearing_rad: float, rows: Sequence[TruthRow]) -> str:
    if not rows:
        return "no landmark in the frame"
    t = min(rows, key=lambda t: abs(t.bearing_rad - bearing_rad))
    return (f"nearest truth r={t.range_m:.2f} b={math.degrees(t.bearing_rad):+.1f} vis={t.visible} "
            f"red/blue vis={t.red_visible}/{t.blue_visible}")


def box(b: Sequence[float]) -> str:
    return "(" + ",".join(f"{v:.0f}" for v in b) + ")"


def replay(folder: str, config: str, track: bool, misses: bool, rec: Recorder) -> List[int]:
    """Print one set's false readings and dropped landmarks.

    Returns [frames, false, false on frames without a landmark, dropped, findable, found].
    """
    truth = aligned_truth(folder, os.path.join(folder, "truth.csv"))
    pipe = Pipeline(load_config(config).pipeline, track=track)
    counts = [0, 0, 0, 0, 0, 0]
    for name, img in iter_recorded(folder):
        counts[0] += 1
        rec.stage.clear()
        res = pipe.process(img)
        rows = truth.get(name, [])
        matches, false = match_frame(name, res.landmarks, rows)
        for f in false:
            counts[1] += 1
            counts[2] += not rows
            cand: Optional[BandCentroids] = next(
                (c for c in rec.stage.get("refined", []) if tuple(c.bbox_px) == tuple(f.bbox_px)), None)
            print(f"FALSE {folder} {name} {'T' if res.tracked else 'S'} r={f.range_m:.2f} "
                  f"b={math.degrees(f.bearing_rad):+.1f} L={f.l_px:.1f} w={f.width_px:.1f} vis={f.visible:.2f} "
                  f"bbox={box(f.bbox_px)} {flags(cand) if cand else ''} | {nearest(f.bearing_rad, rows)}")
        missed = [m.truth for m in matches if m.found is None and m.truth.findable is not False]
        findable = [m for m in matches if m.truth.findable is not False]
        counts[4] += len(findable)
        counts[5] += sum(m.found is not None for m in findable)
        for c, why in zip(rec.stage.get("refined", []), rec.stage.get("reasons", [])):
            if why is None and c not in rec.stage.get("stacked", []):
                continue
            x = 0.5 * (c.red_xy_px[0] + c.blue_xy_px[0])
            r = pipe._reading(c, pipe._camera(img.shape[1], img.shape[0])[0], img)
            for t in missed:
                if abs(r[1] - t.bearing_rad) < math.radians(3) and abs(r[0] - t.range_m) < 0.5 * t.range_m:
                    counts[3] += 1
                    print(f"DROPPED {folder} {name} x={x:.0f} r={r[0]:.2f} bbox={box(c.bbox_px)} {flags(c)} | "
                          f"truth r={t.range_m:.2f} b={math.degrees(t.bearing_rad):+.1f} vis={t.visible} | "
                          f"{why or 'inside or under another landmark (drop_stacked)'}")
        if misses:
            for t in missed:
                print(f"MISS {folder} {name} truth r={t.range_m:.2f} b={math.degrees(t.bearing_rad):+.1f} "
                      f"vis={t.visible} red/blue vis={t.red_visible}/{t.blue_visible}")
    print(f"SET {folder}: frames {counts[0]} false {counts[1]} (on frames without a landmark {counts[2]}) "
          f"real landmarks dropped by the checks {counts[3]}; found {counts[5]} of {counts[4]} findable")
    return counts


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("folders", nargs="+")
    p.add_argument("--config", required=True)
    p.add_argument("--track", action="store_true")
    p.add_argument("--misses", action="store_true", help="also list every findable landmark missed")
    args = p.parse_args(argv)
    rec = Recorder()
    total = [0] * 6
    for folder in args.folders:
        total = [a + b for a, b in zip(total, replay(folder, args.config, args.track, args.misses, rec))]
    if len(args.folders) > 1:
        print(f"ALL: frames {total[0]} false {total[1]} (on empty {total[2]}) dropped {total[3]}; "
              f"found {total[5]} of {total[4]} findable")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
