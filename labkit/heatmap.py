"""Heatmap PNGs of per-block z-scores, written with zlib and struct only.

Colours: |z| = 0 is blue, |z| at the Bonferroni limit is white, |z| >= 2x the limit is red
(so every failing block is pink to red); blocks holding a NaN/Inf pixel are black; the worst
block is outlined in green.  The picture is the image's own size, scaled up by an integer
factor (`heatmap_scale`) so that small test images stay visible; block edges are drawn as
faint grid lines when blocks are large enough on screen.
"""

from __future__ import annotations

import math
import os
import struct
import zlib

import numpy as np

from .pfm import atomic_write

__all__ = ["png_bytes", "write_png", "colormap", "heatmap_scale", "write_heatmap"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
BLUE = np.array([40.0, 90.0, 255.0])
WHITE = np.array([255.0, 255.0, 255.0])
RED = np.array([210.0, 0.0, 0.0])
OUTLINE = np.array([0, 190, 0], dtype=np.uint8)
NONFINITE = np.array([0, 0, 0], dtype=np.uint8)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png_bytes(rgb: np.ndarray) -> bytes:
    """The bytes of an 8-bit RGB PNG holding `rgb` (H, W, 3) uint8, top row first."""
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.shape[0] < 1 or rgb.shape[1] < 1:
        raise ValueError(f"expected an (H, W, 3) image, got shape {rgb.shape}")
    rgb = np.ascontiguousarray(np.clip(rgb, 0, 255).astype(np.uint8))
    h, w = rgb.shape[:2]
    raw = np.zeros((h, 1 + 3 * w), dtype=np.uint8)  # filter type 0 (None) for every row
    raw[:, 1:] = rgb.reshape(h, 3 * w)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)  # 8-bit, truecolour, no interlace
    return (PNG_SIGNATURE + _chunk(b"IHDR", ihdr)
            + _chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)) + _chunk(b"IEND", b""))


def write_png(path: str | os.PathLike, rgb: np.ndarray) -> None:
    """Writes `rgb` as a PNG atomically (temporary file, then os.replace)."""
    atomic_write(os.fspath(path), png_bytes(rgb))


def colormap(absz: np.ndarray, critical: float) -> np.ndarray:
    """Maps |z| to RGB floats: blue at 0, white at `critical`, red at 2*critical and above."""
    t = np.clip(np.nan_to_num(np.abs(absz) / (2.0 * critical), nan=1.0, posinf=1.0), 0.0, 1.0)
    t = t[..., None]
    low = BLUE + (WHITE - BLUE) * np.clip(2.0 * t, 0.0, 1.0)
    high = WHITE + (RED - WHITE) * np.clip(2.0 * t - 1.0, 0.0, 1.0)
    return np.where(t <= 0.5, low, high)


def heatmap_scale(height: int, width: int) -> int:
    """The integer upscaling factor: the picture's longer side becomes at least 256 px."""
    return max(1, math.ceil(256 / max(height, width)))


def write_heatmap(path: str, z_map: np.ndarray, critical: float, block: int, height: int,
                  width: int, nonfinite_blocks: np.ndarray | None = None) -> tuple[int, int]:
    """Writes the heatmap of `z_map` ((by, bx, C) block z-scores for `block`-sized blocks of
    an image of `height` x `width` pixels).  Returns the PNG's (width, height)."""
    z_map = np.asarray(z_map, dtype=np.float64)
    if z_map.ndim == 2:
        z_map = z_map[:, :, None]
    absz = np.abs(z_map).max(axis=2)  # (by, bx)
    colours = colormap(absz, critical).round().astype(np.uint8)
    if nonfinite_blocks is not None:
        colours[np.asarray(nonfinite_blocks, dtype=bool)] = NONFINITE

    s = heatmap_scale(height, width)
    ph, pw = height * s, width * s
    rows = (np.arange(ph) // s) // block
    cols = (np.arange(pw) // s) // block
    img = colours[rows[:, None], cols[None, :]]

    cell = block * s
    if cell >= 12:  # faint grid lines on block edges
        edge_r = (np.arange(ph) % cell) == 0
        edge_c = (np.arange(pw) % cell) == 0
        img[edge_r, :] = (img[edge_r, :] * 0.8).astype(np.uint8)
        img[:, edge_c] = (img[:, edge_c] * 0.8).astype(np.uint8)

    if absz.size:
        by, bx = np.unravel_index(int(np.argmax(absz)), absz.shape)
        y0, y1 = by * cell, min((by + 1) * block, height) * s  # [y0, y1)
        x0, x1 = bx * cell, min((bx + 1) * block, width) * s
        t = max(1, min(3, cell // 8, (y1 - y0) // 3, (x1 - x0) // 3))
        img[y0:y0 + t, x0:x1] = OUTLINE
        img[y1 - t:y1, x0:x1] = OUTLINE
        img[y0:y1, x0:x0 + t] = OUTLINE
        img[y0:y1, x1 - t:x1] = OUTLINE

    write_png(path, img)
    return pw, ph
