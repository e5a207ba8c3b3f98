"""Helpers shared by the modules of the package: errors, JSON, argument checks.

Nothing here computes a number of a study: every number comes from the C++ core (``_core``).
"""

from __future__ import annotations

import json
import math
import numbers
import operator
from typing import Any, Callable, Mapping, Sequence

from . import _core

McplayError = _core.McplayError

#: The status the core gives a bad argument (``MCP_ERROR_ARGUMENT``), for errors raised here.
_STATUS_ARGUMENT = 1


def argument_error(message: str) -> Exception:
    """An :class:`McplayError` for a bad argument caught before the core is called."""
    error = McplayError(message)
    for name, value in (("status", _STATUS_ARGUMENT), ("status_name", "ARGUMENT")):
        try:
            setattr(error, name, value)
        except AttributeError:  # an exception type whose attributes are read-only
            pass
    return error


def to_json(value: Any, what: str) -> str:
    """``value`` as JSON text; NaN, infinities and non-JSON types raise an error naming ``what``."""
    try:
        return json.dumps(value, allow_nan=False, default=_json_default)
    except ValueError as error:
        raise argument_error(f"{what}: {_json_problem(error)}") from None
    except TypeError as error:
        raise argument_error(f"{what}: {error}") from None


def _json_default(value: Any) -> Any:
    """numpy scalars and arrays, and paths, in JSON."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "__fspath__"):
        return str(value.__fspath__())
    raise TypeError(f"a {type(value).__name__} cannot be written as JSON")


def _json_problem(error: ValueError) -> str:
    text = str(error)
    if "Out of range float" in text:
        return "NaN or infinite number (not allowed in a scene or a request)"
    return text


def from_json(text: str) -> Any:
    """JSON text from the core as Python objects."""
    return json.loads(text)


def whole_number(value: Any, name: str, minimum: int | None = None) -> int:
    """``value`` as an int (numpy integers too, never a bool or a float), else an error naming
    ``name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise argument_error(f"{name}: expected a whole number, got {_shown(value)}")
    value = operator.index(value)
    if minimum is not None and value < minimum:
        raise argument_error(f"{name}: expected a whole number >= {minimum}, got {value}")
    return value


def real_number(value: Any, name: str, positive: bool = False) -> float:
    """``value`` as a finite float (``positive``: > 0), else an error naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise argument_error(f"{name}: expected a number, got {_shown(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise argument_error(f"{name}: expected a finite number, got {value}")
    if positive and value <= 0.0:
        raise argument_error(f"{name}: expected a number > 0, got {value}")
    return value


def callable_or_none(value: Any, name: str) -> Callable | None:
    if value is not None and not callable(value):
        raise argument_error(f"{name}: expected a callable or None, got {_shown(value)}")
    return value


def estimator_list(estimators: Any, name: str = "estimators") -> list | None:
    """A preset name, an estimator object or a sequence of them, as the scene's list."""
    if estimators is None:
        return None
    if isinstance(estimators, (str, Mapping)):
        estimators = [estimators]
    if not isinstance(estimators, Sequence):
        raise argument_error(
            f"{name}: expected a name, an estimator object (dict) or a list of them, "
            f"got {_shown(estimators)}"
        )
    items = list(estimators)
    if not items:
        raise argument_error(f"{name}: the list is empty; give at least one estimator")
    for i, item in enumerate(items):
        if not isinstance(item, (str, Mapping)):
            raise argument_error(
                f"{name}[{i}]: expected a preset name or an estimator object (dict), "
                f"got {_shown(item)}"
            )
    return [dict(item) if isinstance(item, Mapping) else item for item in items]


def part_pair(part: Any) -> tuple[int, int] | None:
    """``part=(i, k)``: replicate share i of k, checked for shape (the core checks the range)."""
    if part is None:
        return None
    if isinstance(part, (str, bytes)) or not isinstance(part, Sequence) or len(part) != 2:
        raise argument_error(f"part: expected a pair (i, k), got {_shown(part)}")
    return whole_number(part[0], "part[0]", 0), whole_number(part[1], "part[1]", 1)


def progress_adapter(progress: Callable | None) -> Callable[[str], None] | None:
    """The core's progress callback (one JSON line per level) calling ``progress`` with a dict."""
    if progress is None:
        return None
    callable_or_none(progress, "progress")

    def on_line(line: str) -> None:
        progress(json.loads(line))

    return on_line


def _shown(value: Any) -> str:
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{type(value).__name__} {text}" if not isinstance(value, str) else text


def put(target: dict, key: str, value: Any) -> None:
    """Sets ``target[key]`` when ``value`` is not None."""
    if value is not None:
        target[key] = value


def box_domain(domain: Any) -> dict:
    """A scene box domain from a sequence (or array) of ``(lo, hi)`` pairs, one per axis."""
    if isinstance(domain, (str, bytes)) or not (
        isinstance(domain, Sequence) or hasattr(domain, "tolist")
    ):
        raise argument_error(
            "domain: expected a scene domain dict or a sequence of (lo, hi) pairs, got "
            f"{type(domain).__name__}"
        )
    pairs = domain.tolist() if hasattr(domain, "tolist") else list(domain)
    if not pairs:
        raise argument_error("domain: no (lo, hi) pairs given")
    lower, upper = [], []
    for i, pair in enumerate(pairs):
        if isinstance(pair, (str, bytes)) or not isinstance(pair, Sequence) or len(pair) != 2:
            raise argument_error(f"domain[{i}]: expected a pair (lo, hi), got {pair!r}")
        lower.append(real_number(pair[0], f"domain[{i}][0]"))
        upper.append(real_number(pair[1], f"domain[{i}][1]"))
    return {"type": "box", "lower": lower, "upper": upper}
