"""``rangebearing calibrate``: fit the range model to frames with known range and bearing (or guide a session)."""

from __future__ import annotations

import argparse
import io
import logging
import math
import sys
from pathlib import Path
from typing import Any

from ..config import Config
from ..core.fit import Fit
from ..core.focal_check import FocalCheck
from ..errors import CalibrationError, OutputError, RangeBearingError
from ..evaluation.calibrate import calibrate_checked
from ..sources.recorded import count_recorded, iter_recorded
from .common import (
    add_config_arg,
    add_quiet_arg,
    add_source_args,
    aligned_truth,
    config_from_args,
    progress,
    quiet_or_auto,
    save_config,
)
from .outputs import check_output_file, write_bytes_atomic

STRICT_EXIT = 3  # the config is written, but the bearings say the intrinsics are wrong


def register(sub: Any) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit the range model to frames with known range and bearing",
        description="Detect landmarks in frames whose true range and bearing are known, fit the "
        "model (config model.kind: pinhole or paper), check the focal length against the bearings "
        "and write a complete config that --config accepts. With --guided, ask for the stations one "
        "by one, check and record each live from --source, then fit.",
    )
    p.add_argument("path", nargs="?", help="directory of images or a video file (not with --guided)")
    p.add_argument("--truth", metavar="FILE", help="CSV frame,range_m,bearing_rad (required without --guided)")
    p.add_argument("--out", required=True, metavar="FILE", help="where to write the calibrated config (YAML)")
    add_config_arg(p)
    p.add_argument("--plot", metavar="FILE.png", help="plot measured against true range and the residuals")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an existing --out or --plot (the old --out is kept as FILE.bak); "
                        "never the frames or the truth")
    p.add_argument("--strict", action="store_true",
                   help=f"exit {STRICT_EXIT} when the bearings say the intrinsics are wrong (the config is written)")
    p.add_argument("--fit-focal", action="store_true",
                   help="when the bearings say the focal length is wrong, fit fx (fy by the same factor) and cx "
                   "from them and refit the range model with that camera")
    g = p.add_argument_group("guided calibration")
    g.add_argument("--guided", action="store_true", help="ask for stations one by one and record them live")
    g.add_argument("--plan", metavar="FILE", help="stations as CSV range_m,bearing_deg[,name] (+ left); "
                   "default: 0.2-1.4 m straight ahead and across the field of view")
    g.add_argument("--frames-per-station", type=int, default=5, metavar="N", help="frames per station (default 5)")
    g.add_argument("--record", metavar="DIR", help="where to keep the frames and truth (default: OUT-recording/)")
    add_source_args(p)
    add_quiet_arg(p)
    p.set_defaults(func=run)


def print_fit(fit: Fit) -> None:
    m = fit.model
    if m.kind == "paper":
        print(f"model paper: d_v = {m.k_px_m * 100:.1f} px·cm / L,  d_h = {m.kh_m_per_px * 100:.5f} cm/px · px")
    else:
        print(f"model pinhole: range = f·{m.spacing_m * 1000:.2f} mm / (L·cos θ) + {m.c_m * 1000:.2f} mm")
    print(f"{'frame':>16} {'true m':>8} {'fit m':>8} {'err %':>7} {'true °':>8} {'err °':>7}")
    for r in fit.residuals:
        print(
            f"{r.frame:>16} {r.range_m:8.4f} {r.fitted_range_m:8.4f} {r.range_err_pct:+7.2f} "
            f"{math.degrees(r.bearing_rad):+8.2f} {r.bearing_err_deg:+7.3f}"
        )
    print(
        f"fit over {len(fit.residuals)} landmarks: range error mean {fit.range_err_pct_mean:.2f} % "
        f"(max {fit.range_err_pct_max:.2f} %), bearing error mean {fit.bearing_err_deg_mean:.3f}°"
    )
    (r0, r1), (b0, b1) = m.envelope_range_m, m.envelope_bearing_rad
    print(f"envelope: range {r0:.3f}–{r1:.3f} m, bearing {math.degrees(b0):+.1f}° to {math.degrees(b1):+.1f}°")


