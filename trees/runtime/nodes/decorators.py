"""BehaviorTree.CPP v4's decorators, one class per node name, as ``py_trees`` decorators with BT.CPP's semantics.

Inverter, ForceSuccess, ForceFailure; Repeat (``num_cycles``, -1 forever: repeat while the child succeeds);
RetryUntilSuccessful (``num_attempts``, -1 forever: tick again while the child fails); KeepRunningUntilFailure;
Timeout (``msec`` on the engine clock: when it runs out the child is halted and the node fails); Delay
(``delay_msec`` before the child is first ticked); RunOnce (the child completes once; then SKIPPED, or its
first result with ``then_skip="false"``); Precondition (the ``if`` script, else ``else``); LoopInt, LoopDouble,
LoopString, LoopBool (the child once per item of ``queue``); SkipUnlessUpdated and WaitValueUpdate (the child only
when ``entry`` was written); SubTree (its child is the referenced tree). A child that completes on the very tick it
started returns control to the tree before a loop ticks it again, as BehaviorTree.CPP does with its wake-up
signal, so a loop of instantaneous nodes never spins inside one tick.
"""

from __future__ import annotations

from typing import Any

import py_trees
from aeroexec.trees.conversions import ConversionError, from_blackboard, queue_items
from aeroexec.trees.runtime.manifests import MANIFESTS, decorator
from aeroexec.trees.runtime.ports import NodeConfig, PortError
from aeroexec.trees.runtime.ticking import (
    FAILURE,
    INVALID,
    RUNNING,
    SKIPPED,
    SUCCESS,
    Node,
    Result,
    TickError,
    halt,
    reset,
)
from aeroexec.trees.script import ScriptError, compile_script
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class Decorator(Node, py_trees.decorators.Decorator):
    """A decorator whose ``run()`` decides when and whether to tick its child."""

    manifest = decorator()  # exactly one child; each node's is its name's

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name=name, child=child)
        self.skipped = False
        self.config = config if config is not None else NodeConfig.of(type(self).__name__)

    @classmethod
    def build(cls, config: NodeConfig, children: list[Behaviour]) -> Behaviour:
        return cls(config.model.name, children[0], config)

    def run(self) -> Result:
        decorated = self.decorated
        return decorated.stepper(decorated)  # type: ignore[attr-defined]

    def step(self) -> Result:
        old, old_skipped = self.status, self.skipped
        if old is not RUNNING and self.initialises:
            self.initialise()
        result = self.run()
        if result is not RUNNING:
            self.terminate(SUCCESS if result is SKIPPED else result)
            if self.decorated.status is RUNNING:  # py_trees: a decorator that completes stops its running child
                self.decorated.stop(INVALID)
        return self.settle(old, old_skipped, result)

    def update(self) -> Status:  # unused: ``run()`` decides
        return self.status

    def terminate(self, new_status: Status) -> None:
        if new_status is INVALID:
            self.halted()

    def halted(self) -> None:
        """Reset what a halt resets."""


class Inverter(Decorator):
    manifest = MANIFESTS["Inverter"]

    def run(self) -> Result:
        decorated = self.decorated
        result = decorated.stepper(decorated)
        return FAILURE if result is SUCCESS else SUCCESS if result is FAILURE else result

    def step(self) -> Result:  # Decorator.step and Node.settle for a node with nothing to start or stop
        decorated = self.decorated
        result = decorated.stepper(decorated)
        tree = self.tree
        if result is SUCCESS:
            result = status = FAILURE
        elif result is FAILURE:
            result = status = SUCCESS
        else:
            status = SUCCESS if result is SKIPPED else result
        skipped = result is SKIPPED
        if status is not self.status or skipped is not self.skipped:
            tree.changed.append(self)
        self.status, self.skipped, self.ticked = status, skipped, tree.number
        if tree.visits is not None:
            tree.visits.append((self, result))
        return result


class ForceSuccess(Decorator):
    """A completed child becomes SUCCESS; RUNNING and SKIPPED pass through."""

    manifest = MANIFESTS["ForceSuccess"]
    forced = SUCCESS

    def run(self) -> Result:
        decorated = self.decorated
        result = decorated.stepper(decorated)
        return self.forced if result is SUCCESS or result is FAILURE else result


class ForceFailure(ForceSuccess):
    manifest = MANIFESTS["ForceFailure"]
    forced = FAILURE


