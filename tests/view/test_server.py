"""The view server over real loopback sockets: the page, the streams, the JSON, 400s for bad requests."""

from __future__ import annotations

import http.client
import json
import shutil
import time
from pathlib import Path
from typing import Any, Dict, Iterator, Optional, Tuple

import cv2
import numpy as np
import pytest

from rangebearing.config import Config, load_config
from rangebearing.errors import ServeError
from rangebearing.view import Thresholds, ViewHub, ViewServer
from tests.view.feeder import Feeder

REPO = Path(__file__).resolve().parents[2]
CLIP = REPO / "samples" / "clip"


@pytest.fixture
def served(tmp_path: Path) -> Iterator[Tuple[ViewServer, Feeder, Path]]:
    cfg_path = tmp_path / "rangebearing.yaml"
    shutil.copy(REPO / "config" / "rangebearing.yaml", cfg_path)
    cfg = Config()
    hub = ViewHub(Thresholds.of(cfg.detection), max_fps=20, config_file=str(cfg_path), hfov_rad=cfg.camera.hfov_rad)
    with ViewServer(hub, "127.0.0.1", 0) as srv, Feeder(hub, CLIP, cfg, fps=30) as feeder:
        yield srv, feeder, cfg_path


def request(
    srv: ViewServer, method: str, path: str, body: Optional[bytes] = None, headers: Optional[Dict[str, str]] = None
) -> Tuple[int, Dict[str, str], bytes]:
    conn = http.client.HTTPConnection(*srv.address, timeout=10)
    try:
        conn.request(method, path, body=body, headers=headers or {})
        r = conn.getresponse()
        return r.status, dict(r.getheaders()), r.read()
    finally:
        conn.close()


def post_json(srv: ViewServer, path: str, obj: Any, **headers: str) -> Tuple[int, Any]:
    headers = {"Content-Type": "application/json", **headers}
    status, _, body = request(srv, "POST", path, json.dumps(obj).encode(), headers)
    return status, json.loads(body)


def test_page_and_static_files(served) -> None:
    srv, _, _ = served
    status, head, body = request(srv, "GET", "/")
    assert status == 200 and head["Content-Type"].startswith("text/html") and b'src="/static/app.js"' in body
    status, head, body = request(srv, "GET", "/static/app.js")
    assert status == 200 and "javascript" in head["Content-Type"] and b"EventSource" in body
    for bad in ("/static/../server.py", "/static/hub.py", "/nope", "/static/"):
        status, head, body = request(srv, "GET", bad)
        assert status == 404 and "error" in json.loads(body)
    assert request(srv, "POST", "/stream.mjpg")[0] == 405
    assert request(srv, "GET", "/api/save")[0] == 405


def test_state_has_the_clips_landmarks(served) -> None:
    srv, _, _ = served
    status, head, body = request(srv, "GET", "/api/state")
    assert status == 200 and head["Content-Type"] == "application/json"
    state = json.loads(body)
    assert state["seq"] >= 1 and state["frame"]["width"] == 640
    bearings = sorted(lm["bearing_rad"] for lm in state["landmarks"])
    assert len(bearings) == 2 and bearings[0] < -0.2 and 0.1 < bearings[1] < 0.2  # one right, one left
    assert state["thresholds"]["s_min"] == 90


def test_mjpeg_stream_delivers_jpeg_frames(served) -> None:
    srv, _, _ = served
    conn = http.client.HTTPConnection(*srv.address, timeout=10)
    conn.request("GET", "/stream.mjpg")
    r = conn.getresponse()
    assert r.status == 200 and r.getheader("Content-Type").startswith("multipart/x-mixed-replace; boundary=")
    boundary = r.getheader("Content-Type").split("boundary=")[1].encode()
    images = []
    assert r.readline().strip() == b"--" + boundary
    for _ in range(2):
        headers = {}
        while (line := r.readline().strip()) != b"":
            k, _, v = line.decode().partition(":")
            headers[k.lower()] = v.strip()
        assert headers["content-type"] == "image/jpeg"
        data = r.read(int(headers["content-length"]))
        assert r.readline() == b"\r\n" and r.readline().strip() == b"--" + boundary  # the part ends at once
        images.append(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR))
    conn.close()
    assert all(im.shape == (480, 640, 3) for im in images)


