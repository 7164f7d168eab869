"""The systemd unit and the Pi install script, checked with the real tools.

``systemd-analyze verify`` insists that ExecStart= names an existing executable,
and /opt/rangebearing/venv/bin/rangebearing exists only on an installed Pi.  So
the verify test checks a copy of the unit whose ExecStart= points at /bin/true
(same arguments); every other line is verified as shipped.  User=rangebearing
need not exist: verify does not resolve users.  Verify exits 0 even for unknown
keys and unparsable values, so the tests also fail on any message that names
the unit file.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[1]
UNIT = ROOT / "systemd" / "rangebearing.service"
INSTALL = ROOT / "systemd" / "install.sh"
INSTALLED_BIN = "/opt/rangebearing/venv/bin/rangebearing"
EXEC_START = f"{INSTALLED_BIN} run --config /etc/rangebearing/config.yaml"
MAX_EXPOSURE = 2.0
OVERALL = re.compile(r"Overall exposure level for rangebearing\.service: (\d+(?:\.\d+)?)")

ANALYZE = shutil.which("systemd-analyze")
Unit = List[Tuple[str, str, str]]
Stub = Tuple[Dict[str, str], Path]
needs_analyze = pytest.mark.skipif(ANALYZE is None, reason="systemd-analyze is not installed")


def parse_unit(text: str) -> Unit:
    """(section, key, value) for every assignment, in order, repeats kept."""
    out: Unit = []
    section = ""
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line[0] in "#;":
            continue
        if line.startswith("[") and line.endswith("]"):
            section = line[1:-1]
            continue
        key, sep, value = line.partition("=")
        assert sep, f"not an assignment: {raw!r}"
        assert not value.endswith("\\"), "line continuations are not expected"
        out.append((section, key.strip(), value.strip()))
    return out


@pytest.fixture(scope="module")
def unit() -> Unit:
    return parse_unit(UNIT.read_text(encoding="utf-8"))


def values(unit: Unit, section: str, key: str) -> List[str]:
    return [v for s, k, v in unit if s == section and k == key]


def single(unit: Unit, section: str, key: str) -> str:
    found = values(unit, section, key)
    assert len(found) == 1, f"[{section}] {key}= appears {len(found)} times"
    return found[0]


def verifiable_copy(tmp_path: Path, text: str) -> Path:
    assert EXEC_START in text
    copy = tmp_path / "rangebearing.service"
    copy.write_text(text.replace(EXEC_START, EXEC_START.replace(INSTALLED_BIN, "/bin/true")))
    return copy


def verify_messages(path: Path) -> List[str]:
    assert ANALYZE is not None
    proc = subprocess.run(
        [ANALYZE, "verify", str(path)], capture_output=True, text=True, timeout=60, check=False
    )
    lines = (proc.stdout + proc.stderr).splitlines()
    own = [ln for ln in lines if path.name in ln]
    if proc.returncode != 0:
        own.append(f"exit status {proc.returncode}: {proc.stderr.strip()}")
    return own


# --- the unit file ----------------------------------------------------------


@needs_analyze
def test_unit_passes_systemd_analyze_verify(tmp_path: Path) -> None:
    copy = verifiable_copy(tmp_path, UNIT.read_text(encoding="utf-8"))
    assert verify_messages(copy) == []


@needs_analyze
def test_verify_check_does_catch_mistakes(tmp_path: Path) -> None:
    text = UNIT.read_text(encoding="utf-8").replace(
        "Type=notify\n", "Type=notify\nWatchDogSec=10s\nNoNewPrivileges=maybe\n"
    )
    messages = verify_messages(verifiable_copy(tmp_path, text))
    assert any("WatchDogSec" in m for m in messages)
    assert any("maybe" in m for m in messages)


def security_supports_offline() -> bool:
    assert ANALYZE is not None
    proc = subprocess.run(
        [ANALYZE, "security", "--help"], capture_output=True, text=True, timeout=30, check=False
    )
    return "--offline" in proc.stdout


@needs_analyze
def test_security_exposure_is_at_most_2() -> None:
    if not security_supports_offline():
        pytest.skip("systemd-analyze security --offline needs systemd >= 250")
    assert ANALYZE is not None
    proc = subprocess.run(
        [ANALYZE, "security", "--offline=true", str(UNIT)],
        capture_output=True, text=True, timeout=60, check=False,
    )
    match = OVERALL.search(proc.stdout)
    assert match, f"no overall exposure line in:\n{proc.stdout}\n{proc.stderr}"
    assert float(match.group(1)) <= MAX_EXPOSURE, match.group(0)


def test_service_type_and_lifecycle(unit: Unit) -> None:
    assert single(unit, "Service", "Type") == "notify"
    assert single(unit, "Service", "NotifyAccess") == "main"
    assert single(unit, "Service", "ExecStart") == EXEC_START
    assert single(unit, "Service", "ExecReload") == "/bin/kill -HUP $MAINPID"
    assert single(unit, "Service", "Restart") == "always"
    assert single(unit, "Service", "TimeoutStopSec") in ("5", "5s")
    assert single(unit, "Install", "WantedBy") == "multi-user.target"
    assert values(unit, "Unit", "StartLimitIntervalSec")
    assert values(unit, "Unit", "StartLimitBurst")
    assert single(unit, "Service", "RestartPreventExitStatus") == "2"  # config/frame-size errors: no loop


def _seconds(unit: Unit, section: str, key: str) -> int:
    return int(re.fullmatch(r"(\d+)s?", single(unit, section, key)).group(1))  # type: ignore[union-attr]


def test_a_camera_fault_can_never_reach_the_start_limit(unit: Unit) -> None:
    """Item 10: a robot without its camera restarts forever; only an instant crash loop stops."""
    from rangebearing.config import SourceConfig
    from rangebearing.config.schema import MAX_CAPTURE_BUDGET_S

    src = SourceConfig()
    interval, burst = _seconds(unit, "Unit", "StartLimitIntervalSec"), int(single(unit, "Unit", "StartLimitBurst"))
    restart = _seconds(unit, "Service", "RestartSec")
    # a start that waits for a missing camera lasts open_timeout_s: never `burst` of them in the interval
    assert burst * (src.open_timeout_s + restart) > interval
    # a running daemon's stall ends in its own clean exit, well before the watchdog
    watchdog = _seconds(unit, "Service", "WatchdogSec")
    assert src.timeout_s * src.retries <= MAX_CAPTURE_BUDGET_S <= watchdog - 5
    assert src.open_timeout_s + 10 <= _seconds(unit, "Service", "TimeoutStartSec")


@pytest.mark.parametrize(("key", "lo_s", "hi_s"), [("WatchdogSec", 2, 60), ("RestartSec", 2, 30)])
def test_timers_are_sensible(unit: Unit, key: str, lo_s: float, hi_s: float) -> None:
    value = single(unit, "Service", key)
    match = re.fullmatch(r"(\d+)s?", value)
    assert match, f"{key}={value} should be plain seconds"
    assert lo_s <= int(match.group(1)) <= hi_s


def test_runs_as_unprivileged_user_in_video_group(unit: Unit) -> None:
    assert single(unit, "Service", "User") == "rangebearing"
    assert single(unit, "Service", "Group") == "rangebearing"
    assert "video" in single(unit, "Service", "SupplementaryGroups").split()
    assert single(unit, "Service", "CapabilityBoundingSet") == ""
    assert not values(unit, "Service", "DynamicUser")


def test_camera_devices_allowed_and_nothing_else(unit: Unit) -> None:
    assert single(unit, "Service", "DevicePolicy") == "closed"
    allowed = sorted(values(unit, "Service", "DeviceAllow"))
    assert allowed == ["char-dma_heap rw", "char-media rw", "char-video4linux rw"]
    # PrivateDevices=yes would hide /dev/video*, /dev/media* and /dev/dma_heap.
    assert all(v.lower() in ("no", "false", "0") for v in values(unit, "Service", "PrivateDevices"))


@pytest.mark.parametrize(
    ("key", "expected"),
    [
        ("NoNewPrivileges", "yes"),
        ("ProtectSystem", "strict"),
        ("ProtectHome", "yes"),
        ("PrivateTmp", "yes"),
        ("LockPersonality", "yes"),
        ("MemoryDenyWriteExecute", "yes"),
        ("RestrictRealtime", "yes"),
        ("RestrictSUIDSGID", "yes"),
        ("RestrictNamespaces", "yes"),
        ("ProtectKernelTunables", "yes"),
        ("ProtectKernelModules", "yes"),
        ("ProtectControlGroups", "yes"),
        ("SystemCallArchitectures", "native"),
        ("RestrictAddressFamilies", "AF_UNIX AF_INET AF_INET6 AF_NETLINK"),
        ("Environment", "PYTHONDONTWRITEBYTECODE=1"),
        ("UMask", "0077"),
    ],
)
def test_hardening(unit: Unit, key: str, expected: str) -> None:
    assert expected in values(unit, "Service", key)


def test_system_call_filter_allows_services_only(unit: Unit) -> None:
    filters = values(unit, "Service", "SystemCallFilter")
    assert "@system-service" in filters
    denied = " ".join(f[1:] for f in filters if f.startswith("~")).split()
    assert "@privileged" in denied


def test_no_writable_paths(unit: Unit) -> None:
    for key in ("ReadWritePaths", "StateDirectory", "CacheDirectory", "LogsDirectory"):
        assert not values(unit, "Service", key), f"{key}= would give the daemon a writable path"


# --- install.sh -------------------------------------------------------------

MUTATING = ("apt-get", "apt", "python3", "pip", "pip3", "useradd", "usermod", "groupadd",
            "systemctl", "install", "mkdir", "cp", "env", "sudo")


@pytest.fixture
def stub_path(tmp_path: Path) -> Stub:
    """PATH with every mutating command replaced by a stub that logs and fails."""
    bin_dir = tmp_path / "stub-bin"
    bin_dir.mkdir()
    log = tmp_path / "executed.log"
    for name in MUTATING:
        stub = bin_dir / name
        stub.write_text(f'#!/bin/sh\necho "{name} $*" >> "{log}"\nexit 97\n')
        stub.chmod(0o755)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}")
    return env, log


SHELLS = [s for s in ("bash", "sh") if shutil.which(s)]


@pytest.mark.parametrize("shell", SHELLS)
def test_install_script_syntax(shell: str) -> None:
    proc = subprocess.run([shell, "-n", str(INSTALL)], capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.skipif(sys.platform != "linux", reason="the install script targets Linux")
@pytest.mark.parametrize("shell", SHELLS)
def test_install_dry_run_prints_steps_and_executes_nothing(
    shell: str, stub_path: Stub
) -> None:
    env, log = stub_path
    proc = subprocess.run(
        [shell, str(INSTALL), "--dry-run"], capture_output=True, text=True, env=env,
        timeout=30, check=False,
    )
    assert proc.returncode == 0, proc.stderr
    prefix = "[dry-run] "
    text = "\n".join(ln[len(prefix):] for ln in proc.stdout.splitlines() if ln.startswith(prefix))
    assert "apt-get install -y" in text
    for pkg in ("picamera2", "opencv", "numpy", "yaml", "venv"):
        assert f" python3-{pkg}" in text
    assert "python3 -m venv --system-site-packages /opt/rangebearing/venv" in text
    venv = "/opt/rangebearing/venv"
    assert f"{venv}/bin/pip install --no-deps --no-cache-dir --upgrade {ROOT}" in text
    assert "useradd --system" in text or "usermod -a -G video rangebearing" in text
    assert "--groups video" in text or "-G video" in text
    assert f"install -m 0644 {UNIT} /etc/systemd/system/rangebearing.service" in text
    order = [
        "apt-get install", "venv --system-site-packages", "pip install", "systemctl daemon-reload",
        "systemctl enable rangebearing.service", "systemctl restart rangebearing.service",
    ]
    positions = [text.index(step) for step in order]
    assert positions == sorted(positions), "steps out of order"
    assert not log.exists(), f"dry run executed: {log.read_text()}"


@pytest.mark.parametrize("shell", SHELLS)
def test_the_daemon_reads_the_start_up_cache_the_install_fills(shell: str, stub_path: Stub, unit: Unit) -> None:
    env, _ = stub_path
    assert "RANGEBEARING_CACHE=/opt/rangebearing/cache" in values(unit, "Service", "Environment")
    proc = subprocess.run([shell, str(INSTALL), "--dry-run"], capture_output=True, text=True, env=env,
                          timeout=30, check=False)
    assert proc.returncode == 0, proc.stderr
    warm = ("env RANGEBEARING_CACHE=/opt/rangebearing/cache /opt/rangebearing/venv/bin/rangebearing run --check "
            "--config /etc/rangebearing/config.yaml")
    assert warm in proc.stdout
    assert proc.stdout.index("pip install") < proc.stdout.index(warm) < proc.stdout.index("systemctl restart")


@pytest.mark.skipif(sys.platform != "linux", reason="the install script targets Linux")
@pytest.mark.parametrize("edited", [True, False])
def test_install_never_overwrites_an_existing_config(
    tmp_path: Path, stub_path: Stub, edited: bool
) -> None:
    env, log = stub_path
    # A scratch checkout whose script looks for the config under tmp_path/etc.
    checkout = tmp_path / "checkout"
    (checkout / "systemd").mkdir(parents=True)
    (checkout / "config").mkdir()
    (checkout / "pyproject.toml").write_text("")
    (checkout / "config" / "rangebearing.yaml").write_text("daemon: {}\n")
    shutil.copy(UNIT, checkout / "systemd" / UNIT.name)
    etc = tmp_path / "etc"
    etc.mkdir()
    config = etc / "config.yaml"
    if edited:
        config.write_text("# edited by hand\n")
    script = INSTALL.read_text(encoding="utf-8")
    assert "\nETC_DIR=/etc/rangebearing\n" in script
    script = script.replace("\nETC_DIR=/etc/rangebearing\n", f"\nETC_DIR={etc}\n")
    (checkout / "systemd" / "install.sh").write_text(script)
    proc = subprocess.run(
        ["bash", str(checkout / "systemd" / "install.sh"), "--dry-run"],
        capture_output=True, text=True, env=env, timeout=30, check=False,
    )
    assert proc.returncode == 0, proc.stderr
    copies = [
        ln for ln in proc.stdout.splitlines()
        if ln.startswith("[dry-run] install ") and ln.endswith(f" {config}")
    ]
    if edited:
        assert copies == []
        assert f"keeping the existing {config}" in proc.stdout
    else:
        assert copies == [f"[dry-run] install -m 0644 {checkout}/config/rangebearing.yaml {config}"]
    assert not log.exists()
    if edited:
        assert config.read_text() == "# edited by hand\n"


@pytest.mark.skipif(sys.platform != "linux", reason="the install script targets Linux")
def test_install_refuses_without_root(tmp_path: Path, stub_path: Stub) -> None:
    env, log = stub_path
    fake_id = Path(env["PATH"].split(os.pathsep)[0]) / "id"
    fake_id.write_text('#!/bin/sh\n[ "$1" = "-u" ] && echo 1000 || echo "uid=1000(pi)"\n')
    fake_id.chmod(0o755)
    proc = subprocess.run(
        ["bash", str(INSTALL)], capture_output=True, text=True, env=env, timeout=30, check=False
    )
    assert proc.returncode != 0
    assert "must be run as root" in proc.stderr
    assert "[dry-run]" not in proc.stdout and "+ " not in proc.stdout
    assert not log.exists(), f"ran without root: {log.read_text()}"


def test_install_rejects_unknown_options(stub_path: Stub) -> None:
    env, log = stub_path
    proc = subprocess.run(
        ["bash", str(INSTALL), "--frobnicate"], capture_output=True, text=True, env=env,
        timeout=30, check=False,
    )
    assert proc.returncode == 1
    assert "unknown option" in proc.stderr
    assert not log.exists()
