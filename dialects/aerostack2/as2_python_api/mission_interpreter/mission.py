"""Aerostack2's mission model: ``Mission`` (``target``, ``plan``), ``MissionItem`` (``behavior``, ``method``,
``args``) and the interpreter's status, with the pydantic spellings missions use (``Mission.parse_raw``,
``.json()``). Fields Aerostack2 no longer reads (``verbose``, ``use_sim_time``) are accepted and ignored."""

from __future__ import annotations

import enum
import json
from dataclasses import asdict, dataclass, field
from typing import Any

from aeroexec.dialects.aerostack2 import behaviors as aerostack2
from aeroexec.dialects.aerostack2.as2_msgs.msg import BehaviorStatus


class InterpreterState(enum.IntEnum):
    """Interpreter state."""

    IDLE = BehaviorStatus.IDLE
    RUNNING = BehaviorStatus.RUNNING
    PAUSED = BehaviorStatus.PAUSED

    def __str__(self) -> str:
        return self.name


@dataclass
class MissionItem:
    """Mission Item data model. It represents a behavior call."""

    behavior: str
    method: str = "__call__"
    args: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.behavior, str) or not isinstance(self.method, str) or not isinstance(self.args, dict):
            raise ValueError(f"a mission item is {{behavior: text, method: text, args: {{...}}}}, not "
                             f"{self.behavior!r}, {self.method!r}, {self.args!r}")

    def __str__(self) -> str:
        return f"{self.behavior}: {self.method}: {self.args}"

    @property
    def args_extended(self) -> list[Any]:
        """Every argument of the call in order, defaults filled in (KeyError for a missing one, as Aerostack2)."""
        call = aerostack2.method(self.behavior, self.method)
        try:
            bound = call.bind((), self.args)
        except aerostack2.As2Error as error:
            raise KeyError(error.message) from None
        return [bound[name] for name in call.parameters]


@dataclass
class Mission:
    """Mission data model."""

    target: str
    plan: list[MissionItem] = field(default_factory=list)

    @classmethod
    def parse_obj(cls, data: Any) -> Mission:
        if not isinstance(data, dict) or not isinstance(data.get("target"), str):
            raise ValueError("a mission is {\"target\": drone, \"plan\": [...]}")
        plan = data.get("plan", [])
        if not isinstance(plan, list):
            raise ValueError("the mission's plan is a list of {behavior, method, args}")
        return cls(data["target"], [item if isinstance(item, MissionItem) else
                                    MissionItem(**{k: v for k, v in item.items() if k in ("behavior", "method",
                                                                                          "args")})
                                    for item in plan])

    @classmethod
    def parse_raw(cls, text: str | bytes) -> Mission:
        return cls.parse_obj(json.loads(text))

    model_validate_json = parse_raw
    model_validate = parse_obj

    def dict(self) -> dict[str, Any]:
        return asdict(self)

    def json(self) -> str:
        return json.dumps(self.dict())

    def __str__(self) -> str:
        return self.json()


@dataclass
class InterpreterStatus:
    """Mission status."""

    state: InterpreterState = InterpreterState.IDLE
    pending_items: int = 0
    done_items: int = 0
    current_item: MissionItem | None = None
    feedback_current: Any = None

    @property
    def total_items(self) -> int:
        return self.done_items + (self.current_item is not None) + self.pending_items

    def __str__(self) -> str:
        return f"[{self.state}] [{self.done_items + (self.current_item is not None)}/{self.total_items}] " \
               f"{self.current_item}"
