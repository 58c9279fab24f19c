"""A host on a LAN, probing the bridge's DDS ports, for the bridge's loopback test. Run inside
a private network namespace (tests/netns.py): it makes a second namespace (the "LAN host",
10.77.0.2) joined to this one (10.77.0.1, this machine's LAN address) by a veth pair, starts
the agrisim command given after `--`, and once its DDS ports are open sends one datagram to
each well-known RTPS port of domain 0 (7400, 7401, 7410, 7411), in turn:
  - "lan": from the LAN host to 10.77.0.1;
  - "local": from this machine to its own LAN address 10.77.0.1;
  - "loopback": from this machine to 127.0.0.1.
For each it records what the kernel did: the datagrams the bridge's sockets dropped (the
drops column of /proc/net/udp, summed over agrisim's sockets: a socket filter's drops count
there) and whether the sender got "port unreachable" (no socket at all took the port).
Prints JSON: per origin the drops and the per-port outcome ("refused" or "sent")."""

import argparse
import json
import os
import subprocess
import sys
import time

PORTS = [7400, 7401, 7410, 7411]
HOST, LAN_HOST = "10.77.0.1", "10.77.0.2"

# Run on either side: one datagram per port, then wait for the kernel's answer.
PROBE = """
import json, socket, sys
dst, ports = sys.argv[1], [int(p) for p in sys.argv[2:]]
out = {}
for p in ports:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.connect((dst, p))
    s.settimeout(0.5)
    s.send(b"not RTPS: a probe")
    try:
        s.recv(64)
        out[p] = "answered"
    except ConnectionRefusedError:
        out[p] = "refused"
    except socket.timeout:
        out[p] = "sent"
    s.close()
print(json.dumps(out))
"""


def sh(*argv: str) -> None:
    subprocess.run(argv, check=True, capture_output=True, text=True)


def lan_host() -> subprocess.Popen:
    """A process holding the LAN host's namespace, joined to this one by a veth pair."""
    holder = subprocess.Popen(["unshare", "-n", "sleep", "600"])
    mine = os.readlink("/proc/self/ns/net")
    deadline = time.monotonic() + 10
    while os.readlink(f"/proc/{holder.pid}/ns/net") == mine:
        if time.monotonic() > deadline:
            raise RuntimeError("the LAN host's namespace did not appear")
        time.sleep(0.01)
    sh("ip", "link", "add", "va", "type", "veth", "peer", "name", "vb")
    sh("ip", "link", "set", "vb", "netns", str(holder.pid))
    sh("ip", "addr", "add", f"{HOST}/24", "dev", "va")
    sh("ip", "link", "set", "va", "up")
    inside = ["nsenter", "-t", str(holder.pid), "-n"]
    sh(*inside, "ip", "addr", "add", f"{LAN_HOST}/24", "dev", "vb")
    sh(*inside, "ip", "link", "set", "vb", "up")
    sh(*inside, "ip", "link", "set", "lo", "up")
    return holder


def listening(pid: int) -> list[str]:
    """`ss`'s local addresses of the UDP sockets of process `pid`."""
    out = subprocess.run(["ss", "-uanpH"], capture_output=True, text=True, check=True).stdout
    return sorted(line.split()[3] for line in out.splitlines() if f"pid={pid}," in line)


def drops(pid: int) -> int:
    """Datagrams dropped by the UDP sockets of process `pid` (/proc/net/udp, last column)."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            link = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if link.startswith("socket:["):
            inodes.add(link[8:-1])
    total = 0
    with open("/proc/net/udp") as f:
        for line in f.readlines()[1:]:
            cols = line.split()
            if cols[9] in inodes:
                total += int(cols[-1])
    return total


def probe(prefix: list[str], dst: str) -> dict:
    r = subprocess.run([*prefix, sys.executable, "-c", PROBE, dst, *map(str, PORTS)], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise RuntimeError(r.stderr)
    return json.loads(r.stdout)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    holder = lan_host()
    run = subprocess.Popen(a.agrisim[1:] if a.agrisim[:1] == ["--"] else a.agrisim, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not all(any(addr.endswith(f":{p}") for addr in listening(run.pid)) for p in PORTS):
            if run.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"agrisim's DDS ports did not open (exit {run.poll()})")
            time.sleep(0.05)
        sockets = listening(run.pid)
        seen = {}
        for origin, prefix, dst in (("lan", ["nsenter", "-t", str(holder.pid), "-n"], HOST), ("local", [], HOST), ("loopback", [], "127.0.0.1")):
            before = drops(run.pid)
            outcome = probe(prefix, dst)
            # The kernel counts a drop as the datagram arrives; the probe waited 0.5 s per port.
            seen[origin] = {"drops": drops(run.pid) - before, "ports": outcome}
        out, err = run.communicate(timeout=120)
        print(json.dumps({"sockets": sockets, **seen, "returncode": run.returncode, "stderr": err[-2000:]}))
        return 0
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
        holder.kill()
        holder.wait()


if __name__ == "__main__":
    sys.exit(main())
