"""A looping clip's decoded frames live in the page cache (an unlinked temp file), not in the process."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from rangebearing.sources import RecordedSource
from rangebearing.sources import clip_store as cs
from rangebearing.sources.clip_store import ClipStore

linux_only = pytest.mark.skipif(not sys.platform.startswith("linux") or not cs.CAN_RELEASE,
                                reason="reads /proc/self/smaps_rollup; needs madvise(MADV_DONTNEED)")


def _rss_kib() -> int:
    for line in Path("/proc/self/smaps_rollup").read_text().splitlines():
        if line.startswith("Rss:"):
            return int(line.split()[1])
    raise AssertionError("no Rss line")


@pytest.mark.skipif(not cs.CAN_RELEASE, reason="no madvise(MADV_DONTNEED) here")
def test_arrays_come_back_equal_read_only_and_the_same_objects() -> None:
    store = ClipStore()
    rng = np.random.default_rng(3)
    a = rng.integers(0, 255, (31, 17, 3), np.uint8)
    b = rng.integers(0, 255, (7, 5), np.uint8)[:, ::2]  # not contiguous
    views = store.put("k", [a, b])
    assert views is not None and store.nbytes > 0
    assert np.array_equal(views[0], a) and np.array_equal(views[1], b) and views[1].shape == b.shape
    assert not views[0].flags.writeable
    with pytest.raises(ValueError):
        views[0][0, 0, 0] = 1
    again = store.get("k")
    assert again is not None and again[0] is views[0] and store.get("other") is None
    store.release()  # pages dropped: the views read the same bytes back from the file
    assert np.array_equal(views[0], a) and np.array_equal(views[1], b)
    store.close()
    assert np.array_equal(views[0], a)  # a view kept past close keeps its mapping


@linux_only
@pytest.mark.parametrize("batch_mib", [0, 4, cs.BATCH_BYTES / 2**20])
def test_released_frames_leave_the_process_memory(batch_mib: float) -> None:
    store = ClipStore(batch_bytes=int(batch_mib * 2**20))
    views = []
    for i in range(16):  # 14 MiB of frames, written once
        v = store.put(i, [np.full((480, 640, 3), i, np.uint8)])
        assert v is not None
        views.append(v[0])
        store.release()
    before = _rss_kib()
    for i, v in enumerate(views):  # every frame used again, one at a time
        store.get(i)
        assert int(v[240, 320, 1]) == i and int(v.max()) == i
        store.release()
    grown_mib = (_rss_kib() - before) / 1024
    store.release(now=True)
    dropped_mib = (_rss_kib() - before) / 1024
    store.close()
    # 14 MiB of frames were used; those since the last drop (< batch_mib) and a frame or two may be mapped
    assert grown_mib < batch_mib + 6, grown_mib
    assert dropped_mib < 3, dropped_mib  # now: every one dropped


def test_a_temp_dir_it_cannot_write_keeps_frames_in_memory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse() -> int:
        raise OSError(30, "Read-only file system")

    monkeypatch.setattr(cs, "_unlinked_temp_file", refuse)
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"{i:03d}.png"), np.full((24, 32, 3), 40 * i + 10, np.uint8))
    source = RecordedSource(tmp_path, loop=True, lores=True, in_place=True)
    source.open()
    try:
        frames = [source.read() for _ in range(7)]
    finally:
        source.close()
    assert [int(f.image[0, 0, 0]) for f in frames if f is not None] == [10, 50, 90, 10, 50, 90, 10]
    assert frames[3] is not None and frames[0] is not None and frames[3].image is frames[0].image  # memory cache
    assert not frames[0].image.flags.writeable


@linux_only
def test_a_looping_clip_costs_the_daemon_no_memory(tmp_path: Path) -> None:
    for i in range(12):  # 12 VGA frames and their YUV420: 16 MiB decoded
        img = np.zeros((480, 640, 3), np.uint8)
        cv2.circle(img, (50 * i + 40, 240), 30, (40, 60, 200), -1)
        cv2.imwrite(str(tmp_path / f"{i:03d}.png"), img)
    source = RecordedSource(tmp_path, loop=True, lores=True, in_place=True)
    source.open()
    try:
        first = source.read()
        assert first is not None and first.lores_yuv420 is not None
        want_v = first.lores_yuv420.v.copy()
        before = _rss_kib()
        for _ in range(2 * 12 - 1):
            frame = source.read()
            assert frame is not None and not frame.image.flags.writeable and frame.lores_yuv420 is not None
            assert int(frame.image.max()) == 200 and int(frame.lores_yuv420.v.max()) > 128  # every page used
        again = source.read()  # frame 0 of the third loop: the same stored arrays, the same values
        assert again is not None and again.image is first.image and again.lores_yuv420 is first.lores_yuv420
        assert np.array_equal(again.lores_yuv420.v, want_v)
        grown_mib = (_rss_kib() - before) / 1024
    finally:
        source.close()
    assert grown_mib < 8, grown_mib
