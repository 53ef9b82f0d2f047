"""A device in this process, a simulator in another: the nanohaptics device bridge.

The simulator (``nanohaptics run SCENE --device udp:HOST:PORT``, or
``nanohaptics.run_scene(SCENE, device="udp:HOST:PORT")``) listens on UDP; a
device process says hello with its specifications, then sends one sample per
period and gets a force packet back for each. The byte layout is in
``docs/device-bridge.md``; this module is its Python reference client (standard
library only), plus adapters for real devices through their Python SDKs:

* :class:`TouchDevice` — 3D Systems Touch / Phantom Omni through
  ``pyOpenHaptics`` (OpenHaptics HD API);
* :class:`ForceDimensionDevice` — Force Dimension devices and the Novint
  Falcon through ``forcedimension_core`` (Force Dimension SDK);
* :class:`HaplyInverse3Device` — a Haply Inverse3 (and optionally its
  VerseGrip handle for buttons) through ``HaplyHardwareAPI`` (Haply's Python
  API over USB serial).

Four protocol versions. A device says hello with the version it speaks and the
simulator's welcome names the session's (the device's, at most 4):

* **version 1**: each force packet carries the force F0 (N) computed at the
  answered reading p0 and a local stiffness K (N/m, 3×3); the device renders
  ``F = F0 − K (p − p0)`` between packets.
* **version 2** (the default of :class:`BridgeClient`, :func:`run` and the
  adapters): each force packet also carries the *local model*
  (:class:`LocalModel`): a residual force and stiffness, up to four contact
  planes, the carried body with its coupling (integrated on the device, one step
  per sample, re-anchored on every answer) and the body's contact planes, and
  the energy the world has delivered to the hand. The device evaluates it at its
  own servo rate at the position it reads *now*, behind a two-port passivity
  layer: once the work done on the hand runs more than 0.02 J past the world's
  it adds damping (at most 2 N·s/m), and past a second 0.02 J it also scales the
  force down, to zero two reserves further on.
* **version 3** (``protocol=3``): version 2 with a *bond* (:class:`Bond`), a
  spring that breaks where the world's contact lets go (the nano world's
  anchored tip): the device renders ``k (a − p)`` until the stylus has pulled it
  past its breaking stretch, and nothing beyond, so a pull-off behind a link is
  felt where the world lets go, not a round trip later.
* **version 4** (``protocol=4``): version 3 with a *follower* (:class:`Follower`),
  the optical tweezers' held particle and its working envelope: the device steps
  the particle with each reading it sends, as the world does, and renders the
  spring on the command beyond the envelope, so the trap pushes back where the
  world does and drags nowhere inside the envelope.

:class:`DeviceSide` is the device's rendering for every version, a line-by-line
port of the Rust ``haptic_devices::local::DeviceSide`` (the same forces to the
last bit on ``tests/python/fixtures/device_side.json``): record each reading
sent (:meth:`DeviceSide.record_reading`), hand it each answer as it arrives
(:meth:`DeviceSide.receive`), and ask it for the force once per servo period
(:meth:`DeviceSide.render`). :func:`run` and the adapters do exactly that: the
adapters render from their own servo callback or thread, and zero force once
answers stop for longer than ``hold_s`` (the simulator's watchdog does the same
on its side).

Units: metres, newtons, N/m, N·s/m, kg, joules, seconds, in the device frame.
"""

from __future__ import annotations

import collections
import dataclasses
import decimal
import math
import socket
import struct
import threading
import time
from dataclasses import dataclass, field
from typing import Deque, List, Optional, Sequence, Tuple

__all__ = [
    "MAGIC",
    "VERSION",
    "VERSION_2",
    "VERSION_3",
    "VERSION_4",
    "MAX_PACKET",
    "MAX_PLANES",
    "MAX_REACH_VERTICES",
    "DEVICE_RESERVE_J",
    "DEVICE_MAX_DAMPING_N_S_PER_M",
    "Specs",
    "Plane",
    "Body",
    "Bond",
    "Follower",
    "LocalModel",
    "ForceReply",
    "DeviceSide",
    "BridgeClient",
    "Device",
    "TouchDevice",
    "ForceDimensionDevice",
    "HaplyInverse3Device",
    "encode_hello",
    "encode_welcome",
    "encode_sample",
    "encode_force",
    "encode_bye",
    "encode_refusal",
    "HelloRefused",
    "ROLES",
    "force_v2_len",
    "force_v3_len",
    "force_v4_len",
    "decode",
    "local_force",
    "run",
]

MAGIC = b"NHDB"
#: The protocol version of samples and byes (the same in both versions), and of version-1
#: hellos, welcomes and force packets.
VERSION = 1
#: Protocol version 2: force packets carry the local model.
VERSION_2 = 2
#: Protocol version 3: a force packet whose model has a bond (a spring that breaks) carries it
#: after the model.
VERSION_3 = 3
#: The newest protocol version: a force packet whose model has a follower (the optical
#: tweezers' held particle) carries a bond flag, the bond if any, then the follower.
VERSION_4 = 4
HELLO, WELCOME, SAMPLE, FORCE, BYE, REFUSAL = 1, 2, 3, 4, 5, 6
#: The button roles, in the order of the welcome's four role bytes (docs/devices.md).
ROLES = ("grip", "turn_x", "turn_y", "turn_z")
#: Largest datagram either side accepts, bytes.
MAX_PACKET = 1200
#: Most planes (and most body planes) one answer carries.
MAX_PLANES = 4
#: Energy the device may give the hand beyond what the world delivered, J (protocol 2).
DEVICE_RESERVE_J = 0.02
#: Largest damping the two-port layer adds, N·s/m.
DEVICE_MAX_DAMPING_N_S_PER_M = 2.0
#: Readings a :class:`DeviceSide` keeps for answers that arrive late (1 s at 1 kHz).
KEEP_READINGS = 1000

_HEADER = struct.Struct("<4sBBH")  # magic, version, type, reserved
_SAMPLE = struct.Struct("<QQdddI")  # seq, device time ns, x, y, z, buttons
_FORCE = struct.Struct("<QQ3d9dB")  # seq answered, tick, force, stiffness, status
_PLANE = struct.Struct("<5d")  # normal, offset, stiffness
_BODY = struct.Struct("<16dId")  # position, velocity, m, k, k_s, b, damper, external, substeps, e
_LOCAL_FIXED = struct.Struct("<13d")  # residual force, residual stiffness, world energy
_BOND = struct.Struct("<8d")  # anchor, normal, stiffness, breaking stretch
SAMPLE_LEN = _HEADER.size + _SAMPLE.size  # 52
FORCE_LEN = _HEADER.size + _FORCE.size  # 121
BYE_LEN = _HEADER.size + 1  # 9
_V2_MIN_LEN = FORCE_LEN + _LOCAL_FIXED.size + 3  # 228: no planes, no body, no body planes
_V2_KIND = "force (version 2)"
_V3_KIND = "force (version 3)"
_V4_KIND = "force (version 4)"
_FOLLOWER = struct.Struct("<6dB")  # position, drift, retain, stiffness, vertex count
_VERTEX = struct.Struct("<2d")

Vec3 = Tuple[float, float, float]
_ZERO: Vec3 = (0.0, 0.0, 0.0)


# ---------------------------------------------------------------- numbers as Rust does them
# The rendering below repeats haptic_types::vec3 operation for operation (no fused
# multiply-add, left-to-right sums), so that its forces are the Rust ones to the last bit.


def _add(a, b) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a, b) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _scale(a, s: float) -> Vec3:
    return (a[0] * s, a[1] * s, a[2] * s)


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _norm(a) -> float:
    return math.sqrt(_dot(a, a))


def _finite(v) -> bool:
    return all(math.isfinite(x) for x in v)


def _div(a: float, b: float) -> float:
    """``a / b`` with IEEE 754 semantics (Python raises on a zero divisor; Rust does not)."""
    if b != 0.0:
        return a / b
    if a == 0.0 or math.isnan(a):
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def _min(a: float, b: float) -> float:
    """Rust's ``f64::min``: the other value when one is NaN."""
    if math.isnan(a):
        return b
    if math.isnan(b):
        return a
    return a if a < b else b


def _max(a: float, b: float) -> float:
    """Rust's ``f64::max``: the other value when one is NaN."""
    if math.isnan(a):
        return b
    if math.isnan(b):
        return a
    return a if a > b else b


def _vec3(v, what: str = "position") -> Vec3:
    try:
        x, y, z = v
        return (float(x), float(y), float(z))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what}: expected 3 numbers, got {v!r}") from e


def _fmt(x: float) -> str:
    """A number as Rust's ``{}`` prints an f64 (``-1``, ``2500``, ``0.5``, ``inf``, ``NaN``)."""
    x = float(x)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return format(decimal.Decimal(repr(x)).normalize(), "f")


# ---------------------------------------------------------------- the local model (protocol 2)


@dataclass
class Plane:
    """A unilateral contact plane: ``F = k · max(0, offset − n·p) · n``."""

    #: Unit outward normal, device frame.
    normal: Vec3
    #: The plane is ``n·p = offset_m``, m; the stylus is in contact where ``n·p < offset_m``.
    offset_m: float
    #: Stiffness, N/m (0 ≤ k ≤ the device's largest stiffness).
    stiffness_n_per_m: float

    def force(self, p: Sequence[float]) -> Vec3:
        """The plane's push at ``p``, N."""
        depth = self.offset_m - _dot(self.normal, p)
        if depth > 0.0:
            return _scale(self.normal, self.stiffness_n_per_m * depth)
        return _ZERO

    def stiffness_at(self, p: Sequence[float]) -> Tuple[float, ...]:
        """Its stiffness matrix at ``p``: ``k n nᵀ`` in contact, 0 outside (row-major)."""
        m = [0.0] * 9
        if self.offset_m - _dot(self.normal, p) > 0.0:
            for i in range(3):
                for j in range(3):
                    m[3 * i + j] = self.stiffness_n_per_m * self.normal[i] * self.normal[j]
        return tuple(m)


