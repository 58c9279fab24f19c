"""Decoder (and encoder) for agrisim message ports, for FMPy users and other Python importers.

An agrisim FMU's message port (FMI 3 Binary, mimeType
``application/x-ros2-cdr-frames; version=1; type=pkg/msg/Type``) holds every message the FMU
produced during its last ``port_window`` seconds, each as a frame with its own sequence number
and stamp; the Int64 variable ``<port>_seq`` is the newest sequence number. Read the port at
least every ``port_window`` and keep a :class:`Cursor` per port: it returns each message once,
in order, and raises :class:`GapError` when messages were lost.

Layout (little-endian)::

    header  b"AGF\\x01"  u32 frame count
    frame   u64 sequence number  i64 stamp [ns]  u32 payload length  payload (CDR)

Example with FMPy's FMU3Slave::

    cursor = Cursor()
    for frame in cursor.take(slave.getBinary([vr_imu])[0], slave.getInt64([vr_imu_seq])[0]):
        msg = deserialize_cdr(frame.payload, "sensor_msgs/msg/Imu")  # e.g. with rosbags
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

MAGIC = b"AGF\x01"
MEDIA_TYPE = "application/x-ros2-cdr-frames"
_HEADER = struct.Struct("<4sI")
_FRAME = struct.Struct("<QqI")


@dataclass(frozen=True)
class Frame:
    seq: int
    stamp_ns: int
    payload: bytes


class MalformedError(ValueError):
    """Bytes that are not a frame list."""


class GapError(RuntimeError):
    """Messages ``first..last`` were produced but are no longer in the port."""

    def __init__(self, first: int, last: int):
        super().__init__(f"messages {first} to {last} were lost (sequence gap)" if first != last else f"message {first} was lost (sequence gap)")
        self.first, self.last = first, last


def is_framed_mime(mime: str | None) -> bool:
    return bool(mime) and mime.split(";")[0].strip() == MEDIA_TYPE


def is_frame_list(data: bytes) -> bool:
    return bytes(data[:4]) == MAGIC


def decode(data: bytes) -> list[Frame]:
    data = bytes(data)
    if len(data) < _HEADER.size:
        raise MalformedError(f"{len(data)} bytes, shorter than the header")
    magic, count = _HEADER.unpack_from(data, 0)
    if magic[:3] != MAGIC[:3]:
        raise MalformedError(f"starts with {magic!r}, not the magic b'AGF'")
    if magic[3] != MAGIC[3]:
        raise MalformedError(f"format version {magic[3]}, this reader knows version 1")
    at, frames = _HEADER.size, []
    for i in range(count):
        if len(data) - at < _FRAME.size:
            raise MalformedError(f"frame {i} of {count}: header truncated")
        seq, stamp, n = _FRAME.unpack_from(data, at)
        at += _FRAME.size
        if len(data) - at < n:
            raise MalformedError(f"frame {i} of {count}: payload truncated")
        if frames and seq <= frames[-1].seq:
            raise MalformedError(f"frame {i}: sequence number {seq} does not follow {frames[-1].seq}")
        frames.append(Frame(seq, stamp, data[at:at + n]))
        at += n
    if at != len(data):
        raise MalformedError(f"{len(data) - at} trailing bytes after {count} frames")
    return frames


def encode(frames) -> bytes:
    frames = list(frames)
    out = [_HEADER.pack(MAGIC, len(frames))]
    for f in frames:
        out.append(_FRAME.pack(f.seq, f.stamp_ns, len(f.payload)))
        out.append(bytes(f.payload))
    return b"".join(out)


class Cursor:
    """A consumer's position in one output port: the last sequence number taken."""

    def __init__(self) -> None:
        self.last = 0

    def take(self, data: bytes, counter: int) -> list[Frame]:
        """The frames after the last one taken, in order; GapError when some were lost (the
        cursor then moves past them)."""
        frames = [f for f in decode(data) if f.seq > self.last]
        first = frames[0].seq if frames else counter + 1
        newest = max(frames[-1].seq, counter) if frames else counter
        if first > self.last + 1 and newest > self.last:
            gap = GapError(self.last + 1, min(first, counter + 1) - 1)
            self.last = newest
            raise gap
        if frames:
            self.last = frames[-1].seq
        return frames
