"""``mjswarm arena <action>``: inspect arena specs (``show``) and write MJCF (``export``).

Each action is a ``_register_<action>(actions)`` function adding its parser; ARENA is
anything :func:`mjswarm.arena.load_arena` accepts.
"""

from __future__ import annotations

from mjswarm.arena import load_arena, shipped_arenas
from mjswarm.cli.numbers import whole
from mjswarm.cli.output import atomic_output, check_writable, write_json
from mjswarm.experiments.minds import MAX_ROBOTS

_ARENA_HELP = (
    "a shipped arena ({shipped}), a .json/.toml spec file, or a generator: "
    "lattice:RxC[:SPACING] (R rows, C columns, SPACING in m, default 0.6), "
    "random-tree:E:SEED, random-graph:V:E:SEED, fan:N:DEG[:LEN], wheel:N[:R], "
    "hex:RxC[:SPACING], tri:RxC[:SPACING], random-planar:V:SEED; append @DEG to rotate "
    "the arena about its root"
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "arena",
        help="inspect arena specs (graph of vertex coordinates in m + edges)",
        description="Inspect arena specs: the graph (vertex coordinates in metres, edges) "
        "that the simulated world is built from.",
    )
    actions = parser.add_subparsers(dest="arena_action", metavar="ACTION", required=True)
    _register_show(actions)
    _register_export(actions)


def add_arena_argument(parser, name: str = "arena") -> None:
    """The positional ARENA argument, with help listing what it accepts."""
    parser.add_argument(
        name, metavar="ARENA", help=_ARENA_HELP.format(shipped=", ".join(shipped_arenas()))
    )


def _register_show(actions) -> None:
    parser = actions.add_parser(
        "show",
        help="print an arena's size, root, radius and whether it is a tree",
        description="Load and validate an arena, then print its name, vertex and edge "
        "counts, root, radius from the root (hops), whether it is a tree, and total edge "
        "length (m).",
    )
    add_arena_argument(parser)
    parser.add_argument(
        "--json",
        metavar="PATH",
        help="also write the summary as JSON to PATH ('-' = stdout, replacing the text)",
    )
    parser.set_defaults(func=show)


def show(args) -> int:
    """``mjswarm arena show``: print (or write as JSON) ``ArenaSpec.summary()``."""
    summary = load_arena(args.arena).summary()
    if write_json(summary, args.json):
        return 0
    rows = [
        ("name", summary["name"]),
        ("source", summary["source"]),
        ("vertices", summary["num_vertices"]),
        ("edges", summary["num_edges"]),
        ("root", summary["root"]),
        ("radius", f"{summary['radius_hops']} hops from the root"),
        ("tree", "yes" if summary["is_tree"] else "no"),
        ("total length", f"{summary['total_edge_length_m']:.3f} m"),
    ]
    for key, value in rows:
        print(f"{key:<13}{value}")
    if summary["description"]:
        print(f"{'description':<13}{summary['description']}")
    return 0



def _register_export(actions) -> None:
    parser = actions.add_parser(
        "export",
        help="write an arena as a standalone MJCF file",
        description="Build the arena's MuJoCo world (floor, lane strips, vertex spokes, "
        "corridor walls, a site per vertex) and write it as MJCF that loads in plain "
        "MuJoCo: the scene an embodied exploration starts from. Nothing is written if the "
        "arena is invalid.",
    )
    add_arena_argument(parser)
    parser.add_argument("out", metavar="OUT.xml", help="the MJCF file to write")
    parser.add_argument("--robots", action=whole(least=0, most=MAX_ROBOTS,
                                                 why="the largest team any run takes"),
                        default=0, metavar="K",
                        help="also place K robots in the depot, the row below the arena where "
                             "an embodied exploration's robots wait for their launch "
                             f"(default: 0; at most {MAX_ROBOTS})")
    parser.set_defaults(func=export)


def export(args) -> int:
    """``mjswarm arena export``: write the arena's MJCF, with the robots where an embodied
    exploration puts them before its first launch."""
    from mjswarm.arena.builder import export_mjcf
    from mjswarm.experiments.launching import depot

    check_writable(args.out, "MJCF")
    spec = load_arena(args.arena)
    with atomic_output(args.out, "MJCF") as temp:
        export_mjcf(spec, temp, depot(spec, args.robots))
    print(f"wrote {args.out}")
    return 0
