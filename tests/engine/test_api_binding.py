"""The mission API's binding is per mission thread: three engines fly three Python missions side by side."""

import threading

import aeroexec.engine.api as api
import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.engine import Engine


def test_three_engines_run_three_interleaved_missions_each_talking_to_its_own_engine():
    engines = [Engine(SimulatedDrone(seed=i)) for i in range(3)]
    calls: list[tuple[int, str, float]] = []
    lock = threading.Lock()
    turn = threading.Barrier(3, timeout=30)  # the three missions step through their calls together

    def mission_of(index: int):
        def mission() -> None:
            altitude = 1.0 + index
            for step in range(3):
                turn.wait()  # every mission is between two API calls at once: they interleave
                if step == 0:
                    assert api.execute_behavior("TAKE_OFF") == api.GOAL_ACHIEVED
                elif step == 1:
                    _, here = api.consult_belief("position(self, (?X, ?Y, ?Z))")
                    assert api.execute_behavior("GO_TO_POINT", coordinates=[here["?X"], here["?Y"],
                                                                            altitude]) == api.GOAL_ACHIEVED
                    _, there = api.consult_belief("position(self, (?X, ?Y, ?Z))")
                    with lock:
                        calls.append((index, "climbed", there["?Z"]))
                else:
                    api.execute_behavior("LAND")
                with lock:
                    calls.append((index, ["take off", "climb", "land"][step], api.now()))
            _, here = api.consult_belief("position(self, (?X, ?Y, ?Z))")
            with lock:
                calls.append((index, "landed", here["?Z"]))
        return mission

    threads = [threading.Thread(target=engine.run, args=(mission_of(i),), kwargs={"max_time": 300})
               for i, engine in enumerate(engines)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)
    try:
        assert not any(thread.is_alive() for thread in threads)
        for engine in engines:
            assert engine.log.events(kind="mission_completed"), engine.log.events()
            assert not engine.log.events(kind="mission_failed")
        # each engine flew only its own mission: drone i climbed to 1 + i meters, and nobody else's calls reached it
        for engine in engines:
            goals = [e for e in engine.log.events(kind="GOAL_ACHIEVED") if e.behavior == "GO_TO_POINT"]
            assert len(goals) == 1
        climbed = {index: z for index, what, z in calls if what == "climbed"}
        assert climbed == pytest.approx({0: 1.0, 1: 2.0, 2: 3.0}, abs=0.5)
        # the missions' calls interleaved: no mission finished all its steps before another began its second
        order = [index for index, what, _ in calls if what in ("take off", "climb", "land")]
        assert order[:3] != [order[0]] * 3 and sorted(order[:3]) == [0, 1, 2]
        landed = {index: z for index, what, z in calls if what == "landed"}
        assert landed == pytest.approx({0: 0.0, 1: 0.0, 2: 0.0}, abs=0.2)
    finally:
        for engine in engines:
            engine.stop()


def test_a_thread_bound_to_no_engine_is_told_so_when_several_engines_run():
    first, second = Engine(SimulatedDrone()), Engine(SimulatedDrone())
    bound = threading.Barrier(3, timeout=10)
    release = threading.Event()

    def hold(engine: Engine) -> None:
        api.bind(engine)
        bound.wait()
        release.wait(10)
        api.unbind()

    threads = [threading.Thread(target=hold, args=(e,)) for e in (first, second)]
    for thread in threads:
        thread.start()
    bound.wait()
    try:
        with pytest.raises(RuntimeError, match="several engines"):
            api.now()
    finally:
        release.set()
        for thread in threads:
            thread.join(5)
    with pytest.raises(RuntimeError, match="no engine is running"):
        api.now()
