"""nanohaptics.GaussianTrap: numbers from the optical-tweezers model (ot-physics).

Run: ./scripts/test.sh (builds the wheel into a fresh venv), or
`pytest -q tests/python` in a venv where the wheel is installed.
"""

import math
import threading
import time

import numpy as np
import pytest

import nanohaptics as nh

NM = 1e-9
KB = 1.380649e-23
LN2 = math.log(2.0)


@pytest.fixture
def paper():
    return nh.paper_trap()


# ---------------------------------------------------------------- the paper example


def test_paper_example_true_displacement_and_the_paper_step(paper):
    # Particle at rest 100 nm right of and 50 nm above the trap centre:
    # the trap sits at (-100, -50) nm relative to the particle.
    offsets = np.array([[-100 * NM, -50 * NM]])
    d = paper.displacement(offsets, (0.0, 0.0), nh.PAPER_DT)
    assert d.shape == (1, 2) and d.dtype == np.float64
    assert d[0, 0] / NM == pytest.approx(-136.1, abs=0.05)
    assert d[0, 1] / NM == pytest.approx(-86.7, abs=0.05)
    p = paper.displacement(offsets, (0.0, 0.0), nh.PAPER_DT, method="paper-rk4")
    assert p[0, 0] / NM == pytest.approx(-127.6, abs=0.05)
    assert p[0, 1] / NM == pytest.approx(+54.6, abs=0.05)  # the wrong direction in y


def test_paper_constants(paper):
    assert paper.depth == 1e-15
    assert paper.waist == (600e-9, 300e-9)
    assert paper.mass == 1e-15
    assert paper.axial_waist is None and paper.drag is None and paper.temperature is None
    assert paper.dimension == 2
    assert nh.PAPER_DT == 1e-6 and nh.PAPER_V0_MOVING == (0.1, 0.1)
    kx, ky = paper.stiffness
    assert kx == pytest.approx(2 * LN2 * 1e-15 / 600e-9**2, rel=1e-15)
    assert ky == pytest.approx(2 * LN2 * 1e-15 / 300e-9**2, rel=1e-15)
    # Δt·ω_y ≈ 3.9: outside RK4's stability interval (2.83), the issue's diagnosis.
    assert nh.PAPER_DT * math.sqrt(ky / paper.mass) == pytest.approx(3.92, abs=0.01)


def test_default_method_reaches_a_hundredth_of_a_nanometre(paper):
    g = np.linspace(-1.5e-6, 1.5e-6, 13)
    offsets = np.array([(x, y) for y in g for x in g])
    for v0 in [(0.0, 0.0), nh.PAPER_V0_MOVING]:
        d = paper.displacement(offsets, v0, nh.PAPER_DT)
        ref = paper.displacement(offsets, v0, nh.PAPER_DT, rtol=1e-13)
        assert np.max(np.linalg.norm(d - ref, axis=1)) < 0.01 * NM


def test_rk4_converges_at_fourth_order(paper):
    offsets = np.array([[-100 * NM, -50 * NM], [300 * NM, -200 * NM]])
    ref = paper.displacement(offsets, (0.0, 0.0), 1e-6, rtol=1e-13)
    errs = [
        np.max(np.abs(paper.displacement(offsets, (0, 0), 1e-6, method="rk4", substeps=n) - ref))
        for n in (32, 64, 128)
    ]
    for coarse, fine in zip(errs, errs[1:]):
        assert math.log2(coarse / fine) == pytest.approx(4.0, abs=0.15)


def test_symplectic_methods_match_the_reference(paper):
    offsets = np.array([[-100 * NM, -50 * NM]])
    ref = paper.displacement(offsets, (0, 0), 1e-6, rtol=1e-13)
    for method, n, tol in [("symplectic", 256, 0.05), ("yoshida4", 64, 0.01), ("yoshida6", 32, 0.01)]:
        d = paper.displacement(offsets, (0, 0), 1e-6, method=method, substeps=n)
        assert np.max(np.abs(d - ref)) < tol * NM, method


# ---------------------------------------------------------------- dynamics