@dataclass
class Body:
    """The carried body and its coupling to the stylus (device frame and units).

    A spring ``k`` in parallel with a damper ``b`` acting through a series spring
    ``k_s``. With ``lead = p − x`` and ``e`` the dashpot's share of it, one step of
    ``h`` is ``e ← (e + r·lead) / (1 + r)`` with ``r = h k_s / b``; the pull on the
    body is ``k·lead + k_s (lead − e)`` (the stylus feels ``−pull``); then
    ``v0 = v + h pull / m``, ``v ← v0 + h F_ext / m``,
    ``x ← x + h v0 + h² F_ext / m · (n + 1) / (2n)`` (``n`` substeps), and each
    body plane puts the body back on it and takes its normal velocity into it
    (it leaves at ``restitution`` times it).
    """

    #: The body's grip point, m, in the state from which the next sample is stepped.
    position_m: Vec3
    #: Its velocity, m/s.
    velocity_m_per_s: Vec3
    #: The body's mass as the device feels it, kg.
    mass_kg: float
    #: The coupling's spring ``k``, N/m.
    stiffness_n_per_m: float
    #: The damper's series spring ``k_s``, N/m.
    series_stiffness_n_per_m: float
    #: The damper ``b``, N·s/m.
    damping_n_s_per_m: float
    #: The dashpot's share ``e`` of the lead, m.
    damper_m: Vec3
    #: The force the world puts on the body besides the coupling (its weight), N.
    external_force_n: Vec3
    #: Substeps of the world's rigid-body engine per step (1 for plain symplectic Euler).
    substeps: int
    #: Restitution of the body's contacts, 0–1.
    restitution: float

    def pull(self, p: Sequence[float], h_s: float) -> Tuple[Vec3, Vec3]:
        """The pull on the body for a stylus at ``p`` over a step of ``h_s``, N, and the
        dashpot's new share, m (the state is not changed)."""
        lead = _sub(p, self.position_m)
        k, ks, b = self.stiffness_n_per_m, self.series_stiffness_n_per_m, self.damping_n_s_per_m
        if b > 0.0 and ks > 0.0:
            r = _div(h_s * ks, b)
            e = _scale(_add(self.damper_m, _scale(lead, r)), _div(1.0, 1.0 + r))
            pull = _add(_scale(lead, k), _scale(_sub(lead, e), ks))
            return pull, e
        return _scale(lead, k), _ZERO

    def step(self, p: Sequence[float], h_s: float, planes: Sequence[Plane]) -> Vec3:
        """One step of ``h_s`` with the stylus at ``p``: the body moves under the pull and
        its external force and stays in front of ``planes``; returns the pull, N."""
        pull, e = self.pull(p, h_s)
        self.damper_m = e
        n = float(max(self.substeps, 1))
        im = _div(1.0, self.mass_kg)
        v0 = _add(self.velocity_m_per_s, _scale(pull, h_s * im))
        g = _scale(self.external_force_n, im)
        self.velocity_m_per_s = _add(v0, _scale(g, h_s))
        dx = _add(_scale(v0, h_s), _scale(g, h_s * h_s * (n + 1.0) / (2.0 * n)))
        self.position_m = _add(self.position_m, dx)
        for pl in planes:
            depth = pl.offset_m - _dot(pl.normal, self.position_m)
            if depth > 0.0:
                self.position_m = _add(self.position_m, _scale(pl.normal, depth))
                vn = _dot(pl.normal, self.velocity_m_per_s)
                if vn < 0.0:
                    self.velocity_m_per_s = _sub(
                        self.velocity_m_per_s, _scale(pl.normal, (1.0 + self.restitution) * vn))
        return pull


@dataclass
class Bond:
    """A spring that breaks (protocol 3): ``F = k (a − p)`` while the stretch
    ``s(p) = |d − min(0, n·d) n|`` (``d = p − a``: the pull away from the surface and the
    shear count, a press into it does not) is below ``break_m``, zero from there."""

    #: Where the spring holds the stylus, m.
    anchor_m: Vec3
    #: Unit normal of the surface bonded to, pointing to the stylus's side.
    normal: Vec3
    #: The spring's stiffness, N/m.
    stiffness_n_per_m: float
    #: The stretch at which it breaks, m (> 0).
    break_m: float

    def stretch_m(self, p: Sequence[float]) -> float:
        """The bond's stretch at ``p``, m."""
        d = _sub(p, self.anchor_m)
        along = _dot(d, self.normal)
        return _norm(_sub(d, _scale(self.normal, _min(along, 0.0))))

    def force(self, p: Sequence[float]) -> Vec3:
        """The bond's pull at ``p``, N."""
        if self.stretch_m(p) < self.break_m:
            return _scale(_sub(self.anchor_m, p), self.stiffness_n_per_m)
        return _ZERO


#: Most vertices of a follower's envelope (protocol 4).
MAX_REACH_VERTICES = 24


def _cross2(a, b) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _contains(poly, p) -> bool:
    """Whether ``p`` lies inside the polygon (even–odd rule), as Rust's."""
    inside = False
    j = len(poly) - 1
    for i in range(len(poly)):
        a, b = poly[i], poly[j]
        if (a[1] > p[1]) != (b[1] > p[1]):
            x = a[0] + _div(p[1] - a[1], b[1] - a[1]) * (b[0] - a[0])
            if p[0] < x:
                inside = not inside
        j = i
    return inside


def _first_crossing(poly, a, b) -> Optional[float]:
    """The first ``t`` in (0, 1] where the segment ``a + t (b − a)`` meets the boundary."""
    r = (b[0] - a[0], b[1] - a[1])
    n = len(poly)
    best = None
    for i in range(n):
        q, q2 = poly[i], poly[(i + 1) % n]
        s = (q2[0] - q[0], q2[1] - q[1])
        den = _cross2(r, s)
        if den == 0.0:
            continue
        qa = (q[0] - a[0], q[1] - a[1])
        t = _cross2(qa, s) / den
        u = _cross2(qa, r) / den
        if 0.0 < t <= 1.0 and -1e-12 <= u <= 1.0 + 1e-12 and (best is None or t < best):
            best = t
    return best


def _nearest_on_boundary(poly, p):
    best_d, best = math.inf, (p[0], p[1])
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        d = (b[0] - a[0], b[1] - a[1])
        l2 = d[0] * d[0] + d[1] * d[1]
        if l2 > 0.0:
            t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2
            t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        else:
            t = 0.0
        q = (a[0] + d[0] * t, a[1] + d[1] * t)
        dist = math.hypot(p[0] - q[0], p[1] - q[1])
        if dist < best_d:
            best_d, best = dist, q
    return best


@dataclass
class Follower:
    """A particle that follows the stylus in the device's x–y plane (protocol 4: the optical
    tweezers' held particle). Each sample it moves by the command ``d = p − x`` clipped to
    its working envelope (``reach_m`` shifted by the free drift ``u``), radially from zero
    displacement when the envelope holds it, else from the free drift; the stylus feels
    ``−k (d − clip(d))`` along x and y. After a displacement ``a`` the drift becomes
    ``retain · (2a − u)``. A port of Rust's ``haptic_types::local::Follower``."""

    #: The particle's centre, m, as the next sample meets it (x, y).
    position_m: Tuple[float, float]
    #: Its free drift over one sample, m.
    drift_m: Tuple[float, float]
    #: The envelope less the drift, m, counter-clockwise (3 to :data:`MAX_REACH_VERTICES`).
    reach_m: List[Tuple[float, float]]
    #: The share of its velocity kept from one sample to the next (0–1).
    retain: float
    #: The spring on the excess, N/m.
    stiffness_n_per_m: float

    def clip(self, d) -> Tuple[float, float]:
        """The command ``d`` (m, from the particle) clipped to the envelope."""
        u = self.drift_m
        rel = (d[0] - u[0], d[1] - u[1])
        if _contains(self.reach_m, rel):
            c = rel
        else:
            anchor = next((a for a in ((-u[0], -u[1]), (0.0, 0.0))
                           if _contains(self.reach_m, a)), None)
            t = None if anchor is None else _first_crossing(self.reach_m, anchor, rel)
            if t is not None:
                c = (anchor[0] + (rel[0] - anchor[0]) * t, anchor[1] + (rel[1] - anchor[1]) * t)
            else:
                c = _nearest_on_boundary(self.reach_m, rel)
        return (c[0] + u[0], c[1] + u[1])

    def force(self, p: Sequence[float]) -> Vec3:
        """The spring on the excess at ``p``, N (nothing along z)."""
        d = (p[0] - self.position_m[0], p[1] - self.position_m[1])
        c = self.clip(d)
        k = self.stiffness_n_per_m
        return (-k * (d[0] - c[0]), -k * (d[1] - c[1]), 0.0)

    def step(self, p: Sequence[float]) -> None:
        """One sample with the stylus at ``p``."""
        d = (p[0] - self.position_m[0], p[1] - self.position_m[1])
        a = self.clip(d)
        self.position_m = (self.position_m[0] + a[0], self.position_m[1] + a[1])
        u = self.drift_m
        self.drift_m = (self.retain * (2.0 * a[0] - u[0]), self.retain * (2.0 * a[1] - u[1]))


