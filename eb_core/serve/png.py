"""Fast lossless PNG for images on the wire.

Pillow's PNG encoder spends ~20 ms on a 500 x 500 frame (adaptive filtering), more than a Navigation step takes.
Here every row uses the ``Sub`` filter (computed with one numpy subtraction) and zlib level 1: ~4 ms, ~95 KB, and a
standard PNG that any decoder reads. :func:`decode_png` undoes exactly this layout with numpy (a cumulative sum per
row) and hands anything else to Pillow.
"""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np

__all__ = ["decode_png", "encode_png"]

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_SUB = 1


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an ``(H, W, 3)`` (RGB) or ``(H, W)`` (grey) uint8 image."""
    im = np.ascontiguousarray(image, dtype=np.uint8)
    if im.ndim == 2:
        channels, colour_type = 1, 0
    elif im.ndim == 3 and im.shape[2] in (3, 4):
        channels, colour_type = im.shape[2], (2 if im.shape[2] == 3 else 6)
    else:
        raise ValueError(f"encode_png needs an (H, W), (H, W, 3) or (H, W, 4) image, got shape {im.shape}")
    h, w = im.shape[:2]
    rows = im.reshape(h, w * channels)
    sub = rows.copy()
    np.subtract(rows[:, channels:], rows[:, :-channels], out=sub[:, channels:])
    raw = np.empty((h, w * channels + 1), dtype=np.uint8)
    raw[:, 0] = _SUB
    raw[:, 1:] = sub
    header = struct.pack(">IIBBBBB", w, h, 8, colour_type, 0, 0, 0)
    return (_SIGNATURE + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(raw.tobytes(), 1))
            + _chunk(b"IEND", b""))


def _chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    out, pos = [], len(_SIGNATURE)
    while pos + 8 <= len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        out.append((data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]))
        pos += 12 + length
    return out


def decode_png(data: bytes) -> np.ndarray:
    """The RGB ``(H, W, 3)`` uint8 array of a PNG (fast for :func:`encode_png`'s own layout)."""
    if data[:8] == _SIGNATURE:
        chunks = _chunks(data)
        if chunks and chunks[0][0] == b"IHDR":
            w, h, depth, colour_type, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
            if depth == 8 and colour_type == 2 and interlace == 0:
                raw = zlib.decompress(b"".join(d for k, d in chunks if k == b"IDAT"))
                rows = np.frombuffer(raw, dtype=np.uint8).reshape(h, w * 3 + 1)
                if (rows[:, 0] == _SUB).all():
                    pix = rows[:, 1:].reshape(h, w, 3)
                    return np.cumsum(pix, axis=1, dtype=np.uint8)
    from PIL import Image

    with Image.open(io.BytesIO(data)) as im:
        return np.asarray(im.convert("RGB"), dtype=np.uint8)
