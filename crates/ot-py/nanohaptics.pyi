"""Haptic manipulation at the nanoscale: optical-trap dynamics and the nano world.

SI units throughout: J, m, kg, s, N, Pa·s, K. Bad arguments raise ValueError
naming the argument and its allowed range.
"""

import os
from types import ModuleType
from typing import Any, Callable, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
F64Array = npt.NDArray[np.float64]

Method = Literal[
    "adaptive", "dop853", "dopri5", "paper-rk4", "rk4", "rk8",
    "symplectic", "verlet", "yoshida4", "yoshida6",
]
ThermalScheme = Literal["auto", "baoab", "overdamped"]

DEFAULT_RTOL: float
"""Default relative tolerance of the adaptive methods."""
PAPER_DT: float
"""The paper's haptic tick Δt = 1e-6 s."""
PAPER_V0_MOVING: Tuple[float, float]
"""The paper's moving start v0 = (0.1, 0.1) m/s (100 nm/µs)."""

class GaussianTrap:
    """A particle in the elliptic Gaussian well
    P = -depth·exp(-ln2·(x²/a² + y²/b² [+ z²/c²])).

    depth (J) > 0; waist = (a, b) (m); mass (kg) or None for an overdamped
    particle (needs drag); axial_waist c (m) makes it 3D; radius (m) and
    viscosity (Pa·s) switch Stokes drag γ = 6πηr on; temperature (K) switches
    thermal noise on for brownian(); external_force (N) per axis.
    """

    def __init__(
        self,
        depth: float,
        waist: Tuple[float, float] | ArrayLike,
        mass: Optional[float],
        *,
        axial_waist: Optional[float] = None,
        radius: Optional[float] = None,
        viscosity: Optional[float] = None,
        temperature: Optional[float] = None,
        external_force: Optional[ArrayLike] = None,
    ) -> None: ...
    def displacement(
        self,
        offsets: ArrayLike,
        velocity: ArrayLike,
        dt: float,
        *,
        method: Method = "adaptive",
        rtol: Optional[float] = None,
        substeps: Optional[int] = None,
    ) -> F64Array:
        """(N, D) displacements (m) after dt (s) for (N, D) trap-centre offsets
        relative to the particle (m); velocity (m/s) is (D,) or (N, D).
        The GIL is released during the batch."""
    def flow_jacobian(
        self,
        offsets: ArrayLike,
        velocity: ArrayLike,
        dt: float,
        *,
        method: Method = "adaptive",
        rtol: Optional[float] = None,
        substeps: Optional[int] = None,
    ) -> dict:
        """{"displacement" (N, D) m, "velocity" (N, D) m/s, "d_offset" (N, D, D),
        "d_velocity" (N, D, D) s, "dv_offset" (N, D, D) 1/s} from the
        variational equations; [n, i, j] = ∂(row i)/∂(column j)."""
    def trajectory(
        self,
        offset: ArrayLike,
        velocity: ArrayLike,
        duration: float,
        samples: int,
        *,
        method: Method = "adaptive",
        rtol: Optional[float] = None,
        substeps: Optional[int] = None,
    ) -> Tuple[F64Array, F64Array, F64Array]:
        """(t (S,) s, positions (S, D) m relative to the trap centre,
        velocities (S, D) m/s) at S evenly spaced times, t[0] = 0,
        t[-1] = duration."""
    def brownian(
        self,
        duration: float,
        sample_rate: float,
        *,
        seed: int,
        method: ThermalScheme = "auto",
        substeps: Optional[int] = None,
        start: Optional[ArrayLike] = None,
    ) -> F64Array:
        """(round(duration·sample_rate), D) thermal positions (m) relative to
        the trap centre at the origin; needs radius, viscosity, temperature."""
    def force(self, positions: ArrayLike) -> F64Array:
        """Force (N) at positions relative to the trap centre (m): (D,) -> (D,),
        (N, D) -> (N, D)."""
    def potential(self, positions: ArrayLike) -> Union[float, F64Array]:
        """Potential energy (J): (D,) -> float, (N, D) -> (N,)."""
    @property
    def dimension(self) -> int:
        """2, or 3 with an axial waist."""
    @property
    def depth(self) -> float:
        """Well depth P0 (J)."""
    @property
    def waist(self) -> Tuple[float, float]:
        """Lateral waists (a, b) (m)."""
    @property
    def axial_waist(self) -> Optional[float]:
        """Axial waist c (m) or None."""
    @property
    def mass(self) -> Optional[float]:
        """Particle mass (kg) or None (overdamped)."""
    @property
    def radius(self) -> Optional[float]:
        """Particle radius (m) or None."""
    @property
    def viscosity(self) -> Optional[float]:
        """Fluid viscosity (Pa·s) or None."""
    @property
    def temperature(self) -> Optional[float]:
        """Temperature (K) or None."""
    @property
    def drag(self) -> Optional[float]:
        """Stokes drag γ = 6πηr (kg/s) or None."""
    @property
    def stiffness(self) -> Tuple[float, ...]:
        """Small-oscillation stiffness per axis 2·ln2·P0/w_i² (N/m)."""
    @property
    def external_force(self) -> Tuple[float, ...]:
        """Constant external force per axis (N)."""

