"""Arena geometry conventions: lane strips, spokes and corridor walls of a graph spec.

One source of truth for the spec validator (:mod:`mjswarm.arena.spec`), the MuJoCo
builder and the robots' navigation. All lengths are metres, all angles radians unless
a name ends in ``_DEG``. The world is the x-y plane, +z up; an edge ``(u, v)`` has the
direction ``u -> v``, and "left" means counter-clockwise of that direction seen from +z.

Layout of one edge (Nagavarapu et al., Sec. 4 and Fig. 3: two lanes per edge, a robot keeps
to one side; Sec. 5: black strips on the floor, walls along the free paths so the IR
sensors see an obstacle on an edge and none at a vertex):

* two **lane strips** (line markings, ``STRIP_WIDTH_M`` wide) offset
  ``+-LANE_OFFSET_M`` from the centre line; a robot travelling ``u -> v`` drives on the
  strip to its left;
* at each end vertex a **spoke**: a centre-line strip from ``SPOKE_INNER_RADIUS_M`` to
  ``SPOKE_RADIUS_M``, which a robot finds by rotating in place on the vertex;
* two **walls** whose centre lines are offset ``+-CORRIDOR_HALF_WIDTH_M``, set back
  from each vertex by :func:`wall_setback` so the vertex area stays open.

Choices where the brief leaves room (documented here once):

* Setbacks are measured **along the edge** from the vertex centre (the strip/wall end
  is the perpendicular cross-section at that distance), so the closed form
  ``h / tan(theta / 2)`` below is exactly where the offset lines of two edges meeting
  at angle ``theta`` cross.
* The neighbouring edge "on a side" of edge ``u -> v`` at ``u`` is the next edge
  counter-clockwise (left side) or clockwise (right side) around ``u``; ``theta`` is
  the angle swept to reach it, ``2 pi`` when ``u`` has degree 1.
* Lane strips stop at :func:`lane_setback`, i.e. ``LANE_END_RADIUS_M`` unless the
  neighbouring edge on that side is closer than about 71 degrees: with the fixed
  0.16 m the facing lanes of two neighbouring edges would touch for angles below
  about 64 degrees (at 45 degrees their centre lines cross 0.22 m out), so the lane
  end uses the same offset-line rule as the walls.
* Strips and walls are treated as **capsules** (segment plus half-width disc) when
  checking clearances; a capsule contains the rectangle, so the checks are
  conservative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # avoids an import cycle: the spec validator calls this module
    from mjswarm.arena.spec import ArenaSpec

Point = tuple[float, float]

#: Lane strip centre line offset from the edge centre line (m); a robot drives on the
#: strip to the LEFT of its direction of travel.
LANE_OFFSET_M = 0.09
#: Width of every floor strip, lanes and spokes (m). With the line sensors 22 mm apart a
#: 30 mm strip is under at least one of them whenever the robot is within 37 mm of it
#: (centre alone within +-7 mm, centre and a side sensor from 7 to 15 mm, a side sensor
#: alone beyond), so a follower always knows which side the strip is on; a 20 mm strip
#: would leave 2 mm blind gaps between the sensors.
STRIP_WIDTH_M = 0.03
#: Wall centre line offset from the edge centre line (m).
CORRIDOR_HALF_WIDTH_M = 0.20
#: Wall thickness (m) and height (m).
WALL_THICKNESS_M = 0.02
WALL_HEIGHT_M = 0.10
#: Lane strips stop at least this far (along the edge) from each vertex centre (m).
LANE_END_RADIUS_M = 0.16
#: Spokes: centre-line strips per incident edge from SPOKE_INNER_RADIUS_M to
#: SPOKE_RADIUS_M from the vertex centre (m), found by rotating in place.
SPOKE_RADIUS_M = 0.12
SPOKE_INNER_RADIUS_M = 0.03
#: Walls start at least this far (along the edge) from each vertex centre (m). A robot
#: detects a vertex where its left wall ends and, if another robot is on the vertex, waits
#: there (mjswarm.experiments.exploration, vertex entry): its centre is then 0.26 m from the vertex centre
#: and 0.17 m from the lane of a robot leaving on the neighbouring edge 90 degrees away,
#: more than the 0.15 m two robot bodies need.
VERTEX_CLEAR_RADIUS_M = 0.255
#: Extra gap (m) beyond the point where the offset lines of neighbouring edges meet, used
#: by :func:`wall_setback` and :func:`lane_setback` so neighbouring pieces never touch.
SETBACK_MARGIN_M = 0.02
#: Minimum angle between consecutive edges at a vertex (degrees).
MIN_ANGLE_DEG = 45.0
#: An edge is too short for a robot to follow if either wall, after the setbacks at both
#: ends, is shorter than MIN_WALL_LENGTH_M, or the edge is shorter than MIN_EDGE_LENGTH_M.
MIN_WALL_LENGTH_M = 0.08
MIN_EDGE_LENGTH_M = 0.5
#: A robot at a vertex centre must see no wall: IR range 0.10 m + Spark V radius 0.075 m.
VERTEX_OPEN_RADIUS_M = 0.10 + 0.075


@dataclass(frozen=True)
class Wall:
    """One corridor wall: a box of WALL_THICKNESS_M x WALL_HEIGHT_M on the floor.

    ``start`` and ``end`` are the ends of its centre line (m); ``start`` is the end
    near ``edge[0]``. ``side`` is ``"left"`` or ``"right"`` of ``edge[0] -> edge[1]``.
    """

    start: Point
    end: Point
    edge: tuple[str, str]
    side: str

    @property
    def length(self) -> float:
        """Centre-line length (m)."""
        return math.dist(self.start, self.end)


@dataclass(frozen=True)
class LaneStrip:
    """A lane strip (STRIP_WIDTH_M wide) driven by robots travelling ``travel[0] -> travel[1]``.

    ``start`` (near ``travel[0]``) and ``end`` are the ends of its centre line (m);
    the strip lies to the left of that direction of travel. ``edge`` is the edge as the
    spec lists it.
    """

    start: Point
    end: Point
    edge: tuple[str, str]
    travel: tuple[str, str]


@dataclass(frozen=True)
class Spoke:
    """A centre-line strip (STRIP_WIDTH_M wide) of ``edge`` at ``vertex``, from
    SPOKE_INNER_RADIUS_M (``start``) to SPOKE_RADIUS_M (``end``) from the vertex centre (m)."""

    start: Point
    end: Point
    edge: tuple[str, str]
    vertex: str


def incidence_angle(spec: ArenaSpec, u: str, v: str) -> float:
    """Angle of edge ``u -> v`` measured at ``u`` from +x, counter-clockwise, in [0, 2 pi).

    This is the paper's incidence angle (Nagavarapu et al., Sec. 3, entries of I(vj)), here in
    [0, 2 pi) as the brief asks. Raises ``KeyError`` if ``u``-``v`` is not an edge.
    """
    if (u, v) not in spec.edges and (v, u) not in spec.edges:
        raise KeyError(f"{u}-{v} is not an edge of arena {spec.name!r}")
    return _angle(spec.vertices[u], spec.vertices[v])


def wall_setback(theta: float) -> float:
    """Distance (m, along the edge) from a vertex centre to where a wall starts.

    ``theta`` (rad) is the angle from the edge to the neighbouring edge on the wall's
    side (2 pi at a dead end). The outer faces of the two walls facing each other cross
    at ``h / tan(theta / 2)`` with ``h = CORRIDOR_HALF_WIDTH_M + WALL_THICKNESS_M / 2``;
    the wall starts SETBACK_MARGIN_M beyond that, and never closer than
    VERTEX_CLEAR_RADIUS_M. For theta >= pi the walls diverge and the clear radius rules.
    """
    return _setback(theta, CORRIDOR_HALF_WIDTH_M + WALL_THICKNESS_M / 2, VERTEX_CLEAR_RADIUS_M)


def lane_setback(theta: float) -> float:
    """Distance (m, along the edge) from a vertex centre to where a lane strip starts.

    Same rule as :func:`wall_setback` with ``h = LANE_OFFSET_M + STRIP_WIDTH_M / 2`` and
    floor LANE_END_RADIUS_M, so lanes of neighbouring edges never cross (this only
    exceeds LANE_END_RADIUS_M for theta below about 71 degrees).
    """
    return _setback(theta, LANE_OFFSET_M + STRIP_WIDTH_M / 2, LANE_END_RADIUS_M)


def vertex_fans(spec: ArenaSpec) -> dict[str, list[tuple[float, str]]]:
    """For every vertex, its ``(incidence angle, neighbour)`` pairs sorted counter-clockwise."""
    fans: dict[str, list[tuple[float, str]]] = {u: [] for u in spec.vertices}
    for u, v in spec.edges:
        fans[u].append((_angle(spec.vertices[u], spec.vertices[v]), v))
        fans[v].append((_angle(spec.vertices[v], spec.vertices[u]), u))
    for fan in fans.values():
        fan.sort()
    return fans


def junction_depths(spec: ArenaSpec) -> dict[tuple[str, str], float]:
    """For every directed edge ``(u, v)``: how far (m, along the edge from ``u``'s centre)
    the edge's corridor is still shared with its neighbours at ``u``, up to where both its
    walls have started (:func:`wall_setback` of both side angles). A body stopped nearer
    stands where robots of the other edges turn in and out: the vertex's, not the edge's
    (``mjswarm.experiments.stations``)."""
    return {e: max(wall_setback(left), wall_setback(right))
            for e, (left, right) in side_angles(spec).items()}


def side_angles(spec: ArenaSpec) -> dict[tuple[str, str], tuple[float, float]]:
    """For every directed edge ``(u, v)``: (left, right) neighbour angles at ``u`` (rad).

    ``left`` is the counter-clockwise angle from ``u -> v`` to the next edge around
    ``u``, ``right`` the clockwise one; both are 2 pi when ``u`` has degree 1.
    """
    result: dict[tuple[str, str], tuple[float, float]] = {}
    for u, fan in vertex_fans(spec).items():
        n = len(fan)
        for k, (a, v) in enumerate(fan):
            if n == 1:
                result[(u, v)] = (2 * math.pi, 2 * math.pi)
            else:
                left = (fan[(k + 1) % n][0] - a) % (2 * math.pi)
                right = (a - fan[(k - 1) % n][0]) % (2 * math.pi)
                result[(u, v)] = (left, right)
    return result


def corridor_walls(spec: ArenaSpec) -> list[Wall]:
    """The two walls of every edge, in ``spec.edges`` order, left wall first (m).

    The left wall of ``u -> v`` is set back at ``u`` by the angle to ``u``'s next edge
    counter-clockwise and at ``v`` by the angle to ``v``'s next edge clockwise from
    ``v -> u`` (the same side of the corridor); the right wall symmetrically.
    """
    return [
        Wall(start, end, (u, v), side)
        for u, v, side, start, end in _offset_pieces(
            spec, CORRIDOR_HALF_WIDTH_M, wall_setback
        )
    ]


def lane_strips(spec: ArenaSpec) -> list[LaneStrip]:
    """The two lane strips of every edge, in ``spec.edges`` order (m).

    First the strip for travel ``u -> v`` (left of that direction), then ``v -> u``.
    Each end stops at :func:`lane_setback` of the neighbour angle on its side.
    """
    strips = []
    for u, v, side, start, end in _offset_pieces(spec, LANE_OFFSET_M, lane_setback):
        if side == "left":
            strips.append(LaneStrip(start, end, (u, v), (u, v)))
        else:
            strips.append(LaneStrip(end, start, (u, v), (v, u)))
    return strips


def vertex_spokes(spec: ArenaSpec) -> list[Spoke]:
    """One spoke per edge end, in ``spec.edges`` order: at ``u``, then at ``v`` (m)."""
    spokes = []
    for u, v in spec.edges:
        for a, b in ((u, v), (v, u)):
            pa = np.asarray(spec.vertices[a], float)
            d = _unit(pa, np.asarray(spec.vertices[b], float))
            spokes.append(
                Spoke(
                    _pt(pa + SPOKE_INNER_RADIUS_M * d), _pt(pa + SPOKE_RADIUS_M * d), (u, v), a
                )
            )
    return spokes


# ---------------------------------------------------------------- vectorised geometry


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance from points ``p`` to segments ``a``-``b``; arrays of shape (..., 2)."""
    p, a, b = (np.asarray(x, float) for x in (p, a, b))
    ab = b - a
    denom = np.einsum("...i,...i->...", ab, ab)
    t = np.einsum("...i,...i->...", p - a, ab) / np.where(denom > 0, denom, 1.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def segments_cross(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """True where segment ``a``-``b`` properly crosses ``c``-``d`` (interiors, not touching)."""
    o1, o2 = _cross(b - a, c - a), _cross(b - a, d - a)
    o3, o4 = _cross(d - c, a - c), _cross(d - c, b - c)
    return (o1 * o2 < 0) & (o3 * o4 < 0)


def segment_distance(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance between segments ``a``-``b`` and ``c``-``d``; arrays of shape (..., 2).

    Zero if they cross; otherwise the closest pair involves an endpoint, so it is the
    least of the four endpoint-to-segment distances.
    """
    a, b, c, d = (np.asarray(x, float) for x in (a, b, c, d))
    dist = np.minimum.reduce(
        [
            point_segment_distance(a, c, d),
            point_segment_distance(b, c, d),
            point_segment_distance(c, a, b),
            point_segment_distance(d, a, b),
        ]
    )
    return np.where(segments_cross(a, b, c, d), 0.0, dist)


def candidate_pairs(boxes: np.ndarray) -> np.ndarray:
    """Index pairs ``(i, j)``, ``i < j``, of axis-aligned boxes that overlap (closed).

    ``boxes`` has rows ``(xmin, ymin, xmax, ymax)``. A uniform-grid broad phase (cells
    of at least 1 m, and at least 1/64 of the largest box) keeps this near-linear for
    arenas with thousands of edges. Returns an int array of shape (M, 2), sorted.
    """
    boxes = np.asarray(boxes, float).reshape(-1, 4)
    if len(boxes) < 2:
        return np.empty((0, 2), dtype=np.int64)
    cell = max(1.0, float(np.max(boxes[:, 2:] - boxes[:, :2])) / 64.0)
    lo = np.floor(boxes[:, :2] / cell).astype(np.int64)
    span = np.floor(boxes[:, 2:] / cell).astype(np.int64) - lo + 1
    counts = span[:, 0] * span[:, 1]
    owner = np.repeat(np.arange(len(boxes)), counts)
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    cx = lo[owner, 0] + k % span[owner, 0]
    cy = lo[owner, 1] + k // span[owner, 0]
    order = np.lexsort((owner, cy, cx))
    cx, cy, owner = cx[order], cy[order], owner[order]
    first = np.r_[True, (cx[1:] != cx[:-1]) | (cy[1:] != cy[:-1])]
    starts = np.flatnonzero(first)
    group_end = np.r_[starts[1:], len(owner)][np.cumsum(first) - 1]
    later = group_end - np.arange(len(owner)) - 1
    src = np.repeat(np.arange(len(owner)), later)
    dst = src + 1 + np.arange(later.sum()) - np.repeat(np.cumsum(later) - later, later)
    i, j = owner[src], owner[dst]
    key = np.sort(np.minimum(i, j) * len(boxes) + np.maximum(i, j))
    key = key[np.diff(key, prepend=-1) != 0]  # a pair sharing several cells, once
    pairs = np.stack([key // len(boxes), key % len(boxes)], axis=1)
    a, b = boxes[pairs[:, 0]], boxes[pairs[:, 1]]
    overlap = (a[:, 0] <= b[:, 2]) & (b[:, 0] <= a[:, 2]) & (a[:, 1] <= b[:, 3]) & (
        b[:, 1] <= a[:, 3]
    )
    return pairs[overlap]


def segment_boxes(a: np.ndarray, b: np.ndarray, pad: np.ndarray | float) -> np.ndarray:
    """Axis-aligned boxes ``(xmin, ymin, xmax, ymax)`` of segments ``a``-``b`` grown by ``pad``."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    pad = np.asarray(pad, float).reshape(-1, 1)
    return np.hstack([np.minimum(a, b) - pad, np.maximum(a, b) + pad])


# ---------------------------------------------------------------- helpers


def _setback(theta: float, half_width: float, floor: float) -> float:
    if theta >= math.pi:
        return floor
    return max(floor, half_width / math.tan(theta / 2) + SETBACK_MARGIN_M)


def _offset_pieces(spec: ArenaSpec, offset: float, setback):
    """Yield (u, v, side, start, end) of the pieces offset +-``offset`` from each edge.

    ``start`` is near ``u``; each end is set back by ``setback(theta)`` with theta the
    neighbour angle on that side of the corridor at that vertex.
    """
    angles = side_angles(spec)
    for u, v in spec.edges:
        pu = np.asarray(spec.vertices[u], float)
        pv = np.asarray(spec.vertices[v], float)
        d = _unit(pu, pv)
        n = np.array([-d[1], d[0]])
        length = float(np.linalg.norm(pv - pu))
        u_left, u_right = angles[(u, v)]
        v_left, v_right = angles[(v, u)]
        # The left side of u->v is the right side of v->u.
        for side, sign, theta_u, theta_v in (
            ("left", 1.0, u_left, v_right),
            ("right", -1.0, u_right, v_left),
        ):
            s0, s1 = setback(theta_u), length - setback(theta_v)
            yield u, v, side, _pt(pu + s0 * d + sign * offset * n), _pt(
                pu + s1 * d + sign * offset * n
            )


def _angle(p: Point, q: Point) -> float:
    a = math.atan2(q[1] - p[1], q[0] - p[0]) % (2 * math.pi)
    return 0.0 if a >= 2 * math.pi else a  # -1e-17 % 2pi rounds up to 2pi


def _unit(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    d = q - p
    return d / np.linalg.norm(d)


def _pt(x: np.ndarray) -> Point:
    return (float(x[0]), float(x[1]))


def _cross(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]
