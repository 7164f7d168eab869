"""The daemon as the robot runs it: ``rangebearing run`` in a subprocess, paced, publishing over loopback UDP.

The recording (PNG frames, looped; the recorded source keeps decoded frames
for looping, as a camera hands over decoded buffers) is paced at the asked
frame rate. A listener on 127.0.0.1 stamps every datagram on arrival. From
``/proc/<pid>``: CPU time (every thread's schedstat) over a window that
starts once frames flow, RSS (VmRSS) and its peak (VmHWM). Latency is the
datagram's arrival minus its ``t`` (the frame's capture time on the wall
clock), so it covers capture → process → send → receive. Start-up is from
``Popen`` to the first datagram (with the package's bytecode compiled
beforehand, as pip does at install, and the CPU time spent by then beside it); the window opens after one whole loop of
the recording (the decoding of the PNGs stays out of it). The subprocess inherits the benchmark's
one-core affinity.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import List, Sequence, Tuple

import cv2
import numpy as np

from rangebearing import Config
from rangebearing._compat import frozen
from rangebearing.config import PublishConfig, SourceConfig, dump_config
from rangebearing.daemon.loop import AUTO_SCAN_AFTER_SEND_FPS

SETTLE_S = 0.5  # after the first loop of the recording (decoding it), before the CPU window opens


@frozen
class DaemonFigures:
    """One paced run of the daemon subprocess."""

    fps_asked: float
    duration_s: float
    startup_s: float  # Popen → first datagram
    frames_expected: int  # in the measuring window
    received: int  # datagrams in the window
    dropped: int  # the daemon's own count ("dropped" in the datagrams), over the window
    seq_gaps: int  # frames missing between consecutive seq numbers (lost datagrams)
    cpu_pct: float  # of one core, over the window
    cpu_ms_per_frame: float
    latency_ms_p50: float  # capture -> send: the datagram's kernel stamp (SO_TIMESTAMPNS) minus its t
    latency_ms_p99: float
    latency_ms_max: float
    rss_mib: float
    rss_peak_mib: float
    exit_code: int
    error: str = ""
    startup_cpu_s: float = float("nan")  # CPU time of the daemon (all threads) when its first datagram arrived
    pipeline_cpu_ms: float = float("nan")  # the daemon's own figure: the pipeline's CPU per frame (its final log line)
    tracked_pct: float = float("nan")  # frames the pipeline tracked rather than scanned whole
    bytecode: bool = True  # the package's modules were compiled beforehand, as an installed package's are
    restart: bool = True  # a start after a first one with the same config (the package's cache filled)
    received_ms_p99: float = float("nan")  # capture -> the listener's thread (its own wait for a core included)
    kernel_stamped: bool = False  # latency is capture -> send (else capture -> received)
    clip_mib: float = float("nan")  # the recorded clip decoded (frames and their YUV420): in the page cache, not RSS


def _command() -> List[str]:
    script = Path(sys.executable).with_name("rangebearing")
    if script.exists():
        return [str(script)]
    exe = shutil.which("rangebearing")
    if exe:
        return [exe]
    return [sys.executable, "-c", "import sys; from rangebearing.cli.main import main; sys.exit(main())"]


def _cpu_s(pid: int) -> float:
    """CPU time of a process, all its threads, seconds.

    The sum of each thread's ``schedstat`` run time (nanoseconds); threads that
    ended are lost from it, so the window's threads must live through it (the
    daemon's do). Falls back to utime + stime (clock ticks) without schedstat.
    """
    total, found = 0, False
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            total += int((task / "schedstat").read_text().split()[0])
            found = True
        except (OSError, ValueError, IndexError):
            continue
    if found:
        return total / 1e9
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _status_kib(pid: int, key: str) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return float(line.split()[1])
    return float("nan")


SO_TIMESTAMPNS = 35  # Linux (asm-generic, x86, arm): the kernel stamps each datagram as it is queued (ns)


def _kernel_stamp(ancdata: Sequence[Tuple[int, int, bytes]]) -> float:
    """The ``SCM_TIMESTAMPNS`` of a ``recvmsg`` (wall clock, s), or NaN where the kernel gave none."""
    for level, kind, data in ancdata:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(data) in (8, 16):
            sec, ns = struct.unpack("qq" if len(data) == 16 else "ii", data)
            return sec + ns / 1e9
    return float("nan")


class Listener:
    """Receives datagrams on 127.0.0.1, keeping (arrival wall time, arrival monotonic s, sent wall time, message).

    The sent time is the kernel's stamp of the datagram (``SO_TIMESTAMPNS``): on loopback it is taken in
    the daemon's own ``send`` call, so latency measured with it is capture → send, whatever this
    listener's thread waits for a core (pinned beside the daemon it waits for the daemon's work after the
    send: the full scan, the next frame). NaN where the kernel does not stamp (the arrival is used then).
    """

    def __init__(self) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.2)
        with contextlib.suppress(OSError):  # no stamps: latency is then as received
            self.sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        self.port = self.sock.getsockname()[1]
        self.got: List[Tuple[float, float, float, dict]] = []
        self.first = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                data, ancdata, _, _ = self.sock.recvmsg(65536, socket.CMSG_SPACE(16))
            except OSError:
                continue
            now, mono = time.time(), time.perf_counter()
            try:
                self.got.append((now, mono, _kernel_stamp(ancdata), json.loads(data)))
            except ValueError:
                continue
            self.first.set()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.sock.close()


def _compile_package() -> None:
    """Compile rangebearing's modules into their ``__pycache__`` (git ignores it), as pip does at install.

    An editable checkout run with PYTHONDONTWRITEBYTECODE (as here) would
    otherwise compile every module from source at each start, ~100 ms a robot
    never pays; the daemon still reads bytecode that exists. (Not
    PYTHONPYCACHEPREFIX: that moves the whole standard library's bytecode too.)
    """
    import rangebearing

    package = Path(rangebearing.__file__).resolve().parent
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(package)], check=True, stdout=subprocess.DEVNULL)


_SUMMARY = re.compile(r"stopped: .*pipeline CPU ([0-9.]+) ms/frame \(([0-9.]+) % tracked\)")


def daemon_run(cfg: Config, frames: Sequence[np.ndarray], fps: float, duration_s: float,
               bytecode: bool = True, restart: bool = True) -> DaemonFigures:
    """Run ``rangebearing run`` on ``frames`` (PNG, looped) paced at ``fps``; measure it from outside.

    ``bytecode``: compile the package's modules beforehand (as installed); False leaves
    them as they are (an editable checkout under PYTHONDONTWRITEBYTECODE compiles them at each start).
    ``restart``: the start of a robot's daemon after its first, with the same config (a reboot, a
    systemd restart): ``run --check`` on the config beforehand fills the package's cache (the parsed
    config, the dataclass methods' code) as that first start did; False turns the cache off.
    """
    with tempfile.TemporaryDirectory(prefix="rb-bench-") as tmp:
        clip = Path(tmp) / "clip"
        clip.mkdir()
        for i, frame in enumerate(frames):
            cv2.imwrite(str(clip / f"{i:06d}.png"), frame)
        listener = Listener()
        run_cfg = dataclasses.replace(
            cfg,
            source=SourceConfig(kind="recorded", path=str(clip), fps=fps, loop=True),
            publish=PublishConfig(robot_id="bench", unicast=(("127.0.0.1", listener.port),)),
        )
        conf = Path(tmp) / "bench.yaml"
        conf.write_text(dump_config(run_cfg), encoding="utf-8")
        log = open(Path(tmp) / "daemon.log", "w+", encoding="utf-8")  # noqa: SIM115 - read back below
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        env.pop("NOTIFY_SOCKET", None)
        if bytecode:
            _compile_package()
        if restart:
            subprocess.run([*_command(), "run", "--check", "--config", str(conf)], env=env, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        else:
            env["RANGEBEARING_CACHE"] = "off"
        t0 = time.perf_counter()
        proc = subprocess.Popen([*_command(), "run", "--config", str(conf)], stdout=log, stderr=log, env=env)
        error, code = "", -1
        try:
            if not listener.first.wait(30.0):
                raise RuntimeError("no datagram within 30 s")
            startup_cpu = _cpu_s(proc.pid)
            startup = listener.got[0][1] - t0
            # the first loop decodes the PNGs (a camera hands over decoded buffers): keep it out of the window
            time.sleep(len(frames) / fps + SETTLE_S)
            c0, w0, n0 = _cpu_s(proc.pid), time.perf_counter(), len(listener.got)
            time.sleep(duration_s)
            c1, w1, n1 = _cpu_s(proc.pid), time.perf_counter(), len(listener.got)
            rss, hwm = _status_kib(proc.pid, "VmRSS"), _status_kib(proc.pid, "VmHWM")
        except (RuntimeError, OSError) as exc:
            error = str(exc)
        finally:
            proc.send_signal(signal.SIGTERM)
            try:
                code = proc.wait(timeout=10.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                code = proc.wait()
            listener.close()
            log.seek(0)
            tail = log.read()[-2000:]
            log.close()
        if error:
            return DaemonFigures(fps, duration_s, float("nan"), 0, 0, 0, 0, *([float("nan")] * 8), code,
                                 f"{error}; log: {tail}", bytecode=bytecode, restart=restart)
    summary = _SUMMARY.search(tail)
    window = listener.got[n0:n1]
    # capture -> send by the kernel's stamp (capture -> this listener's thread where there is none)
    lat = np.array([((arr if sent != sent else sent) - msg["t"]) * 1e3 for arr, _, sent, msg in window]
                   if window else [np.nan])
    received = np.array([(arr - msg["t"]) * 1e3 for arr, _, _, msg in window] if window else [np.nan])
    seqs = [msg["seq"] for _, _, _, msg in listener.got]
    gaps = sum(max(0, b - a - 1) for a, b in zip(seqs, seqs[1:]))
    cpu = (c1 - c0) / (w1 - w0)
    return DaemonFigures(
        fps_asked=fps,
        duration_s=w1 - w0,
        startup_s=startup,
        frames_expected=round(fps * (w1 - w0)),
        received=n1 - n0,
        dropped=int(window[-1][3].get("dropped", 0)) - int(listener.got[max(0, n0 - 1)][3].get("dropped", 0))
        if window else 0,
        seq_gaps=gaps,
        cpu_pct=100.0 * cpu,
        cpu_ms_per_frame=1e3 * (c1 - c0) / max(1, n1 - n0),
        latency_ms_p50=float(np.percentile(lat, 50)),
        latency_ms_p99=float(np.percentile(lat, 99)),
        latency_ms_max=float(lat.max()),
        received_ms_p99=float(np.percentile(received, 99)),
        kernel_stamped=bool(window) and all(sent == sent for _, _, sent, _ in window),
        rss_mib=rss / 1024.0,
        rss_peak_mib=hwm / 1024.0,
        exit_code=code,
        startup_cpu_s=startup_cpu,
        pipeline_cpu_ms=float(summary.group(1)) if summary else float("nan"),
        tracked_pct=float(summary.group(2)) if summary else float("nan"),
        bytecode=bytecode,
        restart=restart,
        clip_mib=sum(f.nbytes for f in frames) * (1.5 if run_cfg.source.lores else 1.0) / 2**20,
    )


def bench_clip(n_frames: int = 60) -> Tuple[Config, List[np.ndarray]]:
    """The clip ``bench.py`` runs the daemon on: 640×480, one landmark, the shipped defaults (seed 7)."""
    import bench_apriltag
    import bench_aruco
    from bench_frames import build_scenario

    images = {"aruco": bench_aruco.marker_images, "apriltag": bench_apriltag.tag_images}
    clip = build_scenario(Config(), 640, 480, 1, n_frames, 7, images)
    return clip.cfg, clip.frames


def _mode(later: object, fps: float) -> str:
    """How a row's daemon.scan_after_send reads: on, off, or auto with what it chose at this rate."""
    if later == "auto":
        return f"auto ({'on' if fps >= AUTO_SCAN_AFTER_SEND_FPS else 'off'})"
    return "on" if later else "off"


