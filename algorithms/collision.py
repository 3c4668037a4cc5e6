"""The bearing-rate speed-change collision rule of seed 003, Sec. 4.

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

Noisy bearings (issue 27; the paper's sensor is exact). Each bearing carries Gaussian
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

import numpy as np


#: ``S``, the initial speed of seed 003's experiments (Sec. 5: 5 cm/s), m/s: the default
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
#: what the rule keeps per robot ``R_p`` in view (:class:`BatchCollisionRule`'s codes)
NONE, SLOW, STOP = 0, 1, 2


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


def remainder_2pi(x: np.ndarray) -> np.ndarray:
    """``math.remainder(x, 2 pi)`` elementwise, bit for bit: ``fmod`` is exact, and moving
    its result by one period into ``[-pi, pi]`` is exact (Sterbenz); a tie (``|r| = pi``)
    takes ``math.remainder``'s even quotient."""
    two_pi = 2.0 * math.pi
    r = np.fmod(x, two_pi)
    r = np.where(r > math.pi, r - two_pi, np.where(r < -math.pi, r + two_pi, r))
    for k in np.flatnonzero(np.abs(r) == math.pi):
        r[k] = math.remainder(x[k], two_pi)
    return r


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


def satisfies_28(eps: list[float]) -> bool:
    """Check eq. (28) for a team of ``len(eps)`` robots (``<=`` within a robot's terms)."""
    k = len(eps)
    if k == 1:  # a lone robot meets nobody
        return 0.0 < eps[0] < 1.0
    chain = []
    for e in eps:
        chain += [e, (k - 1) * e]
    for (a, b), i in zip(itertools.pairwise(chain), range(len(chain) - 1)):
        same_robot = i % 2 == 0
        if not (a <= b if same_robot else a < b):
            return False
    return chain[-1] < 1.0


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

    def bearing_rate(self, p: int) -> float | None:
        """The fitted ``d beta_kp / dt`` (rad/s) of :meth:`fit`, None while it cannot tell."""
        fitted = self.fit(p)
        return None if fitted is None else fitted[0]

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


