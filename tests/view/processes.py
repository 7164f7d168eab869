"""``rangebearing view`` and ``rangebearing run`` as real processes, for the view's end-to-end tests."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
import time
from typing import List, Optional


class Served:
    """A running command that serves the view; ``url`` is read from what it logs."""

    def __init__(self, args: List[str], timeout_s: float = 30.0) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "rangebearing.cli.main", *args],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )
        self.log: List[str] = []
        self.url: Optional[str] = None
        found = threading.Event()

        def read() -> None:
            for line in self.proc.stderr:  # type: ignore[union-attr]
                self.log.append(line)
                m = re.search(r"view: serving (http://\S+/)", line)
                if m and self.url is None:
                    self.url = m.group(1)
                    found.set()
            found.set()

        threading.Thread(target=read, daemon=True).start()
        deadline = time.monotonic() + timeout_s
        while not found.wait(0.1) and time.monotonic() < deadline:
            pass
        if self.url is None:
            self.stop()
            raise AssertionError("the view did not start:\n" + "".join(self.log))

    def stop(self, timeout_s: float = 15.0) -> int:
        """SIGTERM, and the exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        return self.proc.wait(timeout_s)
