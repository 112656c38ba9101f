"""The operator channel of a run (the behavior context's ``operator``): how the robot notifies, asks, shows and says.

Questions never block the engine: :meth:`OperatorChannel.ask` returns a :class:`PendingAnswer` that the asking
behavior polls each tick. Three channels: :class:`ConsoleOperator` (someone at the terminal; a daemon thread
reads stdin), :class:`ScriptedOperator` (answers from a YAML file, for tests and rehearsals) and
:class:`LoggingOperator` (no one there: the first possible answer, or a default).

When no one answers, a yes/no question gets its first possible answer the first time it is asked and "no" each
time it is asked again (:meth:`OperatorChannel.unattended`): an operator who walked away asks for no replay, so a
script's ``while confirm("Replay")`` goes round once and ends, where "yes" forever would fly until the battery.
"""

from __future__ import annotations

import logging
import sys
import threading
from collections import deque
from collections.abc import Sequence
from pathlib import Path

from aeroexec.limits import InputError, load_yaml, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, TextIO

logger = logging.getLogger(__name__)


class OperatorError(ValueError):
    """An answers file that cannot be used, phrased for the operator."""


class PendingAnswer:
    """An answer that may come later; thread-safe. ``done`` once answered (or cancelled); ``value`` is the text."""

    def __init__(self, question: str, answers: Sequence[str] = ()) -> None:
        self.question = question
        self.answers = tuple(answers)
        self.note = ""  # how the answer was chosen when no one chose it (e.g. "not in the answers file")
        self._value: str | None = None
        self._done = threading.Event()
        self.cancelled = False

    @property
    def done(self) -> bool:
        return self._done.is_set()

    @property
    def value(self) -> str | None:
        return self._value

    def set(self, value: str | None, note: str = "") -> None:
        """Answer (the first answer wins; later ones and answers to a cancelled question are ignored)."""
        if self._done.is_set():
            return
        self._value, self.note = value, note
        self._done.set()

    def cancel(self) -> None:
        """The asker no longer waits (its behavior stopped)."""
        if not self._done.is_set():
            self.cancelled = True
            self._done.set()

    def __repr__(self) -> str:
        state = "cancelled" if self.cancelled else (repr(self._value) if self.done else "pending")
        return f"<PendingAnswer {self.question!r}: {state}>"


#: The possible answers that say "no" (a yes/no question asked again when no one answers gets this one).
NO_ANSWERS = ("n", "no")


def first_answer(answers: Sequence[str], default: str | None) -> str:
    """What someone absent answers: the default when given, else the first possible answer, else ''."""
    if default is not None:
        return default
    return str(answers[0]) if answers else ""


class OperatorChannel:
    """The protocol every channel follows; this base keeps what it was told and answers nothing by itself.

    ``notifications``, ``spoken`` and ``last_image``/``images_shown`` let a test (or a report) see what the
    operator got. ``voice_command`` is the last command the operator spoke or typed, or None.
    """

    def __init__(self) -> None:
        self.notifications: list[str] = []
        self.spoken: list[str] = []
        self.last_image: bytes | None = None
        self.images_shown = 0
        self.voice_command: str | None = None
        self._lock = threading.Lock()
        self._asked: list[PendingAnswer] = []  # questions and image requests, for answer_pending
        self._unattended: set[str] = set()  # the questions already answered for someone absent

    @property
    def last_voice_command(self) -> str | None:
        """The same as ``voice_command`` (the name VERIFY's VOICE_COMMAND reads)."""
        return self.voice_command

    def notify(self, text: str) -> None:
        """Tell the operator something; delivered when this returns."""
        with self._lock:
            self.notifications.append(text)
        logger.info("to the operator: %s", text)

    def say(self, text: str) -> None:
        """The robot says ``text`` out loud (the channel gets the transcript)."""
        with self._lock:
            self.spoken.append(text)
        logger.info("the robot says: %s", text)

    def display(self, image_png: bytes) -> None:
        """Show the operator a camera image (PNG bytes)."""
        with self._lock:
            self.last_image = image_png
            self.images_shown += 1

    def ask(self, question: str, answers: Sequence[str] = ()) -> PendingAnswer:
        """Ask a question; poll the returned answer's ``done`` and ``value``."""
        pending = PendingAnswer(question, answers)
        self._track(pending)
        self._answer(pending)
        return pending

    def request_image(self, candidates: Sequence[str] = (), image_png: bytes | None = None) -> PendingAnswer:
        """Ask the operator to select an object in the camera image; ``candidates`` are the objects in view,
        nearest first. The answer is the selected object's name."""
        pending = PendingAnswer("select an object in the camera image", candidates)
        if image_png is not None:
            self.display(image_png)
        self._track(pending)
        self._select(pending)
        return pending

    def pending_questions(self) -> list[PendingAnswer]:
        """The questions still waiting for an answer, oldest first."""
        with self._lock:
            self._asked = [p for p in self._asked if not p.done]
            return list(self._asked)

    def answer_pending(self, text: str, note: str = "answered by the operator") -> PendingAnswer | None:
        """Answer the oldest waiting question with ``text`` (or the possible answer numbered ``text``), from any
        thread (the live view, ``aeroexec ctl answer``); the question, or None when none waits."""
        for pending in self.pending_questions():
            if text.isdigit() and 1 <= int(text) <= len(pending.answers):
                text = pending.answers[int(text) - 1]
            pending.set(text, note)
            return pending
        return None

    def _track(self, pending: PendingAnswer) -> None:
        with self._lock:
            self._asked = [p for p in self._asked if not p.done] + [pending]

    def close(self) -> None:
        """Release what the channel holds; never hangs."""

    def unattended(self, pending: PendingAnswer, default: str | None, why: str) -> None:
        """Answer ``pending`` for an operator who is not there (``why`` says so): ``default`` when given, else
        the first possible answer; but a question with a "no" among its answers that was already answered so gets
        "no" — a loop asking it again (``while confirm("Replay")``) ends instead of repeating until the battery."""
        key = _normal(pending.question)
        with self._lock:
            again = key in self._unattended
            self._unattended.add(key)
        no = next((a for a in pending.answers if str(a).strip().lower() in NO_ANSWERS), None)
        if default is None and again and no is not None:
            logger.warning("%s: %r asked again: answering %r (nobody there asks for it again)", why,
                           pending.question, no)
            pending.set(str(no), f"{why}: asked again, {no!r}")
            return
        chosen = "the default answer" if default is not None else "the first possible answer"
        pending.set(first_answer(pending.answers, default), f"{why}: {chosen}")

    # -- how a channel answers -------------------------------------------------------------
    def _answer(self, pending: PendingAnswer) -> None:
        self.unattended(pending, None, "no operator")

    def _select(self, pending: PendingAnswer) -> None:
        pending.set(pending.answers[0] if pending.answers else None, "the nearest object in view")


