"""Build the plant's step as one CasADi SX function and compile it to a cached C library.

One RK4 step of ``model.rhs`` is an SX function; an MX function calls it ``substeps`` times,
so one call of the compiled function advances a whole co-simulation step.
The C source comes from ``casadi.CodeGenerator``; it is compiled with the system C compiler
(``$CC``, else ``gcc``, else ``cc``) into a cache directory, keyed by a hash of the source and
the compiler command, so a changed model or parameter set gets a new library. The library is
written to a temporary file and renamed into place, so concurrent builders are safe.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.integrator import rk4_step
from eoam_sumo.plant.model import INPUT_NAMES, STATE_NAMES, outputs
from eoam_sumo.plant.ops import CASADI_OPS

FUNCTION_NAME = "eoam_plant_step"
C_FLAGS = (
    "-O2", "-shared", "-fPIC", "-ffp-contract=off", "-fno-semantic-interposition",
    "-fno-math-errno",
)
"""``-ffp-contract=off``: no fused multiply-adds, so the C code rounds like the reference.
``-fno-semantic-interposition`` lets the compiler inline CasADi's helpers (``casadi_fmax``,
``casadi_fmin``, ...), which ``-fPIC`` otherwise calls through the PLT, and ``-fno-math-errno``
turns ``sqrt`` into one instruction; neither changes a result (IEEE arithmetic is kept): with
``C_PREAMBLE`` a 10-sub-step call takes ~5 us instead of ~10."""

CACHE_ENV = "EOAM_SUMO_CACHE_DIR"

C_PREAMBLE = """#include <math.h>
/* fmax/fmin inlined, as x86-64 glibc computes them (and FloatOps: max(b, a), min(b, a)) for
   numbers: the first argument when it is greater (smaller), else the second; a NaN argument
   gives the other one. */
static inline double eoam_fmax(double x, double y) { return x > y ? x : (y != y ? x : y); }
static inline double eoam_fmin(double x, double y) { return x < y ? x : (y != y ? x : y); }
#define fmax(x, y) eoam_fmax(x, y)
#define fmin(x, y) eoam_fmin(x, y)
"""
"""Put before CasADi's code: its ``casadi_fmax``/``casadi_fmin`` call ``fmax``/``fmin``, which
``-fno-math-errno`` alone does not inline (~2,300 library calls per 10-sub-step call)."""


@functools.lru_cache(maxsize=16)
def step_function(params: VehicleParams, dt_s: float, substeps: int) -> casadi.Function:
    """``(x[9], u[3], mu) -> (x_next[9], y[len(OUTPUT_NAMES)])``: ``substeps`` calls of one
    SX RK4 step inside an MX function, so the generated C holds the step once (a 36 kB
    library instead of 275 kB unrolled: it stays in the instruction cache between SUMO steps)."""
    x = casadi.SX.sym("x", len(STATE_NAMES))
    u = casadi.SX.sym("u", len(INPUT_NAMES))
    mu = casadi.SX.sym("mu")
    xs = [x[i] for i in range(x.numel())]
    one_step = casadi.Function(
        f"{FUNCTION_NAME}_rk4", [x, u, mu],
        [casadi.vertcat(*rk4_step(xs, [u[i] for i in range(u.numel())], mu, params, dt_s,
                                  CASADI_OPS))],
    )
    measure = casadi.Function(
        f"{FUNCTION_NAME}_outputs", [x, mu], [casadi.vertcat(*outputs(xs, mu, params, CASADI_OPS))]
    )
    X = casadi.MX.sym("x", len(STATE_NAMES))
    U = casadi.MX.sym("u", len(INPUT_NAMES))
    MU = casadi.MX.sym("mu")
    x_next = X
    for _ in range(substeps):
        x_next = one_step(x_next, U, MU)
    return casadi.Function(
        FUNCTION_NAME, [X, U, MU], [x_next, measure(x_next, MU)],
        ["x", "u", "mu"], ["x_next", "y"],
    )


def c_source(fn: casadi.Function) -> str:
    """Self-contained C source of ``fn`` (CasADi's calling convention, 64-bit ``casadi_int``)
    behind ``C_PREAMBLE``."""
    gen = casadi.CodeGenerator(
        f"{fn.name()}.c", {"with_header": False, "casadi_int": "long long int"}
    )
    gen.add(fn)
    return C_PREAMBLE + gen.dump()


def default_cache_dir() -> Path:
    """``$EOAM_SUMO_CACHE_DIR``, else ``$XDG_CACHE_HOME/eoam_sumo``, else ``~/.cache/eoam_sumo``."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "eoam_sumo"


def find_compiler() -> list[str] | None:
    """The C compiler command (``$CC`` split like a shell would, else gcc, else cc), or None."""
    if os.environ.get("CC"):
        cmd = shlex.split(os.environ["CC"])
        path = shutil.which(cmd[0])
        return [path, *cmd[1:]] if path else None
    for name in ("gcc", "cc"):
        path = shutil.which(name)
        if path:
            return [path]
    return None


def build_library(source: str, cache_dir: Path, compiler: list[str]) -> Path:
    """Compile ``source`` into ``cache_dir`` unless already there; return the library path.

    Raises ``RuntimeError`` with the compiler's message when compilation fails and
    ``OSError`` when the directory cannot be written.
    """
    key = hashlib.sha256("\0".join([source, *compiler, *C_FLAGS]).encode()).hexdigest()[:24]
    target = Path(cache_dir) / f"{FUNCTION_NAME}_{key}.so"
    if target.exists():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    try:
        proc = subprocess.run(
            [*compiler, *C_FLAGS, "-x", "c", "-", "-o", tmp, "-lm"],
            input=source.encode(),
            capture_output=True,
            check=False,
        )
        if proc.returncode != 0:
            message = proc.stderr.decode(errors="replace").strip()[-2000:]
            raise RuntimeError(f"C compiler {compiler[0]} failed: {message}")
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return target
