"""The robots' radio: one-hop broadcast within range d_c, delivered one control tick later.

This is the communication model both connectivity papers assume (Ahmadi & Stone, Assumptions 2
and 4; Le et al., section 2): identical ranges (so links are symmetric), a message sent by a
robot is heard by every robot within range d_c of it, and it arrives within one period c,
which here is exactly one control tick. On top of that the radio can drop each copy of a
message with probability ``drop_prob`` (seeded numpy Generator) and can block a link when
line of sight is lost (an injected, vectorised :data:`Blocker`: the embodied world passes
:func:`sight_blocker`, the static harness :func:`walls_blocker`). Per-robot counters give the
papers' message complexities.

One control tick, as the world or the harness drives it::

    radio.step(positions)              # deliver last tick's messages, links from positions
    for robot in robots:
        inbox = radio.receive(robot)   # what arrived this tick
        ...                            # the controller decides
        radio.send(robot, payload)     # heard by robot's neighbours at the next step()

Choices the papers leave open:

* The recipients of a message are fixed when it is sent (the robots within range at the
  last :meth:`Radio.step`); it is delivered at the next ``step`` unless that copy is
  dropped or the recipient has left (:meth:`Radio.remove`).
* A link exists iff the distance is at most d_c (inclusive) and ``blocked`` says it is not
  blocked. Distances are Euclidean over whatever coordinates the positions have (metres);
  the test is ``sum((p_i - p_j)**2) <= d_c**2`` in float64, and a robot with a non-finite
  coordinate has no links.
* Relinking costs O(N + P) for N robots and P in-range pairs (O(N) at bounded density):
  the pairs in range are :meth:`mjswarm.core.neighbours.Neighbours.pairs` (a k-d tree
  proposes, the exact squared-distance test above decides, so the tree's own rounding
  cannot add or lose a link at exactly d_c); an embodied world hands the radio its
  simulation's search (``neighbours=sim.neighbours``), whose tree the bearing sensor
  shares at the same positions. The blocker is called once per relink with every
  in-range pair, in robot order.
* ``send(..., to=j)`` is a broadcast that only robot ``j`` keeps (the papers' table
  exchange and reports): it costs one transmission and reaches ``j`` only if ``j`` is a
  neighbour. Counters count transmissions sent and copies received.
* Drops are decided copy by copy at delivery, in send order and, within a message, in
  robot order, so a run is a pure function of the seed.
* Explicit-edge mode (``edges=...``) replaces the range by a given link set, for the static
  harness and tests; :meth:`Radio.set_edges` changes it.
* Payloads are immutable values (:func:`check_immutable`): one message object is handed to
  every robot that hears it, so a list or a dict in it would be shared state between robots.
  :meth:`Radio.send` and the :class:`Uplink` refuse anything else.
* Delivery is by arrays: a tick's copies are (message, recipient) index pairs, built from
  the link table without a Python step per copy; presence, blackouts and drops are masks
  over them (drop draws ``rng.random(copies)`` in the order above: the same stream, and so
  the same drops, as one draw per copy); counters add up by ``bincount``; a robot's inbox
  is cut from the sorted copies when it asks (``tests/test_radio_arrays.py`` checks
  deliveries and counters against copy-by-copy delivery on random cases).
"""

from __future__ import annotations

import math
import dataclasses
import enum
from itertools import repeat
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import networkx as nx
import numpy as np
from algorithms.robot import NOTHING, Message
from mjswarm.core.neighbours import Neighbours
from mjswarm.errors import MjswarmError

if TYPE_CHECKING:  # the embodied worlds' radio model (sight_blocker) asks the simulation
    from mjswarm.core.simulation import Simulation