def test_events_stream_and_masks(served) -> None:
    srv, _, _ = served
    conn = http.client.HTTPConnection(*srv.address, timeout=10)
    conn.request("GET", "/api/events")
    r = conn.getresponse()
    assert r.getheader("Content-Type") == "text/event-stream"
    line = r.readline()
    assert line.startswith(b"data: ")
    assert len(json.loads(line[6:])["landmarks"]) == 2
    conn.close()
    status, head, body = request(srv, "GET", "/frame.jpg?layer=masks")
    assert status == 200 and head["Content-Type"] == "image/jpeg"
    assert cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_COLOR).shape == (240, 320, 3)


@pytest.mark.parametrize("query", ["layer=x", "layer=frame&layer=masks", "size=2"])
def test_bad_query_parameters(served, query: str) -> None:
    srv, _, _ = served
    for path in ("/frame.jpg", "/stream.mjpg"):
        status, _, body = request(srv, "GET", f"{path}?{query}")
        error = json.loads(body)["error"]
        assert status == 400 and query.split("=")[0] in error


def test_thresholds_change_detection_live(served) -> None:
    srv, feeder, _ = served
    status, body = post_json(srv, "/api/thresholds", {"s_min": 255})
    assert status == 200 and body["thresholds"]["s_min"] == 255
    deadline = time.monotonic() + 10.0  # the loop rebuilds its pipeline between frames: poll until it has
    while True:
        state = json.loads(request(srv, "GET", "/api/state")[2])
        if (state["thresholds"]["s_min"] == 255 and state["landmarks"] == []) or time.monotonic() > deadline:
            break
        time.sleep(0.01)
    assert state["thresholds"]["s_min"] == 255 and state["landmarks"] == []
    assert feeder.cfg.detection.s_min == 255


def test_bad_thresholds_get_400_and_change_nothing(served) -> None:
    srv, _, _ = served
    status, body = post_json(srv, "/api/thresholds", {"s_min": 256, "red_hue": [[20, 10]]})
    assert status == 400 and "s_min" in body["error"] and "red_hue" in body["error"]
    status, _, raw = request(srv, "POST", "/api/thresholds", b"{not json", {"Content-Type": "application/json"})
    assert status == 400 and "not valid JSON" in json.loads(raw)["error"]
    status, _, raw = request(srv, "POST", "/api/thresholds", b'{"s_min": 1}', {"Content-Type": "text/plain"})
    assert status == 400 and "application/json" in json.loads(raw)["error"]
    status, body = post_json(srv, "/api/thresholds", {"s_min": 1}, Origin="http://evil.example")
    assert status == 403
    assert json.loads(request(srv, "GET", "/api/thresholds")[2])["thresholds"]["s_min"] == 90
    assert request(srv, "GET", "/api/state")[0] == 200  # still serving


def test_save_writes_the_config_with_a_backup(served) -> None:
    srv, _, cfg_path = served
    old = cfg_path.read_bytes()
    post_json(srv, "/api/thresholds", {"s_min": 100, "blue_hue": [[95, 130]]})
    status, body = post_json(srv, "/api/save", {})
    assert status == 200 and body["saved"] == str(cfg_path)
    assert Path(body["backup"]).read_bytes() == old
    det = load_config(cfg_path).detection
    assert (det.s_min, det.blue_hue) == (100, ((95, 130),))


def test_save_without_a_config_file() -> None:
    hub = ViewHub(Thresholds.of(Config().detection))
    with ViewServer(hub, "127.0.0.1", 0) as srv:
        status, body = post_json(srv, "/api/save", {})
    assert status == 409 and "without --config" in body["error"]


def test_a_failing_handler_answers_500_and_serving_goes_on(served, monkeypatch: pytest.MonkeyPatch) -> None:
    srv, _, _ = served
    monkeypatch.setattr(ViewHub, "thresholds", property(lambda self: 1 / 0))
    status, _, body = request(srv, "GET", "/api/thresholds")
    assert status == 500 and "ZeroDivisionError" in json.loads(body)["error"]
    monkeypatch.undo()
    assert request(srv, "GET", "/api/thresholds")[0] == 200


def test_port_in_use_is_a_clear_error(served) -> None:
    srv, _, _ = served
    with pytest.raises(ServeError, match=r"cannot listen on 127\.0\.0\.1"):
        ViewServer(ViewHub(Thresholds.of(Config().detection)), "127.0.0.1", srv.address[1])