class BatchCollisionRule:
    """The speeds of a team of ``N`` robots under eqs. (27), (33) over pair arrays: what
    :class:`CollisionRule` does for one robot, for all at once, with the same decisions.

    State is kept per pair ``(R_k, R_p)`` in view, sorted by ``k N + p``: the bearings in
    a ring buffer row (the last ``max_window`` samples, unwrapped), the sample count and
    what is pending for ``R_p`` (``NONE``, ``SLOW``, ``STOP``); per robot its speed
    ``S_k`` and its pending stops. The rate fit is :func:`slope_weights` as a dot product
    over each window (:meth:`fit`). The speed changes of a tick are events (a reduction
    that no longer applies, eq. 33; a new one, eq. 27) taken per robot in
    :class:`CollisionRule`'s order (pairs that left the view, then the bearings by ``p``),
    in rounds: the ``r``-th event of every robot at once.

    The fit sums with numpy where :class:`CollisionRule` sums exactly (``math.fsum``), so
    rates and fitted bearings agree within a few units in the last place; decisions, and
    with them speeds, differ only where a rate lands that close to ``zero_rate`` or a
    standard error to its bound (``tests/test_batch_team.py`` compares the two).
    """

    def __init__(self, initial_speed: float, epsilon: np.ndarray, zero_rate: float = ZERO_RATE_RAD_S,
                 same_lane: float = SAME_LANE_RAD, window: int = WINDOW,
                 max_window: int = MAX_WINDOW, dt: float = 0.02) -> None:
        self.initial_speed = initial_speed
        self.n = len(epsilon)
        self.step = np.asarray(epsilon, float) * initial_speed  # eps_k S (m/s)
        self.zero_rate, self.same_lane, self.dt = zero_rate, same_lane, dt
        self.windows = rate_windows(window, max_window)
        self.speed = np.full(self.n, float(initial_speed))
        self.stops = np.zeros(self.n, np.int64)
        self.key = np.empty(0, np.int64)
        self.slot = np.empty(0, np.intp)
        self.count = np.empty(0, np.int64)
        self.pending = np.empty(0, np.int8)
        self.buffer = np.empty((0, self.windows[-1]))
        self.used = np.empty(0, bool)

    def update(self, robots: np.ndarray, k: np.ndarray, p: np.ndarray,
               beta: np.ndarray) -> np.ndarray:
        """Take the bearings ``beta_kp`` (rad) of this tick's pairs ``(k, p)`` (sorted by
        ``k``, then ``p``) for the robots ``robots`` stepped now; return their ``S_k`` (m/s)."""
        if not len(k) and not len(self.key):  # nobody in view, before or now
            return self.speed[robots]
        key = k.astype(np.int64) * self.n + p
        at = np.minimum(np.searchsorted(self.key, key), max(len(self.key) - 1, 0))
        found = self.key[at] == key if len(self.key) else np.zeros(len(key), bool)
        stepped = np.zeros(self.n, bool)
        stepped[robots] = True
        gone = stepped[self.key // self.n]
        gone[at[found]] = False
        self.used[self.slot[gone]] = False
        left = gone & (self.pending != NONE)
        events = [(self.key[left] // self.n, np.full(left.sum(), -1), self.pending[left])]
        slot, count, pending = self._carry(at, found)
        beta, count = self._record(slot, count, beta), count + 1
        ok, rate, fitted = self.fit(slot, count)
        beta = np.where(ok, fitted, beta)
        off = np.abs(remainder_2pi(beta))
        resume = (pending == STOP) & (off >= 2.0 * self.same_lane)
        pending[resume] = NONE
        act = (pending == NONE) & ok & (np.abs(rate) < self.zero_rate)
        pending[act] = np.where(off[act] < self.same_lane, STOP, SLOW)
        events += [(k[resume], 2 * p[resume], np.full(resume.sum(), STOP, np.int8)),
                   (k[act], 2 * p[act] + 1, -pending[act])]
        self._apply(*(np.concatenate(e) for e in zip(*events)))
        self._keep(~stepped[self.key // self.n], key, slot, count, pending)
        return self.speed[robots]

    def _carry(self, at: np.ndarray, found: np.ndarray) -> tuple[np.ndarray, ...]:
        """Each current pair's buffer row, sample count and pending code (a pair new in
        view gets a free row, no samples, nothing pending)."""
        new = np.flatnonzero(~found)
        free = np.flatnonzero(~self.used)
        if len(free) < len(new):  # grow the ring buffers (at least double)
            grow = max(len(new), len(self.used))
            self.buffer = np.vstack([self.buffer, np.empty((grow, self.buffer.shape[1]))])
            self.used = np.concatenate([self.used, np.zeros(grow, bool)])
            free = np.flatnonzero(~self.used)
        slot = np.empty(len(found), np.intp)
        count = np.zeros(len(found), np.int64)
        pending = np.full(len(found), NONE, np.int8)
        old = at[found]
        slot[found], count[found], pending[found] = self.slot[old], self.count[old], self.pending[old]
        slot[new] = free[:len(new)]
        self.used[slot[new]] = True
        return slot, count, pending

    def _record(self, slot: np.ndarray, count: np.ndarray, beta: np.ndarray) -> np.ndarray:
        """Append each pair's sample to its ring buffer, unwrapped against the previous
        one (rad); the samples as stored."""
        size = self.buffer.shape[1]
        seen = count > 0
        last = self.buffer[slot[seen], (count[seen] - 1) % size]
        beta = np.array(beta, float)
        beta[seen] = last + remainder_2pi(beta[seen] - last)
        self.buffer[slot, count % size] = beta
        return beta

    def fit(self, slot: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, ...]:
        """:meth:`CollisionRule.fit` for every pair: whether a window tells, the rate
        (rad/s) and the fitted ``beta`` now (rad), from the shortest window of the last
        samples whose slope's standard error is at most ``zero_rate / RATE_SIGMAS``."""
        size = self.buffer.shape[1]
        ok = np.zeros(len(slot), bool)
        rate, fitted = np.zeros(len(slot)), np.zeros(len(slot))
        open_ = np.ones(len(slot), bool)
        for w in self.windows:
            open_ &= count >= w
            idx = np.flatnonzero(open_)
            if not len(idx):
                break
            weights, t_mean, sxx = slope_weights(w)
            at = np.arange(w)
            ys = self.buffer[slot[idx, None], (count[idx, None] - w + at) % size]
            slope = ys @ np.array(weights)  # rad per tick
            y_mean = ys.sum(axis=1) / w
            rss = (((ys - y_mean[:, None]) - slope[:, None] * (at - t_mean)) ** 2).sum(axis=1)
            tells = np.sqrt(rss / (w - 2) / sxx) / self.dt <= self.zero_rate / RATE_SIGMAS
            done = idx[tells]
            ok[done], open_[done] = True, False
            rate[done] = slope[tells] / self.dt
            fitted[done] = y_mean[tells] + slope[tells] * (w - 1 - t_mean)
        return ok, rate, fitted

    def _apply(self, robot: np.ndarray, order: np.ndarray, code: np.ndarray) -> None:
        """Apply speed events in each robot's order (by ``order``), the ``r``-th event of
        every robot in round ``r``. ``code``: a reduction for ``R_p`` that no longer
        applies (eq. 33; ``SLOW``, ``STOP``) or a new one (eq. 27; ``-SLOW``, ``-STOP``)."""
        if not len(robot):
            return
        sort = np.lexsort((order, robot))
        robot, code = robot[sort], code[sort]
        rank = np.arange(len(robot)) - np.searchsorted(robot, robot)
        S = self.initial_speed
        for r in range(int(rank.max()) + 1):
            k, c = robot[rank == r], code[rank == r]
            s, e = self.speed[k], self.step[k]
            self.stops[k] += (c == -STOP).astype(np.int64) - (c == STOP)
            pop = c > 0
            s = np.where(pop & (s == 0.0) & (self.stops[k] == 0), S,
                         np.where(pop & (s > 0.0), np.minimum(S, s + e), s))
            s = np.where(c == -STOP, 0.0, np.where(c == -SLOW, np.maximum(0.0, s - e), s))
            self.speed[k] = s

    def _keep(self, stay: np.ndarray, key: np.ndarray, slot: np.ndarray, count: np.ndarray,
              pending: np.ndarray) -> None:
        """The pairs from now on: those of robots not stepped this tick, and this tick's."""
        key = np.concatenate([self.key[stay], key])
        order = np.argsort(key, kind="stable")
        self.key = key[order]
        self.slot = np.concatenate([self.slot[stay], slot])[order]
        self.count = np.concatenate([self.count[stay], count])[order]
        self.pending = np.concatenate([self.pending[stay], pending])[order]