def test_small_oscillation_frequency(paper):
    # x(t) = x0 cos(ωt), ω = sqrt(2 ln2 P0 / (m a²)); anharmonic shift ~ (x0/a)² = 1e-8.
    a = 600e-9
    omega = math.sqrt(2 * LN2 * 1e-15 / (1e-15 * a**2))
    x0 = 1e-4 * a
    period = 2 * math.pi / omega
    t, r, v = paper.trajectory((-x0, 0.0), (0.0, 0.0), 5 * period, 201, rtol=1e-12)
    assert t.shape == (201,) and r.shape == (201, 2) and v.shape == (201, 2)
    np.testing.assert_allclose(r[:, 0], x0 * np.cos(omega * t), rtol=0, atol=1e-6 * x0)
    np.testing.assert_allclose(v[:, 0], -x0 * omega * np.sin(omega * t), rtol=0, atol=1e-6 * x0 * omega)
    assert np.all(r[:, 1] == 0.0)
    assert r[0, 0] == x0  # positions are relative to the trap centre: r(0) = -offset


def test_energy_is_conserved_along_a_large_orbit(paper):
    t, r, v = paper.trajectory((-500 * NM, 200 * NM), (0.05, -0.02), 20e-6, 401, rtol=1e-11)
    e = 0.5 * paper.mass * np.sum(v**2, axis=1) + paper.potential(r)
    assert np.max(np.abs(e - e[0])) < 1e-8 * paper.depth


def test_trajectory_end_is_the_flow_map(paper):
    # Two samples = one interval of the same propagator: identical bits.
    off = np.array([-100 * NM, -50 * NM])
    for method in ["adaptive", "paper-rk4", "yoshida4"]:
        t, r, _ = paper.trajectory(off, (0.1, 0.1), 1e-6, 2, method=method)
        d = paper.displacement(off[None, :], (0.1, 0.1), 1e-6, method=method)
        assert np.array_equal(r[1] - r[0], d[0])
        assert t[1] == 1e-6


def test_paper_rk4_trajectory_is_the_iterated_one_step_map(paper):
    # Ten steps of the paper's difference equation = ten chained displacement calls.
    t, r, v = paper.trajectory((-100 * NM, -50 * NM), (0.0, 0.0), 10e-6, 11, method="paper-rk4")
    pos = np.array([100 * NM, 50 * NM])
    vel = np.zeros(2)
    for k in range(1, 11):
        d = paper.displacement(-pos[None, :], vel, 1e-6, method="paper-rk4")[0]
        pos = pos + d
        assert np.allclose(r[k], pos, rtol=0, atol=1e-18)  # rounding, amplified by the unstable step
        vel = v[k]


def test_force_is_minus_the_gradient_of_the_potential(paper):
    rng = np.random.default_rng(7)
    p = rng.uniform(-1e-6, 1e-6, size=(50, 2))
    f = paper.force(p)
    h = 1e-12
    for axis in range(2):
        e = np.zeros(2)
        e[axis] = h
        grad = (paper.potential(p + e) - paper.potential(p - e)) / (2 * h)
        np.testing.assert_allclose(f[:, axis], -grad, rtol=1e-6, atol=1e-20)
    assert paper.potential((0.0, 0.0)) == -paper.depth
    assert np.array_equal(paper.force((0.0, 0.0)), [0.0, 0.0])
    # Far outside the well: exactly zero, never NaN.
    assert np.array_equal(paper.force([[1.0, -1e3]]), [[0.0, 0.0]])
    # Near the centre the force is -κ r.
    kx, ky = paper.stiffness
    fx, fy = paper.force((1e-12, -2e-12))
    assert fx == pytest.approx(-kx * 1e-12, rel=1e-9) and fy == pytest.approx(ky * 2e-12, rel=1e-9)


