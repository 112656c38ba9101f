"""``aeroexec groot-model``: the TreeNodesModel palette of a catalog, for Groot2."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.trees.groot import tree_nodes_model


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("-o", "--output", metavar="FILE", help="write the palette here (default: standard output)")


def run(args: argparse.Namespace) -> int:
    catalog = chosen_catalog(args.catalog)
    text = tree_nodes_model(catalog)
    if not args.output:
        sys.stdout.write(text)
        return 0
    try:
        Path(args.output).write_text(text, encoding="utf-8")
    except OSError as error:
        print(f"{args.output}: cannot write the palette: {error}", file=sys.stderr)
        return 1
    print(f"{args.output}: {len(catalog)} behaviors for Groot2", file=sys.stderr)
    return 0
