"""A package's submodules as its attributes on first use (PEP 562): ``bearingsim.studies.life`` after a plain
``import bearingsim``, imported then and not before, so that importing a package stays light. A leaf module:
the packages' ``__getattr__``/``__dir__`` call it, and it imports nothing of bearingsim."""
from __future__ import annotations


def submodule(package: str, name: str):
    """The submodule ``package.name``, imported on its first use as an attribute of ``package``;
    AttributeError when the package has no such submodule."""
    import importlib
    import importlib.util

    if not name.startswith("__"):  # dunder probes (copy, pickle, inspect) are never submodules
        fullname = f"{package}.{name}"
        try:
            found = importlib.util.find_spec(fullname) is not None
        except (ImportError, ValueError):
            found = False
        if found:
            return importlib.import_module(fullname)
    raise AttributeError(f"module {package!r} has no attribute {name!r}")


def submodule_names(path) -> list[str]:
    """The names of the modules and subpackages in a package's ``__path__``."""
    import pkgutil

    return [m.name for m in pkgutil.iter_modules(path) if not m.name.startswith("__")]
