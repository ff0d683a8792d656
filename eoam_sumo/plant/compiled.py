"""The fast online plant: all sub-steps of a co-simulation step in one compiled C call.

Where Python's headers are installed, ``advance`` is the ``advance`` of the same C code built
as a Python extension module (``codegen.extension_source``): floats in and lists out in C.
Otherwise the compiled library (``codegen.py``) is called through ``ctypes`` with
pre-allocated ctypes buffers (more Python overhead per call than the extension, far less than
calling the same library through ``casadi.external``). Without a working C compiler the same SX
function runs on CasADi's virtual machine (identical arithmetic, slower) and a
``RuntimeWarning`` says so.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.machinery
import importlib.util
import warnings
from pathlib import Path

import numpy as np

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.codegen import (
    EXTENSION_NAME,
    FUNCTION_NAME,
    build_library,
    c_source,
    default_cache_dir,
    extension_source,
    find_compiler,
    python_include,
    step_function,
)
from eoam_sumo.plant.model import INPUT_NAMES, OUTPUT_NAMES, STATE_NAMES
from eoam_sumo.plant.stepping import check_mu, stable_substeps, validate_step

BACKEND_C = "compiled-c"
BACKEND_VM = "casadi-vm"

_NX, _NU, _NY = len(STATE_NAMES), len(INPUT_NAMES), len(OUTPUT_NAMES)


@functools.lru_cache(maxsize=16)
def _load_library(path: str):
    """The step function of a compiled library and its work sizes (arg, res, iw, w)."""
    lib = ctypes.CDLL(path)
    work = lib[f"{FUNCTION_NAME}_work"]
    work.argtypes = [ctypes.POINTER(ctypes.c_longlong)] * 4
    work.restype = ctypes.c_int
    sizes = [ctypes.c_longlong() for _ in range(4)]
    work(*[ctypes.byref(s) for s in sizes])
    fn = lib[FUNCTION_NAME]
    fn.argtypes = [ctypes.c_void_p] * 4 + [ctypes.c_int]
    fn.restype = ctypes.c_int
    return lib, fn, tuple(s.value for s in sizes)


@functools.lru_cache(maxsize=16)
def _source(params, dt_s, substeps) -> str:
    """The step's C source, generated once per process and parameter set (a batch worker
    builds a plant for every case)."""
    return c_source(step_function(params, dt_s, substeps))


@functools.lru_cache(maxsize=16)
def _load_extension(path: str):
    """The ``advance`` of a compiled extension module (``codegen.extension_source``)."""
    loader = importlib.machinery.ExtensionFileLoader(EXTENSION_NAME, path)
    spec = importlib.util.spec_from_file_location(EXTENSION_NAME, path, loader=loader)
    if spec is None:
        raise ImportError(f"cannot load {path}")
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module.advance


def _extension_advance(params, dt_s, substeps, cache_dir):
    """``advance`` of the step built as a Python extension module, or None where Python's
    headers are missing or the build fails (``Plant.advance`` then calls through ctypes)."""
    include, compiler = python_include(), find_compiler()
    if include is None or compiler is None:
        return None
    source = extension_source(_source(params, dt_s, substeps), _NX, _NU, _NY)
    try:
        path = build_library(source, cache_dir, compiler, (f"-I{include}",), EXTENSION_NAME)
        return _load_extension(str(path))
    except (OSError, RuntimeError, ImportError):
        return None


def _compiled_library(params, dt_s, substeps, cache_dir) -> str | None:
    """Path of the compiled library, or None (with a warning) when it cannot be built."""
    compiler = find_compiler()
    if compiler is None:
        warnings.warn(
            "no C compiler found ($CC, gcc, cc): the plant runs on the CasADi virtual machine",
            RuntimeWarning,
            stacklevel=3,
        )
        return None
    try:
        source = _source(params, dt_s, substeps)
        return str(build_library(source, cache_dir, compiler))
    except (OSError, RuntimeError) as err:
        warnings.warn(
            f"plant compilation failed ({err}); the plant runs on the CasADi virtual machine",
            RuntimeWarning,
            stacklevel=3,
        )
        return None


class Plant:
    """Ego plant: ``step(x, u, mu) -> (x_next, y)`` advances ``substeps * dt_s`` seconds.

    ``x`` (``STATE_NAMES``), ``u`` (``INPUT_NAMES``) and the returned ``x_next``, ``y``
    (``OUTPUT_NAMES``, evaluated at ``x_next``) are 1-D float arrays (``advance``: lists of
    floats, for loops that keep the state in plain floats); ``mu`` is the peak surface
    friction under the vehicle for this step. The model is ``model.rhs`` integrated by the
    midpoint rule (``integrator.py``), ``dt_s`` split further where a vehicle's wheel-and-tyre
    mode needs it (``stepping.stable_substeps``; ``dt_s`` and ``substeps`` then say what runs).
    The C library is built on first construction (a few
    seconds) and cached in ``cache_dir`` (default ``codegen.default_cache_dir()``). Instances
    hold their own buffers: one instance must not be stepped from two threads at once.
    """

    def __init__(
        self,
        params: VehicleParams,
        dt_s: float = 1e-3,
        substeps: int = 10,
        *,
        use_compiler: bool = True,
        cache_dir: str | Path | None = None,
    ):
        validate_step(params, dt_s, substeps)
        dt_s, substeps = stable_substeps(params, float(dt_s), substeps)
        self.params = params
        self.dt_s = dt_s
        self.substeps = substeps
        self._use_compiler = bool(use_compiler)
        self._cache_dir = Path(cache_dir) if cache_dir is not None else default_cache_dir()
        self.library_path = (
            _compiled_library(params, self.dt_s, substeps, self._cache_dir)
            if use_compiler
            else None
        )
        self._x = (ctypes.c_double * _NX)()
        self._u = (ctypes.c_double * _NU)()
        self._mu = (ctypes.c_double * 1)()
        self._x_next = (ctypes.c_double * _NX)()
        self._y = (ctypes.c_double * _NY)()
        if self.library_path is None:
            self._vm = step_function(params, self.dt_s, substeps)
            return
        self._lib, self._fn, (n_arg, n_res, n_iw, n_w) = _load_library(self.library_path)
        self._iw = (ctypes.c_longlong * max(n_iw, 1))()
        self._w = (ctypes.c_double * max(n_w, 1))()
        self._arg = (ctypes.c_void_p * n_arg)(*map(ctypes.addressof, (self._x, self._u, self._mu)))
        self._res = (ctypes.c_void_p * n_res)(*map(ctypes.addressof, (self._x_next, self._y)))
        self._call_args = (
            *map(ctypes.addressof, (self._arg, self._res, self._iw, self._w)),
            0,
        )
        extension = _extension_advance(params, self.dt_s, substeps, self._cache_dir)
        if extension is not None:
            self.advance = extension  # type: ignore[method-assign]  # the same, in C

    @property
    def backend(self) -> str:
        """``"compiled-c"`` or ``"casadi-vm"`` (no compiler, or compilation failed)."""
        return BACKEND_VM if self.library_path is None else BACKEND_C

    @property
    def step_s(self) -> float:
        """Time advanced by one ``step`` call [s]."""
        return self.dt_s * self.substeps

    def step(self, x, u, mu: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance ``substeps`` sub-steps with ``u`` and ``mu`` held; return new arrays."""
        x_next, y = self.advance(x, u, mu)
        return np.array(x_next), np.array(y)

    def advance(self, x, u, mu: float) -> tuple[list[float], list[float]]:
        """``step`` on and to lists of floats (no numpy on the way)."""
        if len(x) != _NX or len(u) != _NU:
            raise ValueError(f"x needs {_NX} and u {_NU} values, got {len(x)} and {len(u)}")
        self._x[:] = x
        self._u[:] = u
        self._mu[0] = check_mu(mu)
        if self.library_path is None:
            x_next, y = self._vm(self._x[:], self._u[:], self._mu[0])
            return x_next.full().ravel().tolist(), y.full().ravel().tolist()
        if self._fn(*self._call_args) != 0:
            raise RuntimeError(f"{FUNCTION_NAME} returned an error")
        return self._x_next[:], self._y[:]

    def __reduce__(self):
        return (
            _restore,
            (self.params, self.dt_s, self.substeps, self._use_compiler, str(self._cache_dir)),
        )


def _restore(params, dt_s, substeps, use_compiler, cache_dir) -> Plant:
    """Unpickle a ``Plant`` (ctypes handles are rebuilt, the compiled library is reused)."""
    return Plant(params, dt_s, substeps, use_compiler=use_compiler, cache_dir=cache_dir)