@dataclass
class LocalModel:
    """What one version-2 answer asks the device to render until the next:
    ``F(p) = F_r − K_r (p − p0) + Σ planes(p) − body pull(p)`` (see :class:`DeviceSide`)."""

    #: The world's force at the answered reading less the primitives' there, N.
    residual_force_n: Vec3 = _ZERO
    #: The world's stiffness less the primitives', N/m, row-major 3×3.
    residual_stiffness_n_per_m: Tuple[float, ...] = (0.0,) * 9
    #: Contact planes (at most :data:`MAX_PLANES`).
    planes: List[Plane] = field(default_factory=list)
    #: The carried body, when one is carried through a coupling.
    body: Optional[Body] = None
    #: Surfaces the carried body touches or nears (at most :data:`MAX_PLANES`; hard
    #: contacts, their stiffness unused).
    body_planes: List[Plane] = field(default_factory=list)
    #: The net work the world's answers did on the hand since the session began, J.
    world_energy_j: float = 0.0
    #: A spring that breaks (a version-3 or 4 packet); None in version 2.
    bond: Optional[Bond] = None
    #: The held particle and its envelope (a version-4 packet); None before version 4.
    follower: Optional[Follower] = None

    def static_force(self, p: Sequence[float], p0: Sequence[float]) -> Vec3:
        """The residual and the planes at ``p`` for the answered reading ``p0`` (the body
        excluded: it has a state of its own), N."""
        d = _sub(p, p0)
        k = self.residual_stiffness_n_per_m
        f = self.residual_force_n
        f = (f[0] - (k[0] * d[0] + k[1] * d[1] + k[2] * d[2]),
             f[1] - (k[3] * d[0] + k[4] * d[1] + k[5] * d[2]),
             f[2] - (k[6] * d[0] + k[7] * d[1] + k[8] * d[2]))
        for pl in self.planes:
            f = _add(f, pl.force(p))
        if self.bond is not None:
            f = _add(f, self.bond.force(p))
        return f

    def check(self, max_stiffness_n_per_m: float = math.inf) -> None:
        """Raises ValueError naming the first number out of range (every number finite,
        unit normals, stiffnesses within ``max_stiffness_n_per_m``, mass, damping, substeps
        and restitution in range), as Rust's ``LocalModel::check``."""
        if not (_finite(self.residual_force_n) and _finite(self.residual_stiffness_n_per_m)
                and math.isfinite(self.world_energy_j)):
            raise ValueError("a residual force, stiffness or energy is not finite")
        if len(self.planes) > MAX_PLANES:
            raise ValueError(f"{len(self.planes)} planes: allowed at most {MAX_PLANES}")
        for i, p in enumerate(self.planes):
            n = _norm(p.normal)
            if not _finite(p.normal) or abs(n - 1.0) > 1e-6 or not math.isfinite(p.offset_m):
                raise ValueError(f"plane {i}: the normal must be a finite unit vector")
            if not 0.0 <= p.stiffness_n_per_m <= max_stiffness_n_per_m:
                raise ValueError(
                    f"plane {i}: stiffness {_fmt(p.stiffness_n_per_m)} N/m is out of range: "
                    f"allowed 0 ≤ k ≤ {_fmt(max_stiffness_n_per_m)} N/m")
        if len(self.body_planes) > MAX_PLANES:
            raise ValueError(f"{len(self.body_planes)} body planes: allowed at most {MAX_PLANES}")
        for i, p in enumerate(self.body_planes):
            n = _norm(p.normal)
            if not _finite(p.normal) or abs(n - 1.0) > 1e-6 or not math.isfinite(p.offset_m):
                raise ValueError(f"body plane {i}: the normal must be a finite unit vector")
        b = self.body
        if b is not None:
            if not 0.0 <= b.restitution <= 1.0:
                raise ValueError(
                    f"body restitution {_fmt(b.restitution)} is out of range: allowed 0 ≤ e ≤ 1")
            if not 1 <= b.substeps <= 64:
                raise ValueError(
                    f"body substeps {b.substeps} is out of range: allowed 1 ≤ n ≤ 64")
            if not (_finite(b.position_m) and _finite(b.velocity_m_per_s)
                    and _finite(b.external_force_n) and _finite(b.damper_m)):
                raise ValueError("the body's state or force is not finite")
            if not (b.mass_kg > 0.0 and b.mass_kg <= 1e4):
                raise ValueError(
                    f"body mass {_fmt(b.mass_kg)} kg is out of range: allowed 0 < m ≤ 10000 kg")
            k, ks = b.stiffness_n_per_m, b.series_stiffness_n_per_m
            if not 0.0 <= k + ks <= max_stiffness_n_per_m or k < 0.0 or ks < 0.0:
                raise ValueError(
                    f"body stiffness {_fmt(k)} + {_fmt(ks)} N/m is out of range: "
                    f"allowed 0 ≤ k + k_s ≤ {_fmt(max_stiffness_n_per_m)} N/m")
            if not 0.0 <= b.damping_n_s_per_m <= 1e4:
                raise ValueError(
                    f"body damping {_fmt(b.damping_n_s_per_m)} N·s/m is out of range: "
                    "allowed 0 ≤ b ≤ 10000 N·s/m")
        bond = self.bond
        if bond is not None:
            n = _norm(bond.normal)
            if not _finite(bond.anchor_m) or not _finite(bond.normal) or abs(n - 1.0) > 1e-6:
                raise ValueError(
                    "bond: the anchor must be finite and the normal a finite unit vector")
            if not 0.0 <= bond.stiffness_n_per_m <= max_stiffness_n_per_m:
                raise ValueError(
                    f"bond.stiffness_n_per_m = {_fmt(bond.stiffness_n_per_m)} is out of range: "
                    f"allowed 0 ≤ k ≤ {_fmt(max_stiffness_n_per_m)} N/m")
            if not (bond.break_m > 0.0 and bond.break_m <= 1.0):
                raise ValueError(
                    f"bond.break_m = {_fmt(bond.break_m)} is out of range: allowed 0 < s ≤ 1 m")
        fo = self.follower
        if fo is not None:
            if not (_finite(fo.position_m) and _finite(fo.drift_m)
                    and all(_finite(v) for v in fo.reach_m)):
                raise ValueError("follower: the position, drift and envelope must be finite")
            n = len(fo.reach_m)
            if not 3 <= n <= MAX_REACH_VERTICES:
                raise ValueError(
                    f"follower.reach_m (vertices) = {n} is out of range: "
                    f"allowed 3 ≤ n ≤ {MAX_REACH_VERTICES}")
            zero = (-fo.drift_m[0], -fo.drift_m[1])
            if not _contains(fo.reach_m, (0.0, 0.0)) and not _contains(fo.reach_m, zero):
                raise ValueError(
                    "follower: the envelope must hold zero displacement or the free drift")
            if not 0.0 <= fo.retain <= 1.0:
                raise ValueError(
                    f"follower.retain = {_fmt(fo.retain)} is out of range: allowed 0 ≤ r ≤ 1")
            if not 0.0 <= fo.stiffness_n_per_m <= max_stiffness_n_per_m:
                raise ValueError(
                    f"follower.stiffness_n_per_m = {_fmt(fo.stiffness_n_per_m)} is out of "
                    f"range: allowed 0 ≤ k ≤ {_fmt(max_stiffness_n_per_m)} N/m")


# ---------------------------------------------------------------- packets


@dataclass
class Specs:
    """What a device announces in its hello."""

    name: str
    max_force_n: float
    max_stiffness_n_per_m: float
    workspace_radius_m: float
    buttons: List[str] = field(default_factory=list)
    rate_hz: int = 1000


@dataclass
class ForceReply:
    """The simulator's answer to one sample."""

    seq: int
    tick: int
    force_n: Tuple[float, float, float]
    stiffness_n_per_m: Tuple[float, ...]  # 9 values, row-major 3x3
    status: int
    received_at: float = 0.0  # time.perf_counter() on arrival, s
    #: The local model (a version-2 or 3 packet); None for a version-1 packet.
    local: Optional[LocalModel] = None


def _string(s: str) -> bytes:
    b = s.encode("utf-8")[:255]
    return bytes([len(b)]) + b


def _check_version(version: int, what: str = "version") -> int:
    if version not in (VERSION, VERSION_2, VERSION_3, VERSION_4):
        raise ValueError(f"{what} = {version!r}: allowed 1, 2, 3 or 4")
    return int(version)


def encode_hello(specs: Specs, version: int = VERSION) -> bytes:
    """The hello datagram of a device with ``specs`` speaking protocol ``version`` (1; 2: it
    renders the local model; 3: and its bond)."""
    body = struct.pack(
        "<Iddd",
        specs.rate_hz,
        specs.max_force_n,
        specs.max_stiffness_n_per_m,
        specs.workspace_radius_m,
    )
    body += _string(specs.name) + bytes([len(specs.buttons)])
    body += b"".join(_string(b) for b in specs.buttons)
    return _HEADER.pack(MAGIC, _check_version(version), HELLO, 0) + body


def encode_welcome(rate_hz: int, start_time_ns: int, scene: str, version: int = VERSION,
                   roles: Optional[Sequence[int]] = None) -> bytes:
    """A welcome datagram (what the simulator sends; for tests and stand-in simulators);
    ``roles``: the button index of grip, turn_x, turn_y, turn_z (255: none), or None for a
    welcome without them (a simulator before issue 41)."""
    out = (_HEADER.pack(MAGIC, _check_version(version), WELCOME, 0)
           + struct.pack("<IQ", rate_hz, start_time_ns) + _string(scene))
    if roles is not None:
        out += bytes(int(r) for r in roles)
    return out


def encode_refusal(field_name: str, allowed: str, message: str) -> bytes:
    """A refusal datagram (version byte 1, type 6): the hello's field, the values allowed
    and the simulator's message (for tests and stand-in simulators)."""
    return (_HEADER.pack(MAGIC, VERSION, REFUSAL, 0) + _string(field_name) + _string(allowed)
            + _string(message))


class HelloRefused(ConnectionError):
    """The simulator refused this device's hello: ``field`` (e.g. ``max_force_n``,
    ``buttons.grip``), the values ``allowed``, and its ``message``, which is also the
    exception's text."""

    def __init__(self, field_name: str, allowed: str, message: str):
        super().__init__(message)
        self.field = field_name
        self.allowed = allowed
        self.message = message


def encode_sample(seq: int, device_time_ns: int, position_m: Sequence[float], buttons: int,
                  two_port_periods: Optional[int] = None) -> bytes:
    """A sample datagram: position in metres (device frame), button bits; with
    ``two_port_periods`` (the servo periods the device side's two-port layer has acted on), a
    version-2 sample, whose count the simulator keeps in its link counters."""
    x, y, z = (float(v) for v in position_m)
    body = _SAMPLE.pack(seq, device_time_ns, x, y, z, buttons)
    if two_port_periods is None:
        return _HEADER.pack(MAGIC, VERSION, SAMPLE, 0) + body
    n = max(0, min(int(two_port_periods), 0xFFFFFFFF))
    return _HEADER.pack(MAGIC, VERSION_2, SAMPLE, 0) + body + struct.pack("<I", n)