#: ``blocked(pairs) -> mask``: for an (M, 2) array of robot-id pairs ``(i, j)`` (int64 when
#: every id is an int, else objects), a bool array with one entry per pair, True when i and
#: j cannot hear each other (no line of sight).
Blocker = Callable[[np.ndarray], np.ndarray]
#: A robot's radio antenna above the floor (m), where the line-of-sight rays start and
#: end: above the wheels (0.05 m), inside the chassis (0.012..0.07 m).
ANTENNA_HEIGHT_M = 0.06
#: Height (m) of the base station's antenna at the root: above the robots (0.07 m tall),
#: so that a robot standing on the root does not shadow the others; walls still block.
BASE_MAST_M = 1.0
#: A link whose line of sight passes within this (m) of a wall fades: it still carries
#: messages, but the robots' ranging gets no fix through it (the first Fresnel zone of
#: a 2.4 GHz link over metres is tens of centimetres wide, and ultra-wideband ranging
#: through a shadowed zone is unreliable). A robot driving at its top speed (0.2 m/s)
#: crosses it in a quarter of a second, so one that treats a faded parent as a lost one
#: (the tether's leash, :mod:`algorithms.exploration.leash`) backs off before the link
#: itself is cut.
FADE_MARGIN_M = 0.02
#: Above a wall's top a link fades within this (m): the line from the base's mast comes
#: down steeply only near the robot, and there a step of the robot moves its height at
#: the wall by a fraction of the step; a full margin there fades links that never cut
#: (``arena1``, 2 robots at 3 m: a line 1.6 cm over a wall stalled a robot for good).
FADE_TOP_M = 0.005

# ------------------------------------------------------------------ immutable payloads
_ATOM, _SEQUENCE, _FIELDS, _HANDLE = range(4)
#: what each type is, found once per type: an immutable atom, an immutable sequence of
#: values (tuple, NamedTuple, frozenset), a frozen dataclass (its fields), or refused (None)
_KINDS: dict[type, tuple[int, tuple[str, ...]] | None] = {
    t: (_ATOM, ()) for t in (type(None), bool, int, float, complex, str, bytes, range,
                             type(Ellipsis), type(NotImplemented))}


def _kind(t: type) -> tuple[int, tuple[str, ...]] | None:
    found = _KINDS.get(t, False)
    if found is not False:
        return found
    if issubclass(t, (np.generic, enum.Enum)):
        found = (_ATOM, ())
    elif issubclass(t, (tuple, frozenset)):
        found = (_SEQUENCE, ())
    elif dataclasses.is_dataclass(t) and t.__dataclass_params__.frozen:
        found = (_FIELDS, tuple(f.name for f in dataclasses.fields(t)))
    else:
        found = None
    _KINDS[t] = found
    return found


def check_immutable(value: Any, what: str = "radio payload") -> None:
    """Raise :class:`MjswarmError` unless ``value`` is an immutable value: None, bool, int,
    float, complex, str, bytes, a numpy scalar, an Enum member, or a tuple (NamedTuple),
    frozenset or frozen dataclass made of such values, at any depth. A list, dict, set,
    bytearray, numpy array, non-frozen dataclass or any other object is refused. The kind
    of each type is found once and kept, so a check costs a dictionary look-up per value.
    """
    stack = [value]
    while stack:
        v = stack.pop()
        kind = _KINDS.get(type(v), False)
        if kind is False:
            kind = _kind(type(v))
        if kind is None:
            raise MjswarmError(
                f"{what} must be an immutable value (tuple, frozenset, NamedTuple, frozen "
                f"dataclass, number, str...), not {type(v).__qualname__}: {_short(v)}")
        if kind[0] == _SEQUENCE:
            stack.extend(v)
        elif kind[0] == _FIELDS:
            stack.extend(getattr(v, name) for name in kind[1])


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."



#: Longest radio range (m): arenas and floors lie within a kilometre or so of the origin,
#: so a longer range reaches every robot all the same.
MAX_RANGE_M = 10_000.0


def _check_options(range_m: float | None, edges, drop_prob: float) -> None:
    """Refuse, in one line, a radio with both or neither of a range (m) and explicit
    edges, a range that is not a positive number up to :data:`MAX_RANGE_M`, or a drop
    probability outside [0, 1)."""
    if (range_m is None) == (edges is None):
        raise MjswarmError("radio: give exactly one of a range (metres) or explicit edges")
    if range_m is not None and not (math.isfinite(range_m) and 0 < range_m <= MAX_RANGE_M):
        raise MjswarmError(f"radio: range must be a positive number of metres up to "
                           f"{MAX_RANGE_M:g}, got {range_m}")
    if not 0.0 <= drop_prob < 1.0:
        raise MjswarmError(f"radio: drop probability must be in [0, 1), got {drop_prob}")


