"""The daemon's CPU with and without a browser watching its view page.

Usage::

    python benchmarks/bench_view.py [--seconds 20] [--fps 30] [--view-fps 10]

Runs ``rangebearing run`` on the bundled clip (recorded source paced at
``--fps``, looping, publishing to loopback) and reads its CPU time from
/proc/PID/stat over ``--seconds`` in four phases: the view off
(``daemon.view_port: 0``), the view on with nobody connected, one viewer (the
MJPEG stream and the server-sent events, read as a browser reads them), and
that viewer with the masks stream too. Prints a markdown table: CPU in percent
of one core, and the frames per second the viewer received.
"""

from __future__ import annotations

import argparse
import http.client
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import List, Optional, Tuple

REPO = Path(__file__).resolve().parents[1]
CLIP = REPO / "samples" / "clip"
TICK = os.sysconf("SC_CLK_TCK")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def cpu_s(pid: int) -> float:
    """User + system CPU seconds of a process (all its threads)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / TICK


class Reader(threading.Thread):
    """Reads one endless HTTP response the way a browser does, counting the frames (or events) in it."""

    def __init__(self, port: int, path: str, marker: bytes) -> None:
        super().__init__(daemon=True)
        self.port, self.path, self.marker = port, path, marker
        self.count = 0
        self.stop = threading.Event()

    def run(self) -> None:
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        conn.request("GET", self.path)
        r = conn.getresponse()
        tail = b""
        while not self.stop.is_set():
            chunk = r.read1(65536)
            if not chunk:
                break
            data = tail + chunk
            self.count += data.count(self.marker)
            tail = data[-len(self.marker) + 1 :]
        conn.close()


def config(path: Path, fps: float, view_port: int, view_fps: float) -> None:
    path.write_text(
        f'source: {{kind: recorded, path: "{CLIP}", fps: {fps}, loop: true}}\n'
        'publish: {unicast: ["127.0.0.1:47899"]}\n'
        f"daemon: {{status_interval_s: 60, view_port: {view_port}, view_fps: {view_fps}}}\n"
    )


def wait_http(port: int, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=1)
            conn.request("GET", "/api/thresholds")
            conn.getresponse().read()
            return
        except OSError:
            time.sleep(0.1)
    raise SystemExit(f"the view did not answer on port {port}")


def measure(pid: int, seconds: float, readers: List[Reader]) -> Tuple[float, float]:
    for r in readers:
        r.start()
    time.sleep(2.0)  # settle: connections made, encoder warm
    c0, n0, t0 = cpu_s(pid), sum(r.count for r in readers[:1]), time.monotonic()
    time.sleep(seconds)
    c1, n1, t1 = cpu_s(pid), sum(r.count for r in readers[:1]), time.monotonic()
    for r in readers:
        r.stop.set()
    return 100.0 * (c1 - c0) / (t1 - t0), (n1 - n0) / (t1 - t0)


def run_phase(
    tmp: Path, fps: float, view_fps: float, seconds: float, view: bool, streams: List[str]
) -> Tuple[float, float]:
    port = free_port() if view else 0
    cfg = tmp / "bench-view.yaml"
    config(cfg, fps, port, view_fps)
    cmd = [sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        if view:
            wait_http(port)
        else:
            time.sleep(2.0)
        readers = [Reader(port, p, b"Content-Type: image/jpeg" if "mjpg" in p else b"data: ") for p in streams]
        return measure(proc.pid, seconds, readers)
    finally:
        proc.terminate()
        proc.wait(10)


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="bench_view.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=10.0, help="measuring time per phase and repeat")
    p.add_argument("--repeats", type=int, default=3, help="rounds of all four phases, interleaved (median shown)")
    p.add_argument("--fps", type=float, default=30.0, help="the recorded source's pace (a Pi camera's 30 fps)")
    p.add_argument("--view-fps", type=float, default=10.0, help="daemon.view_fps")
    args = p.parse_args(argv)
    phases = [
        ("view off (`view_port: 0`)", False, []),
        ("view on, no browser", True, []),
        ("one viewer: stream + events", True, ["/stream.mjpg", "/api/events"]),
        ("one viewer with masks", True, ["/stream.mjpg", "/api/events", "/stream.mjpg?layer=masks"]),
    ]
    print(f"640×480 bundled clip at {args.fps:g} fps, view capped at {args.view_fps:g} fps, {args.seconds:g} s per "
          f"phase, {args.repeats} interleaved rounds; CPU of the daemon process (all threads), % of one core\n")
    got: List[List[Tuple[float, float]]] = [[] for _ in phases]
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            for i, (name, view, streams) in enumerate(phases):
                got[i].append(run_phase(Path(tmp), args.fps, args.view_fps, args.seconds, view, streams))
                print(f"round {r + 1}: {name}: {got[i][-1][0]:.1f} %", file=sys.stderr, flush=True)
    print("| phase | daemon CPU, median (min–max) | frames/s to the viewer |")
    print("|---|---|---|")
    for (name, _, streams), runs in zip(phases, got):
        cpu = sorted(c for c, _ in runs)
        rate = f"{statistics.median(f for _, f in runs):.1f}" if streams else "–"
        print(f"| {name} | {statistics.median(cpu):.1f} % ({cpu[0]:.1f}–{cpu[-1]:.1f}) | {rate} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
