"""Boxes drawn as an image, so that a box far below a pixel is still seen: the pavings of ``workspace``
and the cells of ``singularity``."""
from __future__ import annotations

import numpy as np


def draw_boxes(ax, layers, dlo, dhi, pixels: int, square: bool = True) -> None:
    """Draw ``layers``, a list of (lo (N, 2), hi (N, 2), colour "#rrggbb", grow), in order, as one image
    over [dlo, dhi]: at most ``pixels`` a side with square pixels, or ``pixels`` along each axis when
    ``square`` is false.  Each box colours every pixel it touches (rounded outward; at least one), and
    with ``grow`` g also the g pixels around it; a later layer is drawn over an earlier one.  With
    ``pixels`` at most the axes' size in page pixels and ``grow`` 1, a box of the top layer is seen on
    the page however small (a page pixel straddling two image pixels shows one of them).  Boxes are
    added with a summed-area table: millions take a second."""
    dlo, dhi = np.asarray(dlo, float), np.asarray(dhi, float)
    extent = dhi - dlo
    step = np.full(2, float(np.max(extent)) / pixels) if square else extent / pixels
    step = np.maximum(step, 1e-300)
    shape = np.clip(np.ceil(extent / step), 1, pixels).astype(np.int64)       # (columns, rows)
    rgb = np.ones((shape[1], shape[0], 3))
    for lo, hi, colour, grow in layers:
        if not len(lo):
            continue
        a = np.clip(np.floor((lo - dlo) / step) - grow, 0, shape - 1).astype(np.int64)
        b = np.clip(np.ceil((hi - dlo) / step) + grow, a + 1, shape).astype(np.int64)
        table = np.zeros((shape[1] + 1, shape[0] + 1), np.int64)
        for (i, j), sign in (((a[:, 1], a[:, 0]), 1), ((a[:, 1], b[:, 0]), -1), ((b[:, 1], a[:, 0]), -1),
                             ((b[:, 1], b[:, 0]), 1)):
            np.add.at(table, (i, j), sign)
        covered = np.cumsum(np.cumsum(table, 0), 1)[:shape[1], :shape[0]] > 0
        rgb[covered] = [int(colour[k:k + 2], 16) / 255 for k in (1, 3, 5)]
    ax.imshow(rgb, extent=(dlo[0], dlo[0] + shape[0] * step[0], dlo[1], dlo[1] + shape[1] * step[1]), origin="lower",
              interpolation="nearest", aspect="equal" if square else "auto")