def _id_array(robots: Sequence[Hashable]) -> np.ndarray:
    """The robot ids as an array: int64 when every id is an int, else objects."""
    if all(isinstance(r, (int, np.integer)) for r in robots):
        return np.array(robots, dtype=np.int64)
    ids = np.empty(len(robots), dtype=object)
    for k, r in enumerate(robots):
        ids[k] = r
    return ids


class Radio:
    """Broadcast radio with range d_c (or explicit links), one-tick latency, drops, counters.

    Args:
        robots: robot ids, in the order used for deterministic delivery.
        range_m: communication range d_c in metres (range mode).
        edges: explicit links ``(i, j)`` instead of a range (explicit-edge mode).
        blocked: optional vectorised line-of-sight test (:data:`Blocker`), asked once per
            relink with all in-range pairs.
        drop_prob: probability in [0, 1) that one copy of a message is lost.
        rng: numpy Generator or seed for the drops.
        neighbours: the search for pairs in range (default the radio's own); a world
            passes its simulation's, shared with the bearing sensor.

    Exactly one of ``range_m`` and ``edges`` must be given.
    """

    def __init__(
        self,
        robots: Iterable[Hashable],
        *,
        range_m: float | None = None,
        edges: Iterable[tuple[Hashable, Hashable]] | None = None,
        blocked: Blocker | None = None,
        drop_prob: float = 0.0,
        rng: np.random.Generator | int | None = None,
        neighbours: Neighbours | None = None,
    ) -> None:
        self.robots: tuple[Hashable, ...] = tuple(robots)
        self._index: dict[Hashable, int] = {r: k for k, r in enumerate(self.robots)}
        self._ids = _id_array(self.robots)
        if len(self._index) != len(self.robots):
            raise MjswarmError("radio: duplicate robot ids")
        _check_options(range_m, edges, drop_prob)
        self.range_m = range_m
        self.blocked = blocked
        self._near = Neighbours() if neighbours is None else neighbours
        self.drop_prob = float(drop_prob)
        self._rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        self._present: dict[Hashable, None] = dict.fromkeys(self.robots)
        self._on_air = np.ones(len(self.robots), bool)  # _present as a mask, by index
        self._neighbors: dict[Hashable, frozenset] = {r: frozenset() for r in self.robots}
        self._ordered: dict[Hashable, tuple] = {r: () for r in self.robots}
        self._links: np.ndarray | None = None  # the index pairs the two dicts were built from
        #: the same links as arrays: robot k's neighbours, by index and in robot order,
        #: are ``table[0][table[1][k]:table[1][k + 1]]`` (replaced, never changed, on relink)
        self._table: tuple[np.ndarray, np.ndarray] = (np.empty(0, np.intp),
                                                      np.zeros(len(self.robots) + 1, np.intp))
        self._edges: frozenset[frozenset] | None = None
        self._xy: np.ndarray | None = None  # positions (metres), one row per robot, in order
        #: this tick's transmissions: (message, link table at sending, sender index,
        #: addressee index: -1 everybody who hears it, -2 nobody), or a team's broadcast
        #: (:meth:`send_all`): (its messages as a list, the table, the senders' indices, -1)
        self._outbox: list[tuple] = []
        #: the last team broadcast (:meth:`send_all`): payload, the present robots then,
        #: senders, messages and the senders' indices; immutable messages, reused while a
        #: team sends the same payload object from the same senders (a heartbeat)
        self._broadcast: tuple | None = None
        self._inbox: dict[Hashable, list[Message]] = {r: [] for r in self.robots}
        self._filled: set[Hashable] = set()  # robots whose ``_inbox`` is not empty
        #: the last delivery, cut per robot when it asks: messages, message index of each
        #: copy sorted by recipient, each robot's slice of them, who has not asked yet
        self._batch: tuple[list, np.ndarray, list] | None = None
        self._unread = np.zeros(len(self.robots), bool)
        self._received = np.zeros(len(self.robots), np.int64)
        #: transmissions per robot (one per :meth:`send`)
        self.sent: dict[Hashable, int] = dict.fromkeys(self.robots, 0)
        #: copies lost to ``drop_prob`` or a blackout
        self.dropped = 0
        #: while True, every copy is lost (fault injection: a radio blackout)
        self.blackout = False
        #: number of :meth:`step` calls so far
        self.tick = 0
        #: transmissions the last :meth:`step` delivered (those sent in the tick before it)
        self.last_batch = 0
        if edges is not None:
            self.set_edges(edges)

    # -- topology ---------------------------------------------------------------------
    def set_edges(self, edges: Iterable[tuple[Hashable, Hashable]]) -> None:
        """Explicit-edge mode: replace the link set (takes effect immediately)."""
        if self.range_m is not None:
            raise MjswarmError("radio: set_edges needs a radio built with explicit edges")
        links = set()
        for i, j in edges:
            if i not in self._inbox or j not in self._inbox:
                raise MjswarmError(f"radio: edge ({i}, {j}) names an unknown robot")
            if i != j:
                links.add(frozenset((i, j)))
        self._edges = frozenset(links)
        self._relink()

    def remove(self, robot: Hashable) -> None:
        """The robot leaves (crash or recall): no links, nothing more sent to or by it."""
        # a new dict, never changed in place (``restore`` too): a cached broadcast
        # (:meth:`send_all`) knows the roster it was checked against by identity
        self._present = {r: None for r in self._present if r != robot}
        self._on_air[self._index[robot]] = False
        self._outbox = [self._without(e, robot) if type(e[0]) is list else e
                        for e in self._outbox if type(e[0]) is list or e[0].sender != robot]
        self._inbox[robot].clear()
        self._filled.discard(robot)
        self._unread[self._index[robot]] = False  # what it had not read is lost
        self._relink()

    def restore(self, robot: Hashable) -> None:
        """A removed robot is back on the air (an empty inbox; links at the next relink)."""
        if robot not in self._inbox:
            raise MjswarmError(f"radio: robot {robot!r} is not one of this radio's robots")
        if robot not in self._present:
            self._present = {r: None for r in self.robots if r in self._present or r == robot}
            self._on_air[self._index[robot]] = True

    def neighbors(self, robot: Hashable) -> frozenset:
        """Robots that hear ``robot`` this tick (link-layer knowledge, no message cost)."""
        return self._neighbors[robot]

    def graph(self) -> nx.Graph:
        """The current radio graph of present robots (node attribute ``pos`` if known)."""
        g = nx.Graph()
        for r in self._present:
            g.add_node(r, **({} if self._xy is None else {"pos": tuple(self._xy[self._index[r]])}))
        g.add_edges_from((i, j) for i in self._present for j in self._neighbors[i])
        return g

    @property
    def present(self) -> tuple[Hashable, ...]:
        """Robots still in the team, in the radio's order."""
        return tuple(self._present)

    # -- one control tick -------------------------------------------------------------
    def step(self, positions: Mapping[Hashable, Sequence[float]] | None = None) -> None:
        """Advance one control tick: deliver last tick's messages, then update the links.

        ``positions`` (metres) must cover every present robot in range mode; ``None`` keeps
        the previous positions (static harness) and is the only choice in explicit mode.
        """
        self.tick += 1
        self._deliver()
        if positions is not None:
            self.move(positions)
        elif self.range_m is not None and self._xy is None:
            raise MjswarmError("radio: range mode needs positions at the first step")

    def move(self, positions: Mapping[Hashable, Sequence[float]] | np.ndarray) -> None:
        """Range mode: set the robots' positions (metres) and recompute the links now.

        ``positions`` maps every present robot to its coordinates, or is an array with one
        row per robot in :attr:`robots` order (rows of absent robots are ignored).
        """
        if self.range_m is None:
            raise MjswarmError("radio: explicit-edge mode takes no positions")
        if isinstance(positions, np.ndarray):
            if positions.ndim != 2 or len(positions) != len(self.robots):
                raise MjswarmError(f"radio: positions of shape {positions.shape} for "
                                   f"{len(self.robots)} robots")
            self._xy = positions.astype(float)
        else:
            missing = [r for r in self._present if r not in positions]
            if missing:
                raise MjswarmError(f"radio: no position for robot {missing[0]!r}")
            rows = [np.asarray(positions[r], dtype=float) for r in self._present]
            self._xy = np.full((len(self.robots), len(rows[0]) if rows else 2), np.nan)
            for r, row in zip(self._present, rows):
                self._xy[self._index[r]] = row
        self._relink()

    def send(self, sender: Hashable, payload: Any, to: Hashable | None = None) -> None:
        """Transmit ``payload`` to the sender's current neighbours (or only ``to``)."""
        if sender not in self._present:
            raise MjswarmError(f"radio: robot {sender!r} is not in the team")
        check_immutable(payload)
        self.sent[sender] += 1
        if to is None:
            addressee = -1
        else:
            addressee = self._index[to] if to in self._neighbors[sender] else -2
        self._outbox.append((Message(payload, to, sender), self._table, self._index[sender], addressee))

    def send_all(self, senders: Sequence[Hashable], payload: Any) -> None:
        """Every robot of ``senders`` broadcasts ``payload``: as :meth:`send` once per
        sender, in this order (a team's heartbeat), with one immutability check."""
        present, sent = self._present, self.sent
        cached = self._broadcast
        if (cached is not None and cached[0] is payload and cached[1] is present
                and cached[2] == senders):  # the heartbeat of the tick before: its messages
            messages, rows = cached[3], cached[4]
        else:
            check_immutable(payload)
            for sender in senders:
                if sender not in present:
                    raise MjswarmError(f"radio: robot {sender!r} is not in the team")
            messages = list(map(Message._make, zip(repeat(payload), repeat(None), senders)))
            rows = np.fromiter(map(self._index.__getitem__, senders), np.intp, len(senders))
            rows.flags.writeable = False
            self._broadcast = (payload, present, list(senders), messages, rows)
        for sender in senders:
            sent[sender] += 1
        self._outbox.append((messages, self._table, rows, -1))

    def receive_all(self, robots: Sequence[Hashable]) -> tuple[list[Message], np.ndarray, np.ndarray]:
        """Drain the inboxes of ``robots`` at once, as :meth:`receive` for each in turn:
        the messages (each once), the index of each copy into them, robot by robot in
        delivery order, and each robot's bounds in those copies, shape (len(robots) + 1,)
        (:class:`~algorithms.batch.Readings`' inbox)."""
        if self._batch is None or not self._filled.isdisjoint(robots):  # leftovers: one by one
            inboxes = [self.receive(r) for r in robots]
            messages = [m for inbox in inboxes for m in inbox]
            return (messages, np.arange(len(messages)),
                    np.cumsum([0] + [len(inbox) for inbox in inboxes]))
        k = np.array([self._index[r] for r in robots], np.intp)
        messages, copies, bounds = self._batch
        bounds = np.asarray(bounds)
        start = bounds[k]
        count = np.where(self._unread[k], bounds[k + 1] - start, 0)
        self._unread[k] = False
        first = np.cumsum(count) - count
        at = np.repeat(start - first, count) + np.arange(int(count.sum()))
        return messages, copies[at], np.concatenate([[0], np.cumsum(count)])

    def receive(self, robot: Hashable) -> list[Message]:
        """Drain and return what ``robot`` has received (in delivery order)."""
        inbox = self._inbox[robot]
        if inbox:
            self._inbox[robot] = []
            self._filled.discard(robot)
        else:
            inbox = []
        k = self._index[robot]
        if self._unread[k]:
            self._unread[k] = False
            messages, copies, bounds = self._batch
            inbox += map(messages.__getitem__, copies[bounds[k]:bounds[k + 1]].tolist())
        return inbox

    @property
    def received(self) -> dict[Hashable, int]:
        """Copies received per robot (a fresh dict)."""
        return dict(zip(self.robots, self._received.tolist()))

    @property
    def pending(self) -> int:
        """Transmissions sent this tick and not yet delivered."""
        return sum(len(e[0]) if type(e[0]) is list else 1 for e in self._outbox)

    @property
    def total_sent(self) -> int:
        """All transmissions so far (the papers' message count)."""
        return sum(self.sent.values())

    # -- internals ----------------------------------------------------------------------
    def _deliver(self) -> None:
        outbox, self._outbox = self._outbox, []
        messages = []
        for entry in outbox:  # every transmission's message, in send order
            if type(entry[0]) is list:
                messages += entry[0]
            else:
                messages.append(entry[0])
        self.last_batch = len(messages)
        self._fold_unread()
        if all(not len(entry[1][0]) for entry in outbox):  # nothing sent, or nobody linked
            return
        message, recipient = self._copies(outbox)
        keep = self._on_air[recipient]
        message, recipient = message[keep], recipient[keep]
        if self.blackout or self.drop_prob:
            lost = (np.ones(len(recipient), bool) if self.blackout
                    else self._rng.random(len(recipient)) < self.drop_prob)
            self.dropped += int(lost.sum())
            message, recipient = message[~lost], recipient[~lost]
        if not len(recipient):
            return
        counts = np.bincount(recipient, minlength=len(self.robots))
        self._received += counts
        order = np.argsort(recipient, kind="stable")  # per recipient, in send order
        bounds = np.concatenate([[0], np.cumsum(counts)]).tolist()
        self._batch = (messages, message[order], bounds)
        self._unread = counts > 0

    def _copies(self, outbox: list[tuple]) -> tuple[np.ndarray, np.ndarray]:
        """Every copy of the outbox's messages as (message index, recipient index), in send
        order and, within a message, in robot order: the senders' neighbours in the link
        table of their sending (or the one addressee that hears it). A team's broadcast
        counts as its senders' transmissions, one after another."""
        tables: dict[int, int] = {}  # id(table) -> its offset in the joined neighbour lists
        parts: list[np.ndarray] = []
        size = 0
        start, count = [], []  # per transmission, in runs between teams' broadcasts
        pieces: list = []  # the runs and the teams' (start, count) arrays, in send order
        for first, table, sender, addressee in outbox:
            offset = tables.get(id(table))
            if offset is None:
                offset = tables[id(table)] = size
                parts.append(table[0])
                size += len(table[0])
            if addressee == -1 and type(first) is list:
                bounds = table[1]
                pieces += [(start, count), (offset + bounds[sender], bounds[sender + 1] - bounds[sender])]
                start, count = [], []
            elif addressee == -1:
                bounds = table[1]
                start.append(offset + bounds[sender])
                count.append(bounds[sender + 1] - bounds[sender])
            elif addressee >= 0:
                start.append(size)
                count.append(1)
                parts.append(np.array([addressee], np.intp))
                size += 1
            else:
                start.append(0)
                count.append(0)
        pieces.append((start, count))
        joined = np.concatenate(parts) if len(parts) > 1 else parts[0]
        start_a = np.concatenate([np.asarray(s, np.intp) for s, _ in pieces])
        count_a = np.concatenate([np.asarray(c, np.intp) for _, c in pieces])
        total = int(count_a.sum())
        message = np.repeat(np.arange(len(count_a)), count_a)
        first_copy = np.cumsum(count_a) - count_a
        at = np.repeat(start_a - first_copy, count_a) + np.arange(total)
        return message, joined[at]

    def _without(self, entry: tuple, robot: Hashable) -> tuple:
        """A team's broadcast (an outbox entry of :meth:`send_all`) without ``robot``'s."""
        keep = entry[2] != self._index[robot]
        return ([m for m, kept in zip(entry[0], keep.tolist()) if kept], entry[1], entry[2][keep], -1)

    def _fold_unread(self) -> None:
        """Copies of the last delivery that nobody asked for yet join their inboxes."""
        if self._batch is not None and self._unread.any():
            for k in np.flatnonzero(self._unread).tolist():
                self._unread[k] = False
                messages, copies, bounds = self._batch
                self._filled.add(self.robots[k])
                self._inbox[self.robots[k]] += map(messages.__getitem__,
                                                   copies[bounds[k]:bounds[k + 1]].tolist())
        self._batch = None

    def _relink(self) -> None:
        if self.range_m is None:
            pairs = [tuple(e) for e in self._edges or () if all(r in self._present for r in e)]
            ij = np.array([[self._index[i], self._index[j]] for i, j in pairs], dtype=np.intp)
        else:
            ij = self._pairs_in_range()
        self._set_links(ij.reshape(-1, 2))

    def _pairs_in_range(self) -> np.ndarray:
        """Linked pairs in range mode, as robot indices ``(k, l)``, k < l, sorted."""
        if self._xy is None or len(self._present) < 2:  # nobody to link
            return np.empty((0, 2), dtype=np.intp)
        if len(self._present) == len(self.robots):
            rows = np.arange(len(self.robots))
        else:
            rows = np.array([self._index[r] for r in self._present], dtype=np.intp)
        xy = self._xy[rows]
        finite = np.isfinite(xy).all(axis=1)
        if not finite.all():
            xy, rows = xy[finite], rows[finite]
        ij = rows[self._near.pairs(xy, self.range_m)]  # sorted: ``rows`` increases
        if self.blocked is not None and len(ij):
            cut = np.asarray(self.blocked(self._ids[ij]), dtype=bool)
            if cut.shape != (len(ij),):
                raise MjswarmError(
                    f"radio: the blocker returned shape {cut.shape} for {len(ij)} pairs"
                )
            ij = ij[~cut]
        return ij

    def _set_links(self, ij: np.ndarray) -> None:
        """Neighbour sets and, per robot, its neighbours in robot order, from index pairs
        (kept as they are when the pairs did not change, as between most ticks)."""
        if self._links is not None and np.array_equal(ij, self._links):
            return
        self._links = ij
        src = np.concatenate([ij[:, 0], ij[:, 1]])
        dst = np.concatenate([ij[:, 1], ij[:, 0]])
        order = np.lexsort((dst, src))
        bounds_a = np.searchsorted(src[order], np.arange(len(self.robots) + 1))
        self._table = (dst[order].astype(np.intp), bounds_a.astype(np.intp))
        bounds = bounds_a.tolist()
        names = [self.robots[k] for k in dst[order].tolist()]
        self._ordered = {
            r: tuple(names[bounds[k] : bounds[k + 1]]) for k, r in enumerate(self.robots)
        }
        self._neighbors = {r: frozenset(t) for r, t in self._ordered.items()}


