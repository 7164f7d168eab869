"""``rangebearing calibrate --guided``: the operator's session around :mod:`rangebearing.guided`."""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import sys
from pathlib import Path

from ..config import Config, check
from ..core.stations import default_plan, parse_plan
from ..errors import CalibrationError
from ..evaluation.guided import TRUTH_FILE, run_guided
from ..sources.factory import open_source
from .common import source_from_args

MIN_STATIONS = 4


def _say(text: str) -> None:
    print(text, flush=True)


def run_guided_cmd(args: argparse.Namespace, cfg: Config) -> int:
    """Ask, check and record every station, then fit the recording like ``calibrate DIR --truth``."""
    if args.path or args.truth:
        raise CalibrationError("--guided records its own frames and truth: give no PATH or --truth")
    if args.frames_per_station < 1:
        raise CalibrationError("--frames-per-station must be at least 1")
    src_cfg = source_from_args(args, cfg.source) or cfg.source
    cfg = dataclasses.replace(cfg, source=src_cfg)
    check(cfg)
    if args.plan:
        try:
            text = Path(args.plan).read_text(encoding="utf-8")
        except OSError as exc:
            raise CalibrationError(f"cannot read --plan {args.plan}: {exc.strerror or exc}") from None
        plan = parse_plan(text, args.plan)
    else:
        plan = default_plan(cfg.camera.hfov_rad)
    out = Path(args.out)
    record = Path(args.record) if args.record else out.with_name(out.stem + "-recording")
    _say(f"guided calibration: {len(plan)} stations, {args.frames_per_station} frames each, recorded in {record}")
    _say("measure range to the landmark's axis (its centre) from the camera's lens, on the floor")
    source = open_source(src_cfg, cfg.camera)
    try:
        results = run_guided(source, cfg, plan, record, input, _say, args.frames_per_station)
    except KeyboardInterrupt:
        print(f"\ninterrupted: the stations done so far are in {record} ({TRUTH_FILE} lists them); fit them with "
              f"'rangebearing calibrate {record} --truth {record / TRUTH_FILE} --out {out}'", file=sys.stderr)
        return 130
    finally:
        source.close()
    done = [r for r in results if r.frames]
    _say(f"{len(done)} of {len(plan)} stations recorded, {sum(len(r.frames) for r in done)} frames")
    if len(done) < MIN_STATIONS:
        raise CalibrationError(
            f"{len(done)} station(s) recorded, at least {MIN_STATIONS} are needed to fit; the recording in {record} "
            f"is kept: add stations with another session (--record elsewhere) or fit it by hand"
        )
    if not args.plot and importlib.util.find_spec("matplotlib") is not None:
        args.plot = str(record / "fit.png")
    from .calibrate_cmd import fit_and_write

    return fit_and_write(args, cfg, record, record / TRUTH_FILE, f"a guided session recorded in {record}")
