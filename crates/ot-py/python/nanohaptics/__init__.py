# The package `nanohaptics` (maturin's mixed layout, `python-source` in pyproject.toml): the
# Rust extension `nanohaptics.nanohaptics` (the crate crates/ot-py) holds every binding; this
# file re-exports its names and adds the Python modules `bridge` (the device bridge's client
# and device adapters), `sweeps` (parameter studies: sweep, grid, run_seed) and `closed_loop`.
# The type stub is __init__.pyi (a link to crates/ot-py/nanohaptics.pyi).

from . import nanohaptics as _native
from .nanohaptics import *  # noqa: F401,F403 (the extension's names: its __all__)
from . import bridge, sweeps
from .sweeps import grid, run_seed, sweep

# `closed_loop` is the function; the module stays importable as `nanohaptics.closed_loop`.
from .closed_loop import closed_loop

__doc__ = _native.__doc__
__version__ = _native.__version__
__all__ = [*_native.__all__, "bridge", "sweeps", "sweep", "grid", "run_seed", "closed_loop"]

del _native
