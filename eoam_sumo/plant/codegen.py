"""Build the plant's step as one CasADi SX function and compile it to a cached C library.

One integration sub-step of ``model.rhs`` (``integrator.sub_step``) is an SX function; an MX
function calls it ``substeps`` times, so one call of the compiled function advances a whole
co-simulation step.
The C source comes from ``casadi.CodeGenerator``; it is compiled with the system C compiler
(``$CC``, else ``gcc``, else ``cc``) into a cache directory, keyed by a hash of the source and
the compiler command, so a changed model or parameter set gets a new library. The library is
written to a temporary file and renamed into place, so concurrent builders are safe.

Where Python's headers are installed the same source is also built as a Python extension
module (``extension_source``): ``advance(x, u, mu)`` reads the floats, calls the step and
returns the lists in C, with less overhead per call than the ``ctypes`` call.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shlex
import shutil
import subprocess
import sysconfig
import tempfile
from pathlib import Path

import casadi

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.integrator import sub_step
from eoam_sumo.plant.model import INPUT_NAMES, STATE_NAMES, outputs
from eoam_sumo.plant.ops import CASADI_OPS

FUNCTION_NAME = "eoam_plant_step"
C_FLAGS = (
    "-O2",
    "-shared",
    "-fPIC",
    "-ffp-contract=off",
    "-fno-semantic-interposition",
    "-fno-math-errno",
)
"""``-ffp-contract=off``: no fused multiply-adds, so the C code rounds like the reference.
``-fno-semantic-interposition`` lets the compiler inline CasADi's helpers (``casadi_fmax``,
``casadi_fmin``, ...), which ``-fPIC`` otherwise calls through the PLT, and ``-fno-math-errno``
turns ``sqrt`` into one instruction; neither changes a result (IEEE arithmetic is kept)."""

CACHE_ENV = "EOAM_SUMO_CACHE_DIR"
EXTENSION_NAME = "eoam_plant_ext"  # the extension module's name (its ``PyInit_`` function)

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
``-fno-math-errno`` alone does not inline (a library call each)."""