def encode_bye(reason: int = 0) -> bytes:
    """A goodbye datagram (0: end of session, 1: error)."""
    return _HEADER.pack(MAGIC, VERSION, BYE, 0) + bytes([reason])


def _planes_bytes(planes: Sequence[Plane], what: str) -> bytes:
    if len(planes) > MAX_PLANES:
        raise ValueError(f"{len(planes)} {what}: allowed at most {MAX_PLANES}")
    return bytes([len(planes)]) + b"".join(
        _PLANE.pack(*p.normal, p.offset_m, p.stiffness_n_per_m) for p in planes)


def encode_force(reply: ForceReply) -> bytes:
    """A force datagram (what the simulator sends): version 2 with the local model when
    ``reply.local`` is set, version 3 when that model has a bond, version 4 when it has a
    follower, else version 1. Raises ValueError for more than four planes or more than
    :data:`MAX_REACH_VERTICES` envelope vertices."""
    m = reply.local
    if m is None:
        version = VERSION
    elif m.follower is not None:
        version = VERSION_4
    else:
        version = VERSION_2 if m.bond is None else VERSION_3
    out = _HEADER.pack(MAGIC, version, FORCE, 0) + _FORCE.pack(
        reply.seq, reply.tick, *reply.force_n, *reply.stiffness_n_per_m, reply.status)
    if m is None:
        return out
    out += _LOCAL_FIXED.pack(*m.residual_force_n, *m.residual_stiffness_n_per_m, m.world_energy_j)
    out += _planes_bytes(m.planes, "planes")
    b = m.body
    if b is None:
        out += b"\x00"
    else:
        out += b"\x01" + _BODY.pack(
            *b.position_m, *b.velocity_m_per_s, b.mass_kg, b.stiffness_n_per_m,
            b.series_stiffness_n_per_m, b.damping_n_s_per_m, *b.damper_m, *b.external_force_n,
            b.substeps, b.restitution)
    out += _planes_bytes(m.body_planes, "body planes")
    if m.follower is not None:
        out += b"\x00" if m.bond is None else b"\x01"
    if m.bond is not None:
        d = m.bond
        out += _BOND.pack(*d.anchor_m, *d.normal, d.stiffness_n_per_m, d.break_m)
    fo = m.follower
    if fo is not None:
        if len(fo.reach_m) > MAX_REACH_VERTICES:
            raise ValueError(f"{len(fo.reach_m)} envelope vertices: allowed at most "
                             f"{MAX_REACH_VERTICES}")
        out += _FOLLOWER.pack(*fo.position_m, *fo.drift_m, fo.retain, fo.stiffness_n_per_m,
                              len(fo.reach_m))
        out += b"".join(_VERTEX.pack(*v) for v in fo.reach_m)
    return out


def force_v2_len(planes: int, body: bool, body_planes: int) -> int:
    """Size of a version-2 force packet, bytes: 228 + 40 per plane + 140 for a body."""
    return _V2_MIN_LEN + 40 * planes + (_BODY.size if body else 0) + 40 * body_planes


def force_v3_len(planes: int, body: bool, body_planes: int) -> int:
    """Size of a version-3 force packet, bytes: a version-2 one and its 64-byte bond."""
    return force_v2_len(planes, body, body_planes) + _BOND.size


def force_v4_len(planes: int, body: bool, body_planes: int, bond: bool, vertices: int) -> int:
    """Size of a version-4 force packet, bytes: a version-2 one, the bond flag, the 64-byte
    bond if any, the follower's 49 bytes and 16 a vertex."""
    return (force_v2_len(planes, body, body_planes) + 1 + (_BOND.size if bond else 0)
            + _FOLLOWER.size + _VERTEX.size * vertices)


class _Reader:
    """Reads a datagram front to back; running past its end is a ValueError naming the
    packet kind, the size and the size needed (Rust's ``ProtocolError::TooShort``)."""

    def __init__(self, b: bytes, at: int):
        self.b, self.at = b, at

    def take(self, fmt: struct.Struct, kind: str):
        end = self.at + fmt.size
        if end > len(self.b):
            raise ValueError(f"{kind} packet of {len(self.b)} bytes is too short (needs {end})")
        v = fmt.unpack_from(self.b, self.at)
        self.at = end
        return v

    def u8(self, kind: str) -> int:
        return self.take(_U8, kind)[0]

    def string(self, kind: str) -> str:
        n = self.u8(kind)
        end = self.at + n
        if end > len(self.b):
            raise ValueError(f"{kind} packet of {len(self.b)} bytes is too short (needs {end})")
        raw = self.b[self.at:end]
        self.at = end
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError:
            raise ValueError(f"{kind}: bad string") from None

    def end(self, kind: str) -> None:
        if self.at != len(self.b):
            raise ValueError(
                f"{kind} packet of {len(self.b)} bytes is too long (expected {self.at})")

    def planes(self, kind: str) -> List[Plane]:
        n = self.u8(kind)
        if n > MAX_PLANES:
            raise ValueError(
                f"force packet's local model: {kind}: {n} planes, allowed at most {MAX_PLANES}")
        out = []
        for _ in range(n):
            v = self.take(_PLANE, kind)
            out.append(Plane(v[0:3], v[3], v[4]))
        return out

    def bond(self, kind: str = _V3_KIND) -> Bond:
        v = self.take(_BOND, kind)
        return Bond(anchor_m=v[0:3], normal=v[3:6], stiffness_n_per_m=v[6], break_m=v[7])

    def follower(self) -> Follower:
        v = self.take(_FOLLOWER, _V4_KIND)
        reach = [self.take(_VERTEX, _V4_KIND) for _ in range(v[6])]
        return Follower(position_m=v[0:2], drift_m=v[2:4], reach_m=reach, retain=v[4],
                        stiffness_n_per_m=v[5])

    def local(self) -> LocalModel:
        kind = _V2_KIND
        v = self.take(_LOCAL_FIXED, kind)
        planes = self.planes(kind)
        flag = self.u8(kind)
        if flag == 0:
            body = None
        elif flag == 1:
            w = self.take(_BODY, kind)
            body = Body(position_m=w[0:3], velocity_m_per_s=w[3:6], mass_kg=w[6],
                        stiffness_n_per_m=w[7], series_stiffness_n_per_m=w[8],
                        damping_n_s_per_m=w[9], damper_m=w[10:13], external_force_n=w[13:16],
                        substeps=w[16], restitution=w[17])
        else:
            raise ValueError(f"force packet's local model: body flag {flag}: allowed 0 (none) or 1")
        body_planes = self.planes(kind)
        m = LocalModel(residual_force_n=v[0:3], residual_stiffness_n_per_m=v[3:12],
                       planes=planes, body=body, body_planes=body_planes, world_energy_j=v[12])
        # The device checks the stiffnesses against its own cap when it renders the model.
        try:
            m.check(math.inf)
        except ValueError as e:
            raise ValueError(f"force packet's local model: {e}") from None
        return m


_U8 = struct.Struct("<B")
_WELCOME = struct.Struct("<IQ")
_HELLO = struct.Struct("<Iddd")


def _fixed(data: bytes, kind: str, size: int) -> None:
    if len(data) < size:
        raise ValueError(f"{kind} packet of {len(data)} bytes is too short (needs {size})")
    if len(data) > size:
        raise ValueError(f"{kind} packet of {len(data)} bytes is too long (expected {size})")


def decode(data: bytes):
    """Decode a datagram: ``("welcome", dict)`` (``version``, ``rate_hz``,
    ``start_time_ns``, ``scene``, ``roles``), ``("refusal", dict)`` (``field``, ``allowed``,
    ``message``), ``("force", ForceReply)`` (with ``local`` set for a
    version-2 packet), ``("bye", reason)``, and the device's packets ``("hello", dict)``
    (``version``, ``specs``) and ``("sample", dict)`` (``seq``, ``device_time_ns``,
    ``position_m``, ``buttons``). Any other bytes raise ValueError naming what is wrong
    (the same words as the simulator's decoder), never another exception."""
    data = bytes(data)
    if len(data) > MAX_PACKET:
        raise ValueError(f"datagram of {len(data)} bytes is over the {MAX_PACKET}-byte limit")
    if len(data) < _HEADER.size:
        raise ValueError(f"header packet of {len(data)} bytes is too short (needs {_HEADER.size})")
    magic, version, kind, _ = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise ValueError(f"bad magic [{', '.join(f'{b:02x}' for b in magic)}] (expected NHDB)")
    if version not in (VERSION, VERSION_2, VERSION_3, VERSION_4):
        # Worded so that "(this client speaks 1)", the text tests/python/test_live.py matches
        # since version 1, still appears.
        raise ValueError(f"protocol version {version} (this client speaks 1), 2, 3 and 4")
    r = _Reader(data, _HEADER.size)
    if kind == WELCOME:
        rate, start = r.take(_WELCOME, "welcome")
        scene = r.string("welcome scene")
        roles = None
        if r.at < len(data):  # the button roles (a simulator before issue 41 sends none)
            roles = {name: (None if b == 255 else b)
                     for name, b in zip(ROLES, [r.u8("welcome") for _ in ROLES])}
        r.end("welcome")
        return "welcome", {"version": version, "rate_hz": rate, "start_time_ns": start,
                           "scene": scene, "roles": roles}
    if kind == REFUSAL:
        field_name = r.string("refusal field")
        allowed = r.string("refusal allowed")
        message = r.string("refusal message")
        r.end("refusal")
        return "refusal", {"field": field_name, "allowed": allowed, "message": message}
    if kind == FORCE:
        if version == VERSION:
            _fixed(data, "force", FORCE_LEN)
        elif len(data) < _V2_MIN_LEN:
            raise ValueError(
                f"{_V2_KIND} packet of {len(data)} bytes is too short (needs {_V2_MIN_LEN})")
        v = r.take(_FORCE, "force")
        local = None
        if version == VERSION_2:
            local = r.local()
            r.end(_V2_KIND)
        elif version == VERSION_3:
            local = r.local()
            local.bond = r.bond()
            try:
                local.check(math.inf)
            except ValueError as e:
                raise ValueError(f"force packet's local model: {e}") from None
            r.end(_V3_KIND)
        elif version == VERSION_4:
            local = r.local()
            flag = r.u8(_V4_KIND)
            if flag not in (0, 1):
                raise ValueError(
                    f"force packet's local model: bond flag {flag}: allowed 0 (none) or 1")
            local.bond = r.bond(_V4_KIND) if flag == 1 else None
            local.follower = r.follower()
            try:
                local.check(math.inf)
            except ValueError as e:
                raise ValueError(f"force packet's local model: {e}") from None
            r.end(_V4_KIND)
        return "force", ForceReply(v[0], v[1], tuple(v[2:5]), tuple(v[5:14]), v[14], local=local)
    if kind == BYE:
        _fixed(data, "bye", BYE_LEN)
        return "bye", data[8]
    if kind == SAMPLE:
        if version >= VERSION_2:  # a version-3 sample is a version-2 sample
            _fixed(data, "sample (version 2)", SAMPLE_LEN + 4)
        else:
            _fixed(data, "sample", SAMPLE_LEN)
        seq, t_ns, x, y, z, buttons = _SAMPLE.unpack_from(data, _HEADER.size)
        out = {"seq": seq, "device_time_ns": t_ns, "position_m": (x, y, z), "buttons": buttons}
        if version >= VERSION_2:
            out["two_port_periods"] = struct.unpack_from("<I", data, SAMPLE_LEN)[0]
        return "sample", out
    if kind == HELLO:
        rate, fmax, kmax, radius = r.take(_HELLO, "hello")
        name = r.string("hello name")
        buttons = [r.string("hello button name") for _ in range(r.u8("hello"))]
        r.end("hello")
        return "hello", {"version": version,
                         "specs": Specs(name, fmax, kmax, radius, buttons, rate_hz=rate)}
    raise ValueError(f"unknown packet type {kind}")


