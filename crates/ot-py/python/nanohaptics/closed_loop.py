"""The loop closed around a :class:`nanohaptics.Session` through a modelled device.

:func:`closed_loop` plays an operator's intended path through a
:class:`nanohaptics.DeviceModel` (a device with a moving mass, encoder counts and the
force held over each tick, gripped by a hand modelled as a spring-damper) into a
:class:`nanohaptics.Session`: each tick the session reads the device's encoders and
answers a force and a local stiffness, which the device renders until the next tick.
This is the closed loop `check_closed_loop` runs in Rust, written out in Python so a
script can change anything in it (the path, the grip, switches mid-session).

Units: metres, seconds, newtons, device frame.
"""

from __future__ import annotations

from typing import Callable, Optional, Sequence, Tuple

import numpy as np

__all__ = ["closed_loop"]

Vec3 = Sequence[float]


def closed_loop(session, device, path: Callable[[float], Tuple[Vec3, Vec3]], seconds: float,
                buttons: Optional[Callable[[float], object]] = None) -> dict:
    """Drive ``session`` with ``device`` held by a hand that follows ``path``.

    Args:
        session: an open :class:`nanohaptics.Session`.
        device: a :class:`nanohaptics.DeviceModel`.
        path: ``path(t) -> (position (3,) m, velocity (3,) m/s)``, the operator's intent at
            time ``t`` s from the start.
        seconds: how long to run, s (> 0).
        buttons: ``buttons(t)`` -> button bits or names for the tick at ``t`` (default none).

    Returns:
        dict of numpy arrays, one row per tick: "time_s", "reading_m" (T, 3) what the
        encoders reported, "position_m" (T, 3) the true stylus position, "force_n" (T, 3)
        the force answered; and "energy_to_hand_j", the work the motors did on the hand.
    """
    if not (isinstance(seconds, (int, float)) and np.isfinite(seconds) and 0 < seconds <= 3600):
        raise ValueError(f"seconds = {seconds!r} is out of range: allowed 0 < seconds ≤ 3600")
    dt = 1.0 / session.rate_hz
    n = int(round(seconds * session.rate_hz))
    reading = np.zeros((n, 3))
    position = np.zeros((n, 3))
    force = np.zeros((n, 3))
    time_s = np.arange(n) * dt
    for k in range(n):
        t = time_s[k]
        reading[k] = device.reading
        position[k] = device.position
        f = session.tick(reading[k], buttons(t) if buttons is not None else None)
        force[k] = f
        p, v = path(t + dt)
        device.advance(dt, f, p, v, stiffness=session.stiffness)
    return {
        "time_s": time_s,
        "reading_m": reading,
        "position_m": position,
        "force_n": force,
        "energy_to_hand_j": device.energy_to_hand_j,
    }
