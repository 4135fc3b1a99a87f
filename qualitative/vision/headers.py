"""An image file's size in pixels, read from its header without decoding the pixels.

:func:`qualgrasp.qualitative.vision.contour.read_image` checks this size against its limit *before* it
lets OpenCV decode the file, so that a small file claiming a huge image (a Radiance HDR header of
20,000 x 20,000 pixels is a few dozen bytes) is refused at once instead of making the decoder
allocate gigabytes and run for minutes.

Formats
-------
OpenCV recognises a file by its first bytes, not by its name; so does this module. The formats
OpenCV can decode (``cv2.imread``; this build: BMP, JPEG, PNG, WebP, AVIF, TIFF, JPEG 2000, GIF,
Sun raster, PBM/PGM/PPM/PNM, PAM, PFM, Radiance HDR; other builds add OpenEXR, JPEG XL or GDAL's
rasters) are read here as follows:

* PNG: the IHDR chunk (the first 24 bytes);
* Radiance HDR (``.hdr``, ``.pic``: ``#?RADIANCE`` or ``#?RGBE``): the resolution line after the
  header's blank line (``-Y 512 +X 768``, any of the eight orientations);
* PFM (``PF``/``Pf``), PAM (``P7``: its ``WIDTH`` and ``HEIGHT`` lines), OpenEXR (its
  ``dataWindow`` attribute), AVIF and HEIF (the largest ``ispe`` property): parsed here, Pillow
  does not read them (or not in every build); PBM/PGM/PPM (``P1`` to ``P6``) too, so that a
  huge one is reported with its size;
* every other format through Pillow's lazy :func:`PIL.Image.open`, which reads the header only
  (a header Pillow refuses as a decompression bomb, over about 179 million pixels, is refused
  with Pillow's count of its pixels).

A file none of these recognises is refused (:class:`~qualgrasp.qualitative.errors.ImageError`)
before OpenCV sees it: its size cannot be bounded. The header is read at most
:data:`HEADER_BYTES` bytes deep.
"""

from __future__ import annotations

import re
from pathlib import Path

from PIL import Image

from ..errors import ImageError

__all__ = ["HEADER_BYTES", "header_size"]

HEADER_BYTES = 65_536
"""Bytes read from the start of a file to find its size (Radiance, PAM and OpenEXR headers are
text or attribute lists of a few hundred bytes; ISO media boxes come first in AVIF files)."""

_PNG = b"\x89PNG\r\n\x1a\n"
_EXR = b"\x76\x2f\x31\x01"
_RADIANCE = re.compile(rb"^[-+]([XY]) +(\d+) +[-+]([XY]) +(\d+)[ \t\r]*$", re.MULTILINE)
_PFM = re.compile(rb"P[Ff]\s+(\d+)\s+(\d+)\s")
_BIG = 1 << 62  # stands for a size whose digits overflow any sensible image


def _number(digits: bytes) -> int:
    return int(digits) if len(digits) < 18 else _BIG


def _radiance(head: bytes) -> tuple[int, int] | None:
    blank = head.find(b"\n\n")
    if blank < 0:
        return None
    found = _RADIANCE.match(head, blank + 2)
    if found is None or found.group(1) == found.group(3):
        return None
    first, second = _number(found.group(2)), _number(found.group(4))
    return (second, first) if found.group(1) == b"Y" else (first, second)


def _pam(head: bytes) -> tuple[int, int] | None:
    fields: dict[bytes, int] = {}
    for line in head[3:].split(b"\n"):
        words = line.split()
        if words[:1] == [b"ENDHDR"]:
            break
        if len(words) == 2 and words[0] in (b"WIDTH", b"HEIGHT") and words[1].isdigit():
            fields[words[0]] = _number(words[1])
    if b"WIDTH" in fields and b"HEIGHT" in fields:
        return fields[b"WIDTH"], fields[b"HEIGHT"]
    return None


