"""Writing animation frames to a file: a GIF through Pillow or an MP4 through ``ffmpeg``.

The format comes from the path's suffix alone (:func:`animation_format`), so a temporary
name such as ``.animation.partial.gif`` works. A GIF gets one palette for all frames
(:data:`GIF_COLOURS` colours, the load arrows' :data:`LOAD_COLOURS` kept exact), so pixels
that do not change cost nothing; an MP4 is H.264 in yuv420p through the ffmpeg that
``imageio-ffmpeg`` ships (:func:`ffmpeg`, :func:`mp4_available`).

Private: :mod:`tumble.viz.animation` re-exports :func:`mp4_available`,
:func:`animation_format` and :func:`write_animation`, and draws the frames
(:func:`tumble.viz.structural.beam_animation` uses the same writers). Pillow and matplotlib
are imported inside the functions that use them.

Examples
--------
>>> animation_format("run/.animation.partial.gif")
'gif'
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tumble import _checks
from tumble._atomic import atomic_write

FORMATS = (".gif", ".mp4")
"""Suffixes the animation writers accept."""
GIF_COLOURS = 64
"""Palette size of a GIF (80 frames of 480 × 480 px come to about 0.5–1 MB)."""
LOAD_COLOURS = {"impulse": "tab:red", "force": "tab:orange"}
"""Colours of the load arrows (matplotlib names); a GIF's palette holds them exactly."""


def ffmpeg() -> str | None:
    """The ffmpeg executable: the one ``imageio-ffmpeg`` ships inside its wheel (a dependency,
    so every install has it), else ``ffmpeg`` on ``PATH``, else None."""
    try:
        import imageio_ffmpeg

        return imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):  # not installed, or no binary for this platform
        return shutil.which("ffmpeg")


def mp4_available() -> bool:
    """Whether an ffmpeg is at hand to write ``.mp4`` (:func:`ffmpeg`)."""
    return ffmpeg() is not None


def animation_format(path: str | Path) -> str:
    """The format ``"gif"`` or ``"mp4"`` for ``path``, from its suffix only.

    Raises
    ------
    ValueError
        If the suffix is neither ``.gif`` nor ``.mp4``.
    RuntimeError
        If it is ``.mp4`` and ``ffmpeg`` is not on ``PATH``.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise _checks.fail(
            "path",
            str(path),
            f"a file name ending in {' or '.join(map(repr, FORMATS))}",
            remedy=f"its suffix is {suffix!r}",
        )
    if suffix == ".mp4" and not mp4_available():
        raise RuntimeError(
            f"path={str(path)!r}: writing .mp4 needs ffmpeg: imageio-ffmpeg (a dependency of "
            "tumble) has no binary for this platform and there is none on PATH; install one "
            "or write a .gif"
        )
    return suffix[1:]


def write_animation(images: Sequence[NDArray], path: str | Path, *, fps: float = 20) -> Path:
    """Write RGB frames (each shape (height, width, 3), uint8) as a GIF or an MP4.

    GIF: Pillow, looping, every frame mapped (no dithering) onto one palette of
    :data:`GIF_COLOURS` colours: the median cut of all frames (every fourth pixel), plus the
    load arrows' colours, which are too few pixels to survive the cut. MP4: ffmpeg, H.264 in
    yuv420p (odd sizes padded by one pixel). The format comes from the suffix of ``path``
    only (:func:`animation_format`).

    Returns
    -------
    Path
        ``path``.
    """
    kind = animation_format(path)
    fps = _checks.positive("fps", fps, "frames per second")
    if len(images) == 0:
        raise _checks.fail("images", images, "at least one frame")
    path = Path(path)
    if kind == "gif":
        from PIL import Image

        palette = _gif_palette(images)
        frames = [
            Image.fromarray(image).quantize(palette=palette, dither=Image.Dither.NONE)
            for image in images
        ]
        return atomic_write(
            path,
            lambda tmp: frames[0].save(tmp, format="GIF", save_all=True,
                                       append_images=frames[1:], duration=round(1000 / fps),
                                       loop=0, optimize=True),
        )  # fmt: skip
    height, width = images[0].shape[:2]
    exe = ffmpeg()
    assert exe is not None  # animation_format refused .mp4 without one
    command = [exe, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{width}x{height}", "-r", f"{fps:g}", "-i", "-",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
               "-pix_fmt", "yuv420p", "-f", "mp4"]  # fmt: skip
    data = b"".join(np.ascontiguousarray(image, dtype=np.uint8).tobytes() for image in images)

    def encode(tmp: Path) -> None:
        result = subprocess.run([*command, str(tmp)], input=data, capture_output=True, check=False)
        if result.returncode != 0:
            raise RuntimeError(f"ffmpeg failed writing {str(path)!r}: {result.stderr.decode()}")

    return atomic_write(path, encode)


def _gif_palette(images: Sequence[NDArray]):
    """One palette image for every frame (see :func:`write_animation`)."""
    from matplotlib.colors import to_rgb
    from PIL import Image

    mosaic = Image.fromarray(np.concatenate([image[::4, ::4] for image in images], axis=0))
    reserved = [round(255 * c) for colour in LOAD_COLOURS.values() for c in to_rgb(colour)]
    cut = mosaic.quantize(GIF_COLOURS - len(LOAD_COLOURS), dither=Image.Dither.NONE)
    palette = Image.new("P", (1, 1))
    colours = cut.getpalette() or []  # a quantized image always has one
    palette.putpalette(colours[: 3 * (GIF_COLOURS - len(LOAD_COLOURS))] + reserved)
    return palette
