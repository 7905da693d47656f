"""Load a script of benchmarks/ as a module, so tests can call its functions (the scripts are not a package)."""

import importlib.util
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent.parent / "benchmarks"


def load(name):
    """The module of ``benchmarks/<name>.py``, registered in ``sys.modules`` (dataclasses look it up by name).

    ``benchmarks/`` is on ``sys.path`` while it loads, for scripts that import their siblings.
    """
    sys.path.insert(0, str(BENCHMARKS))
    try:
        spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(BENCHMARKS))
    return module
