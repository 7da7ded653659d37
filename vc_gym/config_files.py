"""Reading settings files (JSON or YAML) safely: plain data only, bounded size and depth.

A settings file may come from anyone (a colleague's hyperparameters, a downloaded run):
reading one must never execute code (YAML is read with a safe loader: no Python tags),
exhaust memory or time (a size limit before parsing; YAML aliases, which let a few
hundred bytes expand into billions of nodes, are refused) or crash the interpreter (deep
nesting is refused with a clear error, not a ``RecursionError``). A key given twice is
refused too, rather than silently keeping the last value.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

__all__ = ["MAX_SETTINGS_BYTES", "MAX_SETTINGS_DEPTH", "read_settings"]

#: Largest settings file read (bytes).
MAX_SETTINGS_BYTES = 1_000_000
#: Deepest nesting of lists and mappings accepted.
MAX_SETTINGS_DEPTH = 20


class _DuplicateKey(ValueError):
    """A mapping names the same key twice."""


def _unique_pairs(pairs: list[tuple[Any, Any]]) -> dict[Any, Any]:
    """``json.loads``'s ``object_pairs_hook``: a dict, refusing a repeated key."""
    out: dict[Any, Any] = {}
    for k, v in pairs:
        if k in out:
            raise _DuplicateKey(f"key {k!r} appears twice in one mapping")
        out[k] = v
    return out


def _yaml_loader():
    """A ``yaml.SafeLoader`` that refuses aliases and repeated keys."""
    import yaml

    class Loader(yaml.SafeLoader):
        def compose_node(self, parent, index):  # noqa: ANN001 - PyYAML's signature
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(
                    None, None, "aliases (*name) are not accepted in settings files",
                    event.start_mark,
                )
            return super().compose_node(parent, index)

        def construct_mapping(self, node, deep=False):  # noqa: ANN001
            seen: set[Any] = set()
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                try:
                    repeated = key in seen
                    seen.add(key)
                except TypeError:  # an unhashable key: the base class reports it
                    repeated = False
                if repeated:
                    raise _DuplicateKey(
                        f"key {key!r} appears twice in one mapping (line "
                        f"{key_node.start_mark.line + 1})"
                    )
            return super().construct_mapping(node, deep=deep)

    return Loader


def _depth(value: Any, limit: int) -> int:
    """Nesting depth of ``value``, iteratively (so a deep value cannot overflow the stack)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, dict | list):
            if d > limit:
                return d
            deepest = max(deepest, d)
            stack.extend((c, d + 1) for c in (v.values() if isinstance(v, dict) else v))
    return deepest


def read_settings(path: str | os.PathLike) -> dict[str, Any]:
    """Read a JSON (``.json``) or YAML (``.yml``, ``.yaml``) file holding one mapping.

    Raises
    ------
    ValueError
        Naming the file: missing, too large (:data:`MAX_SETTINGS_BYTES`), not UTF-8, not
        parseable, holding a YAML alias or a key twice, nested deeper than
        :data:`MAX_SETTINGS_DEPTH`, or not a mapping with string keys.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".json", ".yml", ".yaml"):
        raise ValueError(f"{p}: a settings file must be .json, .yml or .yaml")
    try:
        size = p.stat().st_size
        if size > MAX_SETTINGS_BYTES:
            raise ValueError(f"{p}: {size} bytes, more than a settings file may hold")
        text = p.read_bytes().decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{p}: cannot read the settings file: {exc}") from None
    try:
        if suffix == ".json":
            data = json.loads(text, object_pairs_hook=_unique_pairs)
        else:
            import yaml

            data = yaml.load(text, Loader=_yaml_loader())  # noqa: S506 - a safe loader
    except RecursionError:
        raise ValueError(f"{p}: nested too deeply") from None
    except _DuplicateKey as exc:
        raise ValueError(f"{p}: {exc}") from None
    except Exception as exc:  # json.JSONDecodeError, yaml.YAMLError and their kin
        raise ValueError(f"{p}: not valid {suffix[1:].upper()}: {exc}") from None
    if _depth(data, MAX_SETTINGS_DEPTH) > MAX_SETTINGS_DEPTH:
        raise ValueError(f"{p}: nested deeper than {MAX_SETTINGS_DEPTH} levels")
    if not isinstance(data, dict) or not all(isinstance(k, str) for k in data):
        raise ValueError(f"{p}: must hold one mapping of settings by name")
    return data