def plot_fit(fit: Fit, path: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise RangeBearingError("--plot needs matplotlib: pip install 'rangebearing[plot]'") from None
    true = [r.range_m for r in fit.residuals]
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    a.plot(true, [r.fitted_range_m for r in fit.residuals], "o", ms=3)
    a.plot([min(true), max(true)], [min(true), max(true)], "k--", lw=1)
    a.set(xlabel="true range (m)", ylabel="measured range (m)", title=f"{fit.model.kind} model")
    b.plot(true, [r.range_err_pct for r in fit.residuals], "o", ms=3)
    b.axhline(0, color="k", lw=1)
    b.set(xlabel="true range (m)", ylabel="range residual (%)", title="residuals")
    fig.tight_layout()
    image = io.BytesIO()
    fig.savefig(image, dpi=100, format=_plot_format(path))
    plt.close(fig)
    write_bytes_atomic(path, image.getvalue())  # a full disk: OutputError naming it, no half-written plot


def _plot_format(path: str) -> str:
    """The image format a --plot path asks for by its suffix (png without one)."""
    return Path(path).suffix[1:].lower() or "png"


def report_focal(check: FocalCheck, refitted: bool, cfg: Config) -> None:
    if check.suspect:
        bar = "!" * 72
        print(f"{bar}\nWARNING: {check.message}\n{bar}", file=sys.stderr)
        if refitted:
            c = cfg.camera
            print(f"--fit-focal: camera set to fx_px {c.fx_px:.1f}, fy_px {c.fy_px:.1f}, cx_px {c.cx_px:.1f} "
                  "and the range model refitted with it", file=sys.stderr)
    else:
        print(check.message)


def fit_and_write(args: argparse.Namespace, cfg: Config, frames_dir: Path, truth_path: Path, source_note: str) -> int:
    truth = aligned_truth(frames_dir, truth_path)

    def frames() -> Any:
        items = ((name, image, truth.get(name, [])) for name, image in iter_recorded(frames_dir))
        return progress(items, count_recorded(frames_dir), "calibrate", quiet_or_auto(args))

    try:
        new_cfg, fit, check, refitted = calibrate_checked(frames, cfg, fit_focal=args.fit_focal)
    except KeyboardInterrupt:
        print("\ninterrupted: nothing fitted, nothing written", file=sys.stderr)
        return 130
    print_fit(fit)
    report_focal(check, refitted, new_cfg)
    note = "camera fx, fy, cx refitted from the bearings (--fit-focal)" if refitted else check.message
    save_config(new_cfg, args.out, f"rangebearing config written by 'rangebearing calibrate' from {source_note}\n"
                f"bearing check: {note}")
    if args.plot:
        plot_fit(fit, args.plot)
        print(f"wrote {args.plot}", file=sys.stderr)
    return STRICT_EXIT if args.strict and check.suspect and not refitted else 0


def _check_outputs(args: argparse.Namespace) -> None:
    """Fail now, not after the fit: --out and --plot writable, not inputs, matplotlib there for --plot."""
    inputs = (args.path, args.truth, getattr(args, "plan", None), getattr(args, "record", None))
    check_output_file(args.out, "--out", inputs, args.overwrite)
    if args.plot:
        check_output_file(args.plot, "--plot", (*inputs, args.out), args.overwrite)
        logging.getLogger("matplotlib").setLevel(logging.ERROR)  # no font-cache chatter in the output
        try:
            from matplotlib.backend_bases import FigureCanvasBase
        except ImportError:
            raise RangeBearingError("--plot needs matplotlib: pip install 'rangebearing[plot]'") from None
        formats = FigureCanvasBase.get_supported_filetypes()
        if _plot_format(args.plot) not in formats:
            raise OutputError(f"--plot: matplotlib cannot write {args.plot} (.{_plot_format(args.plot)}); "
                              f"name it .png or one of {', '.join(sorted(formats))}")


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    _check_outputs(args)
    if args.guided:
        from .guided import run_guided_cmd  # only the guided session needs a live source

        return run_guided_cmd(args, cfg)
    if not args.path or not args.truth:
        raise CalibrationError("give the frames PATH and --truth FILE, or --guided with a --source")
    return fit_and_write(args, cfg, Path(args.path), Path(args.truth), args.path)
