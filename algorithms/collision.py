"""The bearing-rate speed-change collision rule of Nagavarapu et al., Sec. 4.

Each robot ``R_k`` sees the bearings ``beta_kp`` of the robots ``R_p`` in its field of
view and changes only its own linear speed ``S_k``:

* Lemma 2 / eq. (17): a collision with ``R_p`` is possible only if ``d beta_kp / dt = 0``;
  we estimate the rate by a least-squares line through the last bearings and call it zero
  when ``|rate| < zero_rate`` (:meth:`CollisionRule.fit`: the window grows from ``window``
  samples until the slope's standard error is small enough to tell, see "Noisy bearings");
* eq. (27), on detection: ``S_k = 0`` if ``beta_kp = 0`` (``R_p`` ahead on the same
  lane; we take ``|beta| < same_lane``, 5 degrees: a robot on the opposite lane, 0.18 m to
  the right, is seen at least 10 degrees off within the sensor's 1 m), else
  ``S_k = S_k - eps_k S``;
* eq. (33), when ``R_p`` leaves the field of view and a reduction for it applies:
  ``S_k = S`` if ``S_k = 0``, else ``S_k = S_k + eps_k S``;
* eq. (34), when ``R_k`` crosses the common vertex: ``S_k = S``, and the pending
  reductions no longer apply (they are forgotten: no later increase by (33));
* eq. (28): distinct ``eps_1 < (K-1) eps_1 < eps_2 < ... < (K-1) eps_K < 1``
  (:func:`epsilons`), so a lower-numbered robot always slows less (Theorem 3).

Choices where the paper is silent (see also :class:`CollisionRule`):

* a reduction is applied once per robot ``R_p`` until (33) or (34) clears it
  (Corollary 2: one reduction per robot in collision);
* with ``K = 2`` eq. (28) reads ``eps_1 < eps_1``; we read its inequalities between one
  robot's own terms as ``<=`` (the paper's own 0.05 / 0.25 for two robots need that);
* the speed never goes below 0 (a robot with several pending reductions stops);
* a robot stopped by (27) for several robots ahead on its lane resumes by (33) only when
  the last of them has left its view;
* a stop (27, ``beta = 0``) also ends, as by (33), when the robot ahead is no longer
  ahead (``|beta| >= 2 same_lane``): on collinear edges a robot that went on and came back
  on the other lane stays in view, and waiting for it to leave the view deadlocks.

Noisy bearings (ours: the paper's sensor is exact). Each bearing carries Gaussian
noise of standard deviation ``sigma``; the rule does not need to be told ``sigma``: the
residuals of its own fit estimate it. Over ``W`` samples ``dt`` apart the fitted slope's
standard error is ``sigma sqrt(12 / (W (W^2 - 1))) / dt``; the rule decides only with the
shortest window (``window``, doubling up to ``max_window``) whose standard error is at
most ``zero_rate / RATE_SIGMAS``, and reads ``beta`` (for ``beta = 0`` and for "no longer
ahead") from the fitted line, not from one sample. Noise-free, the shortest window always
qualifies and the rule is the paper's. With 2 degrees of noise at 50 Hz the window is
1.6 s (80 samples, standard error 0.008 rad/s against ``zero_rate`` 0.02).

What Theorem 3 still guarantees with noisy bearings:

* its conclusion holds for every pair that the rule detects: the proof uses only that
  both robots of a pair on a collision course each reduce their speed once by their own
  ``eps S`` (eq. 27) and the order (28); noise changes neither;
* a detection is no longer certain: on a collision course (true rate 0) one decision
  misses with probability ``P(|N(0, SE)| >= zero_rate)``, below ``2 Phi(-RATE_SIGMAS)``
  (4.6 %), but the test repeats every tick while the pair approaches, over windows that
  stop overlapping after ``max_window`` ticks, so a pair in view for several windows
  is missed with probability of the order of ``0.046^(windows)``;
* the decision comes later: up to ``max_window dt`` (1.6 s) after ``R_p`` enters the view
  instead of ``window dt``: at the top speed two robots close 0.64 m meanwhile, within
  the 1 m sensor range but no longer "well before" at any range, so the guarantee holds
  for pairs that come into view at least that far from the meeting point;
* a false detection (true rate not zero, estimated below ``zero_rate``) only slows a
  robot by ``eps_k S`` until (33) or (34), as the paper's case 5 already allows: it costs
  time, never safety; its probability falls with ``|true rate| - zero_rate`` in units
  of the standard error;
* ``beta = 0`` (stop) against ``beta != 0`` (slow) is read from the fitted line, whose
  error is about ``sigma sqrt(4 / W)`` (0.45 degrees at 2 degrees and 80 samples), far
  within ``same_lane``.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections import deque
from dataclasses import dataclass, field

#: ``S``, the initial speed of Nagavarapu et al.'s experiments (Sec. 5: 5 cm/s), m/s: the default
#: speed of embodied runs.
PAPER_SPEED_M_S = 0.05
#: A rate fit decides only when its standard error is at most ``zero_rate`` over this:
#: a true zero then reads as zero 95 % of the time (two-sided Gaussian), see the module
#: docstring.
RATE_SIGMAS = 2.0
#: ``zero_rate`` (rad/s): ``|d beta / dt|`` below this counts as zero (eq. 17)
ZERO_RATE_RAD_S = 0.02
#: ``same_lane`` (rad): ``|beta|`` below this counts as ``beta = 0`` in (27)
SAME_LANE_RAD = math.radians(5.0)
#: the fewest and the most bearing samples in a rate fit (:class:`CollisionRule`)
WINDOW = 10
MAX_WINDOW = 80


def rate_windows(window: int, max_window: int) -> tuple[int, ...]:
    """The rate fit's windows (samples): ``window``, doubling up to ``max_window``."""
    windows = [window]
    while windows[-1] * 2 <= max_window:
        windows.append(windows[-1] * 2)
    return tuple(windows)


