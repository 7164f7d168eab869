"""Recorded frames: directory order and filtering, corrupt files, videos, pacing, looping."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import cv2
import numpy as np
import pytest

from rangebearing.errors import FrameError, SourceError
from rangebearing.sources import Frame, RecordedSource, count_recorded, iter_recorded
from rangebearing.sources import recorded as recorded_mod

from .conftest import frame_brightness, solid_bgr, video_levels

PERIOD_NS = 100_000_000  # 10 fps


class FakeClock:
    """A monotonic clock in ns that only moves when told to (or when slept on)."""

    def __init__(self, t_ns: int = 1_000_000_000) -> None:
        self.t_ns = t_ns
        self.sleeps: List[float] = []

    def __call__(self) -> int:
        return self.t_ns

    def sleep(self, seconds: float) -> None:
        assert seconds > 0
        self.sleeps.append(seconds)
        self.t_ns += round(seconds * 1e9)

    def advance(self, periods: float) -> None:
        self.t_ns += round(periods * PERIOD_NS)


def write_images(directory: Path, n: int) -> List[str]:
    names = [f"frame_{i:04d}.png" for i in range(n)]
    for i, name in enumerate(names):
        cv2.imwrite(str(directory / name), solid_bgr(10 * i + 5))
    return names


def read_all(source: RecordedSource, limit: int = 100) -> List[Frame]:
    frames = []
    for _ in range(limit):
        frame = source.read()
        if frame is None:
            return frames
        frames.append(frame)
    raise AssertionError("the source never ended")


class TestDirectory:
    def test_sorted_by_name_images_only_case_insensitive(self, tmp_path: Path) -> None:
        cv2.imwrite(str(tmp_path / "b.png"), solid_bgr(1))
        cv2.imwrite(str(tmp_path / "a.jpg"), solid_bgr(2))
        cv2.imwrite(str(tmp_path / "c.BMP"), solid_bgr(3))
        cv2.imwrite(str(tmp_path / "d.JPEG"), solid_bgr(4))
        (tmp_path / "truth.csv").write_text("name,range_m\n")
        (tmp_path / "notes.txt").write_text("not an image")
        (tmp_path / "sub.png").mkdir()  # a directory with an image-like name
        names = [name for name, _ in iter_recorded(tmp_path)]
        assert names == ["a.jpg", "b.png", "c.BMP", "d.JPEG"]
        assert count_recorded(tmp_path) == 4

    def test_images_decode_as_bgr(self, tmp_path: Path) -> None:
        bgr = np.zeros((8, 8, 3), np.uint8)
        bgr[..., 2] = 200  # pure red in OpenCV order
        cv2.imwrite(str(tmp_path / "red.png"), bgr)
        ((name, image),) = list(iter_recorded(tmp_path))
        assert name == "red.png" and image is not None
        np.testing.assert_array_equal(image, bgr)

    def test_corrupt_image_yields_none_and_iteration_goes_on(self, tmp_path: Path) -> None:
        write_images(tmp_path, 3)
        (tmp_path / "frame_0001.png").write_bytes(b"\x89PNG\r\n\x1a\n not really")
        items = list(iter_recorded(tmp_path))
        assert [name for name, _ in items] == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
        assert items[1][1] is None
        assert items[0][1] is not None and items[2][1] is not None

    def test_missing_path(self, tmp_path: Path) -> None:
        with pytest.raises(SourceError, match="no such file"):
            list(iter_recorded(tmp_path / "missing"))
        with pytest.raises(SourceError, match="no such file"):
            count_recorded(tmp_path / "missing")

    def test_directory_without_images(self, tmp_path: Path) -> None:
        (tmp_path / "truth.csv").write_text("x")
        with pytest.raises(SourceError, match="holds no images"):
            list(iter_recorded(tmp_path))
        with pytest.raises(SourceError, match="holds no images"):
            RecordedSource(tmp_path).open()


class TestVideo:
    def test_iterates_every_frame_with_index_names(self, tiny_video: Path) -> None:
        items = list(iter_recorded(tiny_video))
        assert [name for name, _ in items] == [str(i) for i in range(6)]
        for (_, image), level in zip(items, video_levels()):
            assert image is not None and image.shape == (48, 64, 3)
            assert frame_brightness(image) == pytest.approx(level, abs=4)

    def test_count(self, tiny_video: Path) -> None:
        assert count_recorded(tiny_video) in (None, 6)

    def test_unreadable_video(self, tmp_path: Path) -> None:
        bogus = tmp_path / "clip.avi"
        bogus.write_text("this is not a video")
        with pytest.raises(SourceError, match="cannot open"):
            list(iter_recorded(bogus))
        with pytest.raises(SourceError, match="cannot open"):
            RecordedSource(bogus).open()

    def test_source_reads_video_then_ends(self, tiny_video: Path) -> None:
        source = RecordedSource(tiny_video)
        source.open()
        frames = read_all(source)
        source.close()
        assert [f.index for f in frames] == list(range(6))
        assert [f.name for f in frames] == [str(i) for i in range(6)]
        assert [round(frame_brightness(f.image) / 30) for f in frames] == [
            round(v / 30) for v in video_levels()
        ]

    def test_looping_video_restarts(self, tiny_video: Path) -> None:
        source = RecordedSource(tiny_video, loop=True)
        source.open()
        frames = [source.read() for _ in range(14)]
        source.close()
        assert [f.name for f in frames if f] == [str(i % 6) for i in range(14)]
        assert [f.index for f in frames if f] == list(range(14))

    def test_paced_skip_past_the_end_delivers_the_last_frame(self, tiny_video: Path) -> None:
        clock = FakeClock()
        source = RecordedSource(tiny_video, fps=10, clock=clock, sleep=clock.sleep)
        source.open()
        assert source.read().name == "0"  # type: ignore[union-attr]
        clock.advance(20)  # far beyond the 6-frame clip
        last = source.read()
        assert last is not None and last.name == "5" and last.index == 5
        assert source.dropped == 4
        assert source.read() is None


class TestRecordedSource:
    def test_as_fast_as_possible_never_drops(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 5)
        clock = FakeClock()
        source = RecordedSource(tmp_path, fps=None, clock=clock, sleep=clock.sleep)
        source.open()
        frames = []
        for _ in range(5):
            clock.advance(7)  # a very slow consumer
            frames.append(source.read())
        assert source.read() is None
        assert [f.name for f in frames if f] == names
        assert [f.index for f in frames if f] == list(range(5))
        assert source.dropped == 0 and clock.sleeps == []
        assert frames[0] is not None and frames[0].t_mono_ns == 1_000_000_000 + 7 * PERIOD_NS

    def test_fast_consumer_waits_for_each_frame(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 4)
        clock = FakeClock()
        start = clock.t_ns
        source = RecordedSource(tmp_path, fps=10, clock=clock, sleep=clock.sleep)
        source.open()
        frames = read_all(source)
        assert [f.name for f in frames] == names
        assert [f.t_mono_ns for f in frames] == [start + i * PERIOD_NS for i in range(4)]
        assert source.dropped == 0
        assert sum(clock.sleeps) == pytest.approx(0.3)
        assert clock.t_ns == start + 3 * PERIOD_NS

    def test_slow_consumer_gets_the_newest_frame_and_counts_drops(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 12)
        clock = FakeClock()
        start = clock.t_ns
        source = RecordedSource(tmp_path, fps=10, clock=clock, sleep=clock.sleep)
        source.open()
        got: List[Optional[Frame]] = [source.read()]
        for _ in range(3):
            clock.advance(3.5)  # processing takes 3.5 frame periods
            got.append(source.read())
        frames = [f for f in got if f]
        assert [f.index for f in frames] == [0, 3, 7, 10]
        assert [f.name for f in frames] == [names[i] for i in (0, 3, 7, 10)]
        assert [f.t_mono_ns for f in frames] == [start + i * PERIOD_NS for i in (0, 3, 7, 10)]
        assert source.dropped == 2 + 3 + 2
        assert clock.sleeps == []

    def test_slow_consumer_at_the_end_sees_the_last_frame(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 4)
        clock = FakeClock()
        source = RecordedSource(tmp_path, fps=10, clock=clock, sleep=clock.sleep)
        source.open()
        source.read()
        clock.advance(50)
        last = source.read()
        assert last is not None and last.name == names[-1] and last.index == 3
        assert source.dropped == 2
        assert source.read() is None

    def test_loop_restarts_and_index_keeps_counting(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 3)
        source = RecordedSource(tmp_path, loop=True)
        source.open()
        frames = [source.read() for _ in range(8)]
        assert [f.name for f in frames if f] == [names[i % 3] for i in range(8)]
        assert [f.index for f in frames if f] == list(range(8))

    def test_paced_loop_drops_across_the_wrap(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 3)
        clock = FakeClock()
        source = RecordedSource(tmp_path, fps=10, loop=True, clock=clock, sleep=clock.sleep)
        source.open()
        source.read()
        clock.advance(4)
        frame = source.read()
        assert frame is not None and frame.index == 4 and frame.name == names[1]
        assert source.dropped == 3

    def test_a_looped_frame_is_made_before_it_is_due_as_a_camera_hands_over_a_ready_buffer(
            self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 3)
        clock = FakeClock()
        source = RecordedSource(tmp_path, fps=10, loop=True, clock=clock, sleep=clock.sleep, lores=True,
                                in_place=True)
        source.open()
        made: List[tuple] = []
        frame_of = source._frame

        def noted(reader, fetched, i):  # when each frame was made: before or after its wait
            made.append((i, len(clock.sleeps)))
            return frame_of(reader, fetched, i)

        source._frame = noted  # type: ignore[method-assign]
        first_loop = [source.read() for _ in range(3)]
        assert [m[1] for m in made] == [0, 1, 2]  # the first loop's YUV420 is made once its frame is due
        made.clear()
        again = [source.read() for _ in range(3)]
        assert made == [(3, 2), (4, 3), (5, 4)]  # now made before each wait
        assert [f.index for f in again] == [3, 4, 5] and [f.name for f in again] == names
        assert [f.t_mono_ns for f in again] == [1_000_000_000 + i * PERIOD_NS for i in (3, 4, 5)]
        assert all(a.lores_yuv420 is b.lores_yuv420 for a, b in zip(first_loop, again))
        made.clear()
        clock.advance(2.5)  # a late consumer: the frame made ahead is skipped, the newest due one is made
        late = source.read()
        assert late is not None and late.index == 7 and [m[0] for m in made] == [6, 7] and source.dropped == 1

    def test_corrupt_image_raises_then_the_next_read_continues(self, tmp_path: Path) -> None:
        names = write_images(tmp_path, 3)
        (tmp_path / names[1]).write_bytes(b"garbage")
        source = RecordedSource(tmp_path)
        source.open()
        first = source.read()
        with pytest.raises(FrameError, match=names[1]):
            source.read()
        third = source.read()
        assert first is not None and first.name == names[0]
        assert third is not None and third.name == names[2] and third.index == 2
        assert source.read() is None

    def test_images_are_decoded_lazily(
        self, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
    ) -> None:
        write_images(tmp_path, 5)
        decoded: List[str] = []
        real = recorded_mod.decode_file

        def counting(path: Path) -> Optional[np.ndarray]:
            decoded.append(path.name)
            return real(path)

        monkeypatch.setattr(recorded_mod, "decode_file", counting)
        source = RecordedSource(tmp_path)
        source.open()
        assert decoded == []
        source.read()
        assert decoded == ["frame_0000.png"]

    def test_read_before_open_and_double_close(self, tmp_path: Path) -> None:
        write_images(tmp_path, 1)
        source = RecordedSource(tmp_path)
        with pytest.raises(SourceError, match="not open"):
            source.read()
        source.open()
        source.close()
        source.close()
        with pytest.raises(SourceError, match="not open"):
            source.read()


def test_a_sleep_that_returns_true_cuts_the_wait_short(tmp_path: Path) -> None:
    write_images(tmp_path, 3)
    clock = FakeClock()
    calls: List[float] = []

    def interrupted(seconds: float) -> bool:  # like a set threading.Event's wait()
        calls.append(seconds)
        return True

    source = RecordedSource(tmp_path, fps=10, clock=clock, sleep=interrupted)
    source.open()
    source.read()
    frame = source.read()
    assert frame is not None and frame.index == 1
    assert calls == [pytest.approx(0.1)]  # one wait, no spinning


def test_looping_frames_are_cached_but_not_shared(tmp_path: Path) -> None:
    write_images(tmp_path, 2)
    source = RecordedSource(tmp_path, loop=True)
    source.open()
    first = source.read()
    assert first is not None
    first.image[:] = 255  # a consumer drawing on its frame
    source.read()
    again = source.read()
    assert again is not None and again.name == first.name
    assert frame_brightness(again.image) == 5


def test_lores_is_the_frame_in_yuv420_and_is_kept_when_looping(static_clip):
    from rangebearing.core.yuv import yuv420_from_bgr

    source = RecordedSource(static_clip, loop=True, lores=True)
    source.open()
    try:
        frames = [source.read() for _ in range(14)]  # 12 files: the last two come round again
    finally:
        source.close()
    first, again = frames[0], frames[12]
    assert first is not None and again is not None and first.lores_yuv420 is not None
    want = yuv420_from_bgr(first.image)
    assert np.array_equal(first.lores_yuv420.u, want.u) and np.array_equal(first.lores_yuv420.y, want.y)
    assert again.lores_yuv420 is first.lores_yuv420  # converted once, like a camera's free stream
    plain = RecordedSource(static_clip)
    plain.open()
    try:
        assert plain.read().lores_yuv420 is None  # type: ignore[union-attr]
    finally:
        plain.close()


def test_in_place_hands_out_the_cached_frames_read_only_uncopied(tmp_path: Path) -> None:
    write_images(tmp_path, 2)
    source = RecordedSource(tmp_path, loop=True, in_place=True)
    source.open()
    first, _, again = source.read(), source.read(), source.read()
    assert first is not None and again is not None and again.name == first.name
    assert again.image is first.image  # decoded once, as a camera hands over its buffer
    assert not first.image.flags.writeable and not first.borrowed  # immutable, so safe to keep
    with pytest.raises(ValueError):
        first.image[0, 0] = 255  # a consumer cannot alter the next loop