def main(argv: Sequence[str] | None = None) -> int:
    """``python benchmarks/bench_daemon.py [--fps 30 90] [--seconds S] [--runs N]``: the daemon rows alone."""
    import argparse

    p = argparse.ArgumentParser(prog="bench_daemon.py", description=main.__doc__)
    p.add_argument("--fps", type=float, nargs="+", default=[30.0, 90.0])
    p.add_argument("--seconds", type=float, default=None, help="window per run (default 10 s at 30 fps, 5 s else)")
    p.add_argument("--runs", type=int, default=1, help="runs per frame rate")
    p.add_argument("--frames", type=int, default=60)
    p.add_argument("--scan-after-send", choices=("auto", "off", "on", "both"), default="auto",
                   help="daemon.scan_after_send; both: alternate off and on in each run (default auto, the "
                        "config's default: on at >= 60 fps)")
    p.add_argument("--first-start", action="store_true",
                   help="the package's cache off (parsed config, dataclass methods): a robot's very first start")
    p.add_argument("--no-bytecode", action="store_true",
                   help="do not compile the package's modules beforehand (whatever __pycache__ holds is used)")
    args = p.parse_args(argv)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {max(os.sched_getaffinity(0))})
    cfg, frames = bench_clip(args.frames)
    modes = {"auto": ("auto",), "off": (False,), "on": (True,), "both": (False, True)}[args.scan_after_send]
    print("| fps | scan after send | bytecode | start-up s (CPU s) | datagrams / due | dropped | gaps | CPU % "
          "| CPU ms/frame | pipeline ms/frame (tracked) | rest ms/frame | capture→send p50 / p99 / max ms "
          "| →received p99 ms | RSS / peak MiB | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for fps in args.fps:
        for _, later in ((run, later) for run in range(args.runs) for later in modes):
            seconds = args.seconds or (10.0 if fps <= 30 else 5.0)
            run_cfg = dataclasses.replace(cfg, daemon=dataclasses.replace(cfg.daemon, scan_after_send=later))
            d = daemon_run(run_cfg, frames, fps, seconds, bytecode=not args.no_bytecode, restart=not args.first_start)
            if d.error:
                print(f"| {fps:g} | {_mode(later, fps)} | failed: {d.error[:300]} |")
                continue
            print(f"| {fps:g} | {_mode(later, fps)} | {'yes' if d.bytecode else 'no'}"
                  f"{'' if d.restart else ', first start'} "
                  f"| {d.startup_s:.3f} ({d.startup_cpu_s:.3f}) "
                  f"| {d.received} / {d.frames_expected} | {d.dropped} | {d.seq_gaps} | {d.cpu_pct:.2f} "
                  f"| {d.cpu_ms_per_frame:.3f} | {d.pipeline_cpu_ms:.3f} ({d.tracked_pct:.0f} %) "
                  f"| {d.cpu_ms_per_frame - d.pipeline_cpu_ms:.3f} "
                  f"| {d.latency_ms_p50:.2f} / {d.latency_ms_p99:.2f} / {d.latency_ms_max:.2f}"
                  f"{'' if d.kernel_stamped else ' (as received)'} | {d.received_ms_p99:.2f} "
                  f"| {d.rss_mib:.0f} / {d.rss_peak_mib:.0f} (clip {d.clip_mib:.0f} in page cache) "
                  f"| {os.getloadavg()[0]:.2f} |",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
