"""Battery voltage of the Spark V: a simple documented discharge model.

The Spark V runs on a 9.6 V NiMH pack (8 cells). We model, per robot:

* current draw ``I = I_idle + sum_wheels |tau| / k_t``: ``tau`` is the actuator torque
  (N m) MuJoCo applies at the wheel and ``k_t`` the torque per ampere at the wheel
  (gearbox included), chosen so that the actuator's torque limit (0.12 N m) draws the
  600 mA the L293D driver supplies per motor (Nagavarapu et al., Sec. 5);
* charge used ``Q += I dt`` (A s);
* open-circuit voltage falling linearly from ``v_full`` to ``v_empty`` as ``Q`` reaches
  the capacity, and terminal voltage ``V = V_oc - R_internal * I``.

The reading is for completeness of the sensor suite (the paper lists a battery voltage
sensor); no algorithm in the papers uses it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Battery:
    """Vectorised battery state for ``n`` robots (volts, amperes, seconds)."""

    n: int
    v_full: float = 10.4
    v_empty: float = 8.8
    capacity_ah: float = 2.1
    internal_resistance_ohm: float = 0.25
    idle_current_a: float = 0.05
    torque_per_amp_nm: float = 0.2
    charge_used_as: np.ndarray = field(init=False)
    current_a: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.charge_used_as = np.zeros(self.n)
        self.current_a = np.full(self.n, self.idle_current_a)

    def update(self, wheel_torque_nm: np.ndarray, dt_s: float) -> None:
        """Draw current for ``dt_s`` seconds given per-wheel torques, shape (n, 2)."""
        self.current_a = self.idle_current_a + np.abs(wheel_torque_nm).sum(axis=1) / (
            self.torque_per_amp_nm
        )
        self.charge_used_as += self.current_a * dt_s

    @property
    def voltage_v(self) -> np.ndarray:
        """Terminal voltage (V), shape (n,)."""
        soc = np.clip(1.0 - self.charge_used_as / (self.capacity_ah * 3600.0), 0.0, 1.0)
        v_oc = self.v_empty + (self.v_full - self.v_empty) * soc
        return v_oc - self.internal_resistance_ohm * self.current_a