class LoggingOperator(OperatorChannel):
    """No one is there: notifications are logged; questions get ``default`` or the first possible answer."""

    def __init__(self, default: str | None = None, voice_command: str | None = None) -> None:
        super().__init__()
        self.default = default
        self.voice_command = voice_command

    def _answer(self, pending: PendingAnswer) -> None:
        self.unattended(pending, self.default, "no operator")


class ScriptedOperator(OperatorChannel):
    """Answers from a script: a mapping question -> answer (or -> list of answers, used in turn), or a list of
    answers given in order to whatever is asked. A question the script does not know (or a list that has run
    out) gets the first possible answer, and a warning is logged.

    The YAML file may also be ``{answers: <mapping or list>, voice_command: TEXT}``.
    """

    def __init__(self, script: dict[str, Any] | list[Any] | None = None, voice_command: str | None = None,
                 default: str | None = None) -> None:
        super().__init__()
        self.default = default
        self.voice_command = voice_command
        self._ordered: deque[str] = deque()
        self._by_question: dict[str, deque[str]] = {}
        if isinstance(script, list):
            self._ordered.extend(_text(a) for a in script)
        elif isinstance(script, dict):
            for question, answer in script.items():
                values = answer if isinstance(answer, list) else [answer]
                self._by_question[_normal(question)] = deque(_text(a) for a in values)
        elif script is not None:
            raise OperatorError(f"the answers must be a mapping question -> answer or a list, "
                                f"not {type(script).__name__}")

    @classmethod
    def from_file(cls, path: str | Path) -> ScriptedOperator:
        """Read an answers file; raises :class:`OperatorError` with the file's name when it is unusable."""
        path = Path(path)
        try:
            data = load_yaml(read_text(path, what="the answers"), str(path))
        except InputError as exc:
            raise OperatorError(str(exc)) from None
        voice = None
        if isinstance(data, dict) and data and set(data) <= {"answers", "voice_command"} \
                and isinstance(data.get("answers", []), list | dict):
            voice = data.get("voice_command")
            data = data.get("answers")
        try:
            return cls(data, voice_command=None if voice is None else str(voice))
        except OperatorError as error:
            raise OperatorError(f"{path}: {error}") from None

    def _answer(self, pending: PendingAnswer) -> None:
        with self._lock:
            queue = self._by_question.get(_normal(pending.question))
            if queue:
                value = queue.popleft() if len(queue) > 1 else queue[0]  # the last answer stays
                pending.set(value, "from the answers file")
                return
            if not self._by_question and self._ordered:
                pending.set(self._ordered.popleft(), "from the answers file")
                return
        self.unattended(pending, self.default, "not in the answers file")
        logger.warning("the answers file does not answer %r: answering %r", pending.question, pending.value)


