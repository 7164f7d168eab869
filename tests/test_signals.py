"""``_signals``: signals are acted on off the main thread, so a signal landing while that thread holds a lock
the action needs (an Event's own, inside ``clear()`` or ``wait()``) cannot deadlock the process."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

_CHILD = textwrap.dedent("""
    import os, signal, sys, threading, time
    from rangebearing import _signals
    ev, n = threading.Event(), [0]
    def act():
        n[0] += 1
        ev.set()
    if sys.argv[1] == "relay":
        _signals.handle({signal.SIGUSR1: act})
    else:  # the old way: the action inside the handler
        signal.signal(signal.SIGUSR1, lambda *_: act())
    for _ in range(200):
        ev.clear()
        with ev._cond:  # the main thread holds the event's lock, as inside clear() or wait()
            os.kill(os.getpid(), signal.SIGUSR1)
            time.sleep(0.0005)  # the handler runs here, between bytecodes, lock held
        assert ev.wait(5), "the action never ran"
    print(n[0])
""")


def _run(mode: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _CHILD, mode], capture_output=True, text=True, timeout=30)


def test_a_signal_while_the_main_thread_holds_the_actions_lock_is_acted_on() -> None:
    done = _run("relay")
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == 200


def test_the_old_handler_deadlocks_there_which_is_what_the_relay_prevents() -> None:
    with pytest.raises(subprocess.TimeoutExpired):
        subprocess.run([sys.executable, "-c", _CHILD, "handler"], capture_output=True, timeout=3)


def test_an_action_that_raises_does_not_end_the_relay(caplog: pytest.LogCaptureFixture) -> None:
    import os
    import signal
    import threading

    from rangebearing import _signals

    calls, second = [], threading.Event()

    def flaky() -> None:  # e.g. a stop that races the loop closing its source
        calls.append(1)
        if len(calls) == 1:
            raise AttributeError("'NoneType' object has no attribute 'done'")
        second.set()

    previous = signal.getsignal(signal.SIGUSR2)
    try:
        _signals.handle({signal.SIGUSR2: flaky})
        os.kill(os.getpid(), signal.SIGUSR2)
        for _ in range(600):  # until the relay ran the first one (it logs the failure)
            if calls:
                break
            threading.Event().wait(0.1)
        os.kill(os.getpid(), signal.SIGUSR2)
        assert second.wait(60), "the relay thread died with the first action's exception"
    finally:
        signal.signal(signal.SIGUSR2, previous)
    assert any("signal" in r.getMessage() and r.exc_info for r in caplog.records)