class Repeat(Decorator):
    """The child again while it succeeds, ``num_cycles`` times (-1: forever; another negative count, read at run time,
    ends the node at once as BT.CPP does); its first FAILURE ends the node."""

    manifest = MANIFESTS["Repeat"]
    counted = SUCCESS  # the result that counts a cycle; the other one ends the node with it
    port = "num_cycles"

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.cycles_port = self.config.input(self.port, self.manifest.ports)
        self.count = 0

    def run(self) -> Result:
        cycles = self.cycles_port.get()  # a ``{key}`` port is read on every tick, as BT.CPP does
        while cycles == -1 or self.count < cycles:  # BT.CPP: only -1 is forever; -2 ends at once
            before = self.decorated.status
            decorated = self.decorated
            result = decorated.stepper(decorated)
            if result is RUNNING:
                return RUNNING
            if result is SKIPPED:
                halt(self.decorated)
                return SKIPPED
            if result is not self.counted:
                self.count = 0
                halt(self.decorated)
                return result
            self.count += 1
            halt(self.decorated)
            if before is not RUNNING and (cycles == -1 or self.count < cycles):
                return RUNNING  # completed on its first tick: go on at the next tick
        self.count = 0
        return self.counted

    def halted(self) -> None:
        self.count = 0


class RetryUntilSuccessful(Repeat):
    """The child again while it fails, ``num_attempts`` times (-1: forever); its first SUCCESS ends the node."""

    manifest = MANIFESTS["RetryUntilSuccessful"]
    counted = FAILURE
    port = "num_attempts"


class KeepRunningUntilFailure(Decorator):
    manifest = MANIFESTS["KeepRunningUntilFailure"]

    def run(self) -> Result:
        decorated = self.decorated
        result = decorated.stepper(decorated)
        if result is FAILURE:
            halt(self.decorated)
            return FAILURE
        if result is SUCCESS:
            halt(self.decorated)
        return RUNNING


class Timed(Decorator):
    """A decorator measuring the milliseconds of its port (read when it starts) on the engine clock."""

    port = ""

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.msec = self.config.input(self.port, self.manifest.ports)
        self.seconds = 0.0
        self.started_at: float | None = None

    def elapsed(self) -> bool:
        """True once the time has passed since the node started (starting it now if it was not)."""
        now = self.config.context.now()
        if self.started_at is None:
            self.started_at, self.seconds = now, self.msec.get() / 1000.0
        return now - self.started_at >= self.seconds - 1e-9

    def tick_decorated(self) -> Result:
        decorated = self.decorated
        result = decorated.stepper(decorated)
        if result is not RUNNING:
            self.started_at = None
        return result

    def halted(self) -> None:
        self.started_at = None


class Timeout(Timed):
    """Fails when ``msec`` of engine time pass before the child completes, halting the child."""

    manifest = MANIFESTS["Timeout"]
    port = "msec"

    def run(self) -> Result:
        if self.elapsed() and self.seconds > 0:
            self.started_at = None
            self.feedback_message = f"timed out after {self.seconds:g} s"
            halt(self.decorated)
            return FAILURE
        return self.tick_decorated()


class Delay(Timed):
    """Ticks the child only once ``delay_msec`` of engine time have passed since the node started."""

    manifest = MANIFESTS["Delay"]
    port = "delay_msec"

    def run(self) -> Result:
        if not self.elapsed():
            return RUNNING
        return self.tick_decorated()


class RunOnce(Decorator):
    """The child runs to completion once; afterwards SKIPPED (``then_skip``) or its first result again."""

    manifest = MANIFESTS["RunOnce"]

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.then_skip = self.config.input("then_skip", self.manifest.ports)
        self.first: Result | None = None

    def run(self) -> Result:
        if self.first is not None:
            return SKIPPED if self.then_skip.get() else self.first
        decorated = self.decorated
        result = decorated.stepper(decorated)
        if result is SUCCESS or result is FAILURE:
            self.first = result
        return result


class Precondition(Decorator):
    """Ticks its child once the ``if`` script holds, until the child completes; otherwise answers ``else``."""

    manifest = MANIFESTS["Precondition"]

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.script = compile_script(self.config.model.ports.get("if", ""))
        self.otherwise = self.config.input("else", self.manifest.ports)
        self.running = False

    def run(self) -> Result:
        config = self.config
        if not self.running:
            try:
                self.running = self.script.holds(config.blackboard, config.context.belief_holds)
            except ScriptError as error:
                raise TickError(config.model, str(error)) from None
        if not self.running:
            return self.otherwise.get()
        decorated = self.decorated
        result = decorated.stepper(decorated)
        if result is SUCCESS or result is FAILURE:  # as BT.CPP: a skipped child, or a halt, keeps it open
            self.running = False
        return result


