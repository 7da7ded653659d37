"""Layout choices of a scene: the canonical value, or a random one (:class:`Draw`).

A scene builder makes every layout choice (a colour, a position, whether a poster hangs)
through its :attr:`Builder.choices <vc_gym.sim.scenes.builder.Builder.choices>`. In the
canonical scene each choice is its canonical value and draws nothing from the generator;
with ``randomize=True`` it is drawn, so a randomised scene is the same for the same seed.
"""

from __future__ import annotations

import colorsys
import warnings
from collections.abc import Sequence
from typing import TypeVar

import numpy as np

from vc_gym.sim.scenes.parts import RGB
from vc_gym.worlds.paint import hsv

__all__ = ["Draw"]

_T = TypeVar("_T")
_ON_DEPRECATED = "Draw.on is deprecated; use Draw.randomize"
_COLOUR_DEPRECATED = "Draw.colour is deprecated; use Draw.color"


class Draw:
    """Layout choices: drawn from ``rng`` when randomising, else the canonical value.

    Every method takes the canonical value first, then the range to draw from; with
    ``randomize=False`` it returns the canonical value and draws nothing, so the canonical
    scene does not depend on how many choices a builder makes.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the random draws.
    randomize : bool
        Whether to draw (``True``) or return the canonical values (``False``).

    Attributes
    ----------
    rng : numpy.random.Generator
        The generator.
    randomize : bool
        Whether choices are drawn (``True``) or canonical (``False``).
    """

    def __init__(self, rng: np.random.Generator, randomize: bool) -> None:
        self.rng = rng
        self.randomize = randomize

    @property
    def on(self) -> bool:
        """Deprecated name of :attr:`randomize`."""
        warnings.warn(_ON_DEPRECATED, DeprecationWarning, stacklevel=2)
        return self.randomize

    @on.setter
    def on(self, value: bool) -> None:
        warnings.warn(_ON_DEPRECATED, DeprecationWarning, stacklevel=2)
        self.randomize = value

    def uniform(self, canonical: float, lo: float, hi: float) -> float:
        """``canonical`` or a uniform draw from ``[lo, hi)``.

        Parameters
        ----------
        canonical : float
            Value of the canonical scene.
        lo, hi : float
            Range of the random draw.

        Returns
        -------
        float
            The value.
        """
        return float(self.rng.uniform(lo, hi)) if self.randomize else float(canonical)

    def integers(self, canonical: int, lo: int, hi: int) -> int:
        """``canonical`` or a draw from ``lo..hi`` (inclusive).

        Parameters
        ----------
        canonical : int
            Value of the canonical scene.
        lo, hi : int
            Range of the random draw, both ends included.

        Returns
        -------
        int
            The value.
        """
        return int(self.rng.integers(lo, hi + 1)) if self.randomize else int(canonical)

    def choice(self, canonical: _T, options: Sequence[_T]) -> _T:
        """``canonical`` or one of ``options``, each equally likely.

        Parameters
        ----------
        canonical : object
            Value of the canonical scene.
        options : sequence
            What to draw from.

        Returns
        -------
        object
            The value.
        """
        return options[int(self.rng.integers(len(options)))] if self.randomize else canonical

    def chance(self, canonical: bool, p: float) -> bool:
        """``canonical`` or ``True`` with probability ``p``.

        Parameters
        ----------
        canonical : bool
            Value of the canonical scene.
        p : float
            Probability of ``True`` when randomising.

        Returns
        -------
        bool
            The value.
        """
        return bool(self.rng.uniform() < p) if self.randomize else bool(canonical)

    def color(
        self, canonical: RGB, dh: float = 0.04, ds: float = 0.15, dv: float = 0.12
    ) -> np.ndarray:
        """``canonical`` (0..255) or a colour near it in hue, saturation and value.

        Parameters
        ----------
        canonical : sequence of float
            RGB colour (0..255) of the canonical scene.
        dh, ds, dv : float
            Largest change of hue, saturation and value (each on a 0..1 scale) when
            randomising.

        Returns
        -------
        numpy.ndarray
            ``float32`` RGB colour (0..255); multiply it to shade it (``rgb * 0.8``).
        """
        rgb = np.asarray(canonical, np.float32)
        if not self.randomize:
            return rgb
        h, s, v = colorsys.rgb_to_hsv(*(rgb / 255.0))
        return hsv(
            h + self.rng.uniform(-dh, dh),
            s + self.rng.uniform(-ds, ds),
            v + self.rng.uniform(-dv, dv),
        )

    def colour(
        self, canonical: RGB, dh: float = 0.04, ds: float = 0.15, dv: float = 0.12
    ) -> np.ndarray:
        """Deprecated name of :meth:`color` (the British spelling)."""
        warnings.warn(_COLOUR_DEPRECATED, DeprecationWarning, stacklevel=2)
        return self.color(canonical, dh, ds, dv)