def paper_trap() -> GaussianTrap:
    """The optical-tweezers paper's trap: depth 1e-15 J, waists (600e-9,
    300e-9) m, mass 1e-15 kg, no drag, no noise."""

# ---------------------------------------------------------------- envelope (ot-envelope)

def solve_trap(
    trap: GaussianTrap,
    velocity: ArrayLike,
    dt: float,
    target: ArrayLike,
    *,
    method: Method = "rk4",
    rtol: Optional[float] = None,
    substeps: Optional[int] = None,
) -> F64Array:
    """(M, 2) trap offsets (m, trap centre relative to the particle) that move a
    particle of velocity (2,) m/s by target (2,) m in dt s; (0, 2) if none in the
    search region (3 waists around the free drift). Default tick: rk4 x 8 seeds
    Newton; every offset is polished under the true dynamics (within 0.01 nm)."""

def working_envelope(
    trap: GaussianTrap,
    velocity: ArrayLike,
    dt: float,
    *,
    tol: Optional[float] = None,
    method: Method = "rk4",
    rtol: Optional[float] = None,
    substeps: Optional[int] = None,
) -> F64Array:
    """(K, 2) polygon of reachable displacements (m), counter-clockwise, first
    vertex not repeated; tol (m) default 0.5e-9."""

def polygon_radius(polygon: ArrayLike, centre: ArrayLike, angles: ArrayLike) -> F64Array:
    """(M,) distance from centre (2,) to the farthest crossing of the ray at each angle (rad)
    with the closed polygon (K, 2); 0 where a ray meets none. Releases the GIL."""

def clip_command(
    trap: GaussianTrap,
    velocity: ArrayLike,
    dt: float,
    command: ArrayLike,
    *,
    mode: Literal["radial", "nearest"] = "radial",
    tol: Optional[float] = None,
    method: Method = "rk4",
    rtol: Optional[float] = None,
    substeps: Optional[int] = None,
) -> Tuple[F64Array, F64Array]:
    """(allowed (2,), excess (2,)) in m; excess = command - allowed."""

def working_envelope_3d(
    trap: GaussianTrap,
    velocity: ArrayLike,
    dt: float,
    *,
    level: Optional[int] = None,
    reach: float = 3.0,
    step: float = 0.1,
    method: Method = "rk4",
    rtol: Optional[float] = None,
    substeps: Optional[int] = None,
) -> Tuple[F64Array, npt.NDArray[np.int64]]:
    """(vertices (V, 3) m, triangles (T, 3) int64) closed outward mesh of the
    3D working envelope; level 0..6 (default 4), reach and step in waists."""

# ---------------------------------------------------------------- nano world

NanoParams = Union[Literal["game", "physical"], dict, None]
# serde's form of nanoworld's Member and Target, as in a recording's event detail.
Member = Union[Literal["tip"], Dict[Literal["atom"], int]]
Target = Union[Literal["substrate_plane"], Dict[Literal["substrate_atom", "atom"], int]]