# ---------------------------------------------------------------- the device side


@dataclass
class _Answer:
    reply: ForceReply
    p0: Vec3
    local: Optional[LocalModel]


def _reading_at_or_before(readings: Deque[Tuple[int, Vec3]], seq: int) -> Optional[Vec3]:
    """The reading sent as ``seq``, or the last one before it (a skipped number holds the
    reading before it); None when ``seq`` is older than every kept reading."""
    lo, hi = 0, len(readings)
    while lo < hi:  # partition point: the first reading numbered above seq
        mid = (lo + hi) // 2
        if readings[mid][0] <= seq:
            lo = mid + 1
        else:
            hi = mid
    return readings[lo - 1][1] if lo > 0 else None


class DeviceSide:
    """What a device's servo loop renders between the simulator's answers, and (protocol 2)
    its two-port passivity layer: a line-by-line port of Rust's
    ``haptic_devices::local::DeviceSide``.

    * Protocol 1 renders the newest answer's ``F0 − K (p − p0)``, ``p0`` the reading the
      answer was computed from (the last 1000 readings are kept by sequence number; an
      answer older than those is rendered against the oldest kept).
    * Protocol 2 renders the answer's :class:`LocalModel` at the position read now:
      ``F_r − K_r (p − p0) + Σ planes(p) − pull(p)``, the pull of the carried body, which
      is integrated here one step of ``period_s`` per sample with the reading sent
      (:meth:`Body.step`), restarted on every answer from the state the simulator reports
      (the state the sample after the answered one meets) and stepped again through the
      readings sent since. An answer without a local model (a version-1 packet) renders
      ``F0 − K (p − p0)``.
    * Protocol 3 adds the answer's :class:`Bond`, protocol 4 its :class:`Follower`: the held
      particle, stepped here with each reading sent from the answered sample on (the state
      the simulator reports is the particle as that sample met it), and its spring on the
      excess at the position read now.

    Answers of an older tick than the one rendered are dropped; a non-finite force renders
    as zero (a non-finite reading counts no work); a
    force above ``max_force_n`` is scaled down along its direction. Then (protocol 2) the
    two-port layer: with ``W`` the work the rendered forces did on the hand
    (``Σ F·Δp`` over servo periods) and ``W_world`` the world's (the last answer's
    ``world_energy_j``), while the surplus ``s = W − W_world − 0.02 J`` is positive the
    force gets the damping ``α = min(s / (servo_s |v|²), 2 N·s/m)`` on the last servo
    period's velocity ``v`` (``F − α v``); past ``s > 0.02 J`` that is also scaled by
    ``max(0, 1 − (s − 0.02 J) / 0.04 J)``; then scaled down to ``max_force_n`` again.

    Not thread-safe: a device whose servo runs in another thread holds one lock around
    every call (the adapters do). ``period_s`` is the session's sample period (one sample
    per tick, from the welcome), ``servo_s`` in :meth:`render` the servo period.

    >>> side = DeviceSide(2, max_force_n=8.0, period_s=1e-3)
    >>> side.record_reading(0, (0.0, 0.0, -0.001))
    >>> floor = Plane((0.0, 0.0, 1.0), 0.0, 1000.0)
    >>> side.receive(ForceReply(0, 0, (0.0, 0.0, 1.0), (0.0,) * 9, 0,
    ...                         local=LocalModel(planes=[floor])))
    True
    >>> side.render((0.0, 0.0, -0.002), 1e-3)     # 2 mm below the floor: 2 N up
    (0.0, 0.0, 2.0)
    """

    def __init__(self, protocol: int, max_force_n: float, period_s: float):
        self.protocol = _check_version(protocol, "protocol")
        self.max_force_n = float(max_force_n)
        if not (self.max_force_n > 0.0 and math.isfinite(self.max_force_n)):
            raise ValueError(f"max_force_n = {_fmt(self.max_force_n)}: expected a finite force > 0 N")
        self.period_s = float(period_s)
        if not (self.period_s > 0.0 and math.isfinite(self.period_s)):
            raise ValueError(f"period_s = {_fmt(self.period_s)}: expected a finite period > 0 s")
        self._readings: Deque[Tuple[int, Vec3]] = collections.deque()
        self._answer: Optional[_Answer] = None
        # The carried body as integrated here, and the sequence number of the reading it is
        # to be stepped with next (its state is the one that reading meets).
        self._body: Optional[Body] = None
        self._body_next = 0
        # Protocol 4's follower as stepped here, and the reading it is to be stepped with next.
        self._follower: Optional[Follower] = None
        self._follower_next = 0
        self._work_j = 0.0
        self._world_j = 0.0
        self._reserve_j = DEVICE_RESERVE_J
        self._last_p: Optional[Vec3] = None
        self._last_f: Vec3 = _ZERO
        self._interventions = 0
        # The smallest tick − seq of the answers so far (an on-time answer's).
        self._tick_offset: Optional[int] = None
        # Python only (forget()): the newest answer's tick after the answers went silent.
        self._forgotten_tick: Optional[int] = None

    @property
    def work_j(self) -> float:
        """Work the rendered forces did on the hand so far, J."""
        return self._work_j

    @property
    def interventions(self) -> int:
        """Servo periods on which the two-port layer held the force back."""
        return self._interventions

    @property
    def world_energy_j(self) -> float:
        """The world's work on the hand as the last answer reported it, J (protocol 2)."""
        return self._world_j

    @property
    def answered_seq(self) -> Optional[int]:
        """Sequence number of the sample whose answer is rendered (None: none)."""
        return None if self._answer is None else self._answer.reply.seq

    def record_reading(self, seq: int, p: Sequence[float]) -> None:
        """The device sent reading ``p`` (m) as sample ``seq``: record every sample sent,
        in order, with consecutive numbers."""
        self._readings.append((int(seq), _vec3(p)))
        if len(self._readings) > KEEP_READINGS:
            self._readings.popleft()
        self._catch_up(seq)

    def _catch_up(self, seq: int) -> None:
        """Steps the follower and the body with every kept reading before ``seq`` they have
        not met yet."""
        fo = self._follower
        if fo is not None:
            while self._follower_next < seq:
                p = _reading_at_or_before(self._readings, self._follower_next)
                if p is None:
                    break
                fo.step(p)
                self._follower_next += 1
        body = self._body
        if body is None:
            return
        while self._body_next < seq:
            p = _reading_at_or_before(self._readings, self._body_next)
            if p is None:
                break
            a = self._answer
            planes = a.local.body_planes if a is not None and a.local is not None else ()
            body.step(p, self.period_s, planes)
            self._body_next += 1

    def receive(self, reply: ForceReply) -> bool:
        """An answer arrived: rendered from now on unless an answer of a later tick is
        rendered (then dropped: returns False). Protocol 2's body restarts from the state the
        answer reports for the sample after its tick (a stale tick answers an older sample:
        its ``tick − seq`` exceeds an on-time answer's) and replays the readings sent since."""
        newest = self._answer.reply.tick if self._answer is not None else self._forgotten_tick
        if newest is not None and newest > reply.tick:
            return False
        self._forgotten_tick = None
        p0 = _reading_at_or_before(self._readings, reply.seq)
        if p0 is None:
            p0 = self._readings[0][1] if self._readings else _ZERO
        local = reply.local if self.protocol >= VERSION_2 else None
        if local is not None and self.protocol == VERSION_2 and local.bond is not None:
            local = dataclasses.replace(local, bond=None)
        if local is not None and self.protocol < VERSION_4 and local.follower is not None:
            local = dataclasses.replace(local, follower=None)
        lag = reply.tick - reply.seq
        offset = lag if self._tick_offset is None else self._tick_offset
        self._tick_offset = min(offset, lag)
        if local is not None:
            self._world_j = local.world_energy_j
            nxt = reply.tick - min(offset, lag) + 1
            if local.body is not None and nxt >= 0:
                self._body = dataclasses.replace(local.body)
                self._body_next = nxt
            else:
                self._body = None
            # The follower's state is the one the answered sample met: it replays that
            # sample's reading first.
            fo = local.follower
            if fo is not None and nxt >= 1:
                self._follower = dataclasses.replace(fo, reach_m=list(fo.reach_m))
                self._follower_next = nxt - 1
            else:
                self._follower = None
        self._answer = _Answer(reply, p0, local)
        if self._readings:
            self._catch_up(self._readings[-1][0])
        return True

    def forget(self) -> None:
        """The answers stopped (an adapter's ``hold_s``): render zero force until a newer
        answer arrives (the work done keeps being counted). Not in the Rust device side,
        whose callers never go silent; without calls to it, this class is the Rust one."""
        if self._answer is not None:
            self._forgotten_tick = self._answer.reply.tick
        self._answer = None
        self._body = None
        self._follower = None

    def render(self, p: Sequence[float], servo_s: float) -> Vec3:
        """The force to render at the reading ``p`` (m) for the next servo period of
        ``servo_s`` (s), N: the answer's model, held back by the two-port layer (protocol 2).
        Call once per servo period."""
        p = _vec3(p)
        v = _ZERO
        lp = self._last_p
        if lp is not None:
            d = _sub(p, lp)
            w = _dot(self._last_f, d)
            # A non-finite reading counts no work (it would poison the budget for good).
            if math.isfinite(w) and _finite(d):
                self._work_j += w
                v = _scale(d, _div(1.0, servo_s))
        if _finite(p):
            self._last_p = p
        a = self._answer
        if a is None:
            self._last_f = _ZERO
            return _ZERO
        if a.local is None:
            d = _sub(p, a.p0)
            k = a.reply.stiffness_n_per_m
            f0 = a.reply.force_n
            f = (f0[0] - (k[0] * d[0] + k[1] * d[1] + k[2] * d[2]),
                 f0[1] - (k[3] * d[0] + k[4] * d[1] + k[5] * d[2]),
                 f0[2] - (k[6] * d[0] + k[7] * d[1] + k[8] * d[2]))
        else:
            f = a.local.static_force(p, a.p0)
            if self._body is not None:
                f = _sub(f, self._body.pull(p, self.period_s)[0])
            if self._follower is not None:
                f = _add(f, self._follower.force(p))
        if not _finite(f):
            f = _ZERO
        n = _norm(f)
        if n > self.max_force_n:
            f = _scale(f, self.max_force_n / n)
        if self.protocol >= VERSION_2:
            f = self._bound(f, v, servo_s)
            if not _finite(f):
                f = _ZERO
        f = (float(f[0]), float(f[1]), float(f[2]))
        self._last_f = f
        return f

    def _bound(self, f: Vec3, v: Vec3, servo_s: float) -> Vec3:
        """The two-port layer: while the hand has received more than the world delivered
        plus the reserve, a damper on the last servo period's velocity takes the surplus
        back over the next period (at most DEVICE_MAX_DAMPING_N_S_PER_M); past a second
        reserve the force is also scaled down, to zero two reserves further on."""
        surplus = self._work_j - self._world_j - self._reserve_j
        if surplus <= 0.0:
            return f
        self._interventions += 1
        v2 = _dot(v, v)
        if v2 > 0.0:
            alpha = _min(_div(surplus, servo_s * v2), DEVICE_MAX_DAMPING_N_S_PER_M)
            g = _sub(f, _scale(v, alpha))
        else:
            g = f
        if surplus > self._reserve_j:
            scale = _max(1.0 - (surplus - self._reserve_j) / (2.0 * self._reserve_j), 0.0)
            g = _scale(g, scale)
        n = _norm(g)
        if n > self.max_force_n:
            return _scale(g, self.max_force_n / n)
        return g


