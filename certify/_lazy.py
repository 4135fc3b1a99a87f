"""Names of a package that load from their modules on first use (PEP 562).

Importing such a package runs none of its modules: a process that needs one module of it (one
compiling kernels on a cold cache, :mod:`qualgrasp.certify._kernels.sets`) imports that module
alone. The package's names read as before, ``from qualgrasp.certify import Grasp`` as
``qualgrasp.certify.Grasp``, and so do its own subpackages and modules as attributes (imported on
first use) and ``dir()``, which lists both. (The root package ``qualgrasp`` has a loader of its own,
which also answers ``__version__`` and may not import this private module.)
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from typing import Callable

__all__ = ["lazy_names"]


def lazy_names(package: str, homes: dict[str, tuple[str, ...]]) -> tuple[Callable, Callable]:
    """The module-level ``__getattr__`` and ``__dir__`` of ``package``, which exports the names of
    ``homes`` (a relative module name, such as ``".core"``, to the names it defines) and its own
    submodules.

    A name is imported from its module on first use and then kept in the package's namespace, so
    that later uses do not call ``__getattr__``; any other name raises ``AttributeError``.

    Examples
    --------
    >>> import qualgrasp.certify as certify
    >>> certify.Grasp is certify.core.grasp.Grasp
    True
    >>> hasattr(certify, "no_such_name"), hasattr(certify, "core.grasp")
    (False, False)
    """
    home = {name: module for module, names in homes.items() for name in names}
    submodules = frozenset(m.name for m in pkgutil.iter_modules(sys.modules[package].__path__))

    def __getattr__(name: str):
        if name in home:
            value = getattr(importlib.import_module(home[name], package), name)
        elif name in submodules:
            value = importlib.import_module(f"{package}.{name}")
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(home) | submodules)

    return __getattr__, __dir__