def slope_weights(w: int) -> tuple[tuple[float, ...], float, float]:
    """The least-squares slope over ``w`` samples one tick apart as fixed weights on the
    samples, ``sum_i (i - t_mean) (b_i - b_mean) / sum_i (i - t_mean)^2`` (rad per tick),
    with ``t_mean`` and ``sxx = sum_i (i - t_mean)^2``."""
    t_mean = (w - 1) / 2.0
    sxx = sum((i - t_mean) ** 2 for i in range(w))
    return tuple((i - t_mean) / sxx for i in range(w)), t_mean, sxx


def epsilons(k: int, largest: float = 0.5, spread: float = 1.5) -> list[float]:
    """Speed-change terms ``eps_1 .. eps_K`` satisfying eq. (28).

    ``eps_K = min(largest, 0.95 / (K - 1))`` and ``eps_k = eps_{k+1} / ((K - 1) spread)``,
    so ``(K - 1) eps_k < eps_{k+1}`` with room ``spread > 1`` and ``(K - 1) eps_K < 1``.
    """
    if k < 1:
        raise ValueError(f"team size must be >= 1, got {k}")
    if spread <= 1.0 or not 0.0 < largest < 1.0:
        raise ValueError("need spread > 1 and 0 < largest < 1")
    if k == 1:
        return [largest]
    top = min(largest, 0.95 / (k - 1))
    eps = [top]
    for _ in range(k - 1):
        eps.append(eps[-1] / ((k - 1) * spread))
    return eps[::-1]


