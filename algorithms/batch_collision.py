"""Nagavarapu et al.'s speed rule (eqs. 17, 27, 33) for a whole team in one compiled call.

:class:`BatchCollisionRule` keeps, per pair ``(R_k, R_p)`` in view, what
:class:`~algorithms.collision.CollisionRule` keeps per robot ``R_p`` (the last
``max_window`` bearings, unwrapped, in a ring-buffer row; the sample count; what is
pending: ``NONE``, ``SLOW``, ``STOP``), sorted by ``k N + p``, and per robot its speed
``S_k`` and its pending stops. One tick is one pass of :func:`_update` over the pairs,
robot by robot in :class:`~algorithms.collision.CollisionRule`'s order: first the pairs
that left the view (eq. 33, by ``p``), then this tick's bearings by ``p`` (record, fit,
"no longer ahead", eq. 27).

**The same speeds as the per-robot rule, to the bit.** The per-robot fit sums exactly
(``math.fsum``). Here each window is first summed in plain floating point, which errs by
at most about ``w eps max|y|`` (Higham's bound for ``w`` terms; below 1e-13 ``max|y|``
rad for the rule's 80 samples): decisions taken farther than ``NEAR`` (relative to
``1 + max|y|``) from every threshold they compare with (the standard error's bound,
``zero_rate``, ``same_lane`` and twice it) are the exact sums' decisions. A fit nearer
than that is summed again exactly (:func:`_fsum`, CPython's ``math.fsum``: Shewchuk's
partials and its correctly rounded result), with the per-robot rule's expressions in its
order, so its rate and fitted bearing are the per-robot rule's to the bit.
``math.remainder(x, 2 pi)`` is :func:`_remainder_2pi`, exact too. So every robot's speed
is what its own :class:`~algorithms.collision.CollisionRule` would answer, tick by tick
(``tests/test_batch_team.py``: random streams, and rates within a few ulps of
``zero_rate``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from algorithms.collision import (
    MAX_WINDOW,
    RATE_SIGMAS,
    SAME_LANE_RAD,
    WINDOW,
    ZERO_RATE_RAD_S,
    rate_windows,
    slope_weights,
)

#: A fit decides by plain sums unless a compared quantity lies within ``NEAR (1 +
#: max|y|)`` of its threshold (the rate and bearings in rad/s and rad, the standard error
#: relative to its bound): a thousand times the plain sums' worst error (module docstring).
NEAR = 1e-9
#: What a pair keeps pending for ``R_p``: nothing, a reduction (eq. 27), a stop (eq. 27,
#: ``beta = 0``).
NONE, SLOW, STOP = 0, 1, 2
#: Room for :func:`_fsum`'s partials: a sum of doubles never needs more than about 40.
PARTIALS = 64


class BatchCollisionRule:
    """The speeds of a team of ``N`` robots under eqs. (27), (33): what
    :class:`~algorithms.collision.CollisionRule` answers for each robot, for all at once
    (module docstring).

    Args: as :class:`~algorithms.collision.CollisionRule`'s, with ``epsilon`` the team's
    ``eps_k`` by robot index (:func:`~algorithms.collision.epsilons`).
    """

    def __init__(self, initial_speed: float, epsilon: np.ndarray, zero_rate: float = ZERO_RATE_RAD_S,
                 same_lane: float = SAME_LANE_RAD, window: int = WINDOW,
                 max_window: int = MAX_WINDOW, dt: float = 0.02) -> None:
        self.initial_speed = float(initial_speed)
        self.n = len(epsilon)
        self.step = np.asarray(epsilon, float) * initial_speed  # eps_k S (m/s)
        self.zero_rate, self.same_lane, self.dt = float(zero_rate), float(same_lane), float(dt)
        self.windows = np.array(rate_windows(window, max_window), np.int64)
        fits = [slope_weights(w) for w in self.windows.tolist()]
        self._weights = np.zeros((len(fits), self.windows[-1]))
        for row, (weights, _, _) in zip(self._weights, fits):
            row[:len(weights)] = weights
        self._t_mean = np.array([t for _, t, _ in fits])
        self._sxx = np.array([s for _, _, s in fits])
        self.speed = np.full(self.n, self.initial_speed)
        self.stops = np.zeros(self.n, np.int64)
        self.key = np.empty(0, np.int64)  # k N + p of the pairs in view, sorted
        self.slot = np.empty(0, np.int64)  # each pair's ring-buffer row
        self.count = np.empty(0, np.int64)  # samples each pair has had
        self.pending = np.empty(0, np.int8)  # NONE, SLOW or STOP
        self.buffer = np.empty((0, self.windows[-1]))
        self.used = np.empty(0, np.bool_)

    def update(self, robots: np.ndarray, k: np.ndarray, p: np.ndarray,
               beta: np.ndarray) -> np.ndarray:
        """Take the bearings ``beta_kp`` (rad) of this tick's pairs ``(k, p)`` (sorted by
        ``k``, then ``p``) for the robots ``robots`` stepped now; return their ``S_k`` (m/s)."""
        if not len(k) and not len(self.key):  # nobody in view, before or now
            return self.speed[robots]
        stepped = np.zeros(self.n, np.bool_)
        stepped[robots] = True
        free = len(self.used) - len(self.key)
        if free < len(k):  # room for every pair to be new (at least double)
            grow = max(len(k) - free, len(self.used))
            self.buffer = np.vstack([self.buffer, np.empty((grow, self.buffer.shape[1]))])
            self.used = np.concatenate([self.used, np.zeros(grow, np.bool_)])
        size = len(self.key) + len(k)
        out = (np.empty(size, np.int64), np.empty(size, np.int64), np.empty(size, np.int64),
               np.empty(size, np.int8))
        kept = _update(self.n, stepped, self.key, self.slot, self.count, self.pending,
                       np.asarray(k, np.int64), np.asarray(p, np.int64),
                       np.asarray(beta, np.float64), self.buffer, self.used, self.speed,
                       self.stops, self.step, self.initial_speed, self.zero_rate,
                       self.same_lane, self.dt, self.windows, self._weights, self._t_mean,
                       self._sxx, 2.0, *out)
        self.key, self.slot, self.count, self.pending = (a[:kept] for a in out)
        return self.speed[robots]


@njit(cache=True)
def _remainder_2pi(x: float) -> float:
    """``math.remainder(x, 2 pi)``, bit for bit: ``fmod`` is exact, and moving its result
    by one period into ``[-pi, pi]`` is exact (Sterbenz); a tie (``|r| = pi``) takes the
    even quotient, as IEEE 754's remainder does."""
    two_pi = 2.0 * math.pi
    r = np.fmod(x, two_pi)
    if r > math.pi:
        return r - two_pi
    if r < -math.pi:
        return r + two_pi
    if abs(r) == math.pi and round((x - r) / two_pi) % 2 != 0:
        return -r
    return r


