"""MCAP recordings: bit-exact round trips, the mcap library's own reader, cut-short files, the writer thread."""

from __future__ import annotations

import base64
import json
import os
import subprocess
import sys
from importlib import resources
from pathlib import Path
from typing import Iterator, List

import jsonschema
import numpy as np
import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import MissingExtraError, RecordingError
from rangebearing.net.protocol import RemoteLandmark, decode_reading, encode_reading
from rangebearing.recording import CALIBRATION_TOPIC, IMAGE_TOPIC, READINGS_TOPIC, McapRecording, is_mcap
from rangebearing.recording.background import BackgroundRecorder, rotated_path
from rangebearing.recording.mcap_writer import McapRecorder

CAMERA = CameraIntrinsics(width_px=64, height_px=48, fx_px=63.4, fy_px=63.0, cx_px=31.5, cy_px=23.5,
                          distortion=(0.1, -0.02, 0.001, 0.0, 0.003))
LM = RemoteLandmark(0.5, 0.1, True, 40.0, 0.03, 0.0, (30.0, 20.0), (30.0, 24.0), 12.0)
T0_NS = 1_700_000_000_000_000_000


def frames(n: int, seed: int = 0) -> List[np.ndarray]:
    rng = np.random.default_rng(seed)  # noise: PNG cannot cheat, every bit counts
    return [rng.integers(0, 256, (48, 64, 3), dtype=np.uint8) for _ in range(n)]


def reading(seq: int) -> bytes:
    return encode_reading("zumo1", seq, (T0_NS + seq * 66_000_000) / 1e9, [LM] * (seq % 3), fps=15.0)


def schema(name: str) -> dict:
    return json.loads(resources.files("rangebearing").joinpath("schema", name).read_text("utf-8"))


@pytest.fixture
def recording(tmp_path: Path) -> Iterator[Path]:
    path = tmp_path / "clip.mcap"
    with McapRecorder(path, image_format="png") as rec:
        rec.write_calibration(CAMERA, T0_NS)
        for i, image in enumerate(frames(6)):
            t_ns = T0_NS + i * 66_000_000
            rec.write_image(image, t_ns, index=10 + i)
            rec.write_reading(reading(i), t_ns)
    yield path


def test_png_frames_readings_and_intrinsics_round_trip_exactly(recording: Path) -> None:
    rec = McapRecording(recording)
    got = list(rec.frames())
    assert not rec.truncated and is_mcap(recording)
    assert [f.position for f in got] == list(range(6))
    assert [f.index for f in got] == list(range(10, 16))
    assert [f.t_ns for f in got] == [T0_NS + i * 66_000_000 for i in range(6)]
    for f, image in zip(got, frames(6)):
        assert f.image is not None and f.image.dtype == np.uint8
        np.testing.assert_array_equal(f.image, image)
    assert [m.data for m in rec.readings()] == [reading(i) for i in range(6)]
    assert [decode_reading(m.data).landmarks for m in rec.readings()] == [(LM,) * (i % 3) for i in range(6)]
    assert rec.calibration() == CAMERA