class NanoWorld:
    """The nano world of the teaching game: AFM tip (the cursor) over fixed
    substrate atoms, movable atoms, van der Waals attraction, snap-to-contact,
    adhesion, tenfold pull-off, atom transfer, a house blueprint.

    start: (3,) initial cursor position (m). params: "game" (default),
    "physical", or a dict with the scene-table layout (see nano_params();
    no "max_force_n": the limit comes from the device). device: None (the
    Falcon as the presets map it: 8 nN, 20 N/m game; 80 nN, 30 N/m physical)
    or {"max_force_n", "max_stiffness_n_per_m"} in world units.
    """

    def __init__(self, start: ArrayLike, *, params: NanoParams = None, device: Optional[dict] = None) -> None: ...
    @property
    def device(self) -> dict:
        """The device limits in world units: {"max_force_n", "max_stiffness_n_per_m"}."""
    def step(self, position: ArrayLike, dt_s: float = 1e-3) -> dict:
        """One tick: {"force": (3,) N, "unlimited_force": (3,) N,
        "saturated": bool, "events": list[dict]} (events in serde's form of
        nanoworld::Event, as a recording's event detail)."""
    def run(self, positions: ArrayLike, dt_s: float = 1e-3) -> dict:
        """One tick per row of (T, 3) cursor positions (m): {"force" (T, 3) N,
        "unlimited_force" (T, 3) N, "saturated" (T,) bool, "tip" (T, 3) m,
        "anchored" (T,) bool, "carried" (T,) int, "score" (T,) int,
        "events": list[(tick, dict)]}. The GIL is released; Ctrl-C stops
        the batch between chunks of 10 000 ticks."""
    def force_at(self, position: ArrayLike) -> F64Array:
        """(3,) N: the attraction the tip assembly would feel with the tip
        centre at ``position`` (3,) m, without stepping (nothing snaps)."""
    def set_params(self, params: NanoParams) -> None:
        """Run-time change (strengths, masses, gravity, ...; not the geometry)."""
    def house_script(self, step_m: float = 2e-12) -> F64Array:
        """(T, 3) cursor positions (m) of the scripted house session."""
    @property
    def params(self) -> dict:
        """The parameters in force (scene-table layout)."""
    @property
    def tip_position(self) -> F64Array:
        """(3,) tip centre (m)."""
    @property
    def cursor(self) -> F64Array:
        """(3,) last cursor position (m)."""
    @property
    def contact(self) -> Optional[dict]:
        """None when free, else {"member": Member, "target": Target,
        "pair": str, "tip_position": (3,) m, "normal": (3,)}."""
    @property
    def atoms(self) -> F64Array:
        """(M, 3) movable-atom centres (m)."""
    @property
    def carried(self) -> list[int]:
        """Indices of the atoms on the tip."""
    @property
    def atom_on_substrate(self) -> npt.NDArray[np.bool_]:
        """(M,) whether each atom is bonded to the substrate."""
    @property
    def atom_bonds(self) -> list[list[int]]:
        """Per atom, the atoms it is bonded to."""
    @property
    def substrate(self) -> F64Array:
        """(S, 3) substrate-atom centres (m)."""
    @property
    def radii(self) -> dict:
        """{"tip", "atom", "substrate"} radii (m)."""
    @property
    def laws(self) -> dict:
        """Per pair ("tip_substrate", "tip_atom", "atom_atom",
        "atom_substrate"): snap_gap_m, snap_force_n, pull_off_n,
        stiffness_n_per_m, contact_gap_m, cutoff_gap_m, floor_gap_m,
        coef_n_m2, shift_n."""
    @property
    def house(self) -> dict:
        """{"slots" (K, 3) m, "tolerance_m", "filled", "score", "complete"}."""
    @property
    def tick(self) -> int:
        """Ticks stepped so far."""
    @property
    def time(self) -> float:
        """Simulated time (s)."""

def nano_params(mode: Literal["game", "physical"] = "game") -> dict:
    """The default nano-world parameters as an editable dict."""

def force_distance_curve(
    params: NanoParams = None,
    *,
    xy_m: Optional[ArrayLike] = None,
    far_gap_m: float = 2e-9,
    near_gap_m: float = 0.0,
    steps: Optional[int] = None,
    dt_s: float = 1e-3,
    device: Optional[dict] = None,
) -> dict:
    """Approach-retract curve of the bare tip: {"approach_gap", "approach_force",
    "retract_gap", "retract_force" ((steps+1,) m and N), "snap_index",
    "pull_off_index" (int or None), "hysteresis" (J)}."""

# ---------------------------------------------------------------- brick world

Buttons = Union[None, dict, Sequence[bool]]