@dataclass
class CollisionRule:
    """One robot's speed under eqs. (27), (33), (34).

    Args:
        initial_speed: ``S`` (m/s).
        epsilon: this robot's ``eps_k`` (from :func:`epsilons`).
        zero_rate: ``|d beta / dt|`` below this (rad/s) counts as zero (eq. 17).
        same_lane: ``|beta|`` below this (rad) counts as ``beta = 0`` in (27).
        window: the fewest bearing samples in the rate estimate (at the control rate):
            0.2 s at 50 Hz, the whole window with exact bearings.
        max_window: the most (doubling from ``window``): 1.6 s at 50 Hz, what 2 degrees
            of bearing noise needs (module docstring, "Noisy bearings").
        dt: time between samples (s).
    """

    initial_speed: float
    epsilon: float
    zero_rate: float = ZERO_RATE_RAD_S
    same_lane: float = SAME_LANE_RAD
    window: int = WINDOW
    max_window: int = MAX_WINDOW
    dt: float = 0.02
    speed: float = field(init=False)
    activations: int = field(default=0, init=False)
    _history: dict[int, deque] = field(default_factory=dict, init=False)
    _pending: dict[int, str] = field(default_factory=dict, init=False)  # p -> "stop"/"slow"

    def __post_init__(self) -> None:
        self.speed = self.initial_speed
        self._windows = rate_windows(self.window, self.max_window)
        self._weights = {w: slope_weights(w) for w in self._windows}

    def fit(self, p: int) -> tuple[float, float] | None:
        """``(rate rad/s, beta rad now)`` of ``beta_kp`` from the least-squares line through
        the shortest window of the last samples whose slope's standard error is at most
        ``zero_rate / RATE_SIGMAS`` (the residuals estimate the noise); None while no
        window tells (too few samples, or too noisy)."""
        samples = self._history.get(p)
        if samples is None:
            return None
        for w in self._windows:
            if len(samples) < w:
                return None
            ys = list(itertools.islice(samples, len(samples) - w, None))
            weights, t_mean, sxx = self._weights[w]
            slope = math.fsum(map(operator.mul, weights, ys))  # rad per tick
            y_mean = math.fsum(ys) / w
            rss = math.fsum((y - y_mean - slope * (i - t_mean)) ** 2 for i, y in enumerate(ys))
            standard_error = math.sqrt(rss / (w - 2) / sxx) / self.dt
            if standard_error <= self.zero_rate / RATE_SIGMAS:
                return slope / self.dt, y_mean + slope * (w - 1 - t_mean)
        return None

    def update(self, bearings: dict[int, float]) -> float:
        """Take this tick's bearings ``{p: beta_kp}`` (rad) and return ``S_k`` (m/s)."""
        for p in list(self._history):
            if p not in bearings:
                del self._history[p]
                self._out_of_view(p)
        for p, beta in bearings.items():
            samples = self._history.setdefault(p, deque(maxlen=self._windows[-1]))
            if samples:  # unwrap against the previous sample
                beta = samples[-1] + math.remainder(beta - samples[-1], 2.0 * math.pi)
            samples.append(beta)
            fitted = self.fit(p)
            if fitted is not None:
                rate, beta = fitted
            if self._pending.get(p) == "stop" and abs(math.remainder(beta, 2 * math.pi)) >= (
                    2.0 * self.same_lane):
                self._out_of_view(p)  # no longer ahead on this lane: resume as by (33)
            if p in self._pending or fitted is None or abs(rate) >= self.zero_rate:
                continue
            self.activations += 1
            if abs(math.remainder(beta, 2.0 * math.pi)) < self.same_lane:  # eq. (27), beta = 0
                self._pending[p] = "stop"
                self.speed = 0.0
            else:  # eq. (27), otherwise
                self._pending[p] = "slow"
                self.speed = max(0.0, self.speed - self.epsilon * self.initial_speed)
        return self.speed

    def _out_of_view(self, p: int) -> None:
        """Eq. (33): the reduction for ``p`` no longer needed once it is out of view."""
        if self._pending.pop(p, None) is None:
            return
        if self.speed == 0.0 and not any(v == "stop" for v in self._pending.values()):
            self.speed = self.initial_speed
        elif self.speed > 0.0:
            self.speed = min(self.initial_speed, self.speed + self.epsilon * self.initial_speed)

    def forget_bearings(self) -> None:
        """Drop the bearing histories (the rule is paused; see mjswarm.experiments.exploration)."""
        self._history.clear()

    def crossed_vertex(self) -> None:
        """Eq. (34): back to ``S``; pending reductions no longer apply."""
        self.speed = self.initial_speed
        self._pending.clear()