class Loop(Decorator):
    """LoopX: pops the next item of ``queue`` into ``value`` and ticks the child with it, while the queue has items;
    FAILURE when the child fails; ``if_empty`` (SUCCESS) when no item is left.

    As BT.CPP 4.10 reads ``queue``: its text (``1;2;3``; ``""`` is empty) is the queue of each run; a ``{key}``
    holding text (written by SetBlackboard or a script) is converted once when the node starts and the copy is
    popped; a list there is popped in place (BT.CPP's shared queue); a tuple is copied once.
    """

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.item = next(port.type for port in self.manifest.ports if port.name == "value")  # LoopInt: int
        self.queue_port = self.config.input("queue", self.manifest.ports)
        self.static: list[Any] | None = None
        if self.queue_port.key is None:
            text = self.queue_port.value if self.queue_port.value is not None else ""
            try:
                self.static = queue_items(text, self.item)
            except ConversionError as error:
                raise PortError(f"{self.config.model.where}: the queue of {self.config.model.type} cannot be read: "
                                f"{error}") from None
        self.if_empty = self.config.input("if_empty", self.manifest.ports)
        self.value_key = self.config.output("value", self.manifest.ports)
        self.queue: list[Any] | None = None
        self.child_running = False

    def run(self) -> Result:
        popped = False
        if self.status is not RUNNING:
            self.child_running = False
            self.queue = list(self.static) if self.static is not None else None
        if not self.child_running:
            if self.static is None:
                self.read_queue()
            if self.queue:
                value = self.queue.pop(0)
                try:
                    self.config.blackboard[self.value_key] = from_blackboard(value, self.item)
                except ConversionError as error:
                    raise TickError(self.config.model, f"the item {value!r} of its queue: {error}") from None
                popped = True
        if not popped and not self.child_running:
            return self.if_empty.get()
        decorated = self.decorated
        result = decorated.stepper(decorated)
        self.child_running = result is RUNNING
        if result is SUCCESS or result is FAILURE:
            reset(self.decorated)
        return FAILURE if result is FAILURE else RUNNING

    def read_queue(self) -> None:
        """The queue a ``{key}`` holds (BT.CPP throws when the entry holds nothing)."""
        key, board = self.queue_port.key, self.config.blackboard
        if key not in board:
            raise TickError(self.config.model, f"cannot read the port queue: the blackboard has no value for {{{key}}}")
        held = board[key]
        if isinstance(held, list):
            self.queue = held
        elif self.queue is None:
            if isinstance(held, str):
                try:
                    self.queue = queue_items(held, self.item)
                except ConversionError as error:
                    raise TickError(self.config.model, f"the queue {{{key}}} ({held!r}): {error}") from None
            elif isinstance(held, tuple):
                self.queue = list(held)
            else:
                raise TickError(self.config.model, f"the port queue must hold a queue or a string, not {held!r}")

    def halted(self) -> None:
        self.child_running = False


class LoopInt(Loop):
    manifest = MANIFESTS["LoopInt"]


class LoopDouble(Loop):
    manifest = MANIFESTS["LoopDouble"]


class LoopString(Loop):
    manifest = MANIFESTS["LoopString"]


class LoopBool(Loop):
    manifest = MANIFESTS["LoopBool"]


class SkipUnlessUpdated(Decorator):
    """The child runs only when ``entry`` was written since the node last looked (else SKIPPED); a child RUNNING is
    ticked on regardless."""

    manifest = MANIFESTS["SkipUnlessUpdated"]
    otherwise: Result = SKIPPED

    def __init__(self, name: str, child: Behaviour, config: NodeConfig | None = None) -> None:
        super().__init__(name, child, config)
        self.key = self.config.output("entry")
        self.seen = 0
        self.executing = False

    def run(self) -> Result:
        if not self.executing:
            current = self.config.blackboard.version(self.key)
            previous, self.seen = self.seen, current
            if current == 0 or current == previous:
                return self.otherwise
        decorated = self.decorated
        result = decorated.stepper(decorated)
        self.executing = result is RUNNING
        return result

    def halted(self) -> None:
        self.executing = False


class WaitValueUpdate(SkipUnlessUpdated):
    """As SkipUnlessUpdated, RUNNING until ``entry`` is written."""

    manifest = MANIFESTS["WaitValueUpdate"]
    otherwise = RUNNING


class SubTree(Decorator):
    """A SubTree: its child is the referenced tree, on a blackboard of its own (built by the builder)."""

    manifest = MANIFESTS["SubTree"]