def test_overdamped_relaxation_is_exponential():
    # mass=None: γ ṙ = F(r); small offsets relax as exp(-κ t / γ).
    trap = nh.GaussianTrap(1e-17, (1e-6, 1e-6), None, radius=0.5e-6, viscosity=1e-3)
    gamma = 6 * math.pi * 1e-3 * 0.5e-6
    assert trap.drag == pytest.approx(gamma, rel=1e-15)
    kappa = trap.stiffness[0]
    x0 = 1e-4 * 1e-6
    t, r, v = trap.trajectory((-x0, 0.0), (0.0, 0.0), 5 * gamma / kappa, 51, rtol=1e-12)
    np.testing.assert_allclose(r[:, 0], x0 * np.exp(-kappa * t / gamma), rtol=1e-6)
    # The reported velocity is the drift velocity F/γ.
    np.testing.assert_allclose(v[:, 0], -kappa * r[:, 0] / gamma, rtol=1e-6)
    with pytest.raises(ValueError) as e:
        trap.displacement([[0.0, 0.0]], (0.1, 0.0), 1e-6)
    assert str(e.value) == (
        "velocity: must be zero for an overdamped trap (mass=None): it has no velocity state"
    )


def test_3d_trap_axial_motion_and_planar_agreement():
    t3 = nh.GaussianTrap(1e-15, (600e-9, 300e-9), 1e-15, axial_waist=1.5e-6)
    assert t3.dimension == 3 and t3.axial_waist == 1.5e-6 and len(t3.stiffness) == 3
    t2 = nh.paper_trap()
    d3 = t3.displacement([[-100 * NM, -50 * NM, 0.0]], (0, 0, 0), 1e-6, rtol=1e-12)
    d2 = t2.displacement([[-100 * NM, -50 * NM]], (0, 0), 1e-6, rtol=1e-12)
    assert d3.shape == (1, 3) and d3[0, 2] == 0.0
    np.testing.assert_allclose(d3[0, :2], d2[0], rtol=0, atol=1e-6 * NM)
    # Pure axial start: oscillation at ω_z = sqrt(κ_z / m).
    z0 = 1e-4 * 1.5e-6
    wz = math.sqrt(t3.stiffness[2] / 1e-15)
    t, r, _ = t3.trajectory((0, 0, -z0), (0, 0, 0), 3e-5, 31, rtol=1e-12)
    np.testing.assert_allclose(r[:, 2], z0 * np.cos(wz * t), rtol=0, atol=1e-6 * z0)
    assert np.all(r[:, :2] == 0.0)


# ---------------------------------------------------------------- batches and the GIL


def test_batch_equals_per_row_calls_with_shared_and_per_row_velocity(paper):
    rng = np.random.default_rng(1)
    offsets = rng.uniform(-1.5e-6, 1.5e-6, size=(64, 2))
    vels = rng.uniform(-0.1, 0.1, size=(64, 2))
    for method in ["adaptive", "paper-rk4", "dopri5"]:
        shared = paper.displacement(offsets, nh.PAPER_V0_MOVING, 1e-6, method=method)
        each = paper.displacement(offsets, vels, 1e-6, method=method)
        for i in range(len(offsets)):
            one = paper.displacement(offsets[i : i + 1], nh.PAPER_V0_MOVING, 1e-6, method=method)
            assert np.array_equal(shared[i], one[0])
            assert np.array_equal(each[i], paper.displacement(offsets[i : i + 1], vels[i], 1e-6, method=method)[0])


def test_inputs_of_any_real_dtype_and_layout_give_the_same_bits(paper):
    offsets = np.array([[-100, -50], [200, 100], [0, 0]], dtype=np.int64) * 1e-9
    ref = paper.displacement(offsets, (0, 0), 1e-6)
    assert np.array_equal(paper.displacement(offsets.tolist(), [0, 0], 1e-6), ref)
    assert np.array_equal(paper.displacement(np.asfortranarray(offsets), (0, 0), 1e-6), ref)
    assert np.array_equal(paper.displacement(offsets.T.copy().T, np.zeros(2, np.float32), 1e-6), ref)
    strided = np.zeros((3, 4))
    strided[:, ::2] = offsets
    assert np.array_equal(paper.displacement(strided[:, ::2], (0, 0), 1e-6), ref)
    assert paper.displacement(np.zeros((0, 2)), (0, 0), 1e-6).shape == (0, 2)


