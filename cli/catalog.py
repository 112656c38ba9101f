"""``aeroexec catalog``: list the behaviors of a catalog (names without regard to case), its predicates
(``--predicates``), the simulator's worlds (``--worlds``), or check a catalog file and report every problem."""

from __future__ import annotations

import argparse
import logging
import sys
import textwrap
from pathlib import Path

from aeroexec.engine.catalog import BehaviorCatalog, default_catalog_path, load_catalog
from aeroexec.engine.errors import CatalogError, Problem
from aeroexec.flight.robot import chosen_catalog


def add_arguments(parser: argparse.ArgumentParser) -> None:
    behaviors = parser.add_argument("behaviors", nargs="*", metavar="BEHAVIOR",
                                    help="show only these behaviors (any case: take_off is TAKE_OFF)")
    behaviors.completer = _behavior_names  # type: ignore[attr-defined]  # argcomplete
    parser.add_argument("--catalog", metavar="FILE", help="the catalog to list (default: the aerial catalog)")
    parser.add_argument("--check", metavar="FILE", help="validate a catalog file: print every error and warning "
                                                        "with file:line; exit 1 when there are errors")
    parser.add_argument("--predicates", action="store_true",
                        help="list the belief predicates missions may use: arity, computed or stored, meaning")
    parser.add_argument("--worlds", action="store_true",
                        help="list the simulator's worlds (for run/verify --world): bounds, obstacles, markers")


def _behavior_names(prefix: str, parsed_args: argparse.Namespace, **_: object) -> list[str]:
    catalog = chosen_catalog(getattr(parsed_args, "catalog", None))
    return [name for name in catalog.behaviors if name.startswith(prefix.upper())]


def run(args: argparse.Namespace) -> int:
    """The command: the catalog's own problems are printed below, not logged (the logger's level is put back after,
    for a program that called the command in its own process)."""
    logger = logging.getLogger("aeroexec.engine.catalog")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        return _run(args)
    finally:
        logger.setLevel(level)


def _run(args: argparse.Namespace) -> int:
    if args.check:
        return _check(args.check)
    if args.worlds:
        print(worlds_listing())
        return 0
    catalog = chosen_catalog(args.catalog)
    for warning in catalog.warnings:
        print(warning, file=sys.stderr)
    if args.predicates:
        print(predicates_listing(catalog))
        return 0
    names = [name.upper() for name in args.behaviors]
    unknown = [name for name, given in zip(names, args.behaviors, strict=True) if name not in catalog]
    for name in unknown:
        print(f"The behavior {name} does not exist{catalog.suggest(name)}", file=sys.stderr)
    if unknown:
        return 1
    print(listing(catalog, names or None))
    return 0


def predicates_listing(catalog: BehaviorCatalog) -> str:
    """The catalog's predicates: ``name/arity``, computed or stored (with persistence), and their meaning."""
    predicates = sorted(catalog.predicates.values(), key=lambda p: p.name)
    width = max((len(f"{p.name}/{p.arity}") for p in predicates), default=0)
    lines = [f"{catalog.source or default_catalog_path()}: {len(predicates)} predicates", ""]
    for p in predicates:
        kind = "computed" if p.computed else "derived" if p.derived else "stored" + (
            f", forgotten after {p.persistence:g} s" if p.persistence is not None else "")
        kind += ", several values" if p.multivalued and not p.derived else ""
        lines.append(f"{p.name + '/' + str(p.arity):<{width}}  ({kind})" + (f"  {p.description}"
                                                                             if p.description else ""))
    return "\n".join(lines)


def worlds_listing() -> str:
    """The worlds that ship with the simulator: file, bounds, obstacles and markers."""
    from aeroexec.drones.sim import default_world, load_world

    folder = Path(default_world().source or "").parent
    lines = []
    for path in sorted(folder.glob("*.yaml")):
        world = load_world(path)
        lower, upper = world.bounds.lower, world.bounds.upper
        size = " x ".join(f"{hi - lo:g}" for lo, hi in zip(lower, upper, strict=True))
        default = " (default)" if path.name == "default_world.yaml" else ""
        lines += [f"{world.name}{default}: {path}", f"    bounds {size} m, from {tuple(lower)} to {tuple(upper)}",
                  f"    obstacles: {', '.join(o.name for o in world.obstacles) or 'none'}",
                  f"    markers: {', '.join(str(m.id) for m in world.markers) or 'none'}"]
    return "\n".join(lines)


def _check(path: str) -> int:
    try:
        catalog = load_catalog(path)
    except CatalogError as exc:
        for problem in exc.problems:
            print(problem)
        errors, warnings = len(exc.errors), len(exc.problems) - len(exc.errors)
        print(f"{path}: {errors} error{'s' if errors != 1 else ''}, {warnings} warning{'s' if warnings != 1 else ''}")
        return 1
    unserved = [Problem("warning", f"the behavior {name} has no implementation in the behavior library: "
                                   f"missions using it are refused", path, catalog.behaviors[name].line)
                for name in sorted(chosen_catalog(path).unsupported)]
    for problem in [*catalog.warnings, *unserved]:
        print(problem)
    warnings = len(catalog.warnings) + len(unserved)
    print(f"{path}: {len(catalog)} behaviors, no errors, {warnings} warning{'s' if warnings != 1 else ''}")
    return 0


def listing(catalog: BehaviorCatalog, names: list[str] | None = None) -> str:
    """The behaviors as text: name, category, timeout, arguments with their allowed values."""
    source = catalog.source or str(default_catalog_path())
    lines = [f"{source}: {len(catalog)} behaviors", ""]
    for behavior in catalog:
        if names and behavior.name not in names:
            continue
        timeout = f", timeout {behavior.timeout:g} s" if behavior.timeout is not None else ""
        lines.append(f"{behavior.name}  ({behavior.category}{timeout})")
        if behavior.description:
            lines += textwrap.wrap(behavior.description, 100, initial_indent="    ", subsequent_indent="    ")
        width = max((len(a.name) for a in behavior.arguments.values()), default=0)
        for argument in behavior.arguments.values():
            notes = []
            if argument.required:
                notes.append("required")
            if argument.default is not None:
                notes.append(f"default {argument.default}")
            if argument.aliases:
                notes.append("also " + ", ".join(argument.aliases))
            if argument.description:
                notes.append(argument.description)
            lines.append(f"    {argument.name:<{width}}  {argument.describe()}"
                         + (f"  ({'; '.join(notes)})" if notes else ""))
        for group in behavior.one_of:
            lines.append(f"    one of: {', '.join(group)}")
        if behavior.precondition_text:
            lines += textwrap.wrap("precondition: " + " ".join(behavior.precondition_text.split()), 100,
                                   initial_indent="    ", subsequent_indent="        ")
        lines.append("")
    return "\n".join(lines).rstrip()
