"""One case of ``vc-gym check`` and the assertion most cases make (shared by the suites)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Case", "raises"]


@dataclass(frozen=True)
class Case:
    """One check: ``run(tmp)`` raises ``AssertionError`` (or anything) when it fails."""

    suite: str
    name: str
    run: Callable[[Path], None]


def raises(
    kind: type[BaseException] | tuple[type[BaseException], ...],
    match: str,
    fn: Callable[[], object],
) -> None:
    """``fn()`` must raise ``kind`` (or one of them) whose message contains ``match``."""
    try:
        fn()
    except kind as exc:
        if match.lower() not in str(exc).lower():
            raise AssertionError(f"{type(exc).__name__} without {match!r}: {exc}") from None
        return
    names = [k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,))]
    raise AssertionError(f"no {' or '.join(names)} raised")