def test_batch_releases_the_gil(paper):
    # While a worker thread is inside a long batch, the main thread keeps
    # running Python: with the GIL held it would stall for the whole call.
    rng = np.random.default_rng(2)
    offsets = rng.uniform(-1.5e-6, 1.5e-6, size=(40_000, 2))
    t0 = time.perf_counter()
    expected = paper.displacement(offsets, (0.1, 0.1), 1e-6, rtol=1e-12)
    serial = time.perf_counter() - t0
    result = {}

    def work():
        result["d"] = paper.displacement(offsets, (0.1, 0.1), 1e-6, rtol=1e-12)

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    assert np.array_equal(result["d"], expected)
    gaps = np.diff(ticks) if len(ticks) > 1 else np.array([serial])
    assert serial > 0.05, "batch too short to observe"
    assert gaps.max() < 0.5 * serial, (gaps.max(), serial)


# ---------------------------------------------------------------- thermal mode


def _bead():
    # 1 µm polystyrene bead in water at 20 °C; waists chosen so κ_x = 0.1 pN/nm.
    kappa = 1e-4
    a = 1e-6
    depth = kappa * a**2 / (2 * LN2)
    return nh.GaussianTrap(
        depth, (a, 0.8 * a), None, radius=0.5e-6, viscosity=1.002e-3, temperature=293.15
    )


def test_thermal_variance_is_kt_over_kappa_and_decays_as_exp_minus_kappa_t_over_gamma():
    trap = _bead()
    fs = 78_125.0
    x = trap.brownian(10.0, fs, seed=42)
    assert x.shape == (781_250, 2)
    kt = KB * 293.15
    for axis, kappa in enumerate(trap.stiffness):
        var = np.var(x[:, axis])
        assert var == pytest.approx(kt / kappa, rel=0.025)  # ~0.6% standard error
        lag1 = np.corrcoef(x[:-1, axis], x[1:, axis])[0, 1]
        assert lag1 == pytest.approx(math.exp(-kappa / trap.drag / fs), abs=0.003)


