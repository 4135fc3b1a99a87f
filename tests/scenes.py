"""Rendered scenes for the perception tests: a grey object on a difficult background.

Each scene is a grey polygon (the built-in ``polygon`` at 400 x 400 pixels, anti-aliased) with a
known exact shape, on a background that fools a global threshold: a soft shadow, a textured
background, uneven lighting. Grey levels are floats in 0..255, rounded to ``uint8``.
"""

import cv2
import numpy as np

from qualgrasp.qualitative.objects import BACKGROUND, FOREGROUND, render_polygon, shape

SIZE = 400
OBJECT = 100.0
PAPER = 210.0


def truth(rotation=20.0):
    """The object's exact polygon, pixels."""
    return shape("polygon", SIZE, rotation=rotation)


def coverage(poly):
    """Fraction of each pixel the polygon covers (anti-aliased, 0..1)."""
    return (BACKGROUND - render_polygon(poly, SIZE).astype(float)) / (BACKGROUND - FOREGROUND)


def _compose(background, poly, seed=0, noise=2.0):
    cover = coverage(poly)
    image = background * (1 - cover) + OBJECT * cover
    image = image + np.random.default_rng(seed).normal(0.0, noise, image.shape)
    return np.clip(np.round(image), 0, 255).astype(np.uint8)


def plain(rotation=20.0):
    poly = truth(rotation)
    return _compose(np.full((SIZE, SIZE), PAPER), poly), poly


def shadow(rotation=20.0, offset=(20, 20), sigma=8.0, depth=70.0):
    """The object and its soft shadow: the polygon shifted by ``offset`` pixels, blurred with a
    Gaussian of ``sigma`` pixels, ``depth`` grey levels darker than the paper at its core."""
    poly = truth(rotation)
    moved = shape("polygon", SIZE, rotation=rotation, offset=offset)
    dark = cv2.GaussianBlur(coverage(moved), (0, 0), sigma)
    return _compose(PAPER - depth * dark, poly), poly


def textured(rotation=20.0, seed=1):
    """The object on a striped, grainy cloth: soft stripes of 165 and 245 grey levels, 12 pixels
    wide, slanted, with grain (smoothed noise of 8 grey levels)."""
    poly = truth(rotation)
    rows, cols = np.mgrid[0:SIZE, 0:SIZE]
    phase = 2 * np.pi * (cols + 0.4 * rows) / 24.0
    stripes = np.clip(2.0 * np.sin(phase), -1, 1)
    grain = cv2.GaussianBlur(np.random.default_rng(seed).normal(0.0, 1.0, (SIZE, SIZE)), (0, 0), 1.5)
    background = 205.0 + 40.0 * stripes + 8.0 * grain / grain.std()
    return _compose(background, poly, seed), poly


def uneven(rotation=20.0):
    """The object under light falling off across the image: 0.45 to 1.15 of the light, left to right."""
    poly = truth(rotation)
    gain = np.linspace(0.45, 1.15, SIZE)[None, :] * np.ones((SIZE, 1))
    cover = coverage(poly)
    image = gain * (PAPER * (1 - cover) + OBJECT * cover)
    image = image + np.random.default_rng(0).normal(0.0, 2.0, image.shape)
    return np.clip(np.round(image), 0, 255).astype(np.uint8), poly


SCENES = {"plain": plain, "shadow": shadow, "textured": textured, "uneven": uneven}
