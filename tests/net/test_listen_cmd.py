"""``rangebearing listen``: line format, echo loop, and the command run in-process."""

from __future__ import annotations

import argparse
import io
import json
import socket
import threading
from typing import Iterator, List

import pytest

from rangebearing.cli import listen_cmd, swarm_cmd
from rangebearing.cli.main import main
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import Reading, RemoteLandmark, decode_reading, encode_reading

from .factories import make_landmark


def _parse(argv: List[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="rangebearing")
    listen_cmd.register(parser.add_subparsers())
    return parser.parse_args(argv)


def _free_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = int(s.getsockname()[1])
    s.close()
    return port


@pytest.fixture
def tx() -> Iterator[socket.socket]:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    yield s
    s.close()


def _remote(range_m: float, bearing_deg: float, in_envelope: bool) -> RemoteLandmark:
    return RemoteLandmark(range_m, bearing_deg * 3.141592653589793 / 180.0, in_envelope,
                          80.0, range_m, 0.0, (1.0, 2.0), (1.0, 60.0), 10.0)


def test_format_reading_matches_the_documented_line() -> None:
    r = Reading("zumo", 1234, 1732419876.1234,
                (_remote(0.4123, 12.3, True), _remote(1.2049, -4.0, False)))
    assert listen_cmd.format_reading(r) == (
        "zumo #1234 t=1732419876.123  2 landmarks: "
        "0.412 m  +12.3° | 1.205 m  -4.0° (out of envelope)"
    )


def test_format_reading_heartbeat_and_stats() -> None:
    assert listen_cmd.format_reading(Reading("z", 0, 1.0)) == "z #0 t=1.000  0 landmarks"
    r = Reading("z", 1, 1.0, (_remote(0.5, 0.0, True),), fps=29.96, dropped=2)
    assert listen_cmd.format_reading(r) == (
        "z #1 t=1.000  1 landmark: 0.500 m  +0.0°  [30.0 fps, 2 dropped]"
    )


def test_echo_prints_one_line_per_reading(tx: socket.socket) -> None:
    out = io.StringIO()
    with Subscriber(port=0) as sub:
        tx.sendto(b"junk", ("127.0.0.1", sub.port))
        for seq in (1, 2):
            tx.sendto(encode_reading("zumo", seq, 5.0, [make_landmark()]), ("127.0.0.1", sub.port))
        assert listen_cmd.echo(sub, out, count=2, timeout_s=2.0) == 0
    lines = out.getvalue().splitlines()
    assert [line.split()[1] for line in lines] == ["#1", "#2"]
    assert "0.412 m" in lines[0]


def test_echo_json_prints_the_datagram(tx: socket.socket) -> None:
    payload = encode_reading("zumo", 8, 5.0, [make_landmark()])
    out = io.StringIO()
    with Subscriber(port=0) as sub:
        tx.sendto(payload, ("127.0.0.1", sub.port))
        pretty = json.dumps(json.loads(payload), indent=2).encode()
        tx.sendto(pretty, ("127.0.0.1", sub.port))
        assert listen_cmd.echo(sub, out, as_json=True, count=2, timeout_s=2.0) == 0
    lines = out.getvalue().splitlines()
    assert len(lines) == 2
    assert lines[0] == payload.decode()
    assert decode_reading(lines[1].encode()) == decode_reading(payload)


def test_run_prints_a_received_reading(tx: socket.socket,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    port = _free_port()
    args = _parse(["listen", "--port", str(port), "--count", "1", "--timeout", "5"])
    assert args.func is listen_cmd.run
    result: List[int] = []
    worker = threading.Thread(target=lambda: result.append(listen_cmd.run(args)))
    worker.start()
    # The listener binds in its own thread; send until it has printed and quit.
    seq = 0
    while worker.is_alive() and seq < 500:
        tx.sendto(encode_reading("zumo", seq, 7.0, [make_landmark()]), ("127.0.0.1", port))
        seq += 1
        worker.join(timeout=0.01)
    worker.join(timeout=5)
    assert result == [0]
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1 and lines[0].startswith("zumo #") and "1 landmark:" in lines[0]


def test_run_times_out_with_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["listen", "--port", str(_free_port()), "--timeout", "0.05"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("rangebearing: error: no reading arrived on 127.0.0.1:")
    assert "0.05 s" in err


def test_run_reports_a_busy_port(capsys: pytest.CaptureFixture[str]) -> None:
    with Subscriber(port=0) as busy:
        assert main(["listen", "--port", str(busy.port)]) == 1
    assert "rangebearing: error: cannot listen on 127.0.0.1:" in capsys.readouterr().err


def test_interface_needs_a_group(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["listen", "--interface", "127.0.0.1"]) == 2
    assert "--interface only applies with --group" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["--port", "70000"], ["--count", "0"], ["--timeout", "-1"],
                                  ["--timeout", "nan"], ["--port", "http"], ["--timeout", "1e300"]])
def test_bad_arguments_are_rejected_by_the_parser(argv: List[str]) -> None:
    with pytest.raises(SystemExit) as info:
        _parse(["listen", *argv])
    assert info.value.code == 2


@pytest.mark.parametrize("argv", [["--udp", "--port", "70000"], ["--udp", "--port", "-1"], ["--interval", "1e300"],
                                  ["--duration", "1e300"]])
def test_bad_swarm_arguments_are_rejected_by_the_parser(argv: List[str]) -> None:
    """swarm --port 70000 was an OverflowError out of bind(), --duration 1e300 one out of time_t ('a bug?')."""
    parser = argparse.ArgumentParser(prog="rangebearing")
    swarm_cmd.register(parser.add_subparsers())
    assert parser.parse_args(["swarm", "--udp", "--port", "0", "--duration", "1e9"]).duration == 1e9
    with pytest.raises(SystemExit) as info:
        parser.parse_args(["swarm", *argv])
    assert info.value.code == 2


def test_sigterm_ends_listening_cleanly_with_a_summary(tx: socket.socket) -> None:
    """`kill` / `timeout 5 rangebearing listen` is how scripts end it: exit 0, no traceback, a summary."""
    import os
    import signal
    import subprocess
    import sys
    import time

    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "rangebearing", "listen", "--port", str(port)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert proc.stdout is not None
        line = ""
        deadline = time.monotonic() + 30.0
        seq = 0
        while not line and time.monotonic() < deadline:  # resend until the listener is up and prints
            tx.sendto(encode_reading("zumo", seq, 5.0, [make_landmark()]), ("127.0.0.1", port))
            seq += 1
            ready = __import__("select").select([proc.stdout], [], [], 0.2)[0]
            if ready:
                line = proc.stdout.readline()
        assert line.startswith("zumo #"), line
        tx.sendto(b"not a reading", ("127.0.0.1", port))
        time.sleep(0.3)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    shown = 1 + out.count("zumo #")
    assert f"rangebearing listen: terminated after {shown} readings on 127.0.0.1:{port}" in err
    assert "(1 invalid datagrams dropped)" in err
