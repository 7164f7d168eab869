"""Do two trees give the same readings? Dump every reading of some recorded sets, then compare two dumps.

Usage::

    # the old tree (any checkout) and this one, on the same sets and config
    PYTHONPATH=<old checkout>/src python benchmarks/same_readings.py dump old.pkl --config cal.yaml SET_DIR...
    python benchmarks/same_readings.py dump new.pkl --config cal.yaml SET_DIR...
    python benchmarks/same_readings.py compare old.pkl new.pkl [--rel 1e-9] [--loose range_sigma_m=1e-5]

``dump`` replays each set directory (``rangebearing synth`` output: numbered PNG or
JPEG frames) through ``Pipeline.process`` as full scans of independent frames; a
set whose name holds ``moving`` is replayed as a sequence with tracking on (and
once more as full scans); ``--yuv`` adds a replay that searches the frames'
YUV420 image (``yuv420_from_bgr``), as the camera's lores stream would feed it.
Every field of every reading is kept, frame by frame.

``compare`` prints the first differing frames and exits 1 on any difference:
bit for bit by default, or within ``--rel`` relative for a change of arithmetic
order (NaN equals NaN; ids, flags and counts must match exactly).
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import pickle
import sys

os.environ.setdefault("OMP_NUM_THREADS", "1")


def dump(out: str, config: str, sets: list, yuv: bool) -> int:
    import cv2

    from rangebearing import Pipeline, load_config
    from rangebearing.core.yuv import yuv420_from_bgr

    cv2.setNumThreads(1)
    cfg = load_config(config)
    res = {}
    for d in sets:
        name = os.path.basename(os.path.normpath(d))
        files = sorted(glob.glob(os.path.join(d, "*.png")) + glob.glob(os.path.join(d, "*.jpg")))
        modes = ["track", "full"] if "moving" in name else ["full"]
        if yuv:
            modes.append("yuv")
        for mode in modes:
            pipe = Pipeline(cfg.pipeline, track=mode == "track")
            rows = []
            for i, f in enumerate(files):
                img = cv2.imread(f)
                r = pipe.process(img, t_s=i / 30, search=yuv420_from_bgr(img) if mode == "yuv" else None)
                rows.append((r.tracked, [tuple(getattr(lm, k) for k in lm.__dataclass_fields__) for lm in r.landmarks]))
            res[(name, mode)] = rows
            print(f"{name} {mode}: {len(files)} frames, {sum(len(r[1]) for r in rows)} readings", flush=True)
    with open(out, "wb") as fh:
        pickle.dump(res, fh)
    return 0


def _close(x: object, y: object, rel: float) -> bool:
    if isinstance(x, float) and isinstance(y, float):
        if math.isnan(x) or math.isnan(y):
            return math.isnan(x) and math.isnan(y)
        return x == y or abs(x - y) <= rel * max(abs(x), abs(y))
    if isinstance(x, (tuple, list)) and isinstance(y, (tuple, list)):
        return len(x) == len(y) and all(_close(p, q, rel) for p, q in zip(x, y))
    return x == y


def _close_reading(x: tuple, y: tuple, rel: float, loose: dict) -> bool:
    """Two readings (Landmark fields in order) alike; a field index in ``loose`` within its own tolerance."""
    return len(x) == len(y) and all(_close(p, q, loose.get(k, rel)) for k, (p, q) in enumerate(zip(x, y)))


def _close_frame(fa: tuple, fb: tuple, rel: float, loose: dict) -> bool:
    if not loose:
        return _close(fa, fb, rel)
    return fa[0] == fb[0] and len(fa[1]) == len(fb[1]) and all(
        _close_reading(x, y, rel, loose) for x, y in zip(fa[1], fb[1]))


def compare(a_path: str, b_path: str, rel: float, loose: dict | None = None) -> int:
    """``loose``: Landmark field name → its own relative tolerance (the others bit for bit or ``rel``)."""
    from rangebearing import Landmark

    names = list(Landmark.__dataclass_fields__)
    unknown = sorted(set(loose or {}) - set(names))
    if unknown:
        print(f"no such Landmark field: {', '.join(unknown)}")
        return 2
    loose = {names.index(k): v for k, v in (loose or {}).items()}
    with open(a_path, "rb") as fh:
        a = pickle.load(fh)
    with open(b_path, "rb") as fh:
        b = pickle.load(fh)
    bad = readings = 0
    for key, frames in a.items():
        if key not in b:
            print("only in the first dump:", key)
            bad += 1
            continue
        if len(frames) != len(b[key]):
            print(f"{key}: {len(frames)} vs {len(b[key])} frames")
            bad += 1
        for i, (fa, fb) in enumerate(zip(frames, b[key])):
            readings += len(fa[1])
            if not _close_frame(fa, fb, rel, loose):
                bad += 1
                if bad <= 10:
                    print(f"DIFF {key} frame {i}\n  {fa}\n  {fb}")
    print(f"{len(a)} replays, {readings} readings, {bad} differing frames")
    return 1 if bad else 0


def main(argv: list | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump", help="replay sets, keep every reading")
    d.add_argument("out")
    d.add_argument("sets", nargs="+", help="set directories (synth output)")
    d.add_argument("--config", default=None, help="config file (e.g. a calibrated one); default: the defaults")
    d.add_argument("--yuv", action="store_true", help="also replay each set through the YUV420 search path")
    c = sub.add_parser("compare", help="compare two dumps")
    c.add_argument("a")
    c.add_argument("b")
    c.add_argument("--rel", type=float, default=0.0, help="relative tolerance for floats (default 0: bit for bit)")
    c.add_argument("--loose", action="append", default=[], metavar="FIELD=REL",
                   help="a Landmark field with its own relative tolerance (repeatable), e.g. range_sigma_m=1e-5")
    args = p.parse_args(argv)
    if args.cmd == "dump":
        return dump(args.out, args.config, args.sets, args.yuv)
    loose = {}
    for item in args.loose:
        name, _, value = item.partition("=")
        try:
            loose[name] = float(value)
        except ValueError:
            p.error(f"--loose takes FIELD=REL, not {item!r}")
    return compare(args.a, args.b, args.rel, loose)


if __name__ == "__main__":
    sys.exit(main())
