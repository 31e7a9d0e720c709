"""Reading and writing colour PFM images (the renderer's linear float32 output format).

Layout, as written by common/host/image.cpp:

    b"PF\\n<width> <height>\\n<scale>\\n" followed by width*height*3 float32 values,

where a negative scale means little-endian floats (a positive one big-endian; the renderer
always writes -1.0), and the rows are stored bottom to top.  In memory we use the usual
array convention instead: ``img[y, x, c]`` with row 0 at the *top* of the picture, so that
(x, y) coordinates printed by the grader match what an image viewer shows.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

__all__ = ["PFMError", "read_pfm", "write_pfm", "pfm_bytes"]


class PFMError(ValueError):
    """A file that is not a readable colour PFM image."""


def _tokens(data: bytes, path: str, count: int) -> tuple[list[bytes], int]:
    """Returns the first `count` whitespace-separated header tokens and the offset after
    the single whitespace byte that ends the last one."""
    tokens: list[bytes] = []
    pos = 0
    n = len(data)
    while len(tokens) < count:
        while pos < n and data[pos : pos + 1].isspace():
            pos += 1
        start = pos
        while pos < n and not data[pos : pos + 1].isspace():
            pos += 1
        if start == pos or pos - start > 64:
            raise PFMError(f"{path}: truncated or malformed PFM header")
        tokens.append(data[start:pos])
    if pos >= n:
        raise PFMError(f"{path}: truncated PFM header")
    return tokens, pos + 1  # exactly one whitespace byte follows the scale


def _dimension(path: str, token: bytes, what: str) -> int:
    try:
        value = int(token.decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        raise PFMError(f"{path}: expected the image {what}, found {token[:20]!r}") from None
    if not 1 <= value <= 65536:
        raise PFMError(f"{path}: image {what} {value} is outside 1..65536")
    return value


def read_pfm(path: str | os.PathLike) -> np.ndarray:
    """Reads a colour PFM file into a float32 array of shape (height, width, 3), top row
    first.  Raises PFMError (a ValueError) for anything that is not a well-formed colour
    PFM, and OSError when the file cannot be read."""
    path = os.fspath(path)
    with open(path, "rb") as f:
        data = f.read()
    if data[:2] == b"Pf":
        raise PFMError(f"{path}: greyscale PFM ('Pf'); expected a colour PFM ('PF')")
    (magic, w_tok, h_tok, scale_tok), offset = _tokens(data, path, 4)
    if magic != b"PF":
        raise PFMError(f"{path}: not a colour PFM file (expected 'PF', found {magic[:8]!r})")
    width = _dimension(path, w_tok, "width")
    height = _dimension(path, h_tok, "height")
    try:
        scale = float(scale_tok.decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        raise PFMError(f"{path}: expected the PFM scale, found {scale_tok[:20]!r}") from None
    if scale == 0.0 or scale != scale:
        raise PFMError(f"{path}: PFM scale must be non-zero, found {scale_tok[:20]!r}")
    dtype = np.dtype("<f4") if scale < 0 else np.dtype(">f4")
    need = width * height * 3 * 4
    have = len(data) - offset
    if have != need:
        raise PFMError(
            f"{path}: a {width}x{height} PFM needs {need} bytes of pixels, found {have}"
        )
    pixels = np.frombuffer(data, dtype=dtype, count=width * height * 3, offset=offset)
    img = pixels.reshape(height, width, 3)[::-1]  # stored bottom-to-top
    return np.ascontiguousarray(img, dtype=np.float32)


def _as_rgb(img) -> np.ndarray:
    arr = np.asarray(img)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"expected an image of shape (height, width, 3), got {arr.shape}")
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ValueError(f"expected a numeric image, got dtype {arr.dtype}")
    return arr


def pfm_bytes(img) -> bytes:
    """The bytes of a little-endian colour PFM holding `img` ((H, W, 3), top row first)."""
    arr = _as_rgb(img)
    height, width = arr.shape[:2]
    header = f"PF\n{width} {height}\n-1.0\n".encode("ascii")
    body = np.ascontiguousarray(arr[::-1], dtype="<f4").tobytes()
    return header + body


def write_pfm(path: str | os.PathLike, img) -> None:
    """Writes `img` ((H, W, 3), top row first; converted to float32) as a little-endian
    colour PFM.  The file appears atomically: the bytes go to a temporary file in the same
    directory, which then replaces `path`, so readers never see a half-written image."""
    path = os.fspath(path)
    data = pfm_bytes(img)
    atomic_write(path, data)


def atomic_write(path: str, data: bytes) -> None:
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=os.path.basename(path) + ".partial-", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp makes 0600; outputs are ordinary files
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
