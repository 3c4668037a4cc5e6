"""Nothing mutable is reachable from two robots' controllers: a robot's knowledge, its
incidence matrix and whatever numbers its bits, is its own or an immutable value. After
a short run of each world, the object graph of every controller of the loop (robots,
and the fixed radio nodes where there are some) is walked: attributes,
``__slots__``, containers, bound methods' objects, to a bounded depth. Values that cannot
change (numbers, strings, bytes, enum members, code) end a path; tuples, frozensets and
frozen dataclasses are walked but may be shared; a read-only mapping view is walked and
the mapping it wraps counts as shared only when some controller also reaches it
directly. Any other object reached from two controllers fails the test, with its paths.
"""

from __future__ import annotations

import enum
import functools
import gc
import numbers
import types
from collections import deque

import numpy as np
import pytest

from mjswarm.arena import load_arena
from mjswarm.worlds.loop import Loop

MAX_DEPTH, MAX_NODES = 14, 200_000

#: values that never change: a path ends at them
VALUES = (type(None), bool, numbers.Number, str, bytes, range, enum.Enum, np.generic,
          type, types.FunctionType, types.BuiltinFunctionType, types.ModuleType,
          types.CodeType, types.MethodDescriptorType, types.WrapperDescriptorType)


def _frozen(obj) -> bool:
    """Whether ``obj`` itself cannot change (what it holds may)."""
    if isinstance(obj, (tuple, frozenset, types.MappingProxyType)):
        return True
    params = getattr(type(obj), "__dataclass_params__", None)
    return params is not None and params.frozen


def _children(obj, path: str):
    """``(child, path, through_view)`` of everything ``obj`` holds."""
    if isinstance(obj, types.MappingProxyType):
        wrapped, = (r for r in gc.get_referents(obj) if hasattr(r, "items"))
        return [(wrapped, f"{path}<wrapped>", True)]
    if isinstance(obj, dict):
        return [*((k, f"{path}[key {k!r}]", False) for k in obj),
                *((v, f"{path}[{k!r}]", False) for k, v in obj.items())]
    if isinstance(obj, (tuple, list, set, frozenset, deque)):
        return [(v, f"{path}[{i}]", False) for i, v in enumerate(obj)]
    if isinstance(obj, types.MethodType):
        return [(obj.__self__, f"{path}.__self__", False)]
    if isinstance(obj, functools.partial):
        return [(obj.func, f"{path}.func", False), (obj.args, f"{path}.args", False),
                (obj.keywords, f"{path}.keywords", False)]
    if isinstance(obj, np.ndarray):
        return [] if obj.base is None else [(obj.base, f"{path}.base", False)]
    names = list(getattr(obj, "__dict__", {}))
    for cls in type(obj).__mro__:
        slots = getattr(cls, "__slots__", ())
        names += [slots] if isinstance(slots, str) else [s for s in slots if s != "__dict__"]
    return [(getattr(obj, n), f"{path}.{n}", False) for n in names if hasattr(obj, n)]


def reachable(root, name: str) -> dict[int, tuple[object, str, bool]]:
    """Every object of ``root``'s graph that can change: id -> (object, a path to it,
    whether it was reached other than through a read-only view)."""
    found: dict[int, tuple[object, str, bool]] = {}
    seen: set[tuple[int, bool]] = set()
    stack, nodes = [(root, name, 0, False)], 0
    while stack and nodes < MAX_NODES:
        obj, path, depth, viewed = stack.pop()
        if isinstance(obj, VALUES) or depth > MAX_DEPTH or (id(obj), viewed) in seen:
            continue
        seen.add((id(obj), viewed))
        nodes += 1
        if not _frozen(obj):
            known = found.get(id(obj))
            if known is None or (known[2] is False and not viewed):
                found[id(obj)] = (obj, path, not viewed)
        stack += [(c, p, depth + 1, v) for c, p, v in _children(obj, path)]
    assert nodes < MAX_NODES, f"{name}: object graph larger than {MAX_NODES} nodes"
    return found


def shared(controllers: dict) -> list[str]:
    """The mutable objects reachable from two controllers, with a path from each."""
    owners: dict[int, list[tuple[str, bool]]] = {}
    for key, controller in controllers.items():
        for i, (_, path, direct) in reachable(controller, f"robot {key}").items():
            owners.setdefault(i, []).append((path, direct))
    return [" and ".join(p for p, _ in paths) for paths in owners.values()
            if len(paths) > 1 and any(direct for _, direct in paths)]


@pytest.fixture
def loops(monkeypatch):
    """Every loop built during the test."""
    built: list[Loop] = []
    init = Loop.__init__

    def recording(self, *args, **kwargs):
        init(self, *args, **kwargs)
        built.append(self)

    monkeypatch.setattr(Loop, "__init__", recording)
    return built


def _nothing_shared(loops, least: int = 2):
    assert loops
    for loop in loops:
        assert len(loop.controllers) >= least
        found = shared(loop.controllers)
        assert found == [], found[:5]


def test_the_walker_finds_a_shared_list_and_passes_values():
    from types import SimpleNamespace

    common, view = [1], types.MappingProxyType({"a": 1})
    a = SimpleNamespace(x=common, v=view, t=(1, "a"), f=frozenset({2}))
    b = SimpleNamespace(y=[0, common], v=view, t=(1, "a"))
    found = shared({0: a, 1: b})
    assert len(found) == 1 and "robot 0.x" in found[0] and "robot 1.y[1]" in found[0]
    b.w = view  # a view both hold of a mapping nobody holds directly: fine
    assert len(shared({0: a, 1: b})) == 1
    a.d = gc.get_referents(view)[0]  # one of them holds the mapping itself
    assert len(shared({0: a, 1: b})) == 2


@pytest.mark.parametrize("strategy", ["incidence-dfs", "bfs", "mr-dfs", "lrv", "flooding"])
def test_graph_world_robots_share_nothing_mutable(loops, strategy):
    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena("lattice:4x4"), 3, strategy, world="graph", seed=0)
    assert result.completed
    _nothing_shared(loops, 3)


def test_radio_graph_world_robots_share_nothing_mutable(loops):
    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena("lattice:4x4"), 5, world="graph", seed=0,
                             radio_range_m=1.3, connectivity="connected")
    assert result.messages > 0
    _nothing_shared(loops, 5)


def test_embodied_robots_share_nothing_mutable(loops):
    from mjswarm.experiments.embodied import EmbodiedConfig
    from mjswarm.experiments.runs import run_exploration

    run_exploration(load_arena("fan:3:45"), 2, world="embodied", seed=0, max_time=20.0,
                    config=EmbodiedConfig(physics="kinematic"))
    _nothing_shared(loops)