class Uplink:
    """The link between the robots and one piece of infrastructure at ``address`` (the
    vertex stations: Nagavarapu et al.'s central station over XBee): every robot reaches it from
    anywhere, one control tick each way, no drops; counted both ways.

    Robots send with ``Message(payload, to=address)``; the world hands those to
    :meth:`send` and, at the end of each tick, calls :meth:`step`; the station reads
    :meth:`receive` and answers with :meth:`reply`, which the robot reads a tick later.
    """

    def __init__(self, address: Hashable) -> None:
        self.address = address
        self._up: list[Message] = []
        self._down: list[Message] = []
        self._station_inbox: list[Message] = []
        self._robot_inbox: dict[Hashable, list[Message]] = {}
        #: messages from robots, and replies to robots
        self.sent_up = 0
        self.sent_down = 0

    def send(self, robot: Hashable, payload: Any) -> None:
        """A robot's message to the station."""
        check_immutable(payload, "station message")
        self._up.append(Message(payload, self.address, robot))
        self.sent_up += 1

    def reply(self, robot: Hashable, payload: Any) -> None:
        """The station's message to one robot."""
        check_immutable(payload, "station message")
        self._down.append(Message(payload, robot, self.address))
        self.sent_down += 1

    def step(self) -> None:
        """End of a tick: deliver what was sent in it."""
        self._station_inbox += self._up
        for m in self._down:
            self._robot_inbox.setdefault(m.to, []).append(m)
        self._up, self._down = [], []

    def receive(self) -> list[Message]:
        """Drain the station's inbox."""
        inbox, self._station_inbox = self._station_inbox, []
        return inbox

    def receive_for(self, robot: Hashable) -> list[Message]:
        """Drain one robot's replies."""
        return self._robot_inbox.pop(robot, [])