# ---------------------------------------------------------------- the client


class BridgeClient:
    """The device side of the bridge over one UDP socket, speaking ``protocol`` (2 by
    default; 1 for the answered force and stiffness only).

    >>> c = BridgeClient(("127.0.0.1", 9870), Specs("falcon", 8.0, 3000.0, 0.04,
    ...                  ["centre", "plus", "minus", "forward"]))      # doctest: +SKIP
    >>> c.connect()   # hello until welcome; c.version is the session's  # doctest: +SKIP
    >>> c.send(position_m=(0, 0, 0), buttons=0)                        # doctest: +SKIP
    >>> reply = c.receive(timeout_s=0.002)                             # doctest: +SKIP
    """

    def __init__(self, address: Tuple[str, int], specs: Specs, protocol: int = VERSION_2):
        self.protocol = _check_version(protocol, "protocol")
        self.address = (socket.gethostbyname(address[0]), int(address[1]))
        self.specs = specs
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("0.0.0.0", 0))
        self.seq = 0
        self.welcome: Optional[dict] = None
        #: The session's protocol version, from the welcome (None before it).
        self.version: Optional[int] = None
        #: Datagrams from the simulator that did not decode (dropped).
        self.malformed = 0
        self.ended = False
        self._t0 = time.perf_counter_ns()

    def connect(self, timeout_s: float = 30.0) -> dict:
        """Say hello every 50 ms until the simulator welcomes this device;
        returns the welcome (version, rate_hz, start_time_ns, scene, and roles: the button
        index of each role in :data:`ROLES`, None for a role no button plays). Raises
        :class:`HelloRefused` with the simulator's words when it refuses the hello."""
        hello = encode_hello(self.specs, self.protocol)
        deadline = time.monotonic() + timeout_s
        self.sock.settimeout(0.05)
        while time.monotonic() < deadline:
            try:
                self.sock.sendto(hello, self.address)
                data, src = self.sock.recvfrom(2048)
            except (socket.timeout, ConnectionRefusedError):
                continue
            if src != self.address:
                continue
            try:
                kind, value = decode(data)
            except ValueError:
                self.malformed += 1
                continue
            if kind == "welcome":
                self.welcome = value
                self.version = value["version"]
                return value
            if kind == "refusal":
                # The same hello would be refused again: say why.
                raise HelloRefused(value["field"], value["allowed"], value["message"])
        raise TimeoutError(f"no welcome from udp:{self.address[0]}:{self.address[1]} within {timeout_s} s")

    def send(self, position_m: Sequence[float], buttons: int = 0,
             two_port_periods: Optional[int] = None) -> int:
        """Send one sample; returns its sequence number. In a version-2 session, pass the
        device side's two-port count (``DeviceSide.interventions``) to report it."""
        seq = self.seq
        self.seq += 1
        t = time.perf_counter_ns() - self._t0
        n = two_port_periods if self.version is not None and self.version >= VERSION_2 else None
        self.sock.sendto(encode_sample(seq, t, position_m, buttons, n), self.address)
        return seq

    def receive(self, timeout_s: float) -> Optional[ForceReply]:
        """The next force packet, or None after ``timeout_s``; a goodbye from
        the simulator sets ``ended``."""
        self.sock.settimeout(max(timeout_s, 1e-6))
        while True:
            try:
                data, src = self.sock.recvfrom(2048)
            except (socket.timeout, ConnectionRefusedError):
                return None
            at = time.perf_counter()
            if src != self.address:
                continue
            try:
                kind, value = decode(data)
            except ValueError:
                self.malformed += 1
                continue
            if kind == "force":
                value.received_at = at
                return value
            if kind == "bye":
                self.ended = True
                return None

    def close(self) -> None:
        """Say goodbye (the simulator ends the session) and close the socket."""
        try:
            self.sock.sendto(encode_bye(0), self.address)
        finally:
            self.sock.close()

    def __enter__(self) -> "BridgeClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Device:
    """What :func:`run` needs of a device. Subclass and implement ``specs``, ``read`` and
    ``render`` (and ``close`` if the device must be released): :func:`run` then calls
    ``render(answer, p0)`` once per period with the newest answer to one of its own samples
    and that sample's reading (protocol 1's ``F0 − K (p − p0)`` is :func:`local_force`).

    A device with a servo loop of its own renders through a :class:`DeviceSide` instead
    (the adapters here do): ``attach(side)`` returns True, and :func:`run` then calls
    ``record_reading(seq, p)`` for every sample sent and ``receive(answer)`` for every
    answer, and the servo loop calls ``side.render(p, servo_s)`` once per servo period."""

    #: The protocol version the device asks for in its hello.
    protocol: int = VERSION_2

    def specs(self) -> Specs:
        raise NotImplementedError

    def read(self) -> Tuple[Tuple[float, float, float], int]:
        """Stylus position (m, device frame) and button bits."""
        raise NotImplementedError

    def render(self, reply: Optional[ForceReply], position_m: Sequence[float]) -> None:
        """Render the answer computed at ``position_m`` (None: no answer, render zero force)."""
        raise NotImplementedError

    def attach(self, side: Optional[DeviceSide]) -> bool:
        """A session starts with ``side`` (None: it ended). True: this device renders
        through it from its own servo loop."""
        return False

    def record_reading(self, seq: int, position_m: Sequence[float]) -> None:
        """Reading ``position_m`` was sent as sample ``seq`` (devices that attach a side)."""

    def receive(self, reply: ForceReply) -> None:
        """An answer arrived (devices that attach a side)."""

    def close(self) -> None:
        pass


def local_force(reply: Optional[ForceReply], p0: Sequence[float], p: Sequence[float],
                max_force_n: float) -> Tuple[float, float, float]:
    """``F0 − K (p − p0)`` from an answer computed at ``p0``, scaled down to
    ``max_force_n``; zero without an answer or on non-finite input."""
    if reply is None:
        return (0.0, 0.0, 0.0)
    d = [p[i] - p0[i] for i in range(3)]
    k = reply.stiffness_n_per_m
    f = [reply.force_n[i] - sum(k[3 * i + j] * d[j] for j in range(3)) for i in range(3)]
    if not all(math.isfinite(v) for v in f):
        return (0.0, 0.0, 0.0)
    n = math.sqrt(sum(v * v for v in f))
    if n > max_force_n > 0:
        f = [v * max_force_n / n for v in f]
    return (f[0], f[1], f[2])


def _percentile(values: List[float], q: float) -> float:
    if not values:
        return 0.0
    v = sorted(values)
    return v[min(len(v) - 1, max(0, math.ceil(q * len(v)) - 1))]