class ConsoleOperator(OperatorChannel):
    """Someone at a terminal: questions are printed to ``output``; a daemon thread reads answers from ``input``.

    A line read while a question waits answers the oldest one (its text, or its number in the list shown);
    a line read when nothing is asked becomes the ``voice_command``. Once the input ends, questions get the
    first possible answer. Nothing here waits on the input, so the engine's tick never blocks, and
    :meth:`close` returns at once (the reader is a daemon thread).
    """

    def __init__(self, input: TextIO | None = None, output: TextIO | None = None) -> None:  # noqa: A002
        super().__init__()
        self.input = input if input is not None else sys.stdin
        self.output = output if output is not None else sys.stdout
        self._waiting: deque[PendingAnswer] = deque()
        self._closed = threading.Event()
        self._ended = False  # the input reached its end
        self._reader = threading.Thread(target=self._read, name="aeroexec-console-operator", daemon=True)
        self._reader.start()

    def notify(self, text: str) -> None:
        super().notify(text)
        self._write(f"[drone] {text}")

    def say(self, text: str) -> None:
        super().say(text)
        self._write(f"[drone says] {text}")

    def display(self, image_png: bytes) -> None:
        super().display(image_png)
        if self.images_shown == 1:
            self._write(f"[drone] camera image received ({len(image_png)} bytes); this console cannot show it")

    def close(self) -> None:
        self._closed.set()
        with self._lock:
            waiting = list(self._waiting)
            self._waiting.clear()
        for pending in waiting:
            pending.cancel()

    def _answer(self, pending: PendingAnswer) -> None:
        choices = "".join(f"\n  {i}) {a}" for i, a in enumerate(pending.answers, 1))
        self._enqueue(pending, f"[drone asks] {pending.question}{choices}\n> ")

    def _select(self, pending: PendingAnswer) -> None:
        if not pending.answers:
            pending.set(None, "nothing in view")
            return
        choices = "".join(f"\n  {i}) {a}" for i, a in enumerate(pending.answers, 1))
        self._enqueue(pending, f"[drone asks] select an object in the camera image (nearest first):{choices}\n> ")

    def _enqueue(self, pending: PendingAnswer, prompt: str) -> None:
        with self._lock:
            ended = self._ended or self._closed.is_set()
            if not ended:
                self._waiting.append(pending)
        if ended:
            self.unattended(pending, None, "the console has no more input")
            return
        self._write(prompt, newline=False)

    def _read(self) -> None:
        while not self._closed.is_set():
            try:
                line = self.input.readline()
            except (OSError, ValueError):  # closed under us
                line = ""
            if not line:
                break
            self._hear(line.strip())
        with self._lock:
            self._ended = True
            waiting = list(self._waiting)
            self._waiting.clear()
        for pending in waiting:
            self.unattended(pending, None, "the console has no more input")

    def _hear(self, text: str) -> None:
        with self._lock:
            while self._waiting and self._waiting[0].done:  # cancelled ones
                self._waiting.popleft()
            pending = self._waiting.popleft() if self._waiting else None
            if pending is None:
                if text:
                    self.voice_command = text
                return
        if text.isdigit() and 1 <= int(text) <= len(pending.answers):
            text = pending.answers[int(text) - 1]
        pending.set(text, "typed by the operator")

    def _write(self, text: str, newline: bool = True) -> None:
        try:
            self.output.write(text + ("\n" if newline else ""))
            self.output.flush()
        except (OSError, ValueError):
            logger.debug("the console is gone: %s", text)


class RemoteOperator(OperatorChannel):
    """Questions wait until :meth:`answer_pending` answers them (the live view's keys, ``aeroexec ctl answer``);
    :meth:`close` gives each waiting one its first possible answer."""

    def _answer(self, pending: PendingAnswer) -> None:
        logger.info("the robot asks: %s %s", pending.question, list(pending.answers))

    def _select(self, pending: PendingAnswer) -> None:
        self._answer(pending)

    def close(self) -> None:
        for pending in self.pending_questions():
            pending.set(first_answer(pending.answers, None), "the run ended: the first possible answer")


def make_operator(answers: str | Path | None = None, interactive: bool = False) -> OperatorChannel:
    """The channel for a run: a :class:`ScriptedOperator` from ``answers``, else a :class:`ConsoleOperator`
    when someone is at the terminal, else a :class:`LoggingOperator`. Raises :class:`OperatorError`."""
    if answers is not None:
        return ScriptedOperator.from_file(answers)
    if interactive:
        return ConsoleOperator()
    return LoggingOperator()


def _text(value: Any) -> str:
    if isinstance(value, bool):  # YAML reads yes/no as booleans
        return "yes" if value else "no"
    return "" if value is None else str(value)


def _normal(question: Any) -> str:
    return " ".join(_text(question).split()).casefold()


def operator_of(context: Any) -> OperatorChannel:
    """The context's operator channel; without one, a :class:`LoggingOperator` kept on the context."""
    channel = getattr(context, "operator", None)
    if channel is None:
        channel = getattr(context, "_absent_operator", None)
        if channel is None:
            channel = LoggingOperator()
            context._absent_operator = channel
    return channel
