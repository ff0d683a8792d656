"""Labels that never overlap: measured on the rendered figure, then thinned or shrunk."""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

GAP_PX = 3.0  # least space between two labels
MIN_FONT_PT = 5.0


def _renderer(fig: Figure):
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    fig.draw_without_rendering()  # lays the figure out (constrained layout), paints nothing
    return canvas.get_renderer()


def _padded(box: Bbox) -> Bbox:
    return Bbox.from_extents(
        box.x0 - GAP_PX / 2, box.y0 - GAP_PX / 2, box.x1 + GAP_PX / 2, box.y1 + GAP_PX / 2
    )


def thin_ticks(fig: Figure) -> None:
    """Hide every tick label that would touch the last one kept on its axis (keeps the first
    of each axis and then every label that fits, so round edges stay evenly spaced)."""
    renderer = _renderer(fig)
    for ax in fig.axes:
        for labels in (ax.get_xticklabels(), ax.get_yticklabels()):
            shown = [t for t in labels if t.get_visible() and t.get_text()]
            stride = 1
            while stride < len(shown) and _overlaps(shown[::stride], renderer):
                stride += 1
            for k, label in enumerate(shown):
                label.set_visible(k % stride == 0)


def _overlaps(texts: list[Text], renderer) -> bool:
    boxes = [_padded(t.get_window_extent(renderer)) for t in texts]
    return any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1 :])


def fit_in_cells(fig: Figure, texts: list[tuple[Text, Bbox]]) -> None:
    """Shrink each text to fit its cell (``Bbox`` in data coordinates of its axes), down to
    ``MIN_FONT_PT``; hide it when it still does not fit."""
    if not texts:
        return
    renderer = _renderer(fig)
    for text, cell in texts:
        if text.axes is None:
            continue
        window = cell.transformed(text.axes.transData)
        width, height = abs(window.width) - GAP_PX, abs(window.height) - GAP_PX
        size = float(text.get_fontsize())
        while size > MIN_FONT_PT:
            box = text.get_window_extent(renderer)
            if box.width <= width and box.height <= height:
                break
            size -= 0.5
            text.set_fontsize(size)
        box = text.get_window_extent(renderer)
        text.set_visible(box.width <= width and box.height <= height)
