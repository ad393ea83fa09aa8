"""Classes named by import path ("package.module:Class"), imported only when first needed.

The registries (`envs.tasks.catalog`, `envs.robots`, `envs.modes`) name the simulating classes this way, so reading
them loads neither MuJoCo nor anything else heavy.
"""

from __future__ import annotations

import importlib
import re

PATH_PATTERN = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_][\w.]*")


def check(field: str, ref: object, *, optional: bool = False) -> None:
    """Raise ValueError naming `field` unless `ref` is a class or a "package.module:Class" string."""
    if (ref is None and optional) or isinstance(ref, type):
        return
    if not (isinstance(ref, str) and PATH_PATTERN.fullmatch(ref)):
        raise ValueError(f"{field} must be a class or an import path 'package.module:Class', got {ref!r}")


def resolve(ref: str | type) -> type:
    """The class `ref` names (a class is returned as it is)."""
    if isinstance(ref, type):
        return ref
    module, _, attribute = ref.partition(":")
    value = importlib.import_module(module)
    for part in attribute.split("."):
        value = getattr(value, part)
    return value
