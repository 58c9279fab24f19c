"""Runs a command in a private network namespace with only a loopback interface (multicast
on), so DDS discovery stays on this machine and takes ~0.1 s. Needs `unshare -n` (root or
user namespaces); tests that need it skip with the reason when it is not available."""

from __future__ import annotations

import shutil
import subprocess

SETUP = "ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo"


def available() -> str | None:
    """None when private namespaces work here, else why not."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "unshare or ip (util-linux, iproute2) not installed"
    r = subprocess.run(["unshare", "-n", "sh", "-c", SETUP], capture_output=True, text=True)
    return None if r.returncode == 0 else f"cannot make a network namespace: {r.stderr.strip()}"


def run(argv: list[str], timeout: float, **kw) -> subprocess.CompletedProcess:
    """`argv` inside a fresh namespace (it and every process it starts)."""
    script = SETUP + ' && exec "$@"'
    return subprocess.run(["unshare", "-n", "sh", "-c", script, "sh", *argv], timeout=timeout, **kw)
