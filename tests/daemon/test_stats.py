"""The loop's statistics: the percentiles numpy gives, without numpy's generic path in the loop's thread."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing.core.stats import percentile
from rangebearing.daemon.stats import LoopStats


@pytest.mark.parametrize("n", [1, 2, 3, 7, 100, 4096])
def test_percentiles_are_numpys(n: int) -> None:
    rng = np.random.default_rng(n)
    for _ in range(20):
        x = rng.integers(0, 10**8, n)
        for pct in (0, 37.5, 50, 99, 99.9, 100):
            assert percentile(np.sort(x) / 1e6, pct) == float(np.percentile(x / 1e6, pct))


def test_summary_figures() -> None:
    stats = LoopStats(window=100)
    for i in range(150):  # the window keeps the last 100: latencies 50..149 us
        stats.frame_done(i * 10_000_000, 1000 * i, 2, {"process": 2_000_000 + i}, cpu_ns=3_000_000,
                         tracked=i % 4 != 0)
    s = stats.summary(dropped=5)
    lat_ms = np.arange(50, 150) * 1e-3
    assert s.frames == 150 and s.dropped == 5 and s.landmarks == 2
    assert s.latency_ms_p50 == pytest.approx(float(np.percentile(lat_ms, 50)), rel=1e-12)
    assert s.latency_ms_p99 == pytest.approx(float(np.percentile(lat_ms, 99)), rel=1e-12)
    assert s.stage_ms["process"] == pytest.approx(2.0 + 99.5e-6)
    assert s.pipeline_cpu_ms == 3.0 and s.tracked_pct == 75.0 and s.fps == pytest.approx(100.0)
