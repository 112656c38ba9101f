"""BehaviorTree.CPP v4's decorators as ``py_trees`` decorators, and the pre-conditions wrapper.

Inverter, ForceSuccess, ForceFailure; Repeat (``num_cycles``, -1 forever: repeat while the child succeeds);
RetryUntilSuccessful (``num_attempts``, -1 forever: tick again while the child fails); KeepRunningUntilFailure;
Timeout (``msec`` on the engine clock: when it runs out the child is halted and the node fails); Delay
(``delay_msec`` before the child is first ticked); RunOnce (the child completes once; then SKIPPED, or its
first result with ``then_skip="false"``). A child that completes on the very tick it started returns control
to the tree before a loop ticks it again, as BehaviorTree.CPP does with its wake-up signal, so a loop of
instantaneous nodes never spins inside one tick. SubTree passes its child's status through.
"""

from __future__ import annotations

from collections.abc import Callable

import py_trees
from aeroexec.trees.runtime.ticking import INVALID, RUNNING, SKIPPED, Node, Result, halt
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class Decorator(Node, py_trees.decorators.Decorator):
    """A decorator whose ``run()`` decides when and whether to tick its child."""

    def __init__(self, name: str, child: Behaviour) -> None:
        super().__init__(name=name, child=child)
        self.skipped = False

    def run(self) -> Result:
        return self.decorated.step()  # type: ignore[attr-defined]

    def step(self) -> Result:
        old, old_skipped = self.status, self.skipped
        if old is not RUNNING and self.initialises:
            self.initialise()
        result = self.run()
        if result is not RUNNING:
            self.terminate(Status.SUCCESS if result is SKIPPED else result)
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
    def run(self) -> Result:
        result = self.decorated.step()
        return Status.FAILURE if result is Status.SUCCESS else Status.SUCCESS if result is Status.FAILURE else result


class Force(Decorator):
    """ForceSuccess / ForceFailure: a completed child becomes ``status``; RUNNING and SKIPPED pass through."""

    def __init__(self, name: str, child: Behaviour, status: Status) -> None:
        super().__init__(name, child)
        self.forced = status

    def run(self) -> Result:
        result = self.decorated.step()
        return self.forced if result is Status.SUCCESS or result is Status.FAILURE else result


class Loop(Decorator):
    """Repeat (``until`` FAILURE ends it, SUCCESS counts) and RetryUntilSuccessful (SUCCESS ends it, FAILURE counts)."""

    def __init__(self, name: str, child: Behaviour, cycles: int | Callable[[], int], *, retry: bool) -> None:
        super().__init__(name, child)
        self.count_of, self.retry = cycles, retry
        self.cycles = cycles if isinstance(cycles, int) else 0
        self.count = 0
        self.counted = Status.FAILURE if retry else Status.SUCCESS

    def run(self) -> Result:
        if not isinstance(self.count_of, int):  # a ``{key}`` port, read on every tick as BT.CPP does
            self.cycles = self.count_of()
        while self.cycles < 0 or self.count < self.cycles:
            before = self.decorated.status
            result = self.decorated.step()
            if result is Status.RUNNING:
                return Status.RUNNING
            if result is SKIPPED:
                halt(self.decorated)
                return SKIPPED
            if result != self.counted:
                self.count = 0
                halt(self.decorated)
                return result
            self.count += 1
            halt(self.decorated)
            if before is not Status.RUNNING and (self.cycles < 0 or self.count < self.cycles):
                return Status.RUNNING  # completed on its first tick: go on at the next tick
        self.count = 0
        return Status.FAILURE if self.retry else Status.SUCCESS

    def halted(self) -> None:
        self.count = 0


class KeepRunningUntilFailure(Decorator):
    def run(self) -> Result:
        result = self.decorated.step()
        if result is Status.FAILURE:
            halt(self.decorated)
            return Status.FAILURE
        if result is Status.SUCCESS:
            halt(self.decorated)
        return Status.RUNNING


