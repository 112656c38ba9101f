"""``aeroexec catalog``: list the behaviors of a catalog, or check a catalog file and report every problem."""

from __future__ import annotations

import argparse
import logging
import sys
import textwrap

from aeroexec.engine.catalog import BehaviorCatalog, default_catalog, default_catalog_path, load_catalog
from aeroexec.engine.errors import CatalogError, Problem
from aeroexec.engine.library import default_library


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("behaviors", nargs="*", metavar="BEHAVIOR", help="show only these behaviors")
    parser.add_argument("--catalog", metavar="FILE", help="the catalog to list (default: the aerial catalog)")
    parser.add_argument("--check", metavar="FILE", help="validate a catalog file: print every error and warning "
                                                        "with file:line; exit 1 when there are errors")


def run(args: argparse.Namespace) -> int:
    logging.getLogger("aeroexec.engine.catalog").setLevel(logging.ERROR)  # problems are printed below
    if args.check:
        return _check(args.check)
    catalog = chosen_catalog(args.catalog)
    for warning in catalog.warnings:
        print(warning, file=sys.stderr)
    unknown = [name for name in args.behaviors if name not in catalog]
    for name in unknown:
        print(f"The behavior {name} does not exist{catalog.suggest(name)}", file=sys.stderr)
    if unknown:
        return 1
    print(listing(catalog, args.behaviors or None))
    return 0


def chosen_catalog(path: str | None) -> BehaviorCatalog:
    """The catalog of a ``--catalog`` option (the aerial one without it) as the behavior library serves it
    (see :meth:`BehaviorCatalog.served_by`); raises CatalogError."""
    catalog = load_catalog(path) if path else default_catalog()
    return catalog.served_by(default_library().names(), default_catalog())


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
