"""Recorded frames' bytes: bounded decoding, the reason a frame does not decode, and a quiet stderr."""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path
from typing import Callable, Dict

import cv2
import numpy as np
import pytest

from rangebearing.sources import image_bytes
from rangebearing.sources.image_bytes import decode, decode_file
from rangebearing.sources.image_damage import why_bytes_undecodable, why_undecodable


def _frame() -> np.ndarray:
    return (np.random.default_rng(5).random((48, 64, 3)) * 255).astype(np.uint8)


def _png() -> bytes:
    return bytes(cv2.imencode(".png", _frame())[1])


def _jpg() -> bytes:
    return bytes(cv2.imencode(".jpg", _frame())[1])


def _bmp() -> bytes:
    return bytes(cv2.imencode(".bmp", _frame())[1])


def _flip(data: bytes, i: int) -> bytes:
    out = bytearray(data)
    out[i] ^= 0x5A
    return bytes(out)


def _idat_payload_flipped(data: bytes) -> bytes:
    i = data.index(b"IDAT") + 4 + 10  # inside the chunk's data: the type and length stay valid
    return _flip(data, i)


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


DAMAGE: Dict[str, tuple[Callable[[], bytes], str]] = {
    "png cut in IDAT": (lambda: _png()[: len(_png()) // 2], "truncated: the PNG is cut short in its IDAT chunk"),
    "png without IEND": (lambda: _png()[:-12], "truncated: the PNG ends after its IDAT chunk"),
    "png IDAT data flipped": (lambda: _idat_payload_flipped(_png()), "corrupt: the PNG's IDAT chunk at byte 33 fails"),
    "png IHDR flipped": (lambda: _flip(_png(), 20), "corrupt: the PNG's IHDR chunk at byte 8 fails its CRC check"),
    "png chunk type damaged": (lambda: _flip(_png(), 38), "corrupt: the PNG chunk at byte 33 has no valid type"),
    "png signature via text mode": (lambda: _png().replace(b"\r\n", b"\n", 1), "corrupt: a damaged PNG signature"),
    "png without pixels": (
        lambda: _png()[:33] + _chunk(b"IEND", b""), "corrupt: the PNG has no IDAT chunk"),
    "jpeg cut in headers": (lambda: _jpg()[:100], "truncated: the JPEG is cut short in its headers"),
    "jpeg cut in its data": (lambda: _jpg()[: len(_jpg()) // 2], "truncated: the JPEG's image data is cut short"),
    "bmp cut short": (lambda: _bmp()[:500], "truncated: the BMP has 500 of the"),
    "text": (lambda: b"hello, not an image", "not an image (no PNG, JPEG or BMP header)"),
}


@pytest.mark.parametrize("damage", sorted(DAMAGE))
def test_a_damaged_image_says_what_is_wrong_and_nothing_reaches_stderr(
    damage: str, capfd: pytest.CaptureFixture[str]
) -> None:
    make, reason = DAMAGE[damage]
    data = make()
    assert decode(data) is None
    assert reason in why_bytes_undecodable(data)
    out, err = capfd.readouterr()
    assert err == "" and out == ""  # libpng / libjpeg / OpenCV print to fd 2 unless it is captured


def test_good_images_decode_and_a_jpeg_with_extra_bytes_still_does(capfd: pytest.CaptureFixture[str]) -> None:
    for data in (_png(), _bmp()):
        assert np.array_equal(decode(data), _frame())
    jpg = _jpg()
    image = decode(jpg[:-2] + b"\x00\x00\x00" + jpg[-2:])  # "Corrupt JPEG data: 3 extraneous bytes before marker"
    assert image is not None and image.shape == (48, 64, 3)
    assert capfd.readouterr().err == ""


def test_what_the_decoder_prints_is_kept_and_another_threads_logging_passes(capfd: pytest.CaptureFixture[str]) -> None:
    with image_bytes._decoder_output() as said:
        os.write(2, b"libpng error: IDAT: CRC error\n2026-12-03 06:00:00,000 INFO rangebearing.x: still here\n")
        os.write(2, b"[ERROR:0@0.025] global loadsave.cpp:1412 imdecode_ imdecode_(''): can't read data: "
                    b"OpenCV(5.1.0) /io/bitstrm.cpp:59: error: (-2:Unspecified error) Unexpected end\n")
    assert said == ["libpng error: IDAT: CRC error", "can't read data: Unexpected end"]
    assert capfd.readouterr().err == "2026-12-03 06:00:00,000 INFO rangebearing.x: still here\n"
    with image_bytes._decoder_output() as said:  # another thread's traceback is no decoder's line: not swallowed
        os.write(2, b"Traceback (most recent call last):\n  File \"x.py\", line 1\nValueError: boom\n"
                    b"Corrupt JPEG data: 3 extraneous bytes before marker 0xd9\n")
    assert said == ["Corrupt JPEG data: 3 extraneous bytes before marker 0xd9"]
    assert capfd.readouterr().err == 'Traceback (most recent call last):\n  File "x.py", line 1\nValueError: boom\n'
    with image_bytes._decoder_output() as said:  # the scratch file is emptied for the next frame
        pass
    assert said == []


def test_the_file_reason_reads_the_whole_file(tmp_path: Path) -> None:
    big = (np.random.default_rng(1).random((600, 800, 3)) * 255).astype(np.uint8)
    data = bytes(cv2.imencode(".png", big)[1])
    assert len(data) > 200_000  # past the 64 KiB header read
    path = tmp_path / "f.png"
    path.write_bytes(data[:-5000])
    assert decode_file(path) is None
    assert why_undecodable(path).startswith("truncated: the PNG is cut short in its IDAT chunk")
    (tmp_path / "e.png").write_bytes(b"")
    assert why_undecodable(tmp_path / "e.png") == "an empty file (0 bytes)"


def test_a_recorded_mcap_frame_says_why_it_does_not_decode(tmp_path: Path) -> None:
    pytest.importorskip("mcap")
    from rangebearing.errors import FrameError
    from rangebearing.recording.mcap_format import IMAGE_TOPIC, image_message
    from rangebearing.recording.mcap_reader import McapRecording
    from rangebearing.recording.mcap_writer import McapRecorder
    from rangebearing.sources.recorded import RecordedSource, iter_recorded

    path = tmp_path / "r.mcap"
    with McapRecorder(path) as rec:
        rec.write_image(_frame(), 1_000, 0)
        rec._add(IMAGE_TOPIC, 2_000, image_message(_png()[:300], "png", 2_000), 1)
        rec._add(IMAGE_TOPIC, 3_000, b'{"not": "an image"}', 2)
    frames = list(McapRecording(path).frames())
    assert [f.image is None for f in frames] == [False, True, True]
    assert frames[1].why.startswith("its png data: truncated: the PNG is cut short in its IDAT chunk")
    assert frames[2].why.startswith(f"the message on {IMAGE_TOPIC} is not a foxglove.CompressedImage")
    reasons: Dict[str, str] = {}
    assert [n for n, im in iter_recorded(path, reasons) if im is None] == ["1", "2"]
    assert reasons == {"1": frames[1].why, "2": frames[2].why}
    src = RecordedSource(path)
    src.open()
    try:
        assert src.read() is not None
        for expected in (frames[1].why, frames[2].why):
            with pytest.raises(FrameError) as info:
                src.read()
            assert expected in str(info.value)
    finally:
        src.close()
