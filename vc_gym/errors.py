"""Exceptions of vc_gym."""

from __future__ import annotations

__all__ = ["NotLearnedError", "MapFileError"]


class NotLearnedError(RuntimeError):
    """A sensor model was asked for likelihoods before it has colour classes or a map."""


class MapFileError(ValueError):
    """A saved map or colour-class file cannot be read; the message names file and reason."""
