"""SubTrees as BehaviorTree.CPP instantiates them: their paths (no two alike) and the size and depth of the main
tree with every SubTree expanded where it is used (bounded, so a SubTree used thousands of times is refused,
not walked)."""

from __future__ import annotations

from collections.abc import Callable

from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.kinds import is_subtree

from aeroexec.limits import MAX_NESTING, MAX_TREE_NODES

Report = Callable[..., None]  # report(node, message): a problem at a node


def subtree_ids(root: TreeNode) -> list[str]:
    """The trees a tree's SubTree nodes name."""
    return [n.ports.get("ID", "").strip() for n in root.walk() if is_subtree(n.type)]


def check_subtree_paths(document: TreeDocument, report: Report) -> None:
    """BehaviorTree.CPP (4.10) refuses two SubTree instances with one path (the same name, same parent)."""
    seen: set[str] = set()
    uid = [0]

    def walk(node: TreeNode, path: str, stack: tuple[str, ...]) -> None:
        uid[0] += 1
        if is_subtree(node.type):
            target = node.ports.get("ID", "").strip()
            inner = (f"{path}/" if path else "") + (node.name if node.named and node.name != node.type
                                                      else f"{target}::{uid[0]}")
            if inner in seen:
                report(node, f"Duplicate SubTree path detected: '{inner}'. Multiple SubTree nodes with the "
                                  "same 'name' attribute under the same parent are not allowed")
            seen.add(inner)
            if target in document.trees and target not in stack:
                walk(document.trees[target], inner, (*stack, target))
        for child in node.children:
            walk(child, path, stack)

    walk(document.root, "", (document.main,))

def check_expansion(document: TreeDocument, report: Report) -> bool:
    """False (with an error) when the main tree, its SubTrees expanded where used, is too large or too deep."""
    trees = document.trees
    order: list[str] = []  # trees after the trees they use (post-order), found without recursion
    seen: set[str] = set()
    for start in trees:
        stack = [(start, False)]
        while stack:
            tree, finished = stack.pop()
            if finished:
                order.append(tree)
                continue
            if tree in seen:
                continue
            seen.add(tree)
            stack.append((tree, True))
            stack.extend((t, False) for t in subtree_ids(trees[tree]) if t in trees and t not in seen)
    measures: dict[str, tuple[int, int]] = {}  # tree -> (nodes expanded, depth expanded); cycles left out
    for tree in order:
        size, deepest, nodes = 0, 0, [(trees[tree], 1)]
        while nodes:
            node, depth = nodes.pop()
            used = measures.get(node.ports.get("ID", "").strip(), (0, 0)) if is_subtree(node.type) else (0, 0)
            size, deepest = min(size + 1 + used[0], 10 * MAX_TREE_NODES), max(deepest, depth + used[1])
            nodes.extend((child, depth + 1) for child in node.children)
        measures[tree] = (size, deepest)
    size, depth = measures.get(document.main, (0, 0))
    root = document.root
    if size > MAX_TREE_NODES:
        report(root, f"The mission has more than {MAX_TREE_NODES:,} nodes once its SubTrees are expanded "
                          f"where they are used (the limit of the readers)")
    if depth > MAX_NESTING:
        report(root, f"The mission is nested more than {MAX_NESTING} levels deep once its SubTrees are "
                          f"expanded where they are used (the limit of the readers)")
    return size <= MAX_TREE_NODES and depth <= MAX_NESTING

# -- blackboard --------------------------------------------------------------------------------
