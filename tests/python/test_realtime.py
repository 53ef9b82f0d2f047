"""Real-time scheduling from Python: run_scene's rt_priority (issue 33).

A real-time session (a bridged device) asks for SCHED_FIFO at rt_priority, reports what it got
in stats["realtime"] and how late its sleeps woke in stats["wakeup"]; rt_priority=None asks for
nothing; batch runs never ask; a bad priority is a ValueError naming the argument and range.
"""

import os
import threading
from pathlib import Path

import pytest

import nanohaptics as nh
from nanohaptics import bridge

from test_live import free_port

ROOT = Path(__file__).resolve().parents[2]
WALL = ROOT / "scenes" / "wall.toml"


def bridged(rt_priority):
    port = free_port()
    result = {}

    def sim():
        result.update(nh.run_scene(str(WALL), device=f"udp:127.0.0.1:{port}", wait_s=20.0,
                                   rt_priority=rt_priority))

    t = threading.Thread(target=sim)
    t.start()
    specs = bridge.Specs("falcon", 8.0, 3000.0, 0.04, ["centre", "plus", "minus", "forward"])
    client = bridge.BridgeClient(("127.0.0.1", port), specs, protocol=2)
    try:
        client.connect(20.0)
        for _ in range(100):
            client.send((0.0, 0.0, 0.0))
            client.receive(0.01)
    finally:
        client.close()
    t.join()
    return result["stats"]


def test_batch_runs_never_ask_and_a_bad_priority_names_itself():
    s = nh.run_scene("brickworld", seconds=0.05)["stats"]
    assert s["realtime"]["requested"] is False
    assert s["realtime"]["priority"] is None
    assert s["wakeup"]["max_ns"] == 0
    for bad in (0, 100, -5):
        with pytest.raises(ValueError) as e:
            nh.run_scene("brickworld", seconds=0.05, rt_priority=bad)
        assert str(e.value) == f"rt_priority = {bad} is out of range: allowed 1 to 99"


def test_a_bridged_session_asks_for_real_time_unless_told_not_to():
    s = bridged(60)
    rt = s["realtime"]
    assert rt["requested"] is True
    if os.geteuid() == 0:
        # Root may: SCHED_FIFO at the priority asked for (a container may still refuse).
        assert rt["priority"] == 60 or rt["sched_refused"] == "no_runtime", rt
    else:
        assert rt["priority"] in (None, 60), rt
    off = bridged(None)["realtime"]
    assert off["requested"] is False and off["priority"] is None
