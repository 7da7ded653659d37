"""Plug-ins chosen by a name, a ``{"type": name, **kwargs}`` dict or a callable.

One resolver for every kind of plug-in (trackers, sensors), the HighwayEnv way: a
registry maps names to factories, and :func:`make_plugin` turns any spec a user or
the command line gives into an object, with errors that name the known choices.

Only the person at the keyboard chooses code. Import paths (``"module:attr"``) and
callables are accepted from Python code and from the command line; a spec read from a
file (an agent's ``config.json``, a settings file, a saved run) passes
:func:`check_file_spec` first, which accepts only registered names with plain-data
arguments and refuses anything else, naming the file and the field, before anything
is imported.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, MutableMapping
from typing import Any

__all__ = [
    "MAX_SPEC_DEPTH",
    "check_file_spec",
    "check_plain_data",
    "import_factory",
    "make_plugin",
    "register_plugin",
]

#: Deepest nesting of lists and mappings in a plug-in's arguments read from a file.
MAX_SPEC_DEPTH = 8


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

    def called(factory: Callable[..., Any], name: object, kwargs: Mapping[str, Any]) -> Any:
        # a factory that cannot take these arguments (``os:system`` with none) says so here
        try:
            return factory(**kwargs)
        except TypeError as exc:
            raise ValueError(f"bad arguments for {kind} {name!r}: {exc}") from None

    if isinstance(spec, str) and ":" in spec and spec not in registry:
        return checked(called(import_factory(spec, kind), spec, {}))
    if isinstance(spec, str):
        return checked(called(known(spec), spec, {}))
    if isinstance(spec, Mapping):
        kwargs = dict(spec)
        name = kwargs.pop("type", None)
        if not isinstance(name, str):
            raise ValueError(f"a {kind} dict needs a 'type' name, got {spec!r}")
        factory = (
            import_factory(name, kind) if ":" in name and name not in registry else known(name)
        )
        return checked(called(factory, name, kwargs))
    if is_instance(spec) and not isinstance(spec, type):
        return spec
    if callable(spec):
        return checked(called(spec, spec, {}))
    raise ValueError(
        f"a {kind} spec is a name, a {{'type': name, ...}} dict or a callable, got {spec!r}"
    )


def check_plain_data(value: Any, where: str, depth: int = MAX_SPEC_DEPTH) -> None:
    """Refuse anything in ``value`` but JSON's plain data.

    ``None``, booleans, integers, finite or infinite floats, strings, lists (or tuples)
    and mappings with string keys, nested at most ``depth`` levels.

    Raises
    ------
    ValueError
        Starting with ``where`` (the file and field), naming what is not plain data.
    """
    stack = [(value, 0, where)]
    while stack:
        v, d, at = stack.pop()
        if v is None or isinstance(v, bool | int | float | str):
            continue
        if d >= depth:
            raise ValueError(f"{at}: nested deeper than {depth} levels")
        if isinstance(v, list | tuple):
            stack.extend((c, d + 1, f"{at}[{i}]") for i, c in enumerate(v))
        elif isinstance(v, Mapping):
            for k, c in v.items():
                if not isinstance(k, str):
                    raise ValueError(f"{at}: key {k!r} is not a string")
                stack.append((c, d + 1, f"{at}.{k}"))
        else:
            raise ValueError(f"{at}: {type(v).__name__} is not plain data")


def check_file_spec(
    spec: Any,
    registry: Mapping[str, Callable[..., Any]],
    kind: str,
    where: str,
    allow_imports: bool = False,
) -> None:
    """Check a plug-in spec that was read from a file, before anything is built.

    A file may name only plug-ins registered in this process (``register_tracker``,
    ``register_sensor``, ``register_scene``), by name or as ``{"type": name, **kwargs}``
    with plain-data arguments (:func:`check_plain_data`). An import path
    (``"module:attr"``) would run that module's code, so it is refused unless the person
    at the keyboard allowed it (``allow_imports``, e.g. a command-line flag); a callable
    or any other object cannot come from a file at all.

    Parameters
    ----------
    spec : object
        What the file holds.
    registry : mapping
        The registered names of this kind.
    kind : str
        ``"tracker"``, ``"sensor"``, ``"scene"``: for messages.
    where : str
        The file and field, e.g. ``"run/config.json: field 'tracker'"``.
    allow_imports : bool
        Accept ``"module:attr"`` names too.

    Raises
    ------
    ValueError
        Starting with ``where``: what is wrong and how to name a plug-in instead.
    """

    def check_name(name: object) -> None:
        if isinstance(name, str) and name in registry:
            return
        if isinstance(name, str) and ":" in name:
            if allow_imports:
                return
            raise ValueError(
                f"{where}: {kind} {name!r} is an import path, and a file may not choose code "
                f"to import; register it in Python (register_{kind}) and name it, or allow "
                f"import paths from files on the command line (--allow-imports); "
                f"registered: {sorted(registry)}"
            )
        raise ValueError(f"{where}: unknown {kind} {name!r}; registered: {sorted(registry)}")

    if isinstance(spec, str):
        check_name(spec)
    elif isinstance(spec, Mapping):
        if "type" not in spec:
            raise ValueError(f"{where}: a {kind} dict needs a 'type' name")
        check_name(spec["type"])
        check_plain_data(dict(spec), where)
    else:
        raise ValueError(
            f"{where}: a {kind} from a file is a registered name or a {{'type': name, ...}} "
            f"object, got {type(spec).__name__}"
        )