@functools.lru_cache(maxsize=16)
def step_function(params: VehicleParams, dt_s: float, substeps: int) -> casadi.Function:
    """``(x[9], u[3], mu) -> (x_next[9], y[len(OUTPUT_NAMES)])``: ``substeps`` calls of one
    SX sub-step inside an MX function, so the generated C holds the step once (not unrolled
    ``substeps`` times: the smaller library stays in the instruction cache between SUMO
    steps)."""
    x = casadi.SX.sym("x", len(STATE_NAMES))
    u = casadi.SX.sym("u", len(INPUT_NAMES))
    mu = casadi.SX.sym("mu")
    xs = [x[i] for i in range(x.numel())]
    one_step = casadi.Function(
        f"{FUNCTION_NAME}_sub",
        [x, u, mu],
        [
            casadi.vertcat(
                *sub_step(xs, [u[i] for i in range(u.numel())], mu, params, dt_s, CASADI_OPS)
            )
        ],
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
        FUNCTION_NAME,
        [X, U, MU],
        [x_next, measure(x_next, MU)],
        ["x", "u", "mu"],
        ["x_next", "y"],
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


def build_library(
    source: str,
    cache_dir: Path,
    compiler: list[str],
    extra_flags: tuple[str, ...] = (),
    stem: str = FUNCTION_NAME,
) -> Path:
    """Compile ``source`` (with ``C_FLAGS`` and ``extra_flags``) into ``cache_dir`` as
    ``<stem>_<hash>.so`` unless already there; return the library path.

    Raises ``RuntimeError`` with the compiler's message when compilation fails and
    ``OSError`` when the directory cannot be written.
    """
    flags = (*C_FLAGS, *extra_flags)
    key = hashlib.sha256("\0".join([source, *compiler, *flags]).encode()).hexdigest()[:24]
    target = Path(cache_dir) / f"{stem}_{key}.so"
    if target.exists():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    try:
        proc = subprocess.run(
            [*compiler, *flags, "-x", "c", "-", "-o", tmp, "-lm"],
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


_EXTENSION = """
/* --- the Python extension module: advance(x, u, mu) -> (x_next, y), as Plant.advance --- */
static double *eoam_w, eoam_x[%(nx)d], eoam_u[%(nu)d], eoam_mu, eoam_xn[%(nx)d], eoam_y[%(ny)d];
static casadi_int *eoam_iw;
static const double **eoam_arg;  /* n_arg and n_res long: the step uses the rest as scratch */
static double **eoam_res;

static int eoam_read(PyObject *seq, double *out, Py_ssize_t n) {
    PyObject *fast = PySequence_Fast(seq, "x and u must be sequences of floats");
    if (fast == NULL) return -1;
    PyObject **items = PySequence_Fast_ITEMS(fast);
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(items[i]);
        if (out[i] == -1.0 && PyErr_Occurred()) { Py_DECREF(fast); return -1; }
    }
    Py_DECREF(fast);
    return 0;
}

static PyObject *eoam_list(const double *v, Py_ssize_t n) {
    PyObject *list = PyList_New(n);
    if (list == NULL) return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *f = PyFloat_FromDouble(v[i]);
        if (f == NULL) { Py_DECREF(list); return NULL; }
        PyList_SET_ITEM(list, i, f);
    }
    return list;
}

static PyObject *eoam_advance(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "advance(x, u, mu) takes 3 arguments");
        return NULL;
    }
    Py_ssize_t nx = PyObject_Length(args[0]), nu = PyObject_Length(args[1]);
    if (nx < 0 || nu < 0) return NULL;
    if (nx != %(nx)d || nu != %(nu)d) {
        PyErr_Format(PyExc_ValueError, "x needs %(nx)d and u %(nu)d values, got %%zd and %%zd",
                     nx, nu);
        return NULL;
    }
    if (eoam_read(args[0], eoam_x, %(nx)d) || eoam_read(args[1], eoam_u, %(nu)d)) return NULL;
    eoam_mu = PyFloat_AsDouble(args[2]);
    if (eoam_mu == -1.0 && PyErr_Occurred()) return NULL;
    if (!(0.0 < eoam_mu && eoam_mu < HUGE_VAL)) {
        PyObject *mu = PyFloat_FromDouble(eoam_mu);
        if (mu != NULL) PyErr_Format(PyExc_ValueError, "mu=%%R must be finite and > 0", mu);
        Py_XDECREF(mu);
        return NULL;
    }
    eoam_arg[0] = eoam_x;
    eoam_arg[1] = eoam_u;
    eoam_arg[2] = &eoam_mu;
    eoam_res[0] = eoam_xn;
    eoam_res[1] = eoam_y;
    if (%(fn)s(eoam_arg, eoam_res, eoam_iw, eoam_w, 0) != 0) {
        PyErr_SetString(PyExc_RuntimeError, "%(fn)s returned an error");
        return NULL;
    }
    PyObject *xn = eoam_list(eoam_xn, %(nx)d), *y = eoam_list(eoam_y, %(ny)d);
    if (xn == NULL || y == NULL) { Py_XDECREF(xn); Py_XDECREF(y); return NULL; }
    PyObject *out = PyTuple_Pack(2, xn, y);
    Py_DECREF(xn);
    Py_DECREF(y);
    return out;
}

static PyMethodDef eoam_methods[] = {
    {"advance", (PyCFunction)(void (*)(void))eoam_advance, METH_FASTCALL,
     "advance(x, u, mu) -> (x_next, y): all sub-steps of one co-simulation step"},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef eoam_module = {
    PyModuleDef_HEAD_INIT, "%(module)s", NULL, -1, eoam_methods
};

PyMODINIT_FUNC PyInit_%(module)s(void) {
    casadi_int n_arg, n_res, n_iw, n_w;
    if (%(fn)s_work(&n_arg, &n_res, &n_iw, &n_w) != 0) {
        PyErr_SetString(PyExc_RuntimeError, "%(fn)s_work failed");
        return NULL;
    }
    eoam_arg = PyMem_Calloc((size_t)(n_arg > 3 ? n_arg : 3), sizeof(double *));
    eoam_res = PyMem_Calloc((size_t)(n_res > 2 ? n_res : 2), sizeof(double *));
    eoam_iw = PyMem_Calloc((size_t)(n_iw > 0 ? n_iw : 1), sizeof(casadi_int));
    eoam_w = PyMem_Calloc((size_t)(n_w > 0 ? n_w : 1), sizeof(double));
    if (!eoam_arg || !eoam_res || !eoam_iw || !eoam_w) return PyErr_NoMemory();
    return PyModule_Create(&eoam_module);
}
"""


def extension_source(source: str, nx: int, nu: int, ny: int) -> str:
    """``source`` (``c_source``) as the Python extension module ``EXTENSION_NAME``: the same
    step function (so the same arithmetic) behind an ``advance(x, u, mu)`` that checks its
    arguments as :meth:`~eoam_sumo.plant.compiled.Plant.advance` does."""
    names = {"nx": nx, "nu": nu, "ny": ny, "fn": FUNCTION_NAME, "module": EXTENSION_NAME}
    return "#define PY_SSIZE_T_CLEAN\n#include <Python.h>\n" + source + _EXTENSION % names


def python_include() -> str | None:
    """The directory of ``Python.h`` for this interpreter, or None when it is not installed."""
    include = sysconfig.get_paths().get("include")
    return include if include and (Path(include) / "Python.h").is_file() else None
