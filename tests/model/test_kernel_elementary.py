"""The compiled kernels' own complex elementary functions (model/_kernels/elementary.py: cinv, csqrt, cexp,
clog, real_root), which replace the library's division, sqrt, exp, log and pow on the hot path, against Python's
cmath/math: a few ulps apart everywhere, the same branch (principal sqrt and log, the sign of a zero imaginary part
respected), and the library's own code where squares would over- or underflow. Magnitudes below 1e-300 (never met
by the model, whose arguments are 0 or far from the subnormal range) are left out: there numba's own cmath
functions, the fallback, lose digits that CPython's keep."""

from __future__ import annotations

import cmath
import math

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from asymslide.model._kernels import elementary as K

EPS = 2.220446049250313e-16
ULPS = 4.0

TINY = 1e-300


def _normal(w: complex) -> bool:
    return max(abs(w.real), abs(w.imag)) >= TINY


normal = st.complex_numbers(max_magnitude=1e300, allow_nan=False, allow_infinity=False).filter(_normal)


def close(a: complex, b: complex, scale: float) -> bool:
    return abs(a - b) <= ULPS * EPS * scale


@settings(deadline=None)  # the first call compiles
@given(normal)
@example(complex(1e-300, 1e-300))
@example(complex(3e200, -4e200))
@example(complex(-2.0, 0.0))
def test_cinv_is_the_reciprocal(w: complex) -> None:
    want = 1.0 / w
    assert close(K.cinv(w), want, abs(want))


@settings(deadline=None)  # the first call compiles
@given(normal | st.just(0j))
@example(complex(-4.0, 0.0))
@example(complex(-4.0, -0.0))
@example(0j)
@example(complex(1e-200, -1e-200))
@example(complex(-1e300, 1e-300))
def test_csqrt_is_the_principal_root(u: complex) -> None:
    got, want = K.csqrt(u), cmath.sqrt(u)
    assert close(got, want, abs(want))
    if u.imag == 0.0 and u.real < 0.0:  # on the cut: the sign of the zero decides the side, as in C99/cmath
        assert math.copysign(1.0, got.imag) == math.copysign(1.0, u.imag)


# real parts up to 709: beyond, cmath.exp overflows
below_overflow = st.builds(complex, st.floats(min_value=-800.0, max_value=709.0), st.floats(min_value=-800.0,
                                                                                            max_value=800.0))


@settings(deadline=None)  # the first call compiles
@given(below_overflow)
@example(complex(-746.0, 3.0))
@example(complex(-745.9, 3.0))
@example(complex(-745.0, -1.0))
def test_cexp_is_exp_and_exactly_zero_where_it_underflows(w: complex) -> None:
    got, want = K.cexp(w), cmath.exp(w)
    if w.real < K.EXP_ZERO:
        assert got == 0 and want == 0  # the skipped sin/cos multiply an exact 0
    else:  # numba's own cmath.exp, which differs from CPython's by an ulp near overflow
        assert close(got, want, abs(want))


@settings(deadline=None)  # the first call compiles
@given(normal)
@example(complex(1.0, 1e-17))
@example(complex(-1.0, 0.0))
@example(complex(-1.0, -0.0))
@example(complex(1e-300, 1e-300))
@example(complex(1e300, -1e300))
def test_clog_is_the_principal_log(w: complex) -> None:
    got, want = K.clog(w), cmath.log(w)
    # ln|w| to a few ulps of its magnitude (absolute near |w| = 1), the phase as atan2
    assert abs(got.real - want.real) <= ULPS * EPS * max(1.0, abs(want.real))
    assert got.imag == want.imag


@pytest.mark.parametrize("order", [2.0, 4.0])
@settings(deadline=None)
@given(x=st.floats(min_value=1e-300, max_value=1e300))
def test_root_is_the_power(order: float, x: float) -> None:
    assert K.real_root(x, order) == pytest.approx(x ** (1.0 / order), rel=ULPS * EPS)
