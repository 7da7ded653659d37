"""The axes every top view of the field shares: its outline, limits and equal aspect."""

from __future__ import annotations

from typing import Any

from matplotlib.patches import Rectangle

__all__ = ["field_axes"]


def field_axes(ax: Any, field_bounds: tuple[float, float, float, float]) -> None:
    """Draw the field's outline on ``ax``, with a margin, equal aspect and metre labels."""
    x0, x1, y0, y1 = field_bounds
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="0.3", lw=1.2))
    pad = 0.3
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
