"""Wheel-encoder odometry for a differential-drive robot."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from algorithms.navigation.percept import LINE_WINDOW_MAX

#: The spread (a fraction, one standard deviation) of one scan's over-read of a turn
#: without slip: a scan times its full turn by the first spoke's two crossings, each placed
#: to half a control tick (0.15 % of a turn at 1 rad/s and 50 Hz) and jittered by the line
#: filter; with 0.5 mm of line noise single scans spread 0.27 % (165 scans, -0.64 to +0.75
#: %), without it about 0.05 % (``python benchmarks/turn_over_read.py``).
SCAN_OVER_READ_SPREAD = 0.003
#: How many standard errors of the scans' mean over-read must lie above none before
#: :meth:`Odometry.calibrate` corrects the distance: 1.5 % after one scan, 0.75 % after
#: four; the mean over-read of slip 0.02 (1.6 %) is corrected from the first scan, that
#: of 0.01 (0.8 %) from the fourth.
OVER_READ_SIGMAS = 5.0


@dataclass(frozen=True)
class RobotCalibration:
    """What a robot knows about its own body (metres, radians).

    Attributes:
        wheel_radius_m: driven wheel radius.
        track_m: distance between the driven wheels.
        line_ahead_m: how far ahead of the axle the line sensors look.
        max_speed_m_s: top forward speed.
        line_floor_m: what a line sensor reads over the bare floor (its height).
        body_radius_m: its chassis radius (None: unknown; it then passes no body).
        line_spacing_m: lateral distance between neighbouring line sensors (None:
            unknown; it then takes any strip it finds leaving a vertex for its lane).
        turn_over_read: how much its odometry over-reads a turn in place on its floor
            with exact encoders (the wheels' scrub): its scans' effective track over
            ``track_m``, measured once on that floor (1 without scrub). What its scans
            find beyond it is its encoders' own over-read (:meth:`Odometry.calibrate`).
    """

    wheel_radius_m: float
    track_m: float
    line_ahead_m: float
    max_speed_m_s: float
    line_floor_m: float = 0.02
    body_radius_m: float | None = None
    line_spacing_m: float | None = None
    turn_over_read: float = 1.0


class Odometry:
    """Dead reckoning from wheel angles: the exact arc model per update.

    Between two updates the wheels turned by ``dl``, ``dr`` (rad); the robot moved
    ``ds = r (dl + dr) / 2`` along an arc while turning ``dtheta = r (dr - dl) / b``;
    the midpoint heading is used for the translation. The pose is in the robot's own
    frame of reference: its start pose is whatever it is told (e.g. a compass heading
    at the root), never read from the world.
    """

    def __init__(self, calibration: RobotCalibration, x: float = 0.0, y: float = 0.0,
                 theta: float = 0.0) -> None:
        self.cal = calibration
        self.track_m = calibration.track_m  # effective track, refined by calibration
        #: how much the encoders over-read the distance driven (:meth:`calibrate`)
        self.distance_scale = 1.0
        self.x, self.y, self.theta = x, y, theta
        self.distance_m = 0.0  # total path length driven (forward counts positive)
        #: sum over updates of ``dl**2 + dr**2`` (rad^2, the wheels' turns per update): what
        #: the heading's variance under per-update wheel slip grows with
        #: (:meth:`heading_variance_since`); it moves no pose
        self.wheel_sq = 0.0
        self._last: tuple[float, float] | None = None
        #: distance_m after each of the last updates, newest last: what
        #: :meth:`distance_back` answers for a filtered percept's lag
        self._past: deque[float] = deque(maxlen=LINE_WINDOW_MAX)

    def update(self, encoders: tuple[float, float]) -> None:
        """Integrate the wheel motion since the previous call."""
        if self._last is None:
            self._last = encoders
            self._past.append(self.distance_m)
            return
        dl = encoders[0] - self._last[0]
        dr = encoders[1] - self._last[1]
        self._last = encoders
        r, b = self.cal.wheel_radius_m, self.track_m
        ds = r * (dl + dr) / (2.0 * self.distance_scale)
        dtheta = r * (dr - dl) / b
        mid = self.theta + dtheta / 2.0
        self.x += ds * math.cos(mid)
        self.y += ds * math.sin(mid)
        self.theta += dtheta
        self.distance_m += ds
        self.wheel_sq += dl * dl + dr * dr
        self._past.append(self.distance_m)

    def calibrate(self, track_m: float, scans: int, exact_crossings: bool) -> None:
        """Take the effective track and the distance scale that ``track_m`` (m), the mean
        of ``scans`` scans' effective tracks, calls for (ours).

        Encoders that over-read their wheels' turn by a fraction ``e`` (wheel slip: the
        wheel spun more than it rolled) over-read a turn in place and a straight drive
        alike, by ``e`` on average: the turn by ``r (|dl| + |dr|) / b``, the drive by ``r
        (dl + dr) / 2``, both linear in the wheels' readings, and a scan's whole turn
        (about 300 control ticks) averages ``e`` to about a tenth of a per cent. So the
        scans' mean over-read beyond the floor's scrub (``turn_over_read``) divides the
        distance, once it lies ``OVER_READ_SIGMAS`` standard errors
        (``SCAN_OVER_READ_SPREAD / sqrt(scans)``) above none; till then the scale stays
        1, so that runs without slip drive by their encoders' own distance.

        The track: with ``exact_crossings`` (the line readings are noise-free enough for
        the line filter to pass single readings) a scan's crossings are placed to half a
        control tick, its over-read to about 0.05 %, as close as the floor's scrub is
        known (``benchmarks/turn_over_read.py``), and the track is the scans' mean. With noisy line readings one scan's over-read spreads 0.3 %, and a
        mean below the scrub's is that noise alone: encoders never under-read (slip makes
        a wheel spin more than it rolls), so the track is the larger of the scans' mean
        and the scrub's, the most likely track that is not below it (the mean's
        maximum-likelihood estimate under that bound), never farther from the truth than
        the mean. Without the bound, a lone robot whose first scan read its turn 0.53 %
        short would take that for its track and turn its heading 2.3 degrees at once
        (``fan:3:45@17``, 1 robot, 0.1 m/s, line noise 0.5 mm, kinematic, seed 1). On the
        noise grid's sample (``python -m mjswarm.experiments.stress --noise --sample``) the
        bound leaves most runs with line noise alone nearer the truth (not all: the map's
        frame moves with every scan), and slip 0.01's runs and every run without line
        noise as the mean alone leaves them. A mean above the
        scrub's is kept: a noisy scan that reads long cannot be told from slip 0.01's
        0.8 %, and a bar that also ignored means up to 2 standard errors above the scrub
        cost slip 0.01's robots up to 3.3 degrees of heading in that sample."""
        floor_m = self.cal.track_m * self.cal.turn_over_read
        over_read = track_m / floor_m
        significant = OVER_READ_SIGMAS * SCAN_OVER_READ_SPREAD / math.sqrt(scans)
        self.distance_scale = over_read if over_read - 1.0 >= significant else 1.0
        self.track_m = track_m if exact_crossings else max(track_m, floor_m)

    def distance_back(self, ticks: int) -> float:
        """``distance_m`` as it was ``ticks`` updates ago (0: now; a filtered percept's
        lag is at most ``(LINE_WINDOW_MAX - 1) / 2``), or the oldest kept."""
        if not self._past:
            return self.distance_m
        return self._past[max(-len(self._past), -1 - ticks)]

    @property
    def slip_sigma(self) -> float:
        """The spread (a fraction, one standard deviation) of one update's encoder
        over-read about its mean, from the calibrated distance scale (ours, for
        frame fusion): an encoder that over-reads by ``|N(0, S)|`` over-reads by
        ``S sqrt(2 / pi)`` on average, which :meth:`calibrate` measures as
        ``distance_scale - 1``, and spreads ``S sqrt(1 - 2 / pi)`` about it. 0 while the
        scale is 1 (no slip found: noise-free and line-noise runs)."""
        if self.distance_scale == 1.0:
            return 0.0
        s = (self.distance_scale - 1.0) / math.sqrt(2.0 / math.pi)
        return s * math.sqrt(1.0 - 2.0 / math.pi)

    def heading_variance_since(self, wheel_sq: float) -> float:
        """The variance (rad^2) the slip adds to the heading since ``wheel_sq`` was
        :attr:`wheel_sq`: per update the heading errs by ``r (dr e_r - dl e_l) / b``, the
        two wheels' over-reads ``e`` independent with spread :attr:`slip_sigma` (their
        mean is calibrated out), so its variance is ``(r / b)^2 (dl^2 + dr^2) sigma^2``,
        summed over updates: for the Spark V (r 25 mm, b 0.12 m) at slip 0.05 a straight
        metre at 0.15 m/s and 50 Hz adds about (1.1 deg)^2, a scan's whole turn at 1 rad/s
        (0.4 deg)^2. On the noise grid's slip runs (``python -m mjswarm.experiments.stress
        --noise``) the heading's drift from one vertex call to the next is 1.13 degrees
        rms against 0.99 modelled (1070 legs; along the lanes alone 0.75 against 0.74)."""
        k = self.cal.wheel_radius_m / self.track_m * self.slip_sigma
        return k * k * (self.wheel_sq - wheel_sq)

    def correct_heading(self, delta_rad: float) -> None:
        """Rotate the heading estimate by ``delta_rad`` (a landmark-based correction)."""
        self.theta += delta_rad