def run(device: Device, address: Tuple[str, int], *, seconds: Optional[float] = None,
        connect_timeout_s: float = 30.0, stop: Optional[threading.Event] = None,
        protocol: Optional[int] = None) -> dict:
    """Drive a simulator session with ``device`` until ``seconds`` pass, the
    simulator says goodbye or ``stop`` is set: each period read the device, send
    the sample, wait up to one period for its answer, and hand every answer to the
    device. ``protocol`` (default: the device's ``protocol``, 2) is the version asked
    for in the hello; the welcome decides. Returns counts, the session's protocol, the
    round-trip percentiles (s) and, for a device that renders through a
    :class:`DeviceSide`, the two-port layer's interventions and the work done on the
    hand (J)."""
    specs = device.specs()
    proto = _check_version(getattr(device, "protocol", VERSION_2) if protocol is None else protocol,
                           "protocol")
    client = BridgeClient(address, specs, protocol=proto)
    rtts: List[float] = []
    sent = answered = 0
    side: Optional[DeviceSide] = None
    uses_side = False
    try:
        welcome = client.connect(connect_timeout_s)
        period = 1.0 / welcome["rate_hz"]
        side = DeviceSide(welcome["version"], specs.max_force_n, period)
        attach = getattr(device, "attach", None)
        uses_side = bool(attach(side)) if attach is not None else False
        t_end = None if seconds is None else time.perf_counter() + seconds
        next_t = time.perf_counter()
        last: Optional[ForceReply] = None
        last_p0 = (0.0, 0.0, 0.0)
        while not client.ended and not (stop is not None and stop.is_set()):
            now = time.perf_counter()
            if t_end is not None and now >= t_end:
                break
            p, b = device.read()
            if uses_side:
                device.record_reading(client.seq, p)
            t_send = time.perf_counter()
            # A device side's two-port count rides on the sample (read without its lock: an
            # int, at most one period stale).
            seq = client.send(p, b, side.interventions if uses_side else None)
            sent += 1
            reply = client.receive(period)
            while reply is not None:
                if uses_side:
                    device.receive(reply)  # late answers too: newer than the one rendered
                if reply.seq >= seq:
                    break
                reply = client.receive(max(0.0, t_send + period - time.perf_counter()))
            if reply is not None and reply.seq == seq:
                answered += 1
                rtts.append(reply.received_at - t_send)
                last, last_p0 = reply, p
            if not uses_side:
                device.render(last, last_p0)
            next_t += period
            delay = next_t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            else:
                # Late by one period or more: the device's clock has moved on. Skip the
                # missed sequence numbers (the simulator counts them as a gap and has run
                # those ticks on the last sample) so that sequence numbers keep the
                # device's time: resetting the schedule instead would leave every later
                # sample that many periods old, and the watchdog would fade the force out.
                missed = int(-delay // period)
                if uses_side:
                    # The simulator ran those ticks on the last sample: so does the body here
                    # (and the readings stay numbered without a gap).
                    for k in range(missed - min(missed, KEEP_READINGS), missed):
                        device.record_reading(client.seq + k, p)
                client.seq += missed
                next_t += missed * period
    finally:
        if uses_side:
            device.attach(None)
        device.render(None, (0.0, 0.0, 0.0))
        client.close()
        device.close()
    out = {
        "sent": sent,
        "answered": answered,
        "protocol": client.version,
        "round_trip_p50_s": _percentile(rtts, 0.5),
        "round_trip_p99_s": _percentile(rtts, 0.99),
    }
    if uses_side and side is not None:
        out["two_port_interventions"] = side.interventions
        out["work_j"] = side.work_j
    return out


# ---------------------------------------------------------------- adapters


class _ServoRendering(Device):
    """What the adapters share: a servo loop of their own (an SDK callback or a thread)
    asks :meth:`_servo_force` for the force at the position it just read. During a
    :func:`run` session that is the session's :class:`DeviceSide`; outside one (or for a
    direct ``render(answer, p0)``) it is protocol 1's ``F0 − K (p − p0)``. Either way zero
    once the newest answer is older than ``hold_s``, and zero if anything is not finite."""

    def _init_rendering(self, protocol: int, hold_s: float, servo_hz: float) -> None:
        if not (servo_hz > 0 and math.isfinite(servo_hz)):
            raise ValueError(f"servo_hz = {servo_hz}: expected a positive rate in Hz")
        self.protocol = _check_version(protocol, "protocol")
        self.hold_s = hold_s
        self._lock = threading.Lock()
        self._servo_s = 1.0 / servo_hz
        self._side: Optional[DeviceSide] = None
        self._answer_at = 0.0
        self._reply: Optional[ForceReply] = None
        self._p0 = (0.0, 0.0, 0.0)
        self._reply_at = 0.0

    @property
    def device_side(self) -> Optional[DeviceSide]:
        """The session's device side (None outside a session)."""
        return self._side

    def attach(self, side: Optional[DeviceSide]) -> bool:
        with self._lock:
            self._side = side
            self._answer_at = 0.0
            self._reply, self._reply_at = None, 0.0
        return True

    def record_reading(self, seq: int, position_m: Sequence[float]) -> None:
        with self._lock:
            if self._side is not None:
                self._side.record_reading(seq, position_m)

    def receive(self, reply: ForceReply) -> None:
        with self._lock:
            if self._side is not None and self._side.receive(reply):
                self._answer_at = reply.received_at or time.perf_counter()

    def render(self, reply, position_m):
        """Hand over an answer computed at ``position_m``, rendered as ``F0 − K (p − p0)``
        by the servo for ``hold_s`` (outside a :func:`run` session; None: zero force)."""
        with self._lock:
            self._reply, self._p0 = reply, tuple(position_m)
            self._reply_at = time.perf_counter() if reply is not None else 0.0

    def _servo_force(self, p: Sequence[float]) -> Tuple[float, float, float]:
        """The force for the servo period starting now at ``p``; call with the lock held."""
        side = self._side
        if side is not None:
            if side.answered_seq is not None and time.perf_counter() - self._answer_at > self.hold_s:
                side.forget()
            f = side.render(p, self._servo_s)
        else:
            fresh = time.perf_counter() - self._reply_at <= self.hold_s
            f = local_force(self._reply if fresh else None, self._p0, p, self._specs.max_force_n)
        # Belt and braces: a reading far out of range can make the two-port layer's damping
        # overflow; the motors never get anything but finite numbers.
        return f if _finite(f) else _ZERO


class TouchDevice(_ServoRendering):
    """A 3D Systems Touch (Phantom Omni class) through ``pyOpenHaptics``.

    OpenHaptics reports millimetres in its own frame; this adapter reports metres. A servo
    callback of the HD scheduler (1 kHz, ``servo_hz``) renders between answers: the
    session's :class:`DeviceSide` (protocol 2 by default, ``protocol=1`` for
    ``F0 − K (p − p0)``), zero force once answers stop for longer than ``hold_s``.
    """

    def __init__(self, device_name: str = "Default Device", *, hold_s: float = 0.01,
                 max_force_n: float = 3.3, max_stiffness_n_per_m: float = 400.0,
                 workspace_radius_m: float = 0.075, protocol: int = VERSION_2,
                 servo_hz: float = 1000.0):
        self._init_rendering(protocol, hold_s, servo_hz)
        try:
            import pyOpenHaptics.hd as hd
            from pyOpenHaptics.hd_callback import hd_callback
            from pyOpenHaptics.hd_device import HapticDevice
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "TouchDevice needs pyOpenHaptics and the OpenHaptics runtime: "
                "pip install pyOpenHaptics (see docs/device-bridge.md)"
            ) from e
        self._hd = hd
        self._position = (0.0, 0.0, 0.0)
        self._buttons = 0
        self._specs = Specs("touch", max_force_n, max_stiffness_n_per_m, workspace_radius_m,
                            ["button1", "button2"])

        @hd_callback
        def servo():
            t = hd.get_transform()
            p = (t[3][0] * 1e-3, t[3][1] * 1e-3, t[3][2] * 1e-3)
            b = int(hd.get_buttons())
            with self._lock:  # held while rendering: a newer answer never races an older force
                self._position, self._buttons = p, b
                f = self._servo_force(p)
                hd.set_force(list(f))

        self._device = HapticDevice(callback=servo, device_name=device_name, scheduler_type="async")

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        with self._lock:
            return self._position, self._buttons

    def close(self) -> None:
        with self._lock:
            self._side = None
            self._reply, self._reply_at = None, 0.0
        time.sleep(0.003)  # a few servo periods of zero force before the scheduler stops
        self._device.close()


