"""``aeroexec groot-model``: the TreeNodesModel palette of a catalog, for Groot2."""

from __future__ import annotations

import argparse

from aeroexec.cli.lines import write_output
from aeroexec.flight.robot import chosen_catalog
from aeroexec.trees.groot.palette import tree_nodes_model


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("-o", "--output", metavar="FILE", help="write the palette here (default: standard output)")


def run(args: argparse.Namespace) -> int:
    catalog = chosen_catalog(args.catalog)
    return write_output(tree_nodes_model(catalog), args.output, f"{len(catalog)} behaviors for Groot2")
