"""Names that moved or were renamed, still served for one release.

A module whose public names moved elsewhere sets ``__getattr__ = moved_names(__name__,
{...})`` (PEP 562): reading an old name gives the very same object, with a
``DeprecationWarning`` naming its new place; any other missing name is an
``AttributeError`` as usual. A value chosen by name (a mode, a registered plug-in) whose
name changed goes through :func:`renamed`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from types import ModuleType
from typing import Any

__all__ = ["moved_names", "renamed"]


def moved_names(
    module: str, moves: Mapping[str, ModuleType | tuple[ModuleType, str]]
) -> Callable[[str], Any]:
    """A module ``__getattr__`` serving the public names that moved out of ``module``.

    Parameters
    ----------
    module : str
        The old module's name (``__name__``), for the messages.
    moves : mapping
        Each old name to the module now holding it (same name there), or to
        ``(module, new name)``.

    Returns
    -------
    callable
        ``__getattr__(name)`` for the old module.
    """

    def __getattr__(name: str) -> Any:
        if name not in moves:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        target = moves[name]
        new_module, new_name = target if isinstance(target, tuple) else (target, name)
        warnings.warn(
            f"{module}.{name} moved to {new_module.__name__}.{new_name}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(new_module, new_name)

    return __getattr__


def renamed(kind: str, name: object, renames: Mapping[str, str], stacklevel: int = 2) -> object:
    """``name``, or the name a deprecated ``name`` became (with a ``DeprecationWarning``).

    Parameters
    ----------
    kind : str
        What the name names, for the message (e.g. ``"homing mode"``).
    name : object
        The name given; anything not in ``renames`` is returned as is.
    renames : mapping
        Each deprecated name to its new one.
    stacklevel : int
        As :func:`warnings.warn`'s, counted from the caller of this function.
    """
    if not isinstance(name, str) or name not in renames:
        return name
    new = renames[name]
    warnings.warn(
        f"{kind} {name!r} is deprecated; use {new!r}", DeprecationWarning, stacklevel=stacklevel + 1
    )
    return new