class ForceDimensionDevice(_ServoRendering):
    """A Force Dimension device (delta, omega, sigma, lambda) or a Novint Falcon through
    ``forcedimension_core`` (the Force Dimension SDK, which drives the Falcon too).
    Positions are already in metres.

    A servo thread (``servo_hz``, default 1000) makes every SDK call: each period it reads
    the position and buttons and sets the force the session's :class:`DeviceSide` renders
    there (protocol 2 by default, ``protocol=1`` for ``F0 − K (p − p0)``; zero once answers
    stop for longer than ``hold_s``). :meth:`read` returns the newest reading;
    :meth:`close` stops the thread, sets a zero force and closes the device."""

    def __init__(self, device_id: Optional[int] = None, *, name: Optional[str] = None,
                 max_force_n: Optional[float] = None, max_stiffness_n_per_m: float = 3000.0,
                 workspace_radius_m: float = 0.04, buttons: Sequence[str] = ("centre", "plus", "minus", "forward"),
                 hold_s: float = 0.01, servo_hz: float = 1000.0, protocol: int = VERSION_2):
        self._init_rendering(protocol, hold_s, servo_hz)
        try:
            from forcedimension_core import dhd
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "ForceDimensionDevice needs forcedimension_core and the Force Dimension SDK: "
                "pip install forcedimension-core (see docs/device-bridge.md)"
            ) from e
        self._dhd = dhd
        self._id = dhd.open() if device_id is None else dhd.openID(device_id)
        if self._id == -1:
            raise ConnectionError(f"no Force Dimension device: {dhd.errorGetLastStr()}")
        dhd.enableForce(True, ID=self._id)
        sdk_max = dhd.getMaxForce(ID=self._id)
        fmax = max_force_n if max_force_n is not None else (sdk_max if sdk_max and sdk_max > 0 else 8.0)
        self._specs = Specs(name or (dhd.getSystemName(ID=self._id) or "forcedimension")[:32],
                            float(fmax), max_stiffness_n_per_m, workspace_radius_m, list(buttons),
                            rate_hz=int(round(servo_hz)))
        self._pos = [0.0, 0.0, 0.0]
        self._position, self._buttons = self._read_sdk()
        self._error: Optional[BaseException] = None
        self._stop = threading.Event()
        self._closed = False
        self._thread = threading.Thread(target=self._servo, name="forcedimension-servo", daemon=True)
        self._thread.start()

    def _read_sdk(self):
        if self._dhd.getPosition(out=self._pos, ID=self._id) == -1:
            raise IOError(f"getPosition: {self._dhd.errorGetLastStr()}")
        p = (float(self._pos[0]), float(self._pos[1]), float(self._pos[2]))
        return p, int(self._dhd.getButtonMask(ID=self._id))

    def _servo(self) -> None:
        next_t = time.perf_counter()
        try:
            while not self._stop.is_set():
                p, b = self._read_sdk()
                with self._lock:
                    self._position, self._buttons = p, b
                    f = self._servo_force(p)
                self._dhd.setForce([f[0], f[1], f[2]], ID=self._id)
                next_t += self._servo_s
                delay = next_t - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                else:
                    next_t = time.perf_counter()  # late: no burst of catch-up periods
        except BaseException as e:  # reported by the next read()
            self._error = e

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        if self._error is not None:
            raise IOError(f"Force Dimension device: {self._error!r}") from self._error
        with self._lock:
            return self._position, self._buttons

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        with self._lock:
            self._side = None
            self._reply, self._reply_at = None, 0.0
        self._stop.set()
        self._thread.join(timeout=1.0)
        self._dhd.setForce([0.0, 0.0, 0.0], ID=self._id)
        self._dhd.close(ID=self._id)


class HaplyInverse3Device(_ServoRendering):
    """A Haply Inverse3 through ``HaplyHardwareAPI`` (Haply's Python API, over
    USB serial), optionally with a VerseGrip handle on its own serial port for
    buttons.

    The Inverse3 is force in, position out: ``Inverse3.end_effector_force(f)``
    sends a force (N, 3 values) and returns the cursor's position (m) and
    velocity (m/s), and the device keeps that force until the next command. So
    this adapter runs its own servo thread that makes exactly one
    ``end_effector_force`` call per servo period (``servo_hz``), sending the
    force the session's :class:`DeviceSide` renders (protocol 2 by default,
    ``protocol=1`` for ``F0 − K (p − p0)``) at the position the previous call
    returned (zero once answers are older than ``hold_s``); :meth:`read` returns
    the newest position. Outside a session, :meth:`render` hands over an answer
    rendered as ``F0 − K (p − p0)``. :meth:`close` stops the thread and sends a
    zero force (without it the device would keep the last one).

    Frame: the API reports the cursor in the Inverse3's base frame (right
    handed, +x right, +y forward, +z up, origin on the mounting plate), where
    the reachable workspace lies off to one side of the base. The bridge wants
    a frame centred on the workspace, so this adapter subtracts
    ``workspace_centre_m`` (base frame, m) from every position; forces need no
    change (a pure translation). The default centre depends on ``handedness``
    ("right" or "left": the arm is mirrored in x) and is an estimate from
    Haply's own examples, not a Haply figure: measure yours with
    :attr:`raw_position_m` while holding the cursor in the middle of its reach.

    Buttons: with ``handle_port`` (a serial port, or "auto" for the first of
    ``HaplyHardwareAPI.detect_handles()``) a second thread polls
    ``Handle.GetVersegripStatus()["buttons"]``; bit i is ``buttons[i]`` and
    higher bits are dropped (the simulator rejects bits the hello did not
    name). Haply advises against serving a handle and an Inverse3 from one
    thread. Without a handle the device announces no buttons.
    """

    #: Centre of reach in the base frame (m): the ``center_workspace`` of Haply's Python sample
    #: 10_follow_trajectory.py, mirrored in x for a left-handed device. An estimate, not a
    #: published figure (Haply's samples use several centres).
    DEFAULT_CENTRE_M = {"right": (0.03, -0.13, 0.20), "left": (-0.03, -0.13, 0.20)}

    def __init__(self, port: Optional[str] = None, *, handle_port: Optional[str] = None,
                 handedness: str = "right", workspace_centre_m: Optional[Sequence[float]] = None,
                 hold_s: float = 0.01, max_force_n: float = 3.0, max_stiffness_n_per_m: float = 1000.0,
                 workspace_radius_m: float = 0.10, servo_hz: int = 1000,
                 buttons: Sequence[str] = ("a", "b", "c"), name: str = "inverse3",
                 protocol: int = VERSION_2):
        if handedness not in self.DEFAULT_CENTRE_M:
            raise ValueError(f'handedness = "{handedness}": expected "right" or "left"')
        centre = self.DEFAULT_CENTRE_M[handedness] if workspace_centre_m is None else workspace_centre_m
        centre = tuple(float(v) for v in centre)
        if len(centre) != 3 or not all(math.isfinite(v) for v in centre):
            raise ValueError(f"workspace_centre_m: expected 3 finite numbers in metres, got {centre}")
        self._init_rendering(protocol, hold_s, servo_hz)
        try:
            import HaplyHardwareAPI as api
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "HaplyInverse3Device needs Haply's Python API: "
                "pip install HaplyHardwareAPI (see docs/device-bridge.md)"
            ) from e
        self._api = api
        self.handedness = handedness
        self.centre_m: Tuple[float, float, float] = centre  # type: ignore[assignment]
        self._period = 1.0 / servo_hz
        self._stop = threading.Event()
        self._error: Optional[BaseException] = None
        self._buttons = 0
        self._closed = False
        self._servo_thread: Optional[threading.Thread] = None
        self._handle_thread: Optional[threading.Thread] = None
        self._handle = self._handle_stream = None

        if port is None:
            found = list(api.detect_inverse3s())
            if not found:
                raise ConnectionError(
                    "no Haply Inverse3 found (HaplyHardwareAPI.detect_inverse3s() is empty): is it "
                    "plugged in and powered, and may this user open serial ports (Linux: group dialout)?")
            port = found[0]
        if handle_port == "auto":
            handles = list(api.detect_handles())
            if not handles:
                raise ConnectionError("no Haply handle found (HaplyHardwareAPI.detect_handles() is empty)")
            handle_port = handles[0]
        self.port, self.handle_port = port, handle_port
        # The Inverse3 object keeps a pointer to its stream: keep the stream alive as long.
        self._stream = api.SerialStream(port)
        self._inverse3 = api.Inverse3(self._stream)
        self.device_info = dict(self._inverse3.device_wakeup_dict())
        position, _velocity = self._inverse3.end_effector_force([0.0, 0.0, 0.0])
        self._raw = (float(position[0]), float(position[1]), float(position[2]))

        names: List[str] = []
        if handle_port is not None:
            self._handle_stream = api.SerialStream(handle_port)
            self._handle = api.Handle(self._handle_stream)
            names = [str(b) for b in buttons][:32]
        self._button_mask = (1 << len(names)) - 1
        self._specs = Specs(name, float(max_force_n), float(max_stiffness_n_per_m),
                            float(workspace_radius_m), names, rate_hz=int(round(servo_hz)))

        self._servo_thread = threading.Thread(target=self._servo, name="inverse3-servo", daemon=True)
        self._servo_thread.start()
        if self._handle is not None:
            self._handle_thread = threading.Thread(target=self._poll_handle, name="inverse3-handle", daemon=True)
            self._handle_thread.start()

    def _servo(self) -> None:
        """One ``end_effector_force`` call per servo period: the force rendered at the
        position the previous call returned."""
        c = self.centre_m
        next_t = time.perf_counter()
        try:
            while not self._stop.is_set():
                with self._lock:
                    raw = self._raw
                    p = (raw[0] - c[0], raw[1] - c[1], raw[2] - c[2])
                    f = self._servo_force(p)
                position, _velocity = self._inverse3.end_effector_force([f[0], f[1], f[2]])
                with self._lock:
                    self._raw = (float(position[0]), float(position[1]), float(position[2]))
                next_t += self._period
                delay = next_t - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                else:
                    next_t = time.perf_counter()  # late: no burst of catch-up commands
        except BaseException as e:  # reported by the next read()
            self._error = e

    def _poll_handle(self) -> None:
        try:
            while not self._stop.is_set():
                status = self._handle.GetVersegripStatus()
                b = int(status.get("buttons", 0)) & self._button_mask
                with self._lock:
                    self._buttons = b
                time.sleep(0.001)
        except BaseException as e:
            self._error = e

    @property
    def raw_position_m(self) -> Tuple[float, float, float]:
        """The newest cursor position in the Inverse3's base frame (m), before
        the centre is subtracted: hold the cursor in the middle of its reach and
        read this to find your ``workspace_centre_m``."""
        with self._lock:
            return self._raw

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        if self._error is not None:
            raise IOError(f"Haply Inverse3 on {self.port}: {self._error!r}") from self._error
        c = self.centre_m
        with self._lock:
            raw, b = self._raw, self._buttons
        return (raw[0] - c[0], raw[1] - c[1], raw[2] - c[2]), b

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        with self._lock:
            self._side = None
            self._reply, self._reply_at = None, 0.0
        self._stop.set()
        for t in (self._servo_thread, self._handle_thread):
            if t is not None:
                t.join(timeout=6.0)  # a call in progress ends within the API's 5 s serial timeout
        try:
            # The device holds the last force it was sent: send zero from here, after the servo stopped.
            self._inverse3.end_effector_force([0.0, 0.0, 0.0])
        finally:
            self._handle = self._handle_stream = None