class Timed(Decorator):
    """A decorator measuring ``seconds`` of engine time from the tick that starts it."""

    def __init__(self, name: str, child: Behaviour, seconds: float, clock: Callable[[], float]) -> None:
        super().__init__(name, child)
        self.seconds, self.clock = seconds, clock
        self.started_at: float | None = None

    def elapsed(self) -> bool:
        """True once ``seconds`` have passed since the node started (starting it now if it was not)."""
        now = self.clock()
        if self.started_at is None:
            self.started_at = now
        return now - self.started_at >= self.seconds - 1e-9

    def tick_decorated(self) -> Result:
        result = self.decorated.step()
        if result is not Status.RUNNING:
            self.started_at = None
        return result

    def halted(self) -> None:
        self.started_at = None


class Timeout(Timed):
    """Fails when ``seconds`` of engine time pass before the child completes, halting the child."""

    def run(self) -> Result:
        if self.seconds > 0 and self.elapsed():
            self.started_at = None
            self.feedback_message = f"timed out after {self.seconds:g} s"
            halt(self.decorated)
            return Status.FAILURE
        return self.tick_decorated()


class Delay(Timed):
    """Ticks the child only once ``seconds`` of engine time have passed since the node started."""

    def run(self) -> Result:
        if not self.elapsed():
            return Status.RUNNING
        return self.tick_decorated()


class RunOnce(Decorator):
    """The child runs to completion once; afterwards SKIPPED (``then_skip``) or its first result again."""

    def __init__(self, name: str, child: Behaviour, then_skip: bool = True) -> None:
        super().__init__(name, child)
        self.then_skip = then_skip
        self.first: Result | None = None

    def run(self) -> Result:
        if self.first is not None:
            return SKIPPED if self.then_skip else self.first
        result = self.decorated.step()
        if result in (Status.SUCCESS, Status.FAILURE):
            self.first = result
        return result


class PassThrough(Decorator):
    """A SubTree: its child is the referenced tree, on a blackboard of its own."""


class Preconditions(Decorator):
    """BehaviorTree.CPP's ``_failureIf``, ``_successIf``, ``_skipIf`` and ``_while`` around a node.

    ``conditions`` maps each attribute to a function telling whether its belief expression holds. The first three
    and a false ``_while`` are checked when the node starts (FAILURE, SUCCESS, SKIPPED without ticking it); a
    ``_while`` that becomes false while the node runs halts it and the node is SKIPPED.
    """

    ORDER = ("_failureIf", "_successIf", "_skipIf", "_while")

    def __init__(self, name: str, child: Behaviour, conditions: dict[str, Callable[[], bool]],
                 actions: dict[str, Callable[[], None]] | None = None) -> None:
        super().__init__(name, child)
        self.conditions = conditions
        self.actions = actions or {}

    def run(self) -> Result:
        result = self.checked()
        if result in (Status.SUCCESS, Status.FAILURE):  # BT.CPP's post-conditions: _onSuccess/_onFailure, _post
            action = self.actions.get("_onSuccess" if result is Status.SUCCESS else "_onFailure")
            if action is not None:
                action()
            if "_post" in self.actions:
                self.actions["_post"]()
        return result

    def halted(self) -> None:
        if "_onHalted" in self.actions and self.status is Status.RUNNING:
            self.actions["_onHalted"]()

    def checked(self) -> Result:
        starting = self.status is not Status.RUNNING
        for attribute in self.ORDER:
            check = self.conditions.get(attribute)
            if check is None:
                continue
            holds = check()
            if starting and holds and attribute != "_while":
                self.feedback_message = f"{attribute} holds"
                return {"_failureIf": Status.FAILURE, "_successIf": Status.SUCCESS}.get(attribute, SKIPPED)
            if attribute == "_while" and not holds:
                self.feedback_message = "_while does not hold"
                halt(self.decorated)
                return SKIPPED
        return self.decorated.step()
