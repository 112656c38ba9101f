"""Values converted as BehaviorTree.CPP converts them, judged by BT.CPP itself (behaviortreepy, BT.CPP 4.8.2).

Generated trees: a Script or a SetBlackboard writes a value (a number, a boolean, text that reads as one or not, a
``;`` queue, an empty text) into a blackboard entry, and the typed ports of built-in nodes read it (``num_cycles``,
``then_skip``, ``success_count``, a Loop's ``queue``, a Switch's ``variable``), or a script reads it. Every tick of
every node, the blackboard, and where each run stops on an error (refused at load, thrown at a tick) are the same in
both. ``PARITY_SEED`` replays or explores as in ``test_btcpp_parity``.

Where BT.CPP 4.10 changed what 4.8.2 does, aeroexec does as 4.10 and the trees that would tell them apart are not
generated: 4.8.2 gives the entry a Loop's ``queue`` reads the queue's type (text written there becomes a queue, the
Loop drains it, and another typed port on that entry is refused at load); 4.10 leaves it untyped (text stays text,
converted when the Loop starts: ``loop_node.h``, issues #969 and #1065). So a Loop's entry has one writer and no
other reader here (4.8.2 would convert, and refuse, what the second writer overwrites).

One thing of BT.CPP's is not done here, and not generated: SetBlackboard writing text over an entry a script made
(``k := 3``, then ``<SetBlackboard output_key="k" value="5"/>``) empties it in BT.CPP (4.8.2 and 4.10:
``TypeInfo::parseString`` has no converter for an untyped entry), and a second SetBlackboard there throws; aeroexec
writes the text. The same happens to text SetBlackboard copies (``value="{k}"``) into an untyped entry, and to an
entry an untyped port made as the tree loaded: SetBlackboard copying ``{k}`` is left to the one-feature trees
(``test_btcpp_one_feature``), with a number.
"""

from __future__ import annotations

import os
import random
import re

from btcpp_harness import compare
from depth import examples
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

SEED = int(random.randrange(1 << 30) if os.environ.get("PARITY_SEED") == "random"
           else os.environ.get("PARITY_SEED", 20260412))
S, F, R = "SUCCESS", "FAILURE", "RUNNING"

#: Text SetBlackboard writes (to an entry a typed port may have typed: then converted as it is written).
TEXTS = ("3", "2", "1", "0", "-1", "2.5", "2abc", "true", "false", "True", "abc", "", "1;2;3", "2;0", "1;x",
         "0.5;1.5", "a;b", "true;false")
#: Values a Script assigns: numbers, booleans, strings.
LITERALS = ("3", "2.0", "2.5", "-1", "0", "1", "true", "false", "'3'", "'2.5'", "'true'", "'1;2;3'", "'abc'", "''")
#: Nodes reading the entry ``k`` (the scripted leaves A, B, C answer their scripts).
READERS = (
    '<Repeat num_cycles="{k}"><A/></Repeat>',
    '<RetryUntilSuccessful num_attempts="{k}"><A/></RetryUntilSuccessful>',
    '<RunOnce then_skip="{k}"><A/></RunOnce>',
    '<Parallel success_count="{k}"><A/><B/></Parallel>',
    '<Parallel failure_count="{k}"><A/><C/></Parallel>',
    '<ParallelAll max_failures="{k}"><A/><C/></ParallelAll>',
    '<LoopInt queue="{k}" value="{v}"><Sequence><Script code="s := s .. v"/><A/></Sequence></LoopInt>',
    '<LoopDouble queue="{k}" value="{d}"><Sequence><Script code="s := s .. d"/><B/></Sequence></LoopDouble>',
    '<LoopString queue="{k}" value="{w}"><Sequence><Script code="s := s .. w"/><A/></Sequence></LoopString>',
    '<LoopBool queue="{k}" value="{b}"><Fallback><ScriptCondition code="b"/><A/></Fallback></LoopBool>',
    '<Switch2 variable="{k}" case_1="3" case_2="true"><A/><B/><C/></Switch2>',
    '<ScriptCondition code="k == 3"/>',
    '<ScriptCondition code="k &lt; 2.5"/>',
    '<ScriptCondition code="k"/>',
    '<Script code="j := k + 1"/>',
    "<Script code=\"j := k .. '!'\"/>",
    '<Script code="k += 1"/>',
    '<Precondition if="k" else="SUCCESS"><A/></Precondition>',
    '<A _skipIf="k == 1"/>',
)


@st.composite
def conversion_trees(draw) -> str:
    """One or two writers of ``k``, then one or two readers, under a Sequence (the root starts it again after it
    completes, so a writer fills a loop's queue again before the loop runs again)."""
    writers = [draw(st.one_of(st.sampled_from(TEXTS).map(lambda t: f'<SetBlackboard output_key="k" value="{t}"/>'),
                              st.sampled_from(LITERALS).map(lambda v: f'<Script code="k := {v}"/>')))
               for _ in range(draw(st.integers(1, 2)))]
    if len(writers) == 2 and writers[0].startswith("<Script") and writers[1].startswith("<SetBlackboard"):
        writers.reverse()  # BT.CPP empties such an entry (see the module's docstring)
    readers = draw(st.lists(st.sampled_from(READERS), min_size=1, max_size=2))
    if any("<Loop" in r for r in readers):  # 4.8.2 types a Loop's queue entry, 4.10 does not (the docstring)
        readers, writers = readers[:1], writers[-1:]
    if len(readers) == 2:  # leaves of their own (BT.CPP's scripted leaves of one type share their script)
        readers[1] = re.sub(r"<([ABC])\b", lambda m: "<" + {"A": "D", "B": "E", "C": "G"}[m.group(1)], readers[1])
    body = "".join(writers + readers)
    return f'<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>{body}</Sequence>' \
           '</BehaviorTree></root>'


@seed(SEED)
@settings(max_examples=examples(40), deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(conversion_trees(), st.lists(st.sampled_from((S, F, R)), min_size=1, max_size=3))
def test_values_written_by_scripts_and_set_blackboard_are_read_by_typed_ports_as_in_btcpp(tmp_path, xml, script):
    try:
        compare(xml, {"A": script, "B": [S], "C": [F], "D": script, "E": [S], "G": [F]}, 6, tmp_path,
                blackboard={"s": ""})
    except AssertionError as error:
        raise AssertionError(f"{error}\n(replay with PARITY_SEED={SEED})") from None
