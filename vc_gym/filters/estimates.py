"""Estimates the filters report."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["HeadingEstimate"]


@dataclass(frozen=True)
class HeadingEstimate:
    """A heading belief summarised as a Gaussian (paper eq. 25-27).

    Attributes
    ----------
    heading_deg : float
        Circular mean of the belief, in ``[0, 360)`` (eq. 26).
    spread_deg : float
        Circular standard deviation of the belief (eq. 27).
    """

    heading_deg: float
    spread_deg: float