def test_the_mcap_library_reads_our_file_with_schemas_attached(recording: Path) -> None:
    with open(recording, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics.message_count == 13
        messages = list(reader.iter_messages())
    by_topic = {}
    for sch, channel, message in messages:
        assert channel.message_encoding == "json" and sch is not None and sch.encoding == "jsonschema"
        by_topic.setdefault(channel.topic, []).append((json.loads(sch.data), message))
    assert sorted(by_topic) == sorted([IMAGE_TOPIC, CALIBRATION_TOPIC, READINGS_TOPIC])
    assert by_topic[READINGS_TOPIC][0][0] == schema("reading-v1.json")  # the v1 schema travels along
    for topic_messages in by_topic.values():
        for sch_doc, message in topic_messages:
            jsonschema.validate(json.loads(message.data), sch_doc)  # every message meets its schema
    image_schema, first_image = by_topic[IMAGE_TOPIC][0]
    assert image_schema["title"] == "foxglove.CompressedImage"
    msg = json.loads(first_image.data)
    assert msg["format"] == "png" and base64.b64decode(msg["data"])[:8] == b"\x89PNG\r\n\x1a\n"
    assert msg["timestamp"] == {"sec": T0_NS // 10**9, "nsec": 0} and first_image.log_time == T0_NS
    calib = json.loads(by_topic[CALIBRATION_TOPIC][0][1].data)
    assert calib["K"] == [63.4, 0.0, 31.5, 0.0, 63.0, 23.5, 0.0, 0.0, 1.0]
    assert calib["distortion_model"] == "plumb_bob" and len(calib["D"]) == 5


def test_jpeg_frames_come_back_close(tmp_path: Path) -> None:
    smooth = np.tile(np.linspace(0, 255, 64, dtype=np.uint8)[None, :, None], (48, 1, 3))
    with McapRecorder(tmp_path / "j.mcap", image_format="jpeg", jpeg_quality=95) as rec:
        rec.write_image(smooth, T0_NS, 0)
    (frame,) = McapRecording(tmp_path / "j.mcap").frames()
    assert frame.image is not None and frame.image.shape == smooth.shape
    assert np.abs(frame.image.astype(int) - smooth).max() <= 8


def test_a_file_cut_mid_chunk_gives_every_complete_chunk(tmp_path: Path) -> None:
    path = tmp_path / "cut.mcap"
    images = frames(40)
    with McapRecorder(path, chunk_bytes=30_000) as rec:  # ~2 noise frames per chunk
        for i, image in enumerate(images):
            rec.write_image(image, T0_NS + i, i)
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    assert len(chunks) >= 8
    k = len(chunks) // 2
    cut = chunks[k].chunk_start_offset + chunks[k].chunk_length // 2
    path.write_bytes(path.read_bytes()[:cut])  # as a killed process or a full disk leaves it
    rec = McapRecording(path)
    got = list(rec.frames())
    assert rec.truncated
    complete = [i for i in range(40) if T0_NS + i <= chunks[k - 1].message_end_time]
    assert [f.index for f in got] == complete  # every complete chunk, nothing of the cut one
    for f in got:
        np.testing.assert_array_equal(f.image, images[f.index])
    with open(path, "rb") as f, pytest.raises(McapError):  # an index-based reader refuses it outright
        list(make_reader(f).iter_messages())


def test_not_an_mcap_file_is_a_clear_error(tmp_path: Path) -> None:
    bad = tmp_path / "x.mcap"
    bad.write_bytes(b"PNG? no")
    with pytest.raises(RecordingError, match="not an MCAP file"):
        McapRecording(bad)
    with pytest.raises(RecordingError, match="cannot create"):
        McapRecorder(tmp_path / "no" / "such" / "dir.mcap")


def test_missing_mcap_is_a_clear_import_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mcap", None)
    monkeypatch.setitem(sys.modules, "mcap.writer", None)
    with pytest.raises(MissingExtraError, match=r"rangebearing\[mcap\]"):
        McapRecorder(tmp_path / "a.mcap")


def test_writer_thread_rotates_and_keeps_the_latest_files_complete(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    rec = BackgroundRecorder(path, CAMERA, max_bytes=60_000, image_format="png", queue_items=100)
    images = frames(12)
    for i, image in enumerate(images):
        rec.add_frame(image, T0_NS + i, i)
        rec.add_reading(reading(i), T0_NS + i)
    rec.close()
    assert rec.counts["rotations"] >= 2 and rec.counts["dropped"] == 0 and rec.failed is None
    older, newer = McapRecording(rotated_path(str(path))), McapRecording(path)
    old_frames, new_frames = list(older.frames()), list(newer.frames())
    assert not older.truncated and not newer.truncated  # both finished with a footer
    indices = [f.index for f in old_frames + new_frames]
    assert indices == list(range(indices[0], 12))  # contiguous, ending with the last frame
    assert newer.calibration() == CAMERA and older.calibration() == CAMERA
    for f in new_frames:
        np.testing.assert_array_equal(f.image, images[f.index])
    assert os.path.getsize(rotated_path(str(path))) < 60_000 + 40_000


def test_a_full_disk_stops_the_recording_not_the_caller(tmp_path: Path) -> None:
    mount = tmp_path / "tiny"
    mount.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=96k", "tmpfs", str(mount)],
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs to fill (needs root): {done.stderr.strip()}")
    try:
        rec = BackgroundRecorder(mount / "run.mcap", CAMERA, image_format="png", queue_items=400)
        for i, image in enumerate(frames(30)):  # ~9 kB each: the disk fills after ~10
            rec.add_frame(image, T0_NS + i, i)  # never raises, never blocks
        rec.close()
        assert rec.failed is not None and "No space left" in rec.failed
        assert rec.counts["errors"] == 1 and 0 < rec.counts["frames"] < 30
        rec.add_frame(frames(1)[0], T0_NS, 99)  # after the failure: ignored quietly
    finally:
        subprocess.run(["umount", str(mount)], check=False)
