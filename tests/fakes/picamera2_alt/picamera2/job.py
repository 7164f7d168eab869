"""Job: an operation the camera's event loop performs (picamera2/job.py, same semantics)."""

from __future__ import annotations

from concurrent.futures import CancelledError, Future
from typing import Any, Callable, Optional


class Job:
    """A list of functions run on successive frames; the last one's result is the job's (job.py:28-70)."""

    def __init__(self, functions: list[Callable[[], tuple[bool, Any]]], signal_function=None) -> None:
        self._functions = functions
        self._future: Future = Future()
        self._future.set_running_or_notify_cancel()
        self._signal_function = signal_function
        self._result: Any = None
        self.calls = 0

    def execute(self) -> bool:
        """Run what can run now; True when the job is finished (job.py:44-70: an exception ends it)."""
        try:
            while self._functions:
                done, result = self._functions[0]()
                self.calls += 1
                if not done:
                    break
                self._functions.pop(0)
            if not self._functions:
                self._result = result
        except Exception as error:  # the real Job stores any exception in its future
            self._future.set_exception(error)
            self._functions = []
        return not self._functions

    def signal(self) -> None:
        """Publish the result and call the signal function (job.py:72-79)."""
        if not self._future.done():
            self._future.set_result(self._result)
        if self._signal_function:
            self._signal_function(self)

    def get_result(self, timeout: Optional[float] = None) -> Any:
        """Block for the result; concurrent.futures.TimeoutError after `timeout` s (job.py:81-87)."""
        return self._future.result(timeout=timeout)

    def cancel(self) -> None:
        """Make get_result raise CancelledError (job.py:89-93); does not unschedule the job."""
        self._future.set_exception(CancelledError())
