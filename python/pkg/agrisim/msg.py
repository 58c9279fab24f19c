"""numpy views of the messages where it matters: point clouds as structured arrays, images
as HxWxC uint8 (or HxW float32 depth). Zero-copy over the message's ``data`` bytes."""

from __future__ import annotations

import numpy as np

# sensor_msgs/PointField datatype -> numpy scalar type (REP: PointField constants).
_FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}

# sensor_msgs/Image encoding -> (numpy scalar type, channels).
_ENCODINGS = {
    "rgb8": ("u1", 3),
    "bgr8": ("u1", 3),
    "rgba8": ("u1", 4),
    "bgra8": ("u1", 4),
    "mono8": ("u1", 1),
    "8UC1": ("u1", 1),
    "8UC3": ("u1", 3),
    "mono16": ("u2", 1),
    "16UC1": ("u2", 1),
    "32FC1": ("f4", 1),
}


def pointcloud_to_array(msg: dict) -> np.ndarray:
    """A sensor_msgs/PointCloud2 (dict) as a structured array of ``height * width`` points,
    one named field per PointField (offsets and byte order as the message says)."""
    endian = ">" if msg["is_bigendian"] else "<"
    names, formats, offsets = [], [], []
    for f in msg["fields"]:
        if f["datatype"] not in _FIELD_TYPES:
            raise ValueError(f"PointCloud2 field {f['name']!r}: unknown datatype {f['datatype']}")
        t = endian + _FIELD_TYPES[f["datatype"]]
        names.append(f["name"])
        formats.append((t, (f["count"],)) if f["count"] > 1 else t)
        offsets.append(f["offset"])
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": msg["point_step"]})
    n = msg["height"] * msg["width"]
    data = msg["data"]
    if msg["row_step"] * msg["height"] > len(data) or msg["point_step"] * msg["width"] > msg["row_step"]:
        raise ValueError(f"PointCloud2: {len(data)} data bytes do not hold {msg['height']} rows of {msg['row_step']} bytes")
    if msg["row_step"] == msg["point_step"] * msg["width"]:
        return np.frombuffer(data, dtype=dtype, count=n)
    rows = [np.frombuffer(data, dtype=dtype, count=msg["width"], offset=r * msg["row_step"]) for r in range(msg["height"])]
    return np.concatenate(rows)


def image_to_array(msg: dict) -> np.ndarray:
    """A sensor_msgs/Image (dict) as HxWxC (colour) or HxW (one channel: depth, mono)."""
    enc = msg["encoding"]
    if enc not in _ENCODINGS:
        raise ValueError(f"Image encoding {enc!r} is not supported (supported: {', '.join(sorted(_ENCODINGS))})")
    scalar, channels = _ENCODINGS[enc]
    dtype = np.dtype(scalar).newbyteorder(">" if msg["is_bigendian"] else "<")
    h, w, step = msg["height"], msg["width"], msg["step"]
    row = w * channels * dtype.itemsize
    if step < row or step * h > len(msg["data"]):
        raise ValueError(f"Image {w}x{h} {enc}: step {step} and {len(msg['data'])} data bytes do not fit")
    rows = np.frombuffer(msg["data"], dtype=np.uint8, count=step * h).reshape(h, step)[:, :row]
    arr = np.ascontiguousarray(rows).view(dtype).reshape((h, w, channels) if channels > 1 else (h, w))
    return arr.astype(dtype.newbyteorder("="), copy=False)
