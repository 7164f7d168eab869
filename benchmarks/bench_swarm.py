"""Readings over Zenoh vs plain UDP on loopback: latency, CPU per reading, fan-in of 10 publishers.

    .venv/bin/python benchmarks/bench_swarm.py            # ~30 s
    .venv/bin/python benchmarks/bench_swarm.py --quick    # ~10 s, fewer samples

Publishers run in their own processes (as daemons do) and stamp each reading's
``t`` with ``time.time()`` just before encoding it, where the daemon stamps the
capture time; the controller (this process) takes ``time.time() - t`` when it
decodes the reading, so latency covers encode, send, transport, receive and
decode (on one machine, one clock). CPU is process time (user + system) divided
by readings: the publisher's covers encode and send, the controller's receive
and decode. Nothing leaves 127.0.0.1: Zenoh peers listen and dial loopback
endpoints with multicast scouting off. Prints a markdown table.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import socket
import statistics
import time
from typing import Any, Dict, List, Tuple

from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import RemoteLandmark, encode_reading
from rangebearing.net.zenoh_client import ZenohSubscriber
from rangebearing.net.zenoh_transport import ZenohPublisher, ZenohSettings

LM = RemoteLandmark(0.5, 0.1, True, 40.0, 0.03, 0.0, (300.0, 200.0), (300.0, 240.0), 12.0)


def free_port(kind: int) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _make_publisher(transport: str, robot: str, port: int) -> Any:
    if transport == "udp":
        from rangebearing.config import PublishConfig
        from rangebearing.net.publisher import UdpPublisher

        return UdpPublisher(PublishConfig(robot_id=robot, unicast=(("127.0.0.1", port),)))
    settings = ZenohSettings(connect=(f"tcp/127.0.0.1:{port}",), listen=("tcp/127.0.0.1:0",),
                             scouting_multicast=False)
    pub = ZenohPublisher(robot, settings, wait_s=5.0)
    time.sleep(0.5)  # let the subscriber's declaration reach us
    return pub


def publish(transport: str, robot: str, port: int, rate_hz: float, seconds: float, go: Any, ready: Any,
            out: Any) -> None:
    """Child process: send readings at ``rate_hz`` (0: as fast as possible) for ``seconds``."""
    pub = _make_publisher(transport, robot, port)
    ready.put(robot)
    go.wait()
    period = 1.0 / rate_hz if rate_hz else 0.0
    cpu0, t0 = time.process_time(), time.perf_counter()
    seq = 0
    while True:
        now = time.perf_counter()
        if now - t0 >= seconds:
            break
        if period:
            due = t0 + seq * period
            if due > now:
                time.sleep(due - now)
        pub.send(encode_reading(robot, seq, time.time(), (LM, LM), fps=15.0, dropped=0))
        seq += 1
    cpu = time.process_time() - cpu0
    time.sleep(1.0)  # let the last samples drain before the session goes
    pub.close()
    out.put((robot, seq, cpu))


def _subscriber(transport: str, port: int) -> Any:
    if transport == "udp":
        sub = Subscriber(port=port)
        sub._sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        return sub
    return ZenohSubscriber(settings=ZenohSettings(listen=(f"tcp/127.0.0.1:{port}",), scouting_multicast=False),
                           presence=False)


def run(transport: str, publishers: int, rate_hz: float, seconds: float) -> Dict[str, float]:
    """One measurement: returns latencies, CPU per reading and rates."""
    ctx = mp.get_context("spawn")
    port = free_port(socket.SOCK_DGRAM if transport == "udp" else socket.SOCK_STREAM)
    sub = _subscriber(transport, port)
    go, ready, out = ctx.Event(), ctx.Queue(), ctx.Queue()
    procs = [ctx.Process(target=publish, args=(transport, f"r{i}", port, rate_hz, seconds, go, ready, out))
             for i in range(publishers)]
    for p in procs:
        p.start()
    for _ in procs:  # every child has started and connected
        ready.get(timeout=60)
    time.sleep(0.5)
    latencies: List[float] = []
    cpu0 = time.process_time()
    go.set()
    t_end = time.monotonic() + seconds + 1.0
    while time.monotonic() < t_end:
        reading = sub.recv(0.2)
        if reading is not None:
            latencies.append(time.time() - reading.t)
    rx_cpu = time.process_time() - cpu0
    sent: List[Tuple[str, int, float]] = [out.get(timeout=10) for _ in procs]
    for p in procs:
        p.join(10)
    sub.close()
    n_sent = sum(s[1] for s in sent)
    lat = sorted(latencies) or [float("nan")]
    return {
        "sent": n_sent,
        "received": len(latencies),
        "p50_ms": 1e3 * statistics.median(lat),
        "p99_ms": 1e3 * lat[min(len(lat) - 1, int(0.99 * len(lat)))],
        "tx_us": 1e6 * sum(s[2] for s in sent) / max(1, n_sent),
        "rx_us": 1e6 * rx_cpu / max(1, len(latencies)),
        "rate_hz": len(latencies) / seconds,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="shorter runs")
    args = ap.parse_args()
    secs = 2.0 if args.quick else 5.0
    print("| transport | publishers | offered (each) | sent | received | loss | p50 latency | p99 latency "
          "| CPU/reading tx | CPU/reading rx | received/s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for transport in ("udp", "zenoh"):
        for pubs, rate in ((1, 30.0), (1, 200.0), (10, 100.0), (1, 0.0), (10, 0.0)):
            r = run(transport, pubs, rate, secs)
            loss = 1.0 - r["received"] / max(1, r["sent"])
            label = f"{rate:g} Hz" if rate else "max"
            # Flat out, latency is time spent queued behind earlier readings: not shown.
            lat = f"{r['p50_ms']:.2f} ms | {r['p99_ms']:.2f} ms" if rate else "- | -"
            print(f"| {transport} | {pubs} | {label} | {r['sent']:.0f} | {r['received']:.0f} | {100 * loss:.1f} % "
                  f"| {lat} | {r['tx_us']:.0f} µs | {r['rx_us']:.0f} µs | {r['rate_hz']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
