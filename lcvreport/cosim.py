"""The co-simulation engine behind the FMUs (SPEC section 5), in SI units.

:class:`LCVEngine` holds one vehicle, its state ``z = [x, psi1, Y1]`` (thesis units
inside) and a cache of exact zero-order-hold discretizations keyed by (speed, step
size).  The pythonfmu slave in ``fmu_src/LCV.py`` only maps FMI variables onto it;
the native FMU (``lcvreport.native``) is generated from the same coefficients.

Interface (names, units, defaults) is fixed by SPEC section 5 and listed in
:data:`PARAMETERS`, :data:`INPUTS` and :data:`OUTPUTS`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .linear import LRUCache, augmented_state_matrix, discretize, rear_end_global, unit_lengths
from .model import system_coefficients
from .presets import PRESETS, load_preset
from .units import M_PER_IN, N_PER_LBF, NM_PER_LBF_IN

#: axles with P/T inputs, thesis numbering (unit, axle); a preset may lack some
FMU_AXLES = ("11", "12", "13", "21", "31", "41", "51", "61")
#: joint letters of the articulation angle outputs
JOINTS = ("A", "B", "C", "D", "E")
#: default forward speed [m/s] (50 mph = 22.352 m/s exactly)
U_START = 22.352
#: default lowest speed the model is run at [m/s] (5 mph = 2.2352 m/s exactly)
U_MIN_DEFAULT = 2.2352
#: a step this large or larger is refused [s] (one day: protects the exponential)
H_MAX = 86400.0


@dataclass(frozen=True)
class Variable:
    """One FMU variable: name, SI unit (FMI unit name), start value, description."""

    name: str
    unit: str
    start: float | str
    description: str


PARAMETERS = (
    Variable("preset", "", "aucnat", "Vehicle preset: " + ", ".join(PRESETS)),
    Variable("tire_scale", "1", 1.0, "Factor on every tire coefficient CF, CM, CS (chapter V), > 0"),
    Variable("u_min", "m/s", U_MIN_DEFAULT,
             "Lowest forward speed the linear model is run at; a lower input u is clamped to it, > 0"),
)
INPUTS = (
    (Variable("u", "m/s", U_START, "Forward speed of every unit (held over each communication step)"),
     Variable("delta", "rad", 0.0, "Steer angle of the tractor steer axle 11, positive nose-right (toward +y)"))
    + tuple(Variable(f"P{a}", "N", 0.0, f"Residual lateral force (conicity, ply steer) of axle {a} "
                     f"(axle {a[1]} of unit {a[0]}), along +y (curb side)") for a in FMU_AXLES)
    + tuple(Variable(f"T{a}", "N.m", 0.0, f"Residual aligning moment of axle {a} "
                     f"(axle {a[1]} of unit {a[0]}), about +z (down), positive nose-right") for a in FMU_AXLES)
)
OUTPUTS = (
    (Variable("v1", "m/s", 0.0, "Tractor lateral velocity at the CG, +y"),)
    + tuple(Variable(f"r{i}", "rad/s", 0.0, f"Yaw rate of unit {i} (1 tractor, 2 trailer 1, 3 dolly 1, "
                     "4 trailer 2, 5 dolly 2, 6 trailer 3), nose-right positive; 0 if the preset lacks the unit")
            for i in range(1, 7))
    + tuple(Variable(f"theta{j}", "rad", 0.0, f"Articulation angle at joint {j} (heading of the unit ahead minus "
                     "the unit behind); 0 if the preset lacks the joint") for j in JOINTS)
    + tuple(Variable(f"y{k}", "m", 0.0, f"Lateral displacement of the rear end of unit {k} relative to the tractor "
                     "axis (eq. 4.42-4.46); 0 if the preset lacks the unit") for k in range(2, 7))
    + (Variable("psi1", "rad", 0.0, "Tractor heading (yaw angle) from the start, nose-right positive"),
       Variable("Y1", "m", 0.0, "Global lateral position of the tractor CG from the start, +y"),
       Variable("Y_rear", "m", 0.0, "Global lateral position of the rear end of the last unit from the start, +y"),
       Variable("max_real_eig", "1/s", 0.0, "Largest real part of the eigenvalues at the current (clamped) "
                "speed: negative = stable"))
)
INPUT_NAMES = tuple(v.name for v in INPUTS)
OUTPUT_NAMES = tuple(v.name for v in OUTPUTS)


class CosimError(ValueError):
    """A bad parameter or input; ``variable`` names it."""

    def __init__(self, variable: str, message: str):
        super().__init__(message)
        self.variable = variable


def validate_parameters(preset: str, tire_scale: float, u_min: float) -> None:
    """Raise :class:`CosimError` naming the first bad parameter and its valid range."""
    if preset not in PRESETS:
        raise CosimError("preset", f"preset: unknown preset {preset!r}; valid: {', '.join(PRESETS)}")
    if not isinstance(tire_scale, (int, float)) or not math.isfinite(tire_scale) or tire_scale <= 0:
        raise CosimError("tire_scale", f"tire_scale must be finite and > 0, got {tire_scale!r}")
    if not isinstance(u_min, (int, float)) or not math.isfinite(u_min) or u_min <= 0:
        raise CosimError("u_min", f"u_min must be finite and > 0 [m/s], got {u_min!r}")


def input_matrix_si(train, tire_scale: float = 1.0) -> np.ndarray:
    """Generalized force (thesis units) per SI input, columns in :data:`INPUT_NAMES`
    order: u (a zero column: speed enters through the matrices), delta [rad],
    P [N] x8, T [N.m] x8 (zero columns for axles the train lacks)."""
    co = system_coefficients(train)
    B = np.zeros((co.n_states, len(INPUT_NAMES)))
    B[:, 1] = co.B_delta(tire_scale)
    names = train.axle_names
    for j, a in enumerate(FMU_AXLES):
        if a in names:
            col = names.index(a)
            B[:, 2 + j] = co.B_P[:, col] / N_PER_LBF
            B[:, 2 + len(FMU_AXLES) + j] = co.B_T[:, col] / NM_PER_LBF_IN
    return B


def output_matrix(train) -> np.ndarray:
    """Map from ``z = [x, psi1, Y1]`` (thesis units) to the outputs that are linear in z,
    in :data:`OUTPUT_NAMES` order and SI (rows of y2..y6 and max_real_eig are zero),
    followed by the headings of units 2..N relative to the tractor
    (thetaA + ... + theta_k) [rad] that eq. 4.42-4.46 take the sine of."""
    n_u = train.n_units
    n = 2 * n_u
    n_out = len(OUTPUT_NAMES)
    C = np.zeros((n_out + n_u - 1, n + 2))
    C[0, 0] = M_PER_IN                                   # v1
    for i in range(n_u):
        C[1 + i, 1 + i] = 1.0                            # r_i
    for k in range(n_u - 1):
        C[7 + k, 1 + n_u + k] = 1.0                      # theta
        C[n_out + k, 1 + n_u:2 + n_u + k] = 1.0          # thetaA + ... + theta_k
    C[17, n] = 1.0                                       # psi1
    C[18, n + 1] = M_PER_IN                              # Y1
    for j in range(n + 2):                               # Y_rear is linear: apply it to unit vectors
        e = np.zeros(n + 2)
        e[j] = 1.0
        C[19, j] = float(rear_end_global(train, e[n], e[n + 1], e[1 + n_u:n])) * M_PER_IN
    return C


class LCVEngine:
    """Exact zero-order-hold stepping of one vehicle, SI interface.

    Parameters
    ----------
    preset : str
        One of :data:`lcvreport.presets.PRESETS`.
    tire_scale : float
        Factor on every tire coefficient [-], > 0.
    u_min : float
        Lowest speed the model is run at [m/s], > 0.
    cache_size : int
        Number of (speed, step) discretizations kept.

    Raises
    ------
    CosimError
        For a bad parameter (the message names it).
    """

    def __init__(self, preset: str = "aucnat", tire_scale: float = 1.0, u_min: float = U_MIN_DEFAULT,
                 cache_size: int = 128):
        validate_parameters(preset, tire_scale, u_min)
        self.preset = preset
        self.tire_scale = float(tire_scale)
        self.u_min = float(u_min)
        self.train = load_preset(preset)
        self._co = system_coefficients(self.train)
        self.n_units = self.train.n_units
        self.n = 2 * self.n_units
        self._cache = LRUCache(cache_size)
        self._eig_cache = LRUCache(1024)
        self._B_si = self._input_matrix_si()
        self._C = output_matrix(self.train)
        self._L_m = (unit_lengths(self.train) * M_PER_IN).tolist()
        self.reset()

    # ------------------------------------------------------------------ set-up
    def _input_matrix_si(self) -> np.ndarray:
        """Generalized force (thesis units) per SI input, :data:`INPUT_NAMES` order."""
        return input_matrix_si(self.train, self.tire_scale)

    def reset(self) -> None:
        """Back to rest at time 0 (keeps the caches)."""
        # [z, inputs]: one matrix-vector product per step gives the new z and the outputs
        self._zw = np.zeros(self.n + 2 + len(INPUT_NAMES))
        self._vals = None
        self.time = 0.0
        self.clamped = False
        self.last_speed_mps = U_START

    @property
    def z(self) -> np.ndarray:
        """State ``[x, psi1, Y1]`` in thesis units (in/s, rad/s, rad, rad, in)."""
        return self._zw[:self.n + 2]

    def discretization(self, u_mps: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        """(Ad, Bw) with ``z+ = Ad z + Bw w`` for the SI input vector w (cached)."""
        K = self._step_matrix(u_mps, h)
        return K[:self.n + 2, :self.n + 2], K[:self.n + 2, self.n + 2:]

    def _step_matrix(self, u_mps: float, h: float) -> np.ndarray:
        """``[[Ad, Bw], [C Ad, C Bw]]``: new state and linear outputs from ``[z, w]`` (cached)."""
        def compute():
            A, G = augmented_state_matrix(self._co, u_mps / M_PER_IN, self.tire_scale)
            Ad, Gd = discretize(A, G, h)
            K = np.hstack([Ad, Gd @ self._B_si])
            return np.vstack([K, self._C @ K])

        return self._cache.get((u_mps, h), compute)

    @property
    def cache_size(self) -> int:
        """Number of cached discretizations."""
        return len(self._cache)

    def max_real_eig(self, u_mps: float) -> float:
        """Largest real part of the eigenvalues at speed ``u_mps`` [1/s] (cached per speed)."""
        def compute():
            u = u_mps / M_PER_IN
            A = np.linalg.solve(self._co.M(u), self._co.S(u, self.tire_scale))
            return float(np.linalg.eigvals(A).real.max())

        return self._eig_cache.get(u_mps, compute)

    # ------------------------------------------------------------------ stepping
    def effective_speed(self, u_mps: float) -> tuple[float, str | None]:
        """Speed the model runs at [m/s] and a warning when ``u_mps`` is clamped."""
        if u_mps < self.u_min:
            msg = None
            if not self.clamped:
                msg = (f"u = {u_mps!r} m/s is below u_min = {self.u_min!r} m/s; the model runs at u_min "
                       "until u rises again (the linear model needs a forward speed)")
            self.clamped = True
            return self.u_min, msg
        self.clamped = False
        return u_mps, None

    def check_inputs(self, inputs: list[float] | np.ndarray) -> None:
        """Raise :class:`CosimError` naming the first non-finite input."""
        if math.isfinite(sum(inputs)):  # one sum catches nan and +-inf (inf - inf is nan)
            return
        for name, value in zip(INPUT_NAMES, inputs):
            if not math.isfinite(value):
                raise CosimError(name, f"input {name} is not finite ({value!r}); the step is refused and the "
                                       "state is unchanged")

    def step(self, h: float, inputs: list[float] | np.ndarray) -> str | None:
        """Advance by ``h`` [s] with the SI inputs (order :data:`INPUT_NAMES`) held.

        Returns
        -------
        str or None
            A warning to log (speed clamped), else None.

        Raises
        ------
        CosimError
            Non-finite input or bad step size; the state is left unchanged.
        """
        if not (math.isfinite(h) and 0 < h <= H_MAX):
            raise CosimError("communicationStepSize", f"communication step size must be in (0, {H_MAX:g}] s, got {h!r}")
        self.check_inputs(inputs)
        u, warning = self.effective_speed(inputs[0])
        K = self._step_matrix(u, h)
        zw = self._zw
        m = self.n + 2
        zw[m:] = inputs
        res = K @ zw
        zw[:m] = res[:m]
        self._vals = res[m:].tolist()
        self.time += h
        self.last_speed_mps = u
        return warning

    # ------------------------------------------------------------------ outputs
    def outputs(self, u_mps: float | None = None) -> list[float]:
        """Output values in SI, order :data:`OUTPUT_NAMES`; 0 for units the preset lacks.

        ``u_mps`` is the speed for ``max_real_eig`` (the current input, clamped to
        ``u_min``; the last speed used when it is not finite).
        """
        vals = list(self._vals) if self._vals is not None else (self._C @ self.z).tolist()
        n_out = len(OUTPUT_NAMES)
        y = 0.0
        for k, (length, heading) in enumerate(zip(self._L_m, vals[n_out:])):  # eq. 4.42-4.46
            y += length * math.sin(heading)
            vals[12 + k] = y
        out = vals[:n_out]
        out[20] = self.max_real_eig_at_input(u_mps)
        return out

    def max_real_eig_at_input(self, u_mps: float | None) -> float:
        """``max_real_eig`` for an input speed [m/s] (clamped; last speed if None or not finite)."""
        if u_mps is None or not math.isfinite(u_mps):
            return self.max_real_eig(self.last_speed_mps)
        return self.max_real_eig(max(u_mps, self.u_min))

    # ------------------------------------------------------------------ FMU state
    def get_state(self) -> dict:
        """JSON-serializable snapshot of everything that evolves (floats round-trip exactly)."""
        return {"z": self.z.tolist(), "time": self.time, "clamped": self.clamped,
                "last_speed_mps": self.last_speed_mps}

    def set_state(self, state: dict) -> None:
        """Restore a snapshot from :meth:`get_state`."""
        z = np.array(state["z"], dtype=float)
        if z.shape != self.z.shape:
            raise CosimError("FMUstate", f"FMU state of {z.size} values does not fit preset {self.preset!r}")
        self._zw[:self.n + 2] = z
        self._vals = None
        self.time = float(state["time"])
        self.clamped = bool(state["clamped"])
        self.last_speed_mps = float(state["last_speed_mps"])
