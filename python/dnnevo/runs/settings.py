"""A run's settings compared: the digest of a complete config, the first setting two configs
disagree on, and the manifest (``sweep.json``, ``reproduce.json``) that keeps a folder to one
set of settings."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from dnnevo.config import LATER_SETTINGS, EvolutionConfig, with_later_defaults
from dnnevo.errors import ConfigError
from dnnevo.runs.files import RunFileError, checked, read_json, short

__all__ = ['MAX_CONFIG_DEPTH', 'depth', 'check_settings', 'config_digest', 'first_difference',
           'manifest_with_later_defaults']

def config_digest(config: EvolutionConfig, seed: int) -> str:
    """SHA-256 of the complete run config (every setting and the seed), as canonical JSON."""
    settings = config.to_dict()
    defaults = EvolutionConfig()
    for name in LATER_SETTINGS:
        if getattr(config, name) == getattr(defaults, name):
            del settings[name]
    doc = {"config": settings, "seed": seed}
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def manifest_with_later_defaults(found: dict[str, Any]) -> dict[str, Any]:
    """A settings manifest as read (a sweep's ``config``, a reproduction's ``configs`` by
    experiment), each config with the settings added since it was written at their defaults
    (:func:`~dnnevo.config.with_later_defaults`), as today's command would record it.

    >>> manifest_with_later_defaults({"configs": {"a": {"population": 3}}})["configs"]["a"]["precision"]
    'f64'
    """
    out = dict(found)
    if "config" in out:
        out["config"] = with_later_defaults(out["config"])
    if isinstance(out.get("configs"), dict):
        out["configs"] = {k: with_later_defaults(v) for k, v in out["configs"].items()}
    return out


def first_difference(a: Any, b: Any, prefix: str = "") -> tuple[str, Any, Any] | None:
    """The first field (dotted name) where two config dicts differ, with both values; numbers
    compare by value (1 equals 1.0), and ``None`` means they agree."""
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        for key in [*a, *(k for k in b if k not in a)]:
            name = f"{prefix}.{key}" if prefix else str(key)
            if key not in a or key not in b:
                return name, a.get(key, "(missing)"), b.get(key, "(missing)")
            found = first_difference(a[key], b[key], name)
            if found is not None:
                return found
        return None
    same = a == b and isinstance(a, bool) == isinstance(b, bool)
    return None if same else (prefix, a, b)


#: The deepest nesting of tables and arrays accepted in config.toml (a run's own is 3 deep).
MAX_CONFIG_DEPTH = 16


def check_settings(manifest: Path, settings: dict[str, Any], *, what: str, force: bool = True) -> None:
    """The settings file ``manifest`` of a folder of several runs (a ``what``, e.g. "sweep") must
    hold ``settings``; else a one-line :class:`ConfigError` naming the first that differs, or a
    :class:`RunFileError` when the file is unreadable. ``force``: the command has ``--force``."""
    again = ", or pass --force" if force else ""
    try:
        found = read_json(manifest)
    except RunFileError as e:
        problem = str(e).removeprefix(f"{manifest}: ")
        raise RunFileError(f"{manifest}: unreadable ({problem}); choose another --out{again}") from None
    if not isinstance(found, dict):
        raise RunFileError(f"{manifest}: expected a JSON object of settings; choose another --out{again}")
    found = manifest_with_later_defaults(found)
    with checked(manifest):
        diff = first_difference(found, json.loads(json.dumps(settings)))
    if diff is not None:
        raise ConfigError(
            f"{manifest.parent} holds a {what} with {diff[0]} = {short(diff[1])}, not {short(diff[2])}; "
            f"run the same command to continue it, or choose another --out{again}")


def depth(value: Any) -> int:
    """How deeply ``value`` nests lists and dicts, without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, dict | list):
            deepest = max(deepest, d + 1)
            if deepest > MAX_CONFIG_DEPTH:
                return deepest
            stack.extend((x, d + 1) for x in (v.values() if isinstance(v, dict) else v))
    return deepest
