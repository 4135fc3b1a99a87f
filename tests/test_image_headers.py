"""The image size limit is checked from the file's header before OpenCV decodes it (issue 23):
for every format OpenCV reads, Pillow's or not; a header nobody can read is refused."""

import struct

import cv2
import numpy as np
import pytest

from qualgrasp.qualitative.errors import ImageError
from qualgrasp.qualitative.vision.headers import header_size
from qualgrasp.qualitative.vision.contour import MAX_PIXELS, read_image

HUGE = 20_000


def _radiance(resolution: bytes) -> bytes:
    # a header and a few bytes of run-length data: the file claims the size, it does not hold it
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n" + resolution + b"\n" + bytes(64)


def _exr(width: int, height: int) -> bytes:
    def attribute(name, kind, value):
        return name + b"\0" + kind + b"\0" + struct.pack("<i", len(value)) + value
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    return (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attribute(b"channels", b"chlist", b"\0")
            + attribute(b"dataWindow", b"box2i", box) + attribute(b"displayWindow", b"box2i", box) + b"\0")


HUGE_FILES = {
    "huge.hdr": _radiance(b"-Y 20000 +X 20000"),
    "huge.pic": _radiance(b"+X 20000 +Y 20000"),
    "huge.pfm": b"PF\n20000 20000\n-1.0\n" + bytes(64),
    "huge.pam": b"P7\nWIDTH 20000\nHEIGHT 20000\nDEPTH 3\nMAXVAL 255\nTUPLTYPE RGB\nENDHDR\n" + bytes(64),
    "huge.ppm": b"P6\n20000 20000\n255\n" + bytes(64),
    "huge.exr": _exr(HUGE, HUGE),
}


@pytest.mark.parametrize("name", sorted(HUGE_FILES))
def test_a_huge_header_is_refused_before_decoding(name, tmp_path):
    path = tmp_path / name
    path.write_bytes(HUGE_FILES[name])
    assert header_size(path, MAX_PIXELS) == (HUGE, HUGE)
    with pytest.raises(ImageError) as err:
        read_image(path)
    message = str(err.value)
    assert "\n" not in message and f"{HUGE} x {HUGE} pixels, more than the limit" in message


@pytest.mark.parametrize("suffix", ["hdr", "pfm", "pam", "png", "jpg", "bmp", "tif", "webp", "ppm", "pgm",
                                    "sr", "jp2", "avif", "gif"])
def test_small_files_of_every_format_read(suffix, tmp_path):
    image = np.zeros((37, 53, 3), np.uint8)
    image[10:25, 12:40] = (40, 160, 220)
    data = image.astype(np.float32) / 255 if suffix in ("hdr", "pfm") else image
    data = data[:, :, 0] if suffix == "pgm" else data
    path = tmp_path / f"small.{suffix}"
    try:
        written = cv2.imwrite(str(path), data)
    except cv2.error:
        written = False
    if not written:
        pytest.skip(f"this OpenCV build does not write .{suffix}")
    assert header_size(path, MAX_PIXELS) == (53, 37)
    assert read_image(path).shape == (37, 53)


@pytest.mark.parametrize("line", [b"-Y 30 +X 70", b"+Y 30 -X 70", b"+X 70 -Y 30", b"-X 70 +Y 30"])
def test_radiance_orientations(line, tmp_path):
    # the resolution line may give either axis first, either way round
    path = tmp_path / "image.hdr"
    path.write_bytes(_radiance(line))
    assert header_size(path, MAX_PIXELS) == (70, 30)


@pytest.mark.parametrize("content", [
    b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 20000\n",  # no width
    b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n-Y 20 +X 20\n",  # no blank line before the resolution
    b"P7\nDEPTH 3\nENDHDR\n",  # no width or height
    b"\x76\x2f\x31\x01\x02\0\0\0\0",  # OpenEXR without a data window
    b"plain text, not an image",
])
def test_a_header_without_a_size_is_refused(content, tmp_path):
    path = tmp_path / "image.hdr"
    path.write_bytes(content)
    with pytest.raises(ImageError, match="cannot read .* as an image"):
        read_image(path)


def test_pillow_decompression_bomb_is_refused(tmp_path):
    # a BMP header claiming 20,000 x 20,000 pixels: Pillow refuses to open it
    info = struct.pack("<IiiHHIIiiII", 40, HUGE, HUGE, 1, 24, 0, 0, 2835, 2835, 0, 0)
    path = tmp_path / "bomb.bmp"
    path.write_bytes(b"BM" + struct.pack("<IHHI", 54 + 64, 0, 0, 54) + info + bytes(64))
    with pytest.raises(ImageError, match=r"larger than the limit of 40,000,000 pixels by its header \(.*400000000"):
        read_image(path)