class BrickWorld:
    """The macro world of the teaching game: bricks under gravity (rapier),
    a cursor proxy (god-object), grab/throw/rotate, a blueprint score.

    params: None or a dict (scene-table layout; missing fields take defaults).
    device: a model name as every ``device=`` takes it, "falcon" (default,
    8 N, 3000 N/m) or "touch" (3.3 N, 400 N/m: pass a proxy_stiffness_n_per_m
    within it), or {"max_force_n", "max_stiffness_n_per_m"} (the old key
    "max_stiffness_n_m" is still accepted). An unknown name is refused as
    run_scene refuses it; "udp:..." is refused.
    Buttons (the hand's grip): None, {"hold", "turn_x", "turn_y", "turn_z"}
    (the older {"center", "rotate_x", "rotate_y", "rotate_z"} still accepted)
    or 4 bools in that order.
    """

    def __init__(self, params: Optional[dict] = None, *, device: Union[str, dict, None] = None) -> None: ...
    def add_brick(
        self,
        center_m: ArrayLike,
        rotation_deg: Optional[ArrayLike] = None,
        *,
        velocity_m_per_s: Optional[ArrayLike] = None,
        mass_kg: Optional[float] = None,
        friction: Optional[float] = None,
        restitution: Optional[float] = None,
    ) -> int:
        """Add a brick (centre m, rotation vector in degrees, initial velocity
        m/s, its own mass kg / friction / restitution); returns its id."""
    def step(self, position_m: ArrayLike, buttons: Buttons = None) -> dict:
        """One tick: {"tick", "force_n", "saturated", "spring_force_n",
        "stiffness_n_per_m", "weight_force_n", "inertia_force_n",
        "acceleration_m_per_s2", "proxy_penetration_m", "events"}."""
    def run(self, positions_m: ArrayLike, buttons: Union[Buttons, ArrayLike] = None) -> dict:
        """One tick per row of (T, 3) positions; buttons None, one set, or (T, 4).
        Per-tick arrays: force, spring_force, weight_force, inertia_force (T, 3) N,
        acceleration (T, 3) m/s², proxy, cursor (T, 3) m, buttons (T, 4) bool,
        saturated (T,), stiffness (T,) N/m, penetration (T,) m, held (T,) id or -1,
        filled (T,) slots; brick_position_m (T, B, 3) m, brick_orientation_xyzw
        (T, B, 4), brick_count (T,); events list[(tick, dict)]. GIL released;
        Ctrl-C stops the batch between chunks of 10 000 ticks."""
    def run_wall_script(self, start_m: ArrayLike, max_ticks: int = 40000, settle_ticks: int = 1000) -> dict:
        """Run the scripted wall builder; same arrays as run()."""
    def brick(self, id: int) -> dict:
        """One brick: position_m, orientation_xyzw, half_extents_m, velocity_m_per_s, held, sleeping."""
    @property
    def bricks(self) -> dict:
        """Same keys as brick(): id (B,), position_m (B, 3) m, orientation_xyzw
        (B, 4), half_extents_m (B, 3) m, velocity_m_per_s (B, 3) m/s, held (B,),
        sleeping (B,)."""
    @property
    def proxy_position(self) -> F64Array: ...
    @property
    def cursor_position(self) -> F64Array: ...
    @property
    def held_brick(self) -> Optional[int]: ...
    @property
    def touching(self) -> list[Union[str, dict]]:
        """What the cursor touches, as the events name it: "ground", {"brick": id},
        {"obstacle": k}."""
    @property
    def slots(self) -> list[dict]: ...
    @property
    def score(self) -> dict:
        """{"filled": int, "total": int}."""
    @property
    def obstacles(self) -> list[dict]: ...
    @property
    def awake_brick_count(self) -> int:
        """Bricks the physics engine simulates now (a property, not a call)."""
    @property
    def params(self) -> dict: ...
    @property
    def device(self) -> dict: ...
    @property
    def tick(self) -> int: ...
    @property
    def time(self) -> float: ...
    def set_gravity(self, g_m_per_s2: float) -> None: ...
    def set_restitution(self, e: float) -> None: ...
    def set_friction(self, mu: float) -> None: ...
    def set_inertia(self, mode: Union[bool, Literal["coupling", "paper", "off"]]) -> None:
        """How a carried brick's inertia is felt: "coupling" (True), "paper" or "off" (False)."""
    def set_brick_mass(self, kg: float) -> None: ...

# ---------------------------------------------------------------- haptic loop sessions

PathLike = Union[str, "os.PathLike[str]"]

