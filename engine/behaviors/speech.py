"""Speech (SPEECH_GENERATION): the ``speech_synthesizer`` process, which speaks with a local text-to-speech
engine (``espeak-ng`` or ``espeak``) when one is installed, and :func:`speak`, which SAY and SPEAK_UP use.

The synthesizer is never waited on: each sentence is a subprocess started with ``Popen`` and polled on the
engine's ticks; sentences said while one is being spoken wait in a short queue; stopping the process kills
the one being spoken. Without a text-to-speech engine, what would be said is logged. Either way the
operator channel gets the transcript and the event log an ``operator`` event (``action=say``).
"""

from __future__ import annotations

import logging
from collections import deque
from typing import TYPE_CHECKING, Any

from aeroexec.engine.execution.resources import Process
from aeroexec.engine.supervision.operator import operator_of

if TYPE_CHECKING:  # imported when a sentence is spoken: the library is imported by every run (~3 ms)
    import subprocess

logger = logging.getLogger(__name__)

TTS_PROGRAMS = ("espeak-ng", "espeak")
MAX_QUEUED = 5  # sentences waiting to be spoken; older ones are dropped beyond this
_ATTRIBUTE = "speech_synthesizer"  # where the running synthesizer is found on the behavior context


def find_tts() -> str | None:
    """The path of the local text-to-speech program, or None."""
    import shutil  # here: only a run that starts the synthesizer looks for one

    for program in TTS_PROGRAMS:
        path = shutil.which(program)
        if path:
            return path
    return None


class SpeechSynthesizer(Process):
    """speech_synthesizer: owns the text-to-speech subprocess."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.program: str | None = None
        self._current: subprocess.Popen | None = None
        self._queue: deque[tuple[str | None, str]] = deque()

    def on_start(self) -> None:
        self.program = find_tts()
        setattr(self.context, _ATTRIBUTE, self)
        detail = (f"text-to-speech with {self.program}" if self.program
                  else "no text-to-speech engine (espeak-ng, espeak): speech is logged")
        self.context.log.record("speech_synthesizer", detail=detail, program=self.program)

    def say(self, text: str, key: str | None = None) -> bool:
        """Queue ``text`` to be spoken; False when there is no text-to-speech engine to speak it.

        A sentence with a ``key`` replaces the ones with the same key still waiting (e.g. stale task reports).
        """
        if self.program is None:
            return False
        if key is not None:
            self._queue = deque(item for item in self._queue if item[0] != key)
        self._queue.append((key, text))
        while len(self._queue) > MAX_QUEUED:
            _, dropped = self._queue.popleft()
            logger.info("too much to say: %r is not spoken", dropped)
        self._next()
        return self.program is not None

    @property
    def speaking(self) -> bool:
        return self._current is not None and self._current.poll() is None

    def step(self, now: float) -> None:
        self._next()

    def _next(self) -> None:
        if self.speaking or not self._queue:
            return
        self._current = None
        _, text = self._queue.popleft()
        import subprocess  # here: only a sentence spoken needs it

        try:
            self._current = subprocess.Popen([self.program, "--", text], stdin=subprocess.DEVNULL,
                                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except OSError as exc:
            logger.warning("%s cannot speak (%s): speech is logged from now on", self.program, exc)
            self.context.log.record("speech_synthesizer", detail=f"{self.program} failed ({exc}): speech is logged")
            self.program = None
            self._queue.clear()

    def on_stop(self) -> None:
        self._queue.clear()
        if self._current is not None and self._current.poll() is None:
            self._current.kill()  # reaped later by the subprocess module; never waited on here
            self._current.poll()
        self._current = None
        if getattr(self.context, _ATTRIBUTE, None) is self:
            setattr(self.context, _ATTRIBUTE, None)


def speak(context: Any, behavior: str, text: str, key: str | None = None) -> bool:
    """Say ``text`` for ``behavior``: out loud when a synthesizer with a text-to-speech engine runs, else logged.

    The operator channel gets the transcript and the event log an ``operator`` event; True when spoken aloud.
    """
    synthesizer = getattr(context, _ATTRIBUTE, None)
    aloud = bool(synthesizer is not None and synthesizer.say(text, key))
    operator_of(context).say(text)
    if not aloud:
        logger.info("%s says: %s", behavior, text)
    context.log.record("operator", behavior, text, action="say", spoken=aloud)
    return aloud
