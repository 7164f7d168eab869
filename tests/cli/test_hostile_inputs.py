"""Hostile inputs through every command that reads them, run in-process as a user runs the CLI.

Each kind of input (configs, recorded frames, MCAP files) is thrown at the real
``main()``; every case asserts the exit status, ONE clear error line from the
error funnel (``rangebearing: error: ...``, never a traceback nor the funnel's
"a bug?" fallback) and that nothing is lost: the good frames are all processed
and every bad one is counted as skipped.
"""

from __future__ import annotations

import logging
import random
import shutil
import struct
import zlib
from pathlib import Path
from typing import Dict, List, Tuple

import cv2
import numpy as np
import pytest

from rangebearing.cli.main import main

# --- helpers ------------------------------------------------------------------------------


def call(argv: List[str], capsys: pytest.CaptureFixture[str]) -> Tuple[int, str, str]:
    """Exit status, stdout and stderr of one in-process CLI call; fails on any sign of a crash."""
    status = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "a bug?" not in err, err
    assert len([ln for ln in err.splitlines() if ln.startswith("rangebearing: error:")]) <= 1, err
    return status, out, err


def error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.startswith("rangebearing: error:")]
    assert len(lines) == 1, err
    return lines[0]


def png_header_only(width: int, height: int) -> bytes:
    """A valid PNG signature and IHDR claiming ``width``×``height`` with a tiny IDAT: a decompression bomb's shape."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 4096, 9))
            + chunk(b"IEND", b""))


# --- configs --------------------------------------------------------------------------------

ALIAS_BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{n}: &{n} [{', '.join([f'*{p}'] * 9)}]\n" for p, n in zip("abcde", "bcdef"))

HOSTILE_CONFIGS: Dict[str, Tuple[bytes, List[str]]] = {  # content, what the error must say
    "unknown keys and a wrong type": (b"bogus: 1\ndetection:\n  s_min: lots\n  typo_key: 3\n",
                                      ["unknown section 'bogus'", "detection.s_min", "detection.typo_key"]),
    "nan and inf": (b"camera:\n  fx_px: .nan\n  fy_px: .inf\n", ["camera.fx_px", "camera.fy_px"]),
    "huge numbers": (b"camera:\n  fx_px: 1e400\npublish:\n  multicast_port: 99999999999999999999999\n",
                     ["camera.fx_px", "publish.multicast_port"]),
    "alias bomb": (ALIAS_BOMB.encode(), ["alias bomb"]),
    "binary": (b"\xff\xfe" + random.Random(3).randbytes(2000), ["not UTF-8"]),
    "empty": (b"", ["empty"]),
    "blank lines only": (b"\n  \n", ["empty"]),
    "a list at the top": (b"- 1\n- 2\n", ["top level must be a mapping"]),
    "a python tag": (b"camera: !!python/object/apply:os.system [echo hi]\n", ["not valid YAML"]),
    "deep nesting": (b"a: " + b"[" * 3000 + b"]" * 3000 + b"\n", ["nesting deeper"]),
    "a NUL byte": (b"camera:\n  fx_px: 500\x00\n", ["not valid YAML"]),
    "UTF-16": ("camera:\n  fx_px: 500\n".encode("utf-16"), ["not UTF-8"]),
    "over 64 KiB": (b"# " + b"x" * 70000 + b"\n", ["larger than 64 KiB"]),
}


@pytest.fixture(scope="module")
def clip(tmp_path_factory: pytest.TempPathFactory, static_clip: Path) -> Path:
    """Three frames of the static clip and a truth file for them."""
    path = tmp_path_factory.mktemp("hostile") / "clip"
    path.mkdir()
    for src in sorted(static_clip.glob("*.png"))[:3]:
        shutil.copy(src, path / src.name)
    rows = "".join(f"{p.name},0.45,0.20\n{p.name},0.80,-0.15\n" for p in sorted(path.glob("*.png")))
    (path.parent / "truth.csv").write_text("frame,range_m,bearing_rad\n" + rows)
    return path


def commands_with_config(cfg: Path, clip: Path, out: Path) -> Dict[str, List[str]]:
    truth = str(clip.parent / "truth.csv")
    return {
        "run": ["run", "--check", "--config", str(cfg)],
        "replay": ["replay", str(clip), "-q", "--config", str(cfg)],
        "record": ["record", "--config", str(cfg), "--frames", "1", "--out", str(out / "rec")],
        "calibrate": ["calibrate", str(clip), "--truth", truth, "--out", str(out / "cal.yaml"), "--config", str(cfg)],
        "intrinsics": ["intrinsics", str(clip), "--board", "9x6", "--square-mm", "25", "--out",
                       str(out / "intr.yaml"), "--config", str(cfg)],
        "tune": ["tune", "--config", str(cfg), "--out", str(out / "tuned.yaml")],
    }


@pytest.mark.parametrize("kind", list(HOSTILE_CONFIGS))
def test_a_hostile_config_is_refused_by_every_command_with_every_problem_named(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    content, says = HOSTILE_CONFIGS[kind]
    cfg = tmp_path / "hostile.yaml"
    cfg.write_bytes(content)
    for name, argv in commands_with_config(cfg, clip, tmp_path).items():
        status, _out, err = call(argv, capsys)
        assert status == 2, (name, err)
        assert str(cfg) in error_line(err), (name, err)
        for fragment in says:  # every problem at once, not the first one only
            assert fragment in err, (name, fragment, err)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["hostile.yaml"], name  # nothing written


@pytest.mark.parametrize("what", ["a directory", "a missing file", "/dev/zero"])
def test_a_config_that_is_no_file_is_refused(what: str, tmp_path: Path, clip: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    cfg = {"a directory": tmp_path, "a missing file": tmp_path / "nope.yaml", "/dev/zero": Path("/dev/zero")}[what]
    for name, argv in commands_with_config(cfg, clip, tmp_path / "out").items():
        status, _out, err = call(argv, capsys)
        assert status == 2, (name, err)
        assert str(cfg) in error_line(err), (name, err)


# --- recorded frames --------------------------------------------------------------------------


def _frames(clip: Path) -> List[np.ndarray]:
    return [cv2.imread(str(p), cv2.IMREAD_COLOR) for p in sorted(clip.glob("*.png"))]


def hostile_recording(kind: str, clip: Path, where: Path) -> Tuple[Path, int, int]:
    """A directory of two good frames and the hostile ones: (path, frames processed, frames skipped)."""
    good = _frames(clip)
    d = where / kind.replace(" ", "_")
    d.mkdir()
    cv2.imwrite(str(d / "000.png"), good[0])
    cv2.imwrite(str(d / "009.png"), good[1])
    png = cv2.imencode(".png", good[2])[1].tobytes()
    jpg = cv2.imencode(".jpg", good[2])[1].tobytes()
    if kind == "non-image files":
        (d / "003.png").write_text("not an image")
        (d / "notes.txt").write_text("ignored: not an image name")
        return d, 2, 1
    if kind == "truncated png and jpeg":
        (d / "003.png").write_bytes(png[: len(png) // 2])
        (d / "004.jpg").write_bytes(jpg[:600])
        (d / "005.png").write_bytes(b"")
        return d, 2, 3
    if kind == "16-bit grey and alpha":  # decoded as 8-bit BGR: processed, not skipped
        cv2.imwrite(str(d / "003.png"), good[2].astype(np.uint16) * 257)
        cv2.imwrite(str(d / "004.png"), cv2.cvtColor(good[2], cv2.COLOR_BGR2GRAY))
        cv2.imwrite(str(d / "005.png"), cv2.cvtColor(good[2], cv2.COLOR_BGR2BGRA))
        return d, 5, 0
    if kind == "huge images":  # headers claiming 40000×40000 (a 1.6 Gpx bomb) and 9000×9000 (81 Mpx)
        (d / "003.png").write_bytes(png_header_only(40000, 40000))
        (d / "004.png").write_bytes(png_header_only(9000, 9000))
        return d, 2, 2
    if kind == "mixed sizes":  # half size (same aspect: used) and another aspect ratio (skipped)
        cv2.imwrite(str(d / "003.png"), cv2.resize(good[2], (320, 240), interpolation=cv2.INTER_AREA))
        cv2.imwrite(str(d / "004.png"), good[2][:, :600])
        return d, 3, 1
    if kind == "broken links":  # a dangling link and a loop named like frames: bad frames, counted, not missing
        (d / "003.png").symlink_to(where / "nowhere.png")
        (d / "004.png").symlink_to(d / "005.png")
        (d / "005.png").symlink_to(d / "004.png")
        return d, 2, 3
    raise AssertionError(kind)


RECORDINGS = ["non-image files", "truncated png and jpeg", "16-bit grey and alpha", "huge images", "mixed sizes",
              "broken links"]


@pytest.mark.parametrize("kind", RECORDINGS)
def test_replay_processes_every_good_frame_and_counts_every_bad_one(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, good, bad = hostile_recording(kind, clip, tmp_path)
    status, out, err = call(["replay", str(path)], capsys)
    assert status == 0, err
    assert len(out.splitlines()) == good, out
    assert len([ln for ln in err.splitlines() if ": skipped: " in ln]) == bad, err
    if bad:
        assert f"{bad} frame(s) skipped" in err
    for name in ("000.png", "009.png"):  # the good frames, with both landmarks
        line = next(ln for ln in out.splitlines() if ln.startswith(name))
        assert line.count(" m ") == 2, line


@pytest.mark.parametrize("kind", RECORDINGS)
def test_the_daemon_sends_a_reading_for_every_good_frame_and_counts_every_bad_one(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="rangebearing.daemon")
    path, good, bad = hostile_recording(kind, clip, tmp_path)
    status, out, err = call(["run", "--source", str(path), "--fps", "0", "--echo"], capsys)
    assert status == 0, err
    assert len(out.splitlines()) == good, out  # one datagram a good frame (--echo prints each)
    stopped = [r.getMessage() for r in caplog.records if r.getMessage().startswith("stopped:")]
    assert len(stopped) == 1 and f"bad {bad}," in stopped[0], stopped


@pytest.mark.parametrize("kind", RECORDINGS)
def test_record_keeps_every_good_frame_and_counts_every_bad_one(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, good, bad = hostile_recording(kind, clip, tmp_path)
    if kind == "mixed sizes":  # frames are kept as they came: only the pipeline needs one aspect ratio
        good, bad = good + bad, 0
    out_dir = tmp_path / "recorded"
    status, out, err = call(["record", "--source", str(path), "--frames", str(good + bad), "--out", str(out_dir),
                             "-q"], capsys)
    assert status == 0, err
    assert len(list(out_dir.glob("*.png"))) == good
    assert f"{bad} bad" in out + err, out + err


@pytest.mark.parametrize("kind", ["huge images", "truncated png and jpeg"])
def test_intrinsics_and_calibrate_skip_bad_frames_with_a_clear_error(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _good, _bad = hostile_recording(kind, clip, tmp_path)
    status, _out, err = call(["intrinsics", str(path), "--board", "9x6", "--square-mm", "25",
                              "--out", str(tmp_path / "i.yaml"), "-q"], capsys)
    assert status == 1 and "the board was found in 0" in err, err  # no chessboard in these frames: said, no crash
    truth = tmp_path / "truth.csv"
    truth.write_text("frame,range_m,bearing_rad\n000.png,0.45,0.20\n000.png,0.80,-0.15\n")
    status, _out, err = call(["calibrate", str(path), "--truth", str(truth), "--out", str(tmp_path / "c.yaml"),
                              "-q"], capsys)
    assert status == 1 and "rangebearing: error:" in err, err  # one station is too few to fit: said, no crash


@pytest.mark.parametrize("argv", [["replay", "{}"], ["run", "--source", "{}"], ["intrinsics", "{}", "--board", "9x6",
                                  "--square-mm", "25", "--out", "{}/i.yaml"],
                                  ["record", "--source", "{}", "--frames", "1", "--out", "{}_out"]])
def test_an_empty_recording_is_one_clear_error_at_once(argv: List[str], tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str],
                                                      caplog: pytest.LogCaptureFixture) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "truth.csv").write_text("frame,range_m,bearing_rad\n")
    status, _out, err = call([a.replace("{}", str(empty)) for a in argv], capsys)
    assert status == 1
    said = err + " ".join(r.getMessage() for r in caplog.records)
    assert "holds no images" in said
    assert "retrying" not in said  # a recording that is not there does not appear by waiting (no minute of retries)


# --- MCAP recordings ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def mcap_bytes(clip: Path, tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """Three frames of the clip recorded by ``record`` into MCAP (PNG frames, one chunk each or so)."""
    pytest.importorskip("mcap")
    out = tmp_path_factory.mktemp("mcap") / "good.mcap"
    assert main(["record", "--source", str(clip), "--frames", "3", "--out", str(out), "--format", "png", "-q"]) == 0
    return out.read_bytes()


def _flipped(data: bytes, seed: int) -> bytes:
    rng = random.Random(seed)
    out = bytearray(data)
    for _ in range(rng.randrange(1, 8)):
        i = rng.randrange(8, len(out))
        out[i] = rng.randrange(256)
    return bytes(out)


def _chunk_length_huge(data: bytes) -> bytes:
    out = bytearray(data)
    i = out.index(b"\x06", 8)  # the first chunk record's opcode (after the magic and the header)
    out[i + 1:i + 9] = (1 << 62).to_bytes(8, "little")
    return bytes(out)


DAMAGED = {
    "cut after the magic": lambda b: b[:8],
    "cut at a third": lambda b: b[: len(b) // 3],
    "cut at two thirds": lambda b: b[: 2 * len(b) // 3],
    "footer cut": lambda b: b[:-10],
    "a chunk length of 2**62": _chunk_length_huge,
    **{f"bytes flipped (seed {s})": (lambda b, s=s: _flipped(b, s)) for s in range(6)},
}


@pytest.mark.parametrize("damage", list(DAMAGED))
def test_a_damaged_mcap_plays_what_it_can_and_says_where_it_ends(
    damage: str, tmp_path: Path, mcap_bytes: bytes, capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "damaged.mcap"
    path.write_bytes(DAMAGED[damage](mcap_bytes))
    status, out, err = call(["replay", str(path)], capsys)
    assert status == 0, err
    played, skipped = len(out.splitlines()), len([ln for ln in err.splitlines() if ": skipped: " in ln])
    assert played + skipped <= 3
    if damage.startswith("cut") or damage.startswith("a chunk"):
        assert any("cut short or damaged" in r.getMessage() for r in caplog.records), caplog.records
    if damage == "cut at two thirds":
        assert played >= 1  # the chunks before the cut
    caplog.clear()
    status, out, err = call(["run", "--source", str(path), "--fps", "0", "--echo"], capsys)
    assert status == 0, err
    assert len(out.splitlines()) == played  # the daemon sends what replay read


@pytest.mark.parametrize("content", [b"", b"NOTMCAP0" + bytes(200), b"\x89PNG\r\n\x1a\n"])
def test_a_file_named_mcap_that_is_not_one_is_one_clear_error(
    content: bytes, tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "x.mcap"
    path.write_bytes(content)
    for argv in (["replay", str(path)], ["run", "--source", str(path), "--fps", "0"]):
        status, _out, err = call(argv, capsys)
        said = err + " ".join(r.getMessage() for r in caplog.records)
        assert status == 1 and "not an MCAP file" in said, said
        assert "retrying" not in said
        caplog.clear()


@pytest.mark.parametrize("onto", ["the config", "a frame", "the recording's folder"])
def test_run_never_records_over_what_it_reads(onto: str, tmp_path: Path, clip: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    """``run --config c.yaml --record c.yaml`` replaced the config with an MCAP file and exited 0."""
    frames = tmp_path / "frames"
    shutil.copytree(clip, frames)
    cfg = tmp_path / "c.yaml"
    cfg.write_text("detection: {max_landmarks: 8}\n")
    target = {"the config": cfg, "a frame": next(frames.glob("*.png")), "the recording's folder": frames}[onto]
    before = {p: p.read_bytes() for p in [cfg, *frames.iterdir()]}
    status, _out, err = call(["run", "--config", str(cfg), "--source", str(frames), "--fps", "0",
                              "--record", str(target)], capsys)
    assert status == 1 and "--record: will not write" in error_line(err), err
    assert {p: p.read_bytes() for p in [cfg, *frames.iterdir()]} == before


@pytest.mark.parametrize("limit", [["--frames", "0"], ["--frames", "-1"], ["--seconds", "nan"], ["--seconds", "-1"],
                                   ["--seconds", "1e300"]])
def test_record_refuses_a_limit_that_records_nothing(limit: List[str], tmp_path: Path, clip: Path) -> None:
    """record --frames 0 / --seconds nan recorded nothing and exited 0."""
    with pytest.raises(SystemExit) as info:
        main(["record", "--source", str(clip), *limit, "--out", str(tmp_path / "out"), "-q"])
    assert info.value.code == 2
    assert not (tmp_path / "out").exists()


WHY = {  # each skipped frame's line says why it is unreadable
    "non-image files": {"003.png": "not an image (no PNG, JPEG or BMP header)"},
    "truncated png and jpeg": {"003.png": "truncated: the PNG is cut short in its IDAT chunk",
                               "004.jpg": "truncated: the JPEG is cut short in its headers",
                               "005.png": "an empty file (0 bytes)"},
    "huge images": {"003.png": "its header says 40000×40000 = 1600000000 px, over the 67108864 px",
                    "004.png": "its header says 9000×9000 = 81000000 px, over the 67108864 px"},
    "broken links": {"003.png": "No such file or directory", "004.png": "Too many levels of symbolic links"},
}


@pytest.mark.parametrize("kind", sorted(WHY))
def test_replay_and_the_daemon_say_why_a_frame_is_unreadable(
    kind: str, tmp_path: Path, clip: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    path, _, _ = hostile_recording(kind, clip, tmp_path)
    status, _, err = call(["replay", str(path), "-q"], capsys)
    assert status == 0, err
    skipped = {ln.split(": ", 1)[0]: ln for ln in err.splitlines() if ": skipped: " in ln}
    for name, why in WHY[kind].items():
        assert f"{name}: skipped: unreadable image: {why}" in skipped[name], err
    caplog.set_level(logging.DEBUG, logger="rangebearing")
    status, _, err = call(["run", "--source", str(path), "--fps", "0"], capsys)
    assert status == 0, err
    logged = "\n".join(r.getMessage() for r in caplog.records) + err
    for name, why in WHY[kind].items():
        assert f"{name}: unreadable image: {why}" in logged, logged