def run_scene(
    scene: PathLike,
    *,
    script: Optional[PathLike] = None,
    seconds: Optional[float] = None,
    operator: Union[Literal["hand", "rigid"], str, dict, None] = None,
    device: Union[Literal["falcon", "touch"], str, None] = None,
    out: Optional[PathLike] = None,
    wait_s: float = 120.0,
    overrides: Optional[Mapping[str, Any]] = None,
    rt_priority: Optional[int] = 50,
) -> dict:
    """Run a scene in batch mode with a script, or in real time against a
    device in another process (device="udp:HOST:PORT", see nanohaptics.bridge;
    wait_s: how long to wait for its hello). Per-tick arrays (the columns of
    docs/recording-format.md; integers int64, flags bool, status uint8): tick,
    time_s, device_position_m (T, 3), device_buttons, device_seq,
    device_age_ticks, deadline_missed, cursor_m (T, 3), state (T, F) with
    state_fields, world_force_n (T, 3), device_force_n (T, 3),
    device_stiffness_n_per_m (T, 3, 3), engagement, watchdog, status,
    compute_ns, start_late_ns, events [(tick, name, detail)], rate_hz, stats
    (tick timing, "link" counters, "end", per-sink "sinks" timing). Optionally records to `out`.
    `scene` may also be a dict of resolve_scene; `overrides` changes fields by
    dotted name, validated like a scene file (see resolve_scene). A real-time
    session's tick thread asks for SCHED_FIFO at `rt_priority` (1–99; None:
    ask for nothing), says once on stderr with the fix when refused, and
    reports what it got in stats["realtime"] and its wake-up latency (ns) in
    stats["wakeup"]."""

def resolve_scene(
    scene: Union[PathLike, dict],
    *,
    script: Optional[PathLike] = None,
    overrides: Optional[Mapping[str, Any]] = None,
    device: Optional[Literal["falcon", "touch"]] = None,
) -> dict:
    """A scene with its files read and `overrides` (dotted field name → value,
    e.g. {"optical_tweezers.stiffness_n_per_m": 0.4, "loop.rate_hz": 2000};
    "operator.*" names change the simulated hand) applied and validated:
    {"name", "kind", "device", "scene_toml", "script_toml"}, plain data that
    pickles. ValueError names an unknown field (listing the valid names), a
    wrong type, or a value out of range (the scene file's own errors)."""

def read_recording(path: PathLike, *, salvage: bool = False) -> dict:
    """An MCAP recording as the arrays of run_scene (without stats)."""

def render_audio(
    path: PathLike,
    *,
    proximity: bool = False,
    sample_rate: int = 44100,
    out: Optional[PathLike] = None,
) -> Tuple[npt.NDArray[np.float32], int]:
    """The sound of a recorded session: (float32 mono samples, sample rate);
    impacts by impulse, snap and pull-off clicks, and with proximity=True a
    tone rising as the cursor nears the nearest object. out: also a WAV file."""

class Session:
    """The haptic loop stepped one tick at a time from Python, with the same
    recorder and per-tick arrays as every session (replays bit for bit).

    device: None (the scene's), "falcon" or "touch"; out: MCAP path or None.
    """

    def __init__(
        self,
        scene: PathLike,
        *,
        device: Optional[Literal["falcon", "touch"]] = None,
        out: Optional[PathLike] = None,
        arrays: bool = True,
    ) -> None: ...
    def tick(self, position: ArrayLike, buttons: Union[int, Sequence[str], None] = None) -> F64Array:
        """One tick with the device at `position` (3,) m; returns the force (3,) N."""
    def switch(self, name: str, value: Union[float, bool]) -> None:
        """Set a run-time switch of the scene before the next tick (recorded)."""
    @property
    def stiffness(self) -> F64Array:
        """Local stiffness sent with the last force, (3, 3) N/m."""
    @property
    def status(self) -> int:
        """Status bits of the last tick (1 clamped, 2 input invalid, ..., 32 watchdog, 64 passivity, 128 rate limit)."""
    @property
    def events(self) -> list:
        """Events of the last tick: [(name, detail)]."""
    @property
    def cursor(self) -> F64Array:
        """Cursor of the last tick, (3,) m, world frame."""
    @property
    def state(self) -> dict:
        """The scene's state fields after the last tick."""
    @property
    def tick_index(self) -> int:
        """Index of the next tick."""
    @property
    def rate_hz(self) -> int:
        """Tick rate, Hz."""
    @property
    def device(self) -> dict:
        """The device's specifications (name, max_force_n, max_stiffness_n_per_m,
        workspace_radius_m, buttons)."""
    def close(self) -> dict:
        """End the session; the per-tick arrays of run_scene with stats."""

# ---------------------------------------------------------------- a device and a hand in the loop