@njit(cache=True)
def _fsum(values: np.ndarray, partials: np.ndarray) -> float:
    """``math.fsum(values)`` for finite values: CPython's algorithm (Shewchuk's exact
    partials, then the correctly rounded sum of them, half-way cases included)."""
    n = 0
    for x in values:
        i = 0
        for j in range(n):
            y = partials[j]
            if abs(x) < abs(y):
                x, y = y, x
            hi = x + y
            lo = y - (hi - x)
            if lo != 0.0:
                partials[i] = lo
                i += 1
            x = hi
        n = i
        if x != 0.0:
            partials[n] = x
            n += 1
    hi = 0.0
    if n > 0:
        n -= 1
        hi = partials[n]
        lo = 0.0
        while n > 0:
            x = hi
            n -= 1
            y = partials[n]
            hi = x + y
            lo = y - (hi - x)
            if lo != 0.0:
                break
        if n > 0 and ((lo < 0.0 and partials[n - 1] < 0.0) or (lo > 0.0 and partials[n - 1] > 0.0)):
            y = lo * 2.0
            x = hi + y
            if y == x - hi:
                hi = x
    return hi


@njit(cache=True)
def _fit(ys_all: np.ndarray, count: int, windows: np.ndarray, weights: np.ndarray,
         t_mean: np.ndarray, sxx: np.ndarray, dt: float, bound: float, exact: bool,
         two: float, scratch: np.ndarray, partials: np.ndarray):
    """:meth:`~algorithms.collision.CollisionRule.fit` on one pair's ring-buffer row
    ``ys_all`` after ``count`` samples: ``(tells, rate rad/s, fitted beta rad, max|y|,
    near)``; ``exact``: sums by :func:`_fsum`, else plain sums, and ``near`` says whether a
    standard error came within ``NEAR`` of its bound.

    ``two`` is the exponent 2.0 of the exact residuals' squares, handed in at run time:
    the per-robot rule squares with Python's ``**`` (libm's ``pow``), which differs from
    ``e * e`` in about one case in a thousand, and the compiler would turn a constant
    ``pow(e, 2.0)`` into ``e * e``."""
    size = len(ys_all)
    near, y_max = False, 0.0
    for m in range(len(windows)):
        w = windows[m]
        if count < w:
            return False, 0.0, 0.0, y_max, near
        ys = scratch[:w]
        for t in range(w):
            ys[t] = ys_all[(count - w + t) % size]
            y_max = max(y_max, abs(ys[t]))
        tm = t_mean[m]
        if exact:
            for t in range(w):
                partials[PARTIALS + t] = weights[m, t] * ys[t]
            slope = _fsum(partials[PARTIALS:PARTIALS + w], partials)
            y_mean = _fsum(ys, partials) / w
            for t in range(w):
                partials[PARTIALS + t] = math.pow(ys[t] - y_mean - slope * (t - tm), two)
            rss = _fsum(partials[PARTIALS:PARTIALS + w], partials)
        else:
            slope = y_sum = 0.0
            for t in range(w):
                slope += weights[m, t] * ys[t]
                y_sum += ys[t]
            y_mean = y_sum / w
            rss = 0.0
            for t in range(w):
                e = ys[t] - y_mean - slope * (t - tm)
                rss += e * e
        standard_error = math.sqrt(rss / (w - 2) / sxx[m]) / dt
        near = near or abs(standard_error - bound) <= NEAR * (1.0 + y_max) * bound
        if standard_error <= bound:
            return True, slope / dt, y_mean + slope * (w - 1 - tm), y_max, near
    return False, 0.0, 0.0, y_max, near