def test_thermal_runs_are_reproducible_bit_for_bit():
    trap = _bead()
    a = trap.brownian(0.01, 1e5, seed=7)
    b = trap.brownian(0.01, 1e5, seed=7)
    c = trap.brownian(0.01, 1e5, seed=8)
    assert a.shape == (1000, 2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    s = trap.brownian(0.01, 1e5, seed=7, start=(1e-8, 0.0))
    assert not np.array_equal(s, a)


def test_underdamped_baoab_samples_kt_over_kappa():
    # With a mass, BAOAB samples the Boltzmann distribution of the harmonic well.
    kappa, a = 1e-4, 1e-6
    trap = nh.GaussianTrap(
        kappa * a**2 / (2 * LN2), (a, a), 1e-12, radius=0.5e-6, viscosity=1.002e-3, temperature=293.15
    )
    x = trap.brownian(2.0, 1e5, seed=3, method="baoab", substeps=2)
    assert np.var(x[1000:, 0]) == pytest.approx(KB * 293.15 / kappa, rel=0.05)


# ---------------------------------------------------------------- bad arguments


def _err(fn):
    with pytest.raises(ValueError) as e:
        fn()
    return str(e.value)


def test_constructor_errors_name_the_parameter():
    ok = dict(depth=1e-15, waist=(6e-7, 3e-7), mass=1e-15)
    assert _err(lambda: nh.GaussianTrap(**{**ok, "depth": -1.0})) == (
        "depth [J] = -1 is out of range: allowed finite and > 0"
    )
    assert _err(lambda: nh.GaussianTrap(**{**ok, "waist": (6e-7, 0.0)})) == (
        "waist_y [m] = 0 is out of range: allowed finite and > 0"
    )
    assert _err(lambda: nh.GaussianTrap(**{**ok, "waist": (6e-7, 3e-7, 1e-6)})) == (
        "waist: expected the pair (a, b) of lateral waists in m, got 3 values"
    )
    assert _err(lambda: nh.GaussianTrap(**{**ok, "mass": float("nan")})) == (
        "mass [kg] = NaN is out of range: allowed finite and > 0"
    )
    assert _err(lambda: nh.GaussianTrap(**{**ok, "axial_waist": float("inf")})) == (
        "waist_z [m] = inf is out of range: allowed finite and > 0"
    )
    assert _err(lambda: nh.GaussianTrap(**{**ok, "mass": None})) == (
        "mass [kg] (inertia) or radius [m] and viscosity [Pa s] (drag) is required by any dynamics"
    )
    assert _err(lambda: nh.GaussianTrap(**ok, radius=5e-7)) == (
        "viscosity [Pa s] is required by Stokes drag (radius was given)"
    )
    assert _err(lambda: nh.GaussianTrap(**ok, temperature=300.0)) == (
        "radius [m] and viscosity [Pa s] is required by thermal noise (fluctuation-dissipation needs drag)"
    )
    assert _err(lambda: nh.GaussianTrap(**ok, external_force=(1e-12, 0.0, 0.0))) == (
        "external_force: expected shape (2,), got (3,)"
    )


def test_call_errors_name_the_argument(paper):
    one = [[-100e-9, -50e-9]]
    assert _err(lambda: paper.displacement([1e-7, 0.0], (0, 0), 1e-6)) == (
        "offsets: expected shape (N, 2), got (2,)"
    )
    assert _err(lambda: paper.displacement(np.zeros((2, 2)), np.zeros((3, 2)), 1e-6)) == (
        "velocity: expected shape (2,) or (2, 2), got (3, 2)"
    )
    assert _err(lambda: paper.displacement([[0.0, 0.0], [float("nan"), 0.0]], (0, 0), 1e-6)) == (
        "offsets[1, 0] = NaN is out of range: allowed finite (m)"
    )
    assert _err(lambda: paper.displacement(one, (0, float("inf")), 1e-6)) == (
        "velocity[1] = inf is out of range: allowed finite (m/s)"
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 0.0)) == (
        "dt [s] = 0 is out of range: allowed finite and > 0"
    )
    assert _err(lambda: paper.displacement([["a", "b"]], (0, 0), 1e-6)).startswith(
        "offsets: expected an array of real numbers"
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 1e-6, method="rk5")) == (
        'unknown method "rk5": allowed "paper-rk4", "rk4", "rk8", "dopri5", "adaptive", '
        '"symplectic", "yoshida4", "yoshida6"'
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 1e-6, rtol=0.5)) == (
        "rtol = 0.5 is out of range: allowed 1e-14 ..= 0.1"
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 1e-6, method="rk4", rtol=1e-8)) == (
        'rtol is used only by "adaptive" and "dopri5", not by method "rk4"'
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 1e-6, substeps=4)) == (
        'substeps is used only by "rk4", "rk8", "symplectic", "yoshida4" and "yoshida6", '
        'not by method "adaptive"'
    )
    assert _err(lambda: paper.displacement(one, (0, 0), 1e-6, method="rk4", substeps=0)) == (
        "substeps = 0 is out of range: allowed 1 ..= 10000000"
    )
    assert _err(lambda: paper.trajectory((0, 0), (0, 0), 1e-6, 1)) == (
        "samples = 1 is out of range: allowed 2 ..= 10000000"
    )
    assert _err(lambda: paper.trajectory((0, 0), (0, 0), -1e-6, 10)) == (
        "duration = -1e-6 is out of range: allowed finite and > 0 (s)"
    )
    assert _err(lambda: paper.trajectory([[0, 0]], (0, 0), 1e-6, 10)) == (
        "offset: expected shape (2,), got (1, 2)"
    )
    assert _err(lambda: paper.force(np.zeros((4, 3)))) == (
        "positions: expected shape (2,) or (N, 2), got (4, 3)"
    )
    damped = nh.GaussianTrap(1e-15, (6e-7, 3e-7), 1e-15, radius=5e-7, viscosity=1e-3)
    assert _err(lambda: damped.displacement(one, (0, 0), 1e-6, method="symplectic")) == (
        "method symplectic cannot integrate this model: symplectic methods need a conservative "
        "model (inertia on, no drag)"
    )


