"""A private test network: one network namespace per host, joined by a bridge in a namespace of its own.

Nothing touches the machine's own network: the bridge lives in a "switch"
namespace, each host namespace holds only ``lo`` and one veth to it, with an
address in 10.213.x.0/24 that exists nowhere else. Needs root and ``ip``;
:func:`available` says whether both are here and why not.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import uuid
from typing import Dict, List, Optional, Sequence

SUBNET = "10.213.{net}.{host}"


def _ip(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=False)


def available() -> Optional[str]:
    """``None`` when namespaces can be made here, else the reason they cannot."""
    if shutil.which("ip") is None:
        return "the 'ip' tool (iproute2) is not installed"
    if os.geteuid() != 0:
        return "creating network namespaces needs root"
    probe = f"rbprobe{uuid.uuid4().hex[:6]}"
    done = _ip("netns", "add", probe)
    if done.returncode != 0:
        return f"ip netns add failed: {done.stderr.strip()}"
    _ip("netns", "del", probe)
    return None


class PrivateNetwork:
    """Namespaces ``<tag>-<name>`` for each host name, each with one address on a shared bridge."""

    def __init__(self, hosts: Sequence[str], net: int = 1) -> None:
        self.tag = f"rb{uuid.uuid4().hex[:5]}"
        self.switch = f"{self.tag}-sw"
        self.addresses: Dict[str, str] = {}
        self._namespaces: List[str] = []
        try:
            self._add_ns(self.switch)
            self._run(self.switch, "ip", "link", "add", "br0", "type", "bridge")
            self._run(self.switch, "ip", "link", "set", "br0", "up")
            for i, host in enumerate(hosts, start=1):
                self._add_host(host, SUBNET.format(net=net, host=i), i)
        except BaseException:
            self.close()
            raise

    def namespace(self, host: str) -> str:
        return f"{self.tag}-{host}"

    def _add_ns(self, name: str) -> None:
        done = _ip("netns", "add", name)
        if done.returncode != 0:
            raise OSError(f"ip netns add {name}: {done.stderr.strip()}")
        self._namespaces.append(name)

    def _run(self, ns: str, *cmd: str) -> None:
        done = _ip("netns", "exec", ns, *cmd)
        if done.returncode != 0:
            raise OSError(f"{' '.join(cmd)} in {ns}: {done.stderr.strip()}")

    def _add_host(self, host: str, address: str, i: int) -> None:
        ns = self.namespace(host)
        self._add_ns(ns)
        # Both ends are created inside the switch namespace, then one end moves: the
        # machine's own namespace never holds either.
        self._run(self.switch, "ip", "link", "add", f"p{i}", "type", "veth", "peer", "name", "eth0")
        self._run(self.switch, "ip", "link", "set", "eth0", "netns", ns)
        self._run(self.switch, "ip", "link", "set", f"p{i}", "master", "br0")
        self._run(self.switch, "ip", "link", "set", f"p{i}", "up")
        self._run(ns, "ip", "addr", "add", f"{address}/24", "dev", "eth0")
        self._run(ns, "ip", "link", "set", "eth0", "up")
        self._run(ns, "ip", "link", "set", "lo", "up")
        self.addresses[host] = address

    def command(self, host: str, argv: Sequence[str]) -> List[str]:
        """``argv`` wrapped to run inside ``host``'s namespace."""
        return ["ip", "netns", "exec", self.namespace(host), *argv]

    def close(self) -> None:
        """Delete every namespace (their veths and the bridge go with them). Safe to call twice."""
        for ns in reversed(self._namespaces):
            _ip("netns", "del", ns)
        self._namespaces.clear()

    def __enter__(self) -> PrivateNetwork:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