def walls_blocker(
    walls: Iterable[tuple[Sequence[float], Sequence[float]]],
    positions: Mapping[Hashable, Sequence[float]],
) -> Blocker:
    """Line of sight for the static harness: 2-D wall segments block a link.

    Returns a :data:`Blocker`: for each pair ``(i, j)``, True when the segment between the
    positions of robots i and j (read from ``positions`` at call time, metres, x and y) meets
    any wall segment, touching included (the orientation test with collinear-overlap cases),
    computed for all pairs x walls at once by numpy broadcasting. The embodied world uses
    :func:`sight_blocker` instead.
    """
    w = np.asarray([(a[0], a[1], b[0], b[1]) for a, b in walls], dtype=float).reshape(-1, 4)
    c, d = w[None, :, 0:2], w[None, :, 2:4]  # (1, walls, 2)

    def cross(o: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (
            q[..., 0] - o[..., 0]
        )

    def on_segment(o: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        # q collinear with o-p: is it within the bounding box of o-p?
        return (np.minimum(o[..., 0], p[..., 0]) <= q[..., 0]) & (
            q[..., 0] <= np.maximum(o[..., 0], p[..., 0])
        ) & (np.minimum(o[..., 1], p[..., 1]) <= q[..., 1]) & (
            q[..., 1] <= np.maximum(o[..., 1], p[..., 1])
        )

    def blocked(pairs: np.ndarray) -> np.ndarray:
        if not len(w) or not len(pairs):
            return np.zeros(len(pairs), dtype=bool)
        ends = np.array(
            [(positions[i][:2], positions[j][:2]) for i, j in pairs], dtype=float
        )  # (pairs, 2 ends, 2)
        a, b = ends[:, None, 0], ends[:, None, 1]  # (pairs, 1, 2)
        d1, d2 = cross(c, d, a), cross(c, d, b)
        d3, d4 = cross(a, b, c), cross(a, b, d)
        proper = (d1 * d2 < 0) & (d3 * d4 < 0)
        touch = (
            ((d1 == 0) & on_segment(c, d, a))
            | ((d2 == 0) & on_segment(c, d, b))
            | ((d3 == 0) & on_segment(a, b, c))
            | ((d4 == 0) & on_segment(a, b, d))
        )
        return np.any(proper | touch, axis=1)

    return blocked


def sight_blocker(sim: Simulation, fixed: Mapping[Hashable, tuple[float, float]] = NOTHING,
                  mast_m: float = 0.0) -> Blocker:
    """The radio's line-of-sight test on a simulation: a link between robots i and j is
    blocked unless each sees the other (:attr:`Simulation.sight` both ways); a link
    between a robot and a fixed node (a base station at ``fixed[address]``, m, its antenna
    ``mast_m`` above the floor, or a robot docked at it) unless the robot is seen from the
    antenna; two fixed nodes always link."""

    def between_robots(pairs: np.ndarray) -> np.ndarray:
        i, j = np.asarray(pairs, np.int64).reshape(-1, 2).T
        # both ways in one cast: the way back of a blocked way there is not needed, but
        # one call costs less than merging a second one into the state's answers, and the
        # bearing sensor then finds its pairs in range already answered
        seen = sim.sight(np.concatenate([i, j]), np.concatenate([j, i]))
        return ~(seen[:len(i)] & seen[len(i):])

    if not fixed:
        return between_robots

    def blocked(pairs: np.ndarray) -> np.ndarray:
        pairs = np.asarray(pairs).reshape(-1, 2)
        cut = np.zeros(len(pairs), bool)
        robots = np.array([not (a in fixed or b in fixed) for a, b in pairs], bool)
        if robots.any():
            cut[robots] = between_robots(pairs[robots])
        for k in np.flatnonzero(~robots):
            a, b = pairs[k]
            node, robot = (a, b) if a in fixed else (b, a)
            if robot not in fixed:  # two masts see each other
                cut[k] = not sim.sight.from_point(fixed[node], [robot], mast_m)[0]
        return cut

    return blocked
