"""``rangebearing calibrate``: fit the range model to frames with known range and bearing."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from ..config import dump_config
from ..core.fit import Fit
from ..errors import OutputError
from ..evaluation.calibrate import calibrate
from ..evaluation.truth import read_truth
from ..sources.recorded import count_recorded, iter_recorded
from .common import add_config_arg, config_from_args, progress


def register(sub: Any) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit the range model to frames with known range and bearing",
        description="Detect landmarks in frames whose true range and bearing are known, fit the "
        "model (config model.kind: pinhole or paper) and write a complete config that --config accepts.",
    )
    p.add_argument("path", help="directory of images or a video file")
    p.add_argument("--truth", required=True, metavar="FILE", help="CSV frame,range_m,bearing_rad")
    p.add_argument("--out", required=True, metavar="FILE", help="where to write the calibrated config (YAML)")
    add_config_arg(p)
    p.add_argument("--plot", metavar="FILE.png", help="plot measured against true range and the residuals")
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
        raise OutputError("--plot needs matplotlib: pip install 'rangebearing[plot]'") from None
    true = [r.range_m for r in fit.residuals]
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    a.plot(true, [r.fitted_range_m for r in fit.residuals], "o", ms=3)
    a.plot([min(true), max(true)], [min(true), max(true)], "k--", lw=1)
    a.set(xlabel="true range (m)", ylabel="measured range (m)", title=f"{fit.model.kind} model")
    b.plot(true, [r.range_err_pct for r in fit.residuals], "o", ms=3)
    b.axhline(0, color="k", lw=1)
    b.set(xlabel="true range (m)", ylabel="range residual (%)", title="residuals")
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=100)
    except OSError as exc:
        raise OutputError(f"--plot: cannot write {path}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    truth = read_truth(args.truth)
    path = Path(args.path)
    frames = ((name, image, truth.get(name, [])) for name, image in iter_recorded(path))
    new_cfg, fit = calibrate(progress(frames, count_recorded(path), "calibrate"), cfg)
    print_fit(fit)
    out = Path(args.out)
    header = f"# rangebearing config written by 'rangebearing calibrate' from {args.path}\n"
    try:
        out.write_text(header + dump_config(new_cfg), encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"--out: cannot write {out}: {exc.strerror or exc}") from None
    print(f"wrote {out}", file=sys.stderr)
    if args.plot:
        plot_fit(fit, args.plot)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0
