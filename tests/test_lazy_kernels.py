"""Regression tests (two code paths of ours, not physics): the loops of kalker.py, linear.py and
vermeulen_johnson.py run as Python (a small batch before numba is imported, e.g. ``wheelrail contact --method
linear``) and as their numba-compiled copies (each module's ``compiled_kernels()``, lazy_kernels.py) give the same
bits."""

import numpy as np

from rigid_dynamics.contact import kalker, linear, vermeulen_johnson


def _inputs(n=300, seed=3):
    rng = np.random.default_rng(seed)
    ratio = np.concatenate([[0.01, 0.1, 0.5, 1.0, 2.0, 10.0, 100.0], np.exp(rng.uniform(-5.0, 5.0, n))])
    nu = rng.uniform(-0.2, 0.5, ratio.size)
    return rng, ratio, nu


def test_kalker_coefficients_and_asymptotes_same_bits():
    """Both branches: inside Kalker's table (PCHIP) and outside it (slender asymptotes blended at the edge)."""
    _, ratio, nu = _inputs()
    for python, compiled in (
        (kalker._coefficients_many, kalker.compiled_kernels()["_coefficients_many"]),
        (kalker._asymptotes_many, kalker.compiled_kernels()["_asymptotes_many"]),
    ):
        out_python, out_compiled = np.empty((ratio.size, 4)), np.empty((ratio.size, 4))
        python(ratio, nu, out_python)
        compiled(ratio, nu, out_compiled)
        np.testing.assert_array_equal(out_python, out_compiled)


def test_linear_and_saturation_same_bits():
    """Linear theory's (Fx, Fy, Mz) and Vermeulen-Johnson's saturation, from no slip to full sliding."""
    rng, ratio, nu = _inputs()
    n = ratio.size
    a = rng.uniform(1e-3, 1e-2, n)
    b = a / ratio
    coef = np.empty((n, 4))
    kalker._coefficients_many(ratio, nu, coef)
    creep = [rng.uniform(-1e-2, 1e-2, n), rng.uniform(-1e-2, 1e-2, n), rng.uniform(-1.0, 1.0, n)]
    outs = []
    for kernel in (linear._linear_many, linear.compiled_kernels()["_linear_many"]):
        out = np.empty((3, n))
        kernel(8.2e10, a, b, tuple(np.ascontiguousarray(coef[:, i]) for i in range(4)), *creep, out)
        outs.append(out)
    np.testing.assert_array_equal(*outs)
    limit = np.concatenate([[0.0], rng.uniform(0.0, 2.0, n - 1)]) * np.hypot(outs[0][0], outs[0][1])
    sat = []
    for kernel in (vermeulen_johnson._saturate_many, vermeulen_johnson.compiled_kernels()["_saturate_many"]):
        out = np.empty((2, n))
        kernel(outs[0][0], outs[0][1], limit, out)
        sat.append(out)
    np.testing.assert_array_equal(*sat)


def test_public_compiled_laws_are_the_compiled_copies():
    """``linear.linear_one`` and ``vermeulen_johnson.saturate_one`` (the compiled dynamics loop's laws) are the
    numba dispatchers, as before the loops became plain Python."""
    from numba.core.registry import CPUDispatcher

    assert isinstance(linear.linear_one, CPUDispatcher)
    assert isinstance(vermeulen_johnson.saturate_one, CPUDispatcher)
    assert linear.linear_one is linear.compiled_kernels()["_linear_one"]


def test_friction_coefficient_same_bits():
    """``friction._friction_coefficient`` as Python and as its compiled copy: Coulomb, CONTACT's three falling forms,
    Polach's law and a law varying in place, at slip velocities 0 to 20 m/s and places inside and beyond the nodes."""
    from rigid_dynamics.contact import friction

    forms = ("linear", "rational", "exponential")
    slow = (friction.polach(0.4, 0.5, 0.6), friction.polach(0.2, 0.5, 0.3))
    laws = [
        friction.uniform(0.3),
        *(friction.FrictionLaw((friction.falling(f, 0.2, 0.1, 2.0, 0.05, 5.0),)) for f in forms),
        friction.FrictionLaw((friction.polach(0.55, 0.4, 0.6),)),
        friction.varying("surface_inclination", (0.3, 0.5), slow),
        friction.varying("rail_lateral", (-0.01, 0.0, 0.02), tuple(friction.coulomb(m) for m in (0.4, 0.3, 0.1))),
    ]
    compiled = friction.compiled_kernels()["_friction_coefficient"]
    for law in laws:
        record = law.record()
        for s in (0.0, 0.07, 0.7, 2.0, 5.0, 20.0):
            for place in (-0.1, 0.3, 0.41, 0.5, 0.9):
                assert friction._friction_coefficient(record, s, place) == compiled(record, s, place)


def test_small_batches_run_as_python_until_the_call_limit(monkeypatch):
    """With numba imported (as after the BEM's import) a module's first ``PYTHON_CALLS_LIMIT`` small batches run as
    Python -- a one-patch command (``wheelrail contact``, whose ``auto`` solves Hertz and Kalker's table before the
    BEM) loads none of the analytic models' compiled copies -- and later ones, and large batches, by the compiled
    copies; the Hertz patch is the same bits before and after the switch."""
    import numba  # noqa: F401  (the situation tested: numba loaded, the module's copies not made)

    from rigid_dynamics.contact import hertz, lazy_kernels

    monkeypatch.setattr(lazy_kernels, "_COPIES", {})
    monkeypatch.setattr(lazy_kernels, "_PYTHON_CALLS", {})

    def solve():
        return hertz.hertz_solve_batch(2.0, 3.7, normal_force_N=1e4, shear_modulus_Pa=8.2e10, poisson_ratio=0.28)

    first = solve()
    for _ in range(lazy_kernels.PYTHON_CALLS_LIMIT - 1):
        solve()
    assert hertz.__name__ not in lazy_kernels._COPIES
    after = solve()  # the limit's next call: the compiled copies
    assert hertz.__name__ in lazy_kernels._COPIES
    for name in ("semi_axis_long_m", "semi_axis_lat_m", "approach_m", "normal_force_N", "max_pressure_Pa"):
        np.testing.assert_array_equal(getattr(first, name), getattr(after, name))
    assert not lazy_kernels.run_as_python(lazy_kernels.PYTHON_BATCH_LIMIT + 1, "some.module")
