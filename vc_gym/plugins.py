"""Plug-ins chosen by a name, a ``{"type": name, **kwargs}`` dict or a callable.

One resolver for every kind of plug-in (trackers, sensors), the HighwayEnv way: a
registry maps names to factories, and :func:`make_plugin` turns any spec a user, a
config file or the command line gives into an object, with errors that name the
known choices.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, MutableMapping
from typing import Any

__all__ = ["import_factory", "make_plugin", "register_plugin"]


def register_plugin(
    registry: MutableMapping[str, Callable[..., Any]],
    kind: str,
    name: str,
    factory: Callable[..., Any],
    overwrite: bool = False,
) -> None:
    """Add ``factory`` to ``registry`` under ``name`` (refusing to replace one silently)."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"a {kind} name must be a non-empty string, got {name!r}")
    if not callable(factory):
        raise ValueError(f"factory must be callable, got {factory!r}")
    if name in registry and not overwrite:
        raise ValueError(f"{kind} {name!r} is registered already (pass overwrite=True)")
    registry[name] = factory


def import_factory(path: str, kind: str) -> Callable[..., Any]:
    """The callable at ``"package.module:attr.attr"``."""
    module, _, attr = path.partition(":")
    try:
        obj: Any = importlib.import_module(module)
        for part in attr.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ValueError(f"cannot import {kind} factory {path!r}: {exc}") from None
    if not callable(obj):
        raise ValueError(f"{kind} factory {path!r} is not callable")
    return obj


def make_plugin(
    spec: Any,
    registry: Mapping[str, Callable[..., Any]],
    kind: str,
    is_instance: Callable[[object], bool],
    what: str,
) -> Any:
    """Build a plug-in from ``spec``.

    Parameters
    ----------
    spec : str, dict, callable or instance
        A registered name; ``"package.module:factory"`` (imported, called with no
        arguments: survives pickling and the command line); ``{"type": name,
        **kwargs}`` (kwargs to the factory; the type may be an import path too); a
        callable with no arguments; or an instance (``is_instance(spec)``), returned
        as is.
    registry : mapping
        Names to factories.
    kind : str
        What is built (``"tracker"``, ``"sensor"``), for messages.
    is_instance : callable
        Whether an object is a finished plug-in of this kind.
    what : str
        What such an object offers, for the message when a factory returns another.

    Raises
    ------
    ValueError
        An unknown name (listing the known ones), a dict without ``type``, bad
        arguments, or a factory that returns no plug-in of this kind.
    """

    def checked(obj: object) -> Any:
        if not is_instance(obj):
            raise ValueError(f"{kind} spec {spec!r} gave {type(obj).__name__}, which has no {what}")
        return obj

    def known(name: object) -> Callable[..., Any]:
        if not isinstance(name, str) or name not in registry:
            raise ValueError(f"unknown {kind} {name!r}; known: {sorted(registry)}")
        return registry[name]

    if isinstance(spec, str) and ":" in spec and spec not in registry:
        return checked(import_factory(spec, kind)())
    if isinstance(spec, str):
        return checked(known(spec)())
    if isinstance(spec, Mapping):
        kwargs = dict(spec)
        name = kwargs.pop("type", None)
        if not isinstance(name, str):
            raise ValueError(f"a {kind} dict needs a 'type' name, got {spec!r}")
        factory = (
            import_factory(name, kind) if ":" in name and name not in registry else known(name)
        )
        try:
            obj = factory(**kwargs)
        except TypeError as exc:
            raise ValueError(f"bad arguments for {kind} {name!r}: {exc}") from None
        return checked(obj)
    if is_instance(spec) and not isinstance(spec, type):
        return spec
    if callable(spec):
        return checked(spec())
    raise ValueError(
        f"a {kind} spec is a name, a {{'type': name, ...}} dict or a callable, got {spec!r}"
    )
