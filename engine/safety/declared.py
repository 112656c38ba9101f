"""Where safety rules are declared besides the catalog: a rules file (``--safety-rules FILE``), a behavior tree's
``<SafetyRules>`` element (XML, YAML text inside; BehaviorTree.CPP ignores it) or ``safety_rules:`` key (YAML), a
Python mission's module-level ``SAFETY_RULES`` string (YAML). Each problem names the file and its line."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.catalog.safety_rules import RuleSet, read_safety_rules_text, rule_vocabulary
from aeroexec.engine.errors import Problem

from aeroexec.limits import InputError, line_of_offset, read_text

# an XML mission's: compiled on its first reading (re's cache), not at the start of every run
_SECTION = r"(?s)<SafetyRules(?:\s[^>]*)?>(.*?)</SafetyRules\s*>"
_CDATA = r"(?s)^\s*<!\[CDATA\[(.*)\]\]>\s*$"
_TREE_IDS = r"<BehaviorTree\s[^>]*\bID\s*=\s*\"([^\"]+)\""


def vocabulary(catalog: BehaviorCatalog):
    return rule_vocabulary({p.name: p.arity for p in catalog.predicates.values()})


def rules_file(path: str | Path, catalog: BehaviorCatalog) -> RuleSet:
    """The rules of a rules file: a YAML list of rules (or ``safety_rules:`` and the list)."""
    try:
        text = read_text(path, what="the rules file")
    except InputError as exc:
        return RuleSet(problems=[Problem("error", exc.message, exc.file, exc.line)])
    return read_safety_rules_text(text, str(path), vocabulary(catalog))


def mission_rules(path: str | Path, catalog: BehaviorCatalog) -> RuleSet:
    """The rules a mission file declares (none when it declares none, or cannot be read: its check says why)."""
    path = Path(path)
    try:
        text = read_text(path, what="the mission")
    except InputError:
        return RuleSet()
    suffix = path.suffix.lower()
    if suffix == ".py":
        return _python_rules(text, str(path), catalog)
    if suffix == ".xml":
        return _xml_rules(text, str(path), catalog)
    if suffix in (".yaml", ".yml") and re.search(r"^safety_rules\s*:", text, re.MULTILINE):
        return read_safety_rules_text(text, str(path), vocabulary(catalog), subtrees=_yaml_tree_ids(text))
    return RuleSet()


def _xml_rules(text: str, file: str, catalog: BehaviorCatalog) -> RuleSet:
    found = RuleSet()
    ids = re.findall(_TREE_IDS, text)
    for match in re.finditer(_SECTION, text):
        body, start = match.group(1), match.start(1)
        cdata = re.match(_CDATA, body)
        if cdata:
            start += cdata.start(1)
            body = cdata.group(1)
        else:
            body = _unescape(body)
        offset = line_of_offset(text, start) - 1
        found.extend(read_safety_rules_text(_dedent(body), file, vocabulary(catalog), offset, subtrees=ids))
    return found


def _unescape(text: str) -> str:
    """XML's five named entities as ``xml.sax.saxutils.unescape`` resolves them (``&amp;`` last), without importing
    it: it imports urllib.request, http.client and ssl, ~10 ms of every run's start."""
    for entity, character in (("&lt;", "<"), ("&gt;", ">"), ("&quot;", '"'), ("&apos;", "'"), ("&amp;", "&")):
        text = text.replace(entity, character)
    return text


def _python_rules(text: str, file: str, catalog: BehaviorCatalog) -> RuleSet:
    if "SAFETY_RULES" not in text and text.isascii():  # (a name of other letters may read as it: NFKC)
        return RuleSet()  # declares none: not parsed again (its check has parsed it)
    try:
        tree = ast.parse(text, file)
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return RuleSet()  # the mission's check reports it
    functions = [node.name for node in tree.body if isinstance(node, ast.FunctionDef)]
    for node in tree.body:
        if (isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "SAFETY_RULES"
                                                 for t in node.targets)):
            value = node.value
            if not (isinstance(value, ast.Constant) and isinstance(value.value, str)):
                return RuleSet(problems=[Problem("error", "SAFETY_RULES must be a string of YAML (a list of rules)",
                                                 file, node.lineno)])
            # a string's first line is the line of its opening quotes (and its text starts there)
            return read_safety_rules_text(value.value, file, vocabulary(catalog), value.lineno - 1, functions=functions)
    return RuleSet()


def _yaml_tree_ids(text: str) -> list[str]:
    return re.findall(r"^\s*-?\s*(?:ID|id)\s*:\s*([\w-]+)", text, re.MULTILINE) + \
        re.findall(r"^  ([\w-]+)\s*:\s*$", text, re.MULTILINE)


def _dedent(body: str) -> str:
    """The YAML inside an XML element, its indentation taken off (the lines stay where they are)."""
    lines = body.split("\n")
    indents = [len(line) - len(line.lstrip(" ")) for line in lines if line.strip()]
    cut = min(indents) if indents else 0
    return "\n".join(line[cut:] for line in lines)


__all__ = ["mission_rules", "rules_file"]
