"""Writers that take an animation's frames one at a time and keep none of them: a GIF
written frame by frame, and an MP4 piped to ffmpeg, so memory does not grow with the
number of frames.

Pillow writes a GIF of many frames only from all of them at once; here each frame is
quantised to a palette of its own (256 colours at most) and encoded by Pillow as a GIF of
one frame, whose image block is appended to the file with that palette as its local
colour table and a graphics control extension giving its duration.
"""

from __future__ import annotations

import io
import struct
import subprocess
from pathlib import Path
from typing import BinaryIO

import numpy as np


class GifWriter:
    """An animated GIF (looping forever) written frame by frame: ``add(rgb)``, then ``close()``."""

    def __init__(self, path: str | Path, fps: float):
        self.path = Path(path)
        self.delay = max(1, round(100 / fps))  # GIF durations are in hundredths of a second
        self.file: BinaryIO | None = None
        self.size: tuple[int, int] | None = None

    def add(self, rgba: np.ndarray) -> None:
        """Append a frame: an (height, width, 4) uint8 RGBA array (a canvas's buffer, its
        alpha ignored), the same size every frame."""
        from PIL import Image

        height, width = rgba.shape[:2]
        if self.file is None:
            self.size = (width, height)
            self.file = open(self.path, "wb")
            self.file.write(b"GIF89a" + struct.pack("<HHBBB", width, height, 0x70, 0, 0))
            self.file.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")  # loop forever
        elif (width, height) != self.size:
            raise ValueError(f"frame of {width}x{height} pixels in a GIF of {self.size[0]}x{self.size[1]}")
        frame = Image.frombuffer("RGBA", (width, height), rgba, "raw", "RGBA", 0, 1).convert("RGB")
        frame = frame.quantize(256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        single = io.BytesIO()
        frame.save(single, format="GIF")
        table, image = _split_single_gif(single.getvalue())
        self.file.write(b"\x21\xf9\x04\x04" + struct.pack("<H", self.delay) + b"\x00\x00")
        self.file.write(image[:9] + bytes([image[9] | 0x80 | table[0]]) + table[1] + image[10:])

    def close(self) -> None:
        if self.file is not None:
            self.file.write(b"\x3b")
            self.file.close()
            self.file = None


def _split_single_gif(data: bytes) -> tuple[tuple[int, bytes], bytes]:
    """A one-frame GIF's colour table (its size bits and bytes) and its image block (the
    image descriptor, with its local-table bits cleared, and the image data)."""
    packed = data[10]
    pos = 13
    table_bits, table = packed & 0x07, b""
    if packed & 0x80:
        length = 3 << (table_bits + 1)
        table = data[13:13 + length]
        pos += length
    while data[pos] == 0x21:  # extensions before the image: skip their sub-blocks
        pos += 2
        while data[pos]:
            pos += data[pos] + 1
        pos += 1
    if data[pos] != 0x2C:
        raise ValueError("Pillow wrote a GIF without an image block")
    descriptor = bytearray(data[pos:pos + 10])
    if descriptor[9] & 0x80:  # a local table already: use it
        table_bits = descriptor[9] & 0x07
        length = 3 << (table_bits + 1)
        table = data[pos + 10:pos + 10 + length]
        rest = data[pos + 10 + length:]
    else:
        rest = data[pos + 10:]
    descriptor[9] &= 0x78
    end = len(rest) - 1 if rest.endswith(b"\x3b") else len(rest)
    return (table_bits, table), bytes(descriptor) + rest[:end]


class Mp4Writer:
    """An H.264 MP4 made by ffmpeg from frames piped to it raw, one at a time."""

    def __init__(self, path: str | Path, fps: float, ffmpeg: str):
        self.path, self.fps, self.ffmpeg = Path(path), fps, ffmpeg
        self.process: subprocess.Popen | None = None
        self.size: tuple[int, int] | None = None

    def add(self, rgba: np.ndarray) -> None:
        """Append a frame: an (height, width, 4) uint8 RGBA array, the same size every frame."""
        height, width = rgba.shape[:2]
        if self.process is None:
            self.size = (width + width % 2, height + height % 2)  # H.264 wants even sizes
            self.process = subprocess.Popen(
                [self.ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba",
                 "-s", f"{self.size[0]}x{self.size[1]}", "-r", f"{self.fps:g}", "-i", "-",
                 "-vcodec", "h264", "-pix_fmt", "yuv420p", str(self.path)],
                stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        if (width, height) == self.size:
            self.process.stdin.write(memoryview(np.ascontiguousarray(rgba)).cast("B"))
            return
        padded = np.full((self.size[1], self.size[0], 4), 255, dtype=np.uint8)
        padded[:height, :width] = rgba
        self.process.stdin.write(padded.tobytes())

    def close(self) -> None:
        if self.process is None:
            return
        _, err = self.process.communicate()
        if self.process.returncode:
            raise RuntimeError(f"ffmpeg failed writing {self.path}: {err.decode(errors='replace').strip()}")
        self.process = None