def test_brownian_errors_name_the_argument(paper):
    assert _err(lambda: paper.brownian(1.0, 1e3, seed=1)) == (
        "temperature [K], radius [m] and viscosity [Pa s] is required by thermal simulation"
    )
    bead = _bead()
    assert _err(lambda: bead.brownian(1.0, 1e3, seed=-1)) == (
        "seed = -1 is out of range: allowed 0 ..= 18446744073709551615"
    )
    assert _err(lambda: bead.brownian(0.0, 1e3, seed=1)) == (
        "duration [s] = 0 is out of range: allowed finite and > 0"
    )
    assert _err(lambda: bead.brownian(1.0, 1e3, seed=1, method="euler")) == (
        'unknown method "euler": allowed "auto", "baoab", "overdamped"'
    )
    assert _err(lambda: bead.brownian(1.0, 1e3, seed=1, method="baoab")) == (
        "mass [kg] is required by the BAOAB scheme"
    )
    assert _err(lambda: bead.brownian(1.0, 1e3, seed=1, substeps=0)) == (
        "substeps = 0 is out of range: allowed 1 ..= 1000000"
    )
    with pytest.raises(TypeError, match="seed: expected an integer"):
        bead.brownian(1.0, 1e3, seed=1.5)


def test_default_tolerance_is_the_crate_default(paper):
    offsets = np.array([[-100 * NM, -50 * NM], [400 * NM, 250 * NM]])
    d = paper.displacement(offsets, nh.PAPER_V0_MOVING, 1e-6)
    assert np.array_equal(d, paper.displacement(offsets, nh.PAPER_V0_MOVING, 1e-6, rtol=nh.DEFAULT_RTOL))
    assert not np.array_equal(d, paper.displacement(offsets, nh.PAPER_V0_MOVING, 1e-6, rtol=1e-12))
    assert 1e-14 <= nh.DEFAULT_RTOL <= 1e-3


def test_flow_jacobian_matches_finite_differences(paper):
    offsets = np.array([[-100 * NM, -50 * NM], [350 * NM, 120 * NM], [0.0, 0.0]])
    v0 = np.array(nh.PAPER_V0_MOVING)
    j = paper.flow_jacobian(offsets, v0, 1e-6, rtol=1e-12)
    assert j["d_offset"].shape == (3, 2, 2) and j["displacement"].shape == (3, 2)
    # Same dynamics; the step control also watches the sensitivities, so not the same bits.
    np.testing.assert_allclose(
        j["displacement"], paper.displacement(offsets, v0, 1e-6, rtol=1e-12), rtol=1e-9, atol=1e-18
    )
    h, hv = 1e-11, 1e-5
    for col in range(2):
        e = np.zeros(2)
        e[col] = h
        fd = (paper.displacement(offsets + e, v0, 1e-6, rtol=1e-12)
              - paper.displacement(offsets - e, v0, 1e-6, rtol=1e-12)) / (2 * h)
        np.testing.assert_allclose(j["d_offset"][:, :, col], fd, rtol=1e-5, atol=1e-6)
        ev = np.zeros(2)
        ev[col] = hv
        fdv = np.stack([
            (paper.displacement(offsets[n : n + 1], v0 + ev, 1e-6, rtol=1e-12)
             - paper.displacement(offsets[n : n + 1], v0 - ev, 1e-6, rtol=1e-12))[0] / (2 * hv)
            for n in range(3)
        ])
        np.testing.assert_allclose(j["d_velocity"][:, :, col], fdv, rtol=1e-5, atol=1e-12)
    # At rest at the centre: ∂d/∂offset = I − cos(ω_i Δt) per axis (linear oscillator).
    kx, ky = paper.stiffness
    w = np.sqrt(np.array([kx, ky]) / paper.mass)
    j0 = paper.flow_jacobian([[0.0, 0.0]], (0.0, 0.0), 1e-6, rtol=1e-12)["d_offset"][0]
    np.testing.assert_allclose(np.diag(j0), 1 - np.cos(w * 1e-6), rtol=1e-8)
    assert j0[0, 1] == 0.0 and j0[1, 0] == 0.0