class DeviceModel:
    """A haptic device held by a hand: moving mass, viscous friction, encoder counts, force
    resolution, the force held over each tick at the device's servo rate, and a hand that
    follows the intended path as a spring-damper (docs/devices.md)."""

    def __init__(
        self,
        model: Literal["falcon", "touch", "delta3", "inverse3"] = "falcon",
        *,
        grip: str = "loose",
        counts: bool = True,
        start: Optional[ArrayLike] = None,
    ) -> None: ...
    def advance(
        self,
        dt_s: float,
        force: ArrayLike,
        intent_position: ArrayLike,
        intent_velocity: Optional[ArrayLike] = None,
        stiffness: Optional[ArrayLike] = None,
    ) -> None:
        """Hold `force` (3,) N (and the local `stiffness` (3, 3) N/m) for dt_s s while the
        hand pulls toward `intent_position` (3,) m moving at `intent_velocity` (3,) m/s."""
    @property
    def reading(self) -> F64Array:
        """What the encoders report, (3,) m."""
    @property
    def position(self) -> F64Array:
        """True end-effector position, (3,) m."""
    @property
    def velocity(self) -> F64Array:
        """True end-effector velocity, (3,) m/s."""
    @property
    def energy_to_hand_j(self) -> float:
        """Work the motors did on the hand, J."""
    @property
    def time_s(self) -> float:
        """Time advanced so far, s."""
    @property
    def specs(self) -> dict:
        """The device's figures and the grip's."""

def check_closed_loop(
    scene: Union[PathLike, dict],
    *,
    script: Optional[PathLike] = None,
    model: Literal["falcon", "touch", "delta3", "inverse3"] = "falcon",
    grip: str = "loose",
    counts: bool = True,
    seconds: Optional[float] = None,
) -> dict:
    """Play a scene's script through a modelled device held by a hand; "stable" and the
    figures behind it (undeclared_jumps, hf_fraction, min_observer_j, ...)."""

def closed_loop(
    session: Session,
    device: DeviceModel,
    path: Callable[[float], Tuple[ArrayLike, ArrayLike]],
    seconds: float,
    buttons: Optional[Callable[[float], Any]] = None,
) -> dict:
    """Drive `session` with `device` held by a hand following path(t) -> (position, velocity);
    per-tick arrays time_s, reading_m, position_m, force_n and energy_to_hand_j."""

bridge: ModuleType
"""The device bridge: protocol client (BridgeClient, run) and adapters for a
Touch (pyOpenHaptics) and Force Dimension devices / the Falcon
(forcedimension_core). See docs/device-bridge.md."""

# ---------------------------------------------------------------- parameter studies

def sweep(
    scene: Union[PathLike, dict, Callable[[dict, int], Mapping[str, Any]]],
    runs: Sequence[Mapping[str, Any]],
    *,
    seed: int = 0,
    executor: Any = None,
    arrays: bool = False,
    progress: bool = True,
    workers: Optional[int] = None,
    script: Optional[PathLike] = None,
    seconds: Optional[float] = None,
    operator: Union[Literal["hand", "rigid"], str, dict, None] = None,
    device: Optional[Literal["falcon", "touch"]] = None,
    metrics: Optional[Callable[[dict], Mapping[str, Any]]] = None,
    record_dir: Optional[PathLike] = None,
    chunksize: Optional[int] = None,
) -> Any:
    """Run a scene (or fn(run, seed) -> dict) once per override dict of `runs`
    on a thread pool (GIL released), any concurrent.futures executor or a Dask
    Client; run i gets seed run_seed(seed, i). Returns a pandas DataFrame, one
    row per run: run, seed, the overrides, summary metrics (units in the
    names), and with arrays=True the per-tick arrays; chunksize: runs per
    task on an executor (None: chosen from the first run's measured time and
    the task's cost; the results do not depend on it). Ctrl-C returns the
    runs that finished (df.attrs["interrupted"]). See docs/sweeps.md."""

def grid(axes: Mapping[str, Sequence[Any]]) -> List[Dict[str, Any]]:
    """Every combination of the axes (dotted name → values), last axis fastest,
    as a list of override dicts for sweep."""

def run_seed(seed: int, index: int) -> int:
    """Seed of run `index` of a sweep with master seed `seed` (numpy
    SeedSequence(seed, spawn_key=(index,)), 0 ..= 2**64 - 1)."""

sweeps: ModuleType
"""Parameter studies: sweep, grid, run_seed, scene_metrics. See docs/sweeps.md."""
