"""The Python argument converters under random extreme arguments (issue 11: the fuzzing harness,
its Python target). A seeded random campaign calls the wheel's entry points with extreme numbers
(1e308, -0, NaN, inf, 5e-324, huge integers), wrong types and wrong shapes, in a child process
(so an abort or a hang is seen, not suffered): every call returns finite numbers or raises
ValueError / TypeError / OSError / OverflowError; never a panic, an abort or a hang.

Longer campaign: NANOHAPTICS_FUZZ_PY_CALLS=100000 python -m pytest tests/python/test_fuzz_args.py
"""

import json
import os
import subprocess
import sys
import textwrap

CHILD = textwrap.dedent(
    r'''
    import json, math, random, sys
    import numpy as np
    import nanohaptics as nh

    seed, calls = int(sys.argv[1]), int(sys.argv[2])
    rng = random.Random(seed)
    X = [float("nan"), float("inf"), float("-inf"), 1e308, -1e308, 0.0, -0.0, 5e-324,
         1e-300, 1e300, -1.0, 1.0, 2**63, -(2**63) - 1, 10**30, 1e-9, 0.001]
    WRONG = [None, "x", [], [1.0] * 4, [[1.0]], {}, True, b"\x00", object()]

    def num():
        return rng.choice(X) if rng.random() < 0.8 else rng.choice(WRONG)

    def vec(n):
        if rng.random() < 0.1:
            return rng.choice(WRONG)
        if rng.random() < 0.05:
            return [num() for _ in range(rng.choice([0, n - 1, n + 1]))]
        return [rng.choice(X) if rng.random() < 0.5 else rng.uniform(-1e-6, 1e-6)
                for _ in range(n)]

    trap = nh.paper_trap()
    nano = nh.NanoWorld((3e-9, 3e-9, 2e-9))
    bricks = nh.BrickWorld()
    CALLS = [
        ("GaussianTrap", lambda: nh.GaussianTrap(num(), vec(2), num())),
        ("trap.force", lambda: trap.force(vec(2))),
        ("trap.potential", lambda: trap.potential(vec(2))),
        ("trap.displacement", lambda: trap.displacement([vec(2)], vec(2), num(), method="rk4",
                                                        substeps=1)),
        ("nano.step", lambda: nano.step(vec(3), rng.choice([1e-3, num()]))),
        ("nano.force_at", lambda: nano.force_at(vec(3))),
        ("force_distance_curve", lambda: nh.force_distance_curve(
            steps=50, **{rng.choice(["far_gap_m", "near_gap_m", "dt_s"]): num()})),
        ("bricks.step", lambda: bricks.step(vec(3))),
        ("bricks.set_gravity", lambda: bricks.set_gravity(num())),
        ("bricks.set_friction", lambda: bricks.set_friction(num())),
        ("bricks.set_restitution", lambda: bricks.set_restitution(num())),
        ("bricks.set_brick_mass", lambda: bricks.set_brick_mass(num())),
        ("run_scene.seconds", lambda: nh.run_scene("wall", seconds=num())),
    ]
    ALLOWED = (ValueError, TypeError, OSError, OverflowError)

    def finite(r):
        if isinstance(r, dict):
            return all(finite(v) for v in r.values())
        if isinstance(r, (list, tuple)):
            return all(finite(v) for v in r)
        if isinstance(r, np.ndarray) and r.dtype.kind == "f":
            return bool(np.isfinite(r).all())
        if isinstance(r, float):
            return math.isfinite(r)
        return True

    findings = {}
    for i in range(calls):
        name, f = rng.choice(CALLS)
        try:
            r = f()
        except ALLOWED:
            continue
        except BaseException as e:  # a pyo3 PanicException is a BaseException
            findings.setdefault(name + ": " + type(e).__name__, f"call {i}: {e}"[:300])
            continue
        if not finite(r):
            findings.setdefault(name + ": non-finite result", f"call {i}")
    print(json.dumps(findings))
    '''
)


def run_campaign(seed, calls, timeout):
    p = subprocess.run(
        [sys.executable, "-c", CHILD, str(seed), str(calls)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert p.returncode == 0, f"the child died (abort?): {p.returncode}\n{p.stderr[-2000:]}"
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_random_extreme_arguments_raise_typed_errors_or_return_finite_values():
    calls = int(os.environ.get("NANOHAPTICS_FUZZ_PY_CALLS", "400"))
    findings = run_campaign(seed=1, calls=calls, timeout=120 + calls // 10)
    assert findings == {}, json.dumps(findings, indent=1)
