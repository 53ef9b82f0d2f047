"""Haptic manipulation at the nanoscale: optical-trap dynamics and the nano world.

SI units throughout: J, m, kg, s, N, Pa·s, K. Bad arguments raise ValueError
naming the argument and its allowed range.
"""

from typing import Literal, Optional, Sequence, Tuple, Union

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