@njit(cache=True)
def _pop(r: int, code: int, speed: np.ndarray, stops: np.ndarray, step: np.ndarray,
         initial_speed: float) -> None:
    """Eq. (33): robot ``r``'s reduction ``code`` (SLOW, STOP) no longer applies."""
    if code == STOP:
        stops[r] -= 1
    s = speed[r]
    if s == 0.0 and stops[r] == 0:
        speed[r] = initial_speed
    elif s > 0.0:
        speed[r] = min(initial_speed, s + step[r])


@njit(cache=True)
def _update(n, stepped, key, slot, count, pending, k, p, beta, buffer, used, speed, stops,
            step, initial_speed, zero_rate, same_lane, dt, windows, weights, t_mean, sxx,
            two, key_out, slot_out, count_out, pending_out) -> int:
    """One tick of :class:`BatchCollisionRule` (module docstring): the pairs kept from
    now on go to the ``*_out`` arrays, sorted by key; returns how many. ``two``: 2.0
    (:func:`_fit`)."""
    size = buffer.shape[1]
    bound = zero_rate / RATE_SIGMAS
    scratch = np.empty(size)
    partials = np.empty(PARTIALS + size)
    n_old, n_new = len(key), len(k)
    i = j = kept = 0
    free = 0  # where the search for a free ring-buffer row goes on
    while i < n_old or j < n_new:
        r = min(key[i] // n if i < n_old else n, k[j] if j < n_new else n)
        i_end, j_end = i, j
        while i_end < n_old and key[i_end] // n == r:
            i_end += 1
        while j_end < n_new and k[j_end] == r:
            j_end += 1
        if not stepped[r]:  # not stepped this tick: its pairs stay as they are
            for a in range(i, i_end):
                key_out[kept], slot_out[kept] = key[a], slot[a]
                count_out[kept], pending_out[kept] = count[a], pending[a]
                kept += 1
            i, j = i_end, j_end
            continue
        b = j
        for a in range(i, i_end):  # pairs that left the view: eq. (33)
            q = key[a] - r * n
            while b < j_end and p[b] < q:
                b += 1
            if b < j_end and p[b] == q:
                continue
            used[slot[a]] = False
            if pending[a] != NONE:
                _pop(r, pending[a], speed, stops, step, initial_speed)
        a = i
        for b in range(j, j_end):  # this tick's bearings, by p
            while a < i_end and key[a] - r * n < p[b]:
                a += 1
            if a < i_end and key[a] - r * n == p[b]:
                row, samples, code = slot[a], count[a], pending[a]
            else:  # new in view: a free row, no samples, nothing pending
                while used[free]:
                    free += 1
                row, samples, code = free, 0, NONE
                used[row] = True
            sample = beta[b]
            if samples > 0:  # unwrap against the previous sample
                last = buffer[row, (samples - 1) % size]
                sample = last + _remainder_2pi(sample - last)
            buffer[row, samples % size] = sample
            samples += 1
            tells, rate, fitted, y_max, near = _fit(buffer[row], samples, windows, weights,
                                                    t_mean, sxx, dt, bound, False, two,
                                                    scratch, partials)
            margin = NEAR * (1.0 + y_max)
            off = abs(_remainder_2pi(fitted if tells else sample))
            if near or (tells and (abs(abs(rate) - zero_rate) <= margin
                                   or abs(off - same_lane) <= margin
                                   or abs(off - 2.0 * same_lane) <= margin)):
                tells, rate, fitted, y_max, near = _fit(buffer[row], samples, windows,
                                                        weights, t_mean, sxx, dt, bound,
                                                        True, two, scratch, partials)
                off = abs(_remainder_2pi(fitted if tells else sample))
            if code == STOP and off >= 2.0 * same_lane:  # no longer ahead: as by (33)
                code = NONE
                _pop(r, STOP, speed, stops, step, initial_speed)
            if code == NONE and tells and abs(rate) < zero_rate:  # eq. (27)
                if off < same_lane:
                    code = STOP
                    stops[r] += 1
                    speed[r] = 0.0
                else:
                    code = SLOW
                    speed[r] = max(0.0, speed[r] - step[r])
            key_out[kept], slot_out[kept] = r * n + p[b], row
            count_out[kept], pending_out[kept] = samples, code
            kept += 1
        i, j = i_end, j_end
    return kept
