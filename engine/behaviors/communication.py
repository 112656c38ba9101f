"""Communication (paper Table A.3): with the operator through the context's operator channel, and with the other
drones of the run through its message bus.

- NOTIFY_OPERATOR: the operator gets MESSAGE; achieved once delivered.
- ASK_OPERATOR: asks QUESTION with POSSIBLE_ANSWERS and waits (polling, never blocking) for the answer, believed
  as ``answer(Question, Text)`` and returned as the result. An answer outside POSSIBLE_ANSWERS (compared without
  case or surrounding spaces) is refused and the question asked again, at most ``MAX_ASKS`` times in all; then
  the behavior fails (WRONG_PROGRESS). Without POSSIBLE_ANSWERS any answer goes. The catalog's timeout applies.
- ASK_FOR_OBJECT_IMAGE: the operator selects one of the objects in the camera's view (nearest first; scripted
  and logging channels take the nearest). Waits while nothing is in view. Believes ``image(Object, ImageRef)``
  (ImageRef: the PNG written to the run's output folder when the drone gives images and the run has one,
  else ``camera:<time>``); the result is the object's name.
- DISPLAY_CAMERA_IMAGE (recurrent): sends ``drone.capture_image()`` to the operator every ``display_period``
  seconds (``EngineSettings.extra``, 0.5); a drone without images is said once and is no failure.
- SPEAK_UP (recurrent): says the active behaviors whenever they change.
- SAY: says SENTENCE (:mod:`.speech`); achieved once handed to the synthesizer, which goes on speaking.
- BROADCAST_MESSAGE: MESSAGE goes to every other drone on the bus (``message(Sender, Text)`` there); flying alone,
  it is logged and achieved.

Everything told to or heard from the operator is an ``operator`` event (``action`` says what).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

from aeroexec.beliefs import Struct
from aeroexec.engine.behaviors.speech import SpeechSynthesizer, speak
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.engine.execution.process import BehaviorProcess
from aeroexec.engine.execution.resources import Process
from aeroexec.engine.supervision.operator import PendingAnswer, operator_of

logger = logging.getLogger(__name__)

MAX_ASKS = 3  # times a question is asked when the answers are not among the possible ones
DISPLAY_PERIOD = 0.5  # s between two camera images sent to the operator
_ENDINGS = {o.value for o in (Outcome.GOAL_ACHIEVED, Outcome.TIME_OUT, Outcome.WRONG_PROGRESS, Outcome.INTERRUPTED)}


class Communicating(BehaviorProcess):
    """A behavior that calls the operator channel: a channel that raises makes it fail, not the engine."""

    _error = ""

    def call(self, function: Callable[..., Any], *args: Any) -> Any:
        try:
            return function(*args)
        except Exception as exc:
            logger.exception("the operator channel failed in %s", self.name)
            self._error = f"the operator channel failed: {type(exc).__name__}: {exc}"
            return None

    def on_run(self) -> Outcome | None:
        if self._error:
            return self.fail(self._error)
        return Outcome.GOAL_ACHIEVED


class NotifyOperator(Communicating):
    behavior = "NOTIFY_OPERATOR"

    def on_start(self) -> None:
        text = str(self.arguments["MESSAGE"])
        self.call(operator_of(self.context).notify, text)
        self.context.log.record("operator", self.name, text, action="notify", delivered=not self._error)


class AskOperator(Communicating):
    behavior = "ASK_OPERATOR"

    def on_start(self) -> None:
        self.question = str(self.arguments["QUESTION"])
        self.answers = tuple(str(a) for a in self.arguments.get("POSSIBLE_ANSWERS") or ())
        self.asked = 0
        self.pending: PendingAnswer | None = None
        self._ask()

    def _ask(self) -> None:
        self.asked += 1
        self.pending = self.call(operator_of(self.context).ask, self.question, self.answers)
        self.context.log.record("operator", self.name, self.question, action="ask", answers=list(self.answers),
                                attempt=self.asked)

    def on_run(self) -> Outcome | None:
        if self._error or self.pending is None:
            return self.fail(self._error or "the operator channel asked nothing")
        if not self.pending.done:
            return None
        if self.pending.cancelled:
            return self.fail("the operator channel closed before the question was answered")
        given = "" if self.pending.value is None else str(self.pending.value).strip()
        chosen = choose(given, self.answers)
        if chosen is None:
            refused = f"{given!r} is not one of {', '.join(self.answers)}"
            self.context.log.record("operator", self.name, refused, action="wrong_answer", answer=given,
                                    attempt=self.asked)
            if self.asked >= MAX_ASKS:
                return self.fail(f"the operator answered {self.asked} times outside the possible answers "
                                 f"(last: {refused})")
            self._ask()
            return None
        self.result = chosen
        self.memory.add(Struct("answer", (self.question, chosen)))
        self.context.log.record("operator", self.name, f"{self.question} {chosen}", action="answer",
                                answer=chosen, note=self.pending.note)
        return Outcome.GOAL_ACHIEVED

    def on_stop(self, outcome: Outcome) -> None:
        if self.pending is not None and not self.pending.done:
            self.pending.cancel()


def choose(given: str, answers: tuple[str, ...]) -> str | None:
    """``given`` as spelled in ``answers`` (case and spaces aside), or None; any answer when ``answers`` is empty."""
    if not answers:
        return given
    wanted = " ".join(given.split()).casefold()
    return next((a for a in answers if " ".join(a.split()).casefold() == wanted), None)


class AskForObjectImage(Communicating):
    behavior = "ASK_FOR_OBJECT_IMAGE"

    def on_start(self) -> None:
        self.pending: PendingAnswer | None = None
        self.candidates: tuple[str, ...] = ()
        self.image: bytes | None = None
        self.asked = 0
        self._waiting_said = False
        self._request()

    def _in_view(self) -> tuple[str, ...]:
        seen = sorted(self.drone.observations(), key=lambda o: o.distance)
        return tuple(dict.fromkeys(o.name for o in seen))

    def _request(self) -> None:
        self.candidates = self._in_view()
        if not self.candidates:
            if not self._waiting_said:
                self._waiting_said = True
                self.context.log.record("operator", self.name, "nothing in view to select yet; waiting",
                                        action="request_image", candidates=[])
            return
        self.asked += 1
        self.image = self.call(self.drone.capture_image)
        self._error = ""  # a drone without images is no failure
        self.pending = self.call(operator_of(self.context).request_image, self.candidates, self.image)
        self.context.log.record("operator", self.name, "select an object: " + ", ".join(self.candidates),
                                action="request_image", candidates=list(self.candidates), attempt=self.asked)

    def on_run(self) -> Outcome | None:
        if self._error:
            return self.fail(self._error)
        if self.pending is None:
            self._request()
            return None
        if not self.pending.done:
            return None
        if self.pending.cancelled:
            return self.fail("the operator channel closed before an object was selected")
        chosen = choose("" if self.pending.value is None else str(self.pending.value).strip(), self.candidates)
        if chosen is None:
            self.context.log.record("operator", self.name, f"{self.pending.value!r} is not an object in view",
                                    action="wrong_answer", answer=self.pending.value, attempt=self.asked)
            if self.asked >= MAX_ASKS:
                return self.fail(f"the operator selected no object in view in {self.asked} requests")
            self.pending = None
            return None
        reference = self._save(chosen)
        self.result = chosen
        self.memory.add(Struct("image", (chosen, reference)))
        self.context.log.record("operator", self.name, f"the operator selected {chosen} ({reference})",
                                action="image_selected", object=chosen, image=reference, note=self.pending.note)
        return Outcome.GOAL_ACHIEVED

    def _save(self, chosen: str) -> str:
        now = self.now()
        folder = self.context.output_dir
        if self.image is not None and folder is not None:
            path = folder / f"object_image_{chosen}_{now:.2f}.png"
            try:
                folder.mkdir(parents=True, exist_ok=True)
                path.write_bytes(self.image)
                return str(path)
            except OSError as exc:
                logger.warning("the object image cannot be written to %s: %s", path, exc)
        return f"camera:{now:.2f}"

    def on_stop(self, outcome: Outcome) -> None:
        if self.pending is not None and not self.pending.done:
            self.pending.cancel()


class DisplayCameraImage(Communicating):
    behavior = "DISPLAY_CAMERA_IMAGE"

    def on_start(self) -> None:
        self.period = float(self.settings.extra.get("display_period", DISPLAY_PERIOD))
        self.shown = 0
        self._last: float | None = None
        self._missing = False

    def on_run(self) -> Outcome | None:
        now = self.now()
        if self._last is not None and now - self._last < self.period - 1e-9:
            return None
        self._last = now
        image = self.call(self.drone.capture_image)
        self._error = ""
        if image is None:
            if not self._missing:
                self._missing = True
                self.context.log.record("operator", self.name, "the drone gives no camera image to display",
                                        action="display", available=False)
            return None
        self.call(operator_of(self.context).display, image)
        if self._error:
            return self.fail(self._error)
        self.shown += 1
        if self.shown == 1 or self._missing:
            self.context.log.record("operator", self.name, "the camera image is shown to the operator",
                                    action="display", available=True, size=len(image))
        self._missing = False
        return None

    def on_stop(self, outcome: Outcome) -> None:
        self.context.log.record("operator", self.name, f"{self.shown} camera images shown",
                                action="display_stopped", images=self.shown)


class SpeakUp(BehaviorProcess):
    """SPEAK_UP CONTENT=TASKS: the behaviors active now, said whenever they change (from the event log)."""

    behavior = "SPEAK_UP"

    def on_start(self) -> None:
        self._lock = threading.Lock()
        self._active: dict[str, None] = {}
        for event in self.context.log.events():
            self._hear(event)
        self._said: str | None = None
        self._unsubscribe = self.context.log.subscribe(self._hear)

    def _hear(self, event: EngineEvent) -> None:
        if not event.behavior or event.behavior == self.name:
            return
        with self._lock:
            if event.kind == "activated":
                self._active[event.behavior] = None
            elif event.kind in _ENDINGS:
                self._active.pop(event.behavior, None)

    def on_run(self) -> Outcome | None:
        with self._lock:
            active = list(self._active)
        sentence = describe_tasks(active)
        if sentence != self._said:
            self._said = sentence
            speak(self.context, self.name, sentence, key=self.name)
        return None

    def on_stop(self, outcome: Outcome) -> None:
        self._unsubscribe()


def describe_tasks(behaviors: list[str]) -> str:
    """A sentence saying what the robot does: ``Now: take off and pay attention to visual markers.``"""
    if not behaviors:
        return "Nothing to do now."
    words = [b.lower().replace("_", " ") for b in behaviors]
    listed = words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]
    return f"Now: {listed}."


class Say(BehaviorProcess):
    behavior = "SAY"

    def on_start(self) -> None:
        self.spoken = speak(self.context, self.name, str(self.arguments["SENTENCE"]))

    def on_run(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED


class BroadcastMessage(BehaviorProcess):
    behavior = "BROADCAST_MESSAGE"

    def on_start(self) -> None:
        text = str(self.arguments["MESSAGE"])
        bus = self.context.bus
        if bus is None:
            self.receivers: list[str] = []
            self.context.log.record("message_sent", self.name, f"{text} (no other drone in this run)",
                                    text=text, receivers=[])
            return
        sender = bus.name_of(self.memory) or bus.join_anonymous(self.memory, self.context.log)
        self.receivers = bus.broadcast(sender, text)
        self.context.log.record("message_sent", self.name, f"to {', '.join(self.receivers) or 'nobody'}: {text}",
                                sender=sender, text=text, receivers=self.receivers)

    def on_run(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED


COMMUNICATION_BEHAVIORS: list[type[BehaviorProcess]] = [NotifyOperator, AskOperator, AskForObjectImage,
                                                        DisplayCameraImage, SpeakUp, Say, BroadcastMessage]
COMMUNICATION_PROCESSES: dict[str, Callable[[str], Process]] = {"speech_synthesizer": SpeechSynthesizer}
