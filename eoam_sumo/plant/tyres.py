"""The Fiala brush tyre the offline design plans with (``offline/model.py``).

The plant's own tyre is the Magic Formula (``magic_formula.py``); this brush tyre is the one
the offline design model uses below its peak, kept here as that model's reference
(Pacejka 2012 sec. 3.2.2; R. Y. Hindiyeh & J. C. Gerdes, ASME J. Dyn. Sys. Meas. Control 136,
2014). Written against an ``ops`` object (``ops.py``) so it runs on floats and on CasADi.
"""

from __future__ import annotations


def fiala_lateral_force_n(tan_slip, cornering_stiffness_npr, peak_force_n, ops):
    """Fiala brush lateral force [N] (Pacejka 2012 sec. 3.2.2; Hindiyeh & Gerdes 2014).

    With ``z = C tan(alpha) / (3 F_peak)`` the classic cubic
    ``-C tan a + C^2 |tan a| tan a / (3 F) - C^3 tan^3 a / (27 F^2)`` equals
    ``-F sgn(z) (1 - (1 - |z|)^3)`` for ``|z| <= 1`` and ``-F sgn(z)`` beyond (full sliding),
    so the slope at zero slip is ``-C`` and the force saturates at ``F_peak``.
    """
    u = ops.fmin(cornering_stiffness_npr * ops.fabs(tan_slip) / (3.0 * peak_force_n), 1.0)
    w = 1.0 - u
    return -ops.sign(tan_slip) * peak_force_n * (1.0 - w * w * w)