def _exr(head: bytes) -> tuple[int, int] | None:
    at = 8  # magic number and version
    while at < len(head):
        name_end = head.find(b"\0", at)
        if name_end <= at:  # an empty name ends the header
            return None
        type_end = head.find(b"\0", name_end + 1)
        if type_end < 0 or type_end + 5 > len(head):
            return None
        size = int.from_bytes(head[type_end + 1:type_end + 5], "little")
        value = head[type_end + 5:type_end + 5 + size]
        if head[at:name_end] == b"dataWindow" and len(value) == 16:
            x0, y0, x1, y1 = (int.from_bytes(value[k:k + 4], "little", signed=True) for k in range(0, 16, 4))
            return x1 - x0 + 1, y1 - y0 + 1
        at = type_end + 5 + size
    return None


def _isobmff(head: bytes) -> tuple[int, int] | None:
    # AVIF/HEIF: every image (the primary one, thumbnails, alpha) has an image spatial extents
    # property, 'ispe': version and flags, then width and height; the largest bounds the decode.
    sizes = []
    at = head.find(b"ispe")
    while 0 <= at <= len(head) - 16:
        sizes.append((int.from_bytes(head[at + 8:at + 12], "big"), int.from_bytes(head[at + 12:at + 16], "big")))
        at = head.find(b"ispe", at + 4)
    return max(sizes, key=lambda s: s[0] * s[1]) if sizes else None


def _own(head: bytes) -> tuple[int, int] | None:
    """The size from the formats parsed here (None: not one of them, or no size found)."""
    if head.startswith(_PNG) and len(head) >= 24:  # the IHDR chunk comes first
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    if head.startswith((b"#?RADIANCE", b"#?RGBE")):
        return _radiance(head)
    if _PFM.match(head):
        found = _PFM.match(head)
        return _number(found.group(1)), _number(found.group(2))
    if head.startswith(b"P7") and head[2:3].isspace():
        return _pam(head)
    if head[:1] == b"P" and head[1:2] in b"123456" and head[2:3].isspace():
        words = re.sub(rb"#[^\n]*", b" ", head[:1024]).split()
        if len(words) >= 3 and words[1].isdigit() and words[2].isdigit():
            return _number(words[1]), _number(words[2])
        return None
    if head.startswith(_EXR):
        return _exr(head)
    if head[4:8] == b"ftyp":
        return _isobmff(head)
    return None


def header_size(path: str | Path, limit: int) -> tuple[int, int]:
    """``(width, height)`` of an image file, pixels, from its header (module notes).

    Parameters
    ----------
    path : str or pathlib.Path
        An existing file.
    limit : int
        The caller's limit, pixels, named in the message refusing a file Pillow takes for a
        decompression bomb (far beyond any such limit).

    Returns
    -------
    (int, int)
        Width and height, pixels, as the header states them (the pixels are not read).

    Raises
    ------
    ImageError
        The header is not one of a format OpenCV decodes (module notes), or holds no size; Pillow
        refuses it as a decompression bomb.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "huge.hdr"
    >>> _ = path.write_bytes(b"#?RADIANCE\\nFORMAT=32-bit_rle_rgbe\\n\\n-Y 20000 +X 30000\\n")
    >>> header_size(path, 40_000_000)
    (30000, 20000)
    """
    path = Path(path)
    with path.open("rb") as fh:
        head = fh.read(HEADER_BYTES)
    size = _own(head)
    if size is not None:
        return size
    try:
        with Image.open(path) as im:
            return im.size
    except Image.DecompressionBombError as err:  # far beyond the caller's limit
        raise ImageError(f"{path} is larger than the limit of {limit:,} pixels by its header ({err})") from None
    except (OSError, ValueError, SyntaxError):  # Pillow's plugins raise all three on bad headers
        pass
    raise ImageError(f"cannot read {path} as an image (its header is not one of an image format whose "
                     "size can be read before decoding)")
